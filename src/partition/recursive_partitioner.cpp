#include "obsgroup/partition/recursive_partitioner.h"

#include <algorithm>
#include <deque>
#include <stdexcept>

namespace obsgroup {

std::string toString(SplitNode::Kind kind) {
  switch (kind) {
    case SplitNode::Kind::Leaf: return "leaf";
    case SplitNode::Kind::Components: return "components";
    case SplitNode::Kind::Bisection: return "bisection";
  }
  return "?";
}

std::string toString(SplitNode::Outcome outcome) {
  switch (outcome) {
    case SplitNode::Outcome::Accepted: return "accepted";
    case SplitNode::Outcome::NcutAboveThreshold: return "ncut_above_threshold";
    case SplitNode::Outcome::GroupTooSmall: return "group_too_small";
    case SplitNode::Outcome::NoSplit: return "no_split";
    case SplitNode::Outcome::MaxDepth: return "max_depth";
    case SplitNode::Outcome::TooFewNodes: return "too_few_nodes";
  }
  return "?";
}

namespace {

class Partitioner {
 public:
  Partitioner(const WeightMatrix& W, const PartitionOptions& options) : W_(W), options_(options) {}

  Partition run() {
    const int n = static_cast<int>(W_.rows());
    if (n > 0) {
      SplitNode root;
      root.members.resize(n);
      for (int i = 0; i < n; ++i) root.members[i] = i;
      addNode(std::move(root));
    }
    // Breadth-first with a FIFO: the node order (and so the whole output) is
    // deterministic, and deep recursions cannot overflow the stack.
    while (!queue_.empty()) {
      const int id = queue_.front();
      queue_.pop_front();
      process(id);
    }
    return collect(n);
  }

 private:
  void addNode(SplitNode node) {
    queue_.push_back(static_cast<int>(out_.splits.size()));
    out_.splits.push_back(std::move(node));
  }

  void addChild(int parent, std::vector<int> members, int depth) {
    SplitNode child;
    child.members = std::move(members);
    child.parent = parent;
    child.depth = depth;
    out_.splits[parent].children.push_back(static_cast<int>(out_.splits.size()));
    addNode(std::move(child));
  }

  void process(int id) {
    const std::vector<int> members = out_.splits[id].members;  // copy: out_.splits grows below
    const int depth = out_.splits[id].depth;
    if (members.size() < 2) return;  // Leaf / TooFewNodes by default
    const WeightMatrix sub = inducedSubgraph(W_, members);

    // A disconnected graph is split into its components first: their Ncut is
    // 0, and the eigensolver then never meets a repeated zero eigenvalue.
    auto components = connectedComponents(sub);
    if (components.size() > 1) {
      SplitNode& node = out_.splits[id];
      node.kind = SplitNode::Kind::Components;
      node.outcome = SplitNode::Outcome::Accepted;
      node.accepted = true;
      node.ncut = 0.0;
      for (auto& component : components) {
        for (int& local : component) local = members[local];
        addChild(id, std::move(component), depth);
      }
      return;
    }

    const int min_size = std::max(1, options_.min_group_size);
    if (static_cast<int>(members.size()) < 2 * min_size) return;  // TooFewNodes
    if (depth >= options_.max_depth) {
      out_.splits[id].outcome = SplitNode::Outcome::MaxDepth;
      return;
    }

    Bisection b = spectralBisection(sub, options_.split, options_.eigen, min_size);
    SplitNode& node = out_.splits[id];
    node.attempted = true;
    node.ncut = b.cut.ncut;
    node.threshold = b.threshold;
    node.eigenvalue = b.fiedler.eigenvalue;
    node.sparse_solver = b.fiedler.sparse;
    if (options_.keep_eigenvectors) node.eigenvector = std::move(b.fiedler.y);

    std::vector<int> a, rest;
    for (std::size_t k = 0; k < members.size(); ++k) (b.in_a[k] ? a : rest).push_back(members[k]);
    if (!b.valid) {
      node.outcome = SplitNode::Outcome::NoSplit;
    } else if (!(b.cut.ncut < options_.ncut_threshold)) {
      node.outcome = SplitNode::Outcome::NcutAboveThreshold;
    } else if (static_cast<int>(a.size()) < min_size || static_cast<int>(rest.size()) < min_size) {
      node.outcome = SplitNode::Outcome::GroupTooSmall;
    } else {
      node.kind = SplitNode::Kind::Bisection;
      node.outcome = SplitNode::Outcome::Accepted;
      node.accepted = true;
      // The side holding the smallest observation comes first.
      if (rest.front() < a.front()) std::swap(a, rest);
      addChild(id, std::move(a), depth + 1);
      addChild(id, std::move(rest), depth + 1);
    }
  }

  Partition collect(int n) {
    for (const SplitNode& node : out_.splits)
      if (!node.accepted) out_.groups.push_back(node.members);
    std::sort(out_.groups.begin(), out_.groups.end(),
              [](const std::vector<int>& a, const std::vector<int>& b) { return a.front() < b.front(); });
    out_.group_of.assign(n, -1);
    for (std::size_t g = 0; g < out_.groups.size(); ++g)
      for (int i : out_.groups[g]) out_.group_of[i] = static_cast<int>(g);
    return std::move(out_);
  }

  const WeightMatrix& W_;
  const PartitionOptions& options_;
  Partition out_;
  std::deque<int> queue_;
};

}  // namespace

Partition recursivePartition(const WeightMatrix& W, const PartitionOptions& options) {
  if (W.rows() != W.cols()) throw std::invalid_argument("recursivePartition: W must be square");
  if (!(options.ncut_threshold >= 0.0))
    throw std::invalid_argument("recursivePartition: the Ncut threshold must be >= 0");
  return Partitioner(W, options).run();
}

}  // namespace obsgroup
