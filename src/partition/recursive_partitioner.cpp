#include "obsgroup/partition/recursive_partitioner.h"

#include "obsgroup/common/parallel_for.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <unordered_map>

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
    case SplitNode::Outcome::EigenSolverFailed: return "eigen_solver_failed";
  }
  return "?";
}

namespace {

/// What to do with one node of the split tree: its own fields, and the
/// member lists of its children.
struct Decision {
  SplitNode node;  // members, parent and depth unchanged; the rest decided
  std::vector<std::vector<int>> children;
  int child_depth = 0;
  std::string warning;  // empty, or what the user should know about this node
  bool from_cache = false;  // copied from SplitCache
};

/// A node's members (by stable id) as a hash key.
std::uint64_t nodeKey(const std::vector<int>& member_ids) {
  std::uint64_t h = 1469598103934665603ull;
  for (int id : member_ids) h = (h ^ std::uint64_t(std::uint32_t(id))) * 1099511628211ull;
  return h ^ (std::uint64_t(member_ids.size()) << 32);
}

/// What the partitioner reuses and records: the ids of W's nodes, the nodes
/// at one end of every entry that changed (sources), and the decisions of
/// the previous and of this run.
struct Reuse {
  const std::vector<int>& ids;
  const std::vector<char>& sources;
  SplitCache::Store& previous;  // a copied decision is moved on to `next` when recorded
  SplitCache::Store& next;
  std::vector<FiedlerWorkspace>& workspaces;  // kept from one run to the next
};

}  // namespace

/// A decision with its members and children given by stable id.
struct SplitCache::Store {
  struct Entry {
    std::vector<int> member_ids;
    int depth = 0;
    Decision decision;  // children by id
    std::uint64_t key = 0;  // nodeKey(member_ids)
  };
  std::unordered_map<std::uint64_t, std::vector<Entry>> entries;
  std::size_t reused = 0, computed = 0;
  /// Nodes solved ahead of their level (Partitioner::guessPath): all, and
  /// those whose decision the run then took.
  std::size_t ahead = 0, ahead_used = 0;
  /// Filled by a run that checked every row of its W (checkWeights), or
  /// whose unchanged rows an earlier such run had checked.
  bool weights_checked = false;
  /// The mutual-neighbour count of the run and each node's threshold, by
  /// id (ascending): the next run finds from them which kept entries moved
  /// (keptEntrySources).
  int neighbour_count = 0;
  std::vector<int> threshold_ids;
  std::vector<double> thresholds;
  /// The ids of the run's nodes (ascending): which members of a node are
  /// new since (Partitioner::guessPath).
  std::vector<int> ids;

  /// The decision of the node with these members at `depth`, or at any
  /// depth when both lie below `max_depth`: there a node's decision does
  /// not depend on its depth, which only numbers its children (an insert
  /// that adds a split above a part of the tree moves that part a level
  /// down, and its nodes are still the same).
  Entry* find(const std::vector<int>& member_ids, int depth, int max_depth) {
    const auto it = entries.find(nodeKey(member_ids));
    if (it == entries.end()) return nullptr;
    for (Entry& e : it->second)
      if ((e.depth == depth || (depth < max_depth && e.depth < max_depth)) && e.member_ids == member_ids) return &e;
    return nullptr;
  }
  void add(std::vector<int> member_ids, int depth, Decision decision) {
    const std::uint64_t key = nodeKey(member_ids);
    entries[key].push_back({std::move(member_ids), depth, std::move(decision), key});
  }
  /// Moves over an entry of another store, whose decision a run copied.
  void take(Entry& entry) {
    const std::uint64_t key = entry.key;
    entries[key].push_back(std::move(entry));
  }
};

SplitCache::SplitCache()
    : store_(std::make_shared<Store>()), workspaces_(std::make_shared<std::vector<FiedlerWorkspace>>()),
      kept_(std::make_shared<WeightMatrix>()) {}
void SplitCache::clear() { *store_ = Store{}; }
std::size_t SplitCache::reusedNodes() const { return store_->reused; }
std::size_t SplitCache::computedNodes() const { return store_->computed; }
std::size_t SplitCache::aheadNodes() const { return store_->ahead; }
std::size_t SplitCache::aheadNodesUsed() const { return store_->ahead_used; }

namespace {

/// The elimination ranks the user gave for the whole graph, or none: then
/// each node's Fiedler solve orders its own block (AMD), so that a node's
/// decision depends on its block of W alone (SplitCache relies on it).
/// Measured on 10,000-scan route graphs: see docs/performance.md.
std::vector<int> eliminationRanks(const WeightMatrix& W, const FiedlerOptions& eigen) {
  if (eigen.elimination_rank.empty()) return {};
  if (Eigen::Index(eigen.elimination_rank.size()) != W.rows())
    throw std::invalid_argument("recursivePartition: elimination_rank needs one rank per observation");
  return eigen.elimination_rank;
}

/// What each thread of a level of the split tree works with.
struct NodeScratch {
  std::vector<int> local_of;     // inducedSubgraph's
  FiedlerWorkspace* workspace;   // this thread's, kept over the levels
};

class Partitioner {
 public:
  Partitioner(const WeightMatrix& W, const PartitionOptions& options, Reuse* reuse = nullptr)
      : W_(W), options_(options), rank_(eliminationRanks(W, options.eigen)), reuse_(reuse),
        workspaces_(reuse ? reuse->workspaces : own_workspaces_) {
    // One workspace per thread a level can run on, so that every node's
    // eigen solve reuses the buffers of the solves before it on its thread.
    const std::size_t threads = std::size_t(threadCount(options.threads));
    if (workspaces_.size() < threads) workspaces_.resize(threads);
    if (reuse_ && !reuse_->ids.empty()) {
      index_of_id_.assign(std::size_t(reuse_->ids.back()) + 1, -1);
      for (std::size_t k = 0; k < reuse_->ids.size(); ++k) index_of_id_[std::size_t(reuse_->ids[k])] = int(k);
    }
  }

  Partition run() {
    const int n = static_cast<int>(W_.rows());
    speculate_ = reuse_ != nullptr && threadCount(options_.threads) > 1 && !reuse_->previous.ids.empty();
    std::vector<int> frontier;
    if (n > 0) {
      SplitNode root;
      root.members.resize(n);
      for (int i = 0; i < n; ++i) root.members[i] = i;
      out_.splits.push_back(std::move(root));
      frontier.push_back(0);
    }
    // Breadth-first, one level at a time: the nodes of a level are decided in
    // parallel, then their children are numbered in level order, exactly as a
    // FIFO would: the output is the same for any thread count, and deep
    // recursions cannot overflow the stack.
    while (!frontier.empty()) {
      throwIfInterrupted(options_.interrupt);
      std::vector<Decision> decisions(frontier.size());
      // The previous run's decisions are copied here, and only the nodes left
      // to solve are shared out: online, that is mostly one node a level,
      // which then runs on this thread without an OpenMP team.
      std::vector<std::size_t> to_solve;
      std::vector<SplitCache::Store::Entry*> copied(frontier.size(), nullptr);
      for (std::size_t k = 0; k < frontier.size(); ++k)
        if (!copyCachedDecision(out_.splits[frontier[k]], decisions[k], copied[k]) &&
            !takeGuessed(out_.splits[frontier[k]], decisions[k]))
          to_solve.push_back(k);
      // Online, the nodes to solve form a path, one node a level, each
      // known only once its parent is decided. The previous run's tree
      // says what the path most likely is: its nodes are solved now, beside
      // this level's, on the other threads (see guessPath).
      std::vector<SplitNode> guesses;
      if (speculate_)
        for (std::size_t k : to_solve) guessPath(out_.splits[frontier[k]], guesses);
      std::vector<Decision> guessed(guesses.size());
      // Each thread has its own scratch for inducedSubgraph and its own
      // workspace, taken in turn (not by OpenMP's thread number: a level run
      // on the calling thread may be inside a caller's own team); the first
      // failing node's exception is rethrown unchanged (an input error stays one).
      std::atomic<std::size_t> next_workspace{0};
      parallelForWithScratch(
          to_solve.size() + guesses.size(), options_.threads, 1,
          [&] { return NodeScratch{std::vector<int>(n, -1), &workspaces_.at(next_workspace++)}; },
          [&](std::size_t j, NodeScratch& scratch) {
            if (j >= to_solve.size()) {
              guessed[j - to_solve.size()] = decide(guesses[j - to_solve.size()], scratch);
              return;
            }
            const std::size_t k = to_solve[j];
            decisions[k] = decide(out_.splits[frontier[k]], scratch);
          });
      for (std::size_t g = 0; g < guesses.size(); ++g)
        addGuessed(idsOf(guesses[g].members), guesses[g].depth, std::move(guessed[g]));
      if (reuse_) reuse_->next.ahead += guesses.size();
      std::vector<int> next;
      for (std::size_t k = 0; k < frontier.size(); ++k) {
        const int id = frontier[k];
        Decision& d = decisions[k];
        if (reuse_) record(out_.splits[id], d, copied[k]);
        if (!d.warning.empty()) out_.warnings.push_back(std::move(d.warning));
        d.node.members = std::move(out_.splits[id].members);
        d.node.parent = out_.splits[id].parent;
        d.node.depth = out_.splits[id].depth;
        out_.splits[id] = std::move(d.node);
        for (auto& members : d.children) {
          SplitNode child;
          child.members = std::move(members);
          child.parent = id;
          child.depth = d.child_depth;
          out_.splits[id].children.push_back(static_cast<int>(out_.splits.size()));
          next.push_back(static_cast<int>(out_.splits.size()));
          out_.splits.push_back(std::move(child));
        }
      }
      frontier = std::move(next);
    }
    return collect(n);
  }

 private:
  std::vector<int> idsOf(const std::vector<int>& members) const {
    std::vector<int> ids(members.size());
    for (std::size_t k = 0; k < members.size(); ++k) ids[k] = reuse_->ids[members[k]];
    return ids;
  }

  /// The previous run's decision of this node, when none of its members is
  /// a source: every entry that changed has a source at one end, so none of
  /// its block did, and its block of W, hence its decision, is the same.
  bool copyCachedDecision(const SplitNode& current, Decision& d, SplitCache::Store::Entry*& copied) const {
    if (!reuse_) return false;
    for (int i : current.members)
      if (reuse_->sources[i]) return false;
    SplitCache::Store::Entry* entry = reuse_->previous.find(idsOf(current.members), current.depth, options_.max_depth);
    if (!entry) return false;
    d = entry->decision;
    d.child_depth += current.depth - entry->depth;
    // A child's members are the node's, each of them in the graph.
    for (auto& child : d.children)
      for (int& member : child) member = index_of_id_[std::size_t(member)];
    d.from_cache = true;
    copied = entry;
    return true;
  }

  /// The decision of a node solved ahead (guessPath) with exactly these
  /// members: a node's decision depends on its block of W alone, so it is
  /// the one this node would get. Below max_depth a node's depth only
  /// numbers its children, so one solved at another depth serves too, its
  /// children's depth moved by the difference.
  bool takeGuessed(const SplitNode& current, Decision& d) {
    if (!speculate_ || guessed_.empty()) return false;
    Guessed* guess = findGuessed(idsOf(current.members), current.depth);
    if (!guess) return false;
    d = std::move(guess->decision);
    d.child_depth += current.depth - guess->depth;
    guess->member_ids.clear();  // taken: no node is visited twice in a run
    ++reuse_->next.ahead_used;
    return true;
  }

  struct Guessed {
    std::vector<int> member_ids;
    int depth;
    Decision decision;
  };
  void addGuessed(std::vector<int> member_ids, int depth, Decision decision) {
    const std::uint64_t key = nodeKey(member_ids);
    guessed_[key].push_back({std::move(member_ids), depth, std::move(decision)});
  }
  /// A node solved ahead with these members whose decision holds at `depth`.
  Guessed* findGuessed(const std::vector<int>& member_ids, int depth) {
    const auto it = guessed_.find(nodeKey(member_ids));
    if (it == guessed_.end()) return nullptr;
    const int max_depth = options_.max_depth;
    for (Guessed& g : it->second)
      if (g.member_ids == member_ids && (g.depth == depth || (g.depth < max_depth && depth < max_depth))) return &g;
    return nullptr;
  }

  /// Guesses the nodes below `node` (about to be solved) that will need
  /// solving: the previous run's children of the node it was then (its
  /// members without the new ones, at any depth below max_depth), each new member
  /// joining the child it is most strongly linked to; then the same below
  /// each guessed child holding a source, down to the leaves. Appends to
  /// `guesses` those not solved or guessed already.
  void guessPath(const SplitNode& node, std::vector<SplitNode>& guesses) {
    const std::vector<int>& previous_ids = reuse_->previous.ids;
    const auto was_there = [&previous_ids](int id) {
      return std::binary_search(previous_ids.begin(), previous_ids.end(), id);
    };
    struct Pending {
      std::vector<int> old_members, fresh;  // current indices: in the previous run, and new since
      int depth;
    };
    std::vector<Pending> pending(1);
    for (int i : node.members) (was_there(reuse_->ids[i]) ? pending[0].old_members : pending[0].fresh).push_back(i);
    pending[0].depth = node.depth;
    if (child_of_.size() != std::size_t(W_.rows())) child_of_.assign(std::size_t(W_.rows()), -1);
    while (!pending.empty()) {
      Pending at = std::move(pending.back());
      pending.pop_back();
      const auto* entry = reuse_->previous.find(idsOf(at.old_members), at.depth, options_.max_depth);
      if (!entry || entry->decision.children.size() < 2) continue;
      const auto& children = entry->decision.children;  // by id
      std::vector<std::vector<int>> old_children(children.size()), predicted(children.size());
      for (std::size_t c = 0; c < children.size(); ++c)
        for (int id : children[c]) {
          const int i = std::size_t(id) < index_of_id_.size() ? index_of_id_[std::size_t(id)] : -1;
          if (i < 0) continue;  // no longer in the graph
          old_children[c].push_back(i);
          child_of_[std::size_t(i)] = int(c);
        }
      // New members join the child they weigh most to; those linked only
      // to other new ones in a second pass.
      std::vector<int> unplaced = at.fresh;
      std::vector<double> weight(children.size());
      for (int pass = 0; pass < 2 && !unplaced.empty(); ++pass) {
        std::vector<int> left;
        for (int i : unplaced) {
          std::fill(weight.begin(), weight.end(), 0.0);
          for (WeightMatrix::InnerIterator it(W_, i); it; ++it) {
            const int c = child_of_[std::size_t(it.row())];
            if (it.row() != i && c >= 0) weight[std::size_t(c)] += it.value();
          }
          const auto best = std::max_element(weight.begin(), weight.end());
          if (*best > 0.0) {
            predicted[std::size_t(best - weight.begin())].push_back(i);
            child_of_[std::size_t(i)] = int(best - weight.begin());
          } else {
            left.push_back(i);
          }
        }
        unplaced = std::move(left);
      }
      for (const auto& child : old_children)
        for (int i : child) child_of_[std::size_t(i)] = -1;
      for (const auto& child : predicted)
        for (int i : child) child_of_[std::size_t(i)] = -1;
      if (!unplaced.empty()) continue;  // the guess would miss members: none of its children is right
      // Each child holding a source will be solved (the others are cached):
      // guessed, and followed down.
      const int child_depth = at.depth + (entry->decision.child_depth - entry->depth);
      for (std::size_t c = 0; c < children.size(); ++c) {
        SplitNode guess;
        guess.members = old_children[c];
        guess.members.insert(guess.members.end(), predicted[c].begin(), predicted[c].end());
        std::sort(guess.members.begin(), guess.members.end());
        guess.depth = child_depth;
        if (std::none_of(guess.members.begin(), guess.members.end(), [this](int i) { return reuse_->sources[i] != 0; }))
          continue;
        pending.push_back({std::move(old_children[c]), std::move(predicted[c]), child_depth});
        if (findGuessed(idsOf(guess.members), child_depth)) continue;
        bool listed = false;
        for (const SplitNode& g : guesses) listed = listed || (g.depth == child_depth && g.members == guess.members);
        if (!listed) guesses.push_back(std::move(guess));
      }
    }
  }

  /// Keeps this node's decision, by ids, for the next run: a copied one is
  /// moved over from the previous run's (no node is visited twice in a run).
  void record(const SplitNode& current, const Decision& d, SplitCache::Store::Entry* copied) {
    if (d.from_cache) {
      // The entry it was copied from holds this node's ids: moved over, at this node's depth.
      copied->decision.child_depth = d.child_depth;
      copied->depth = current.depth;
      reuse_->next.take(*copied);
      ++reuse_->next.reused;
      return;
    }
    Decision kept = d;
    kept.from_cache = false;
    for (auto& child : kept.children) child = idsOf(child);
    reuse_->next.add(idsOf(current.members), current.depth, std::move(kept));
    ++reuse_->next.computed;
  }

  Decision decide(const SplitNode& current, NodeScratch& scratch) const {
    Decision d;
    const std::vector<int>& members = current.members;
    d.child_depth = current.depth;
    if (members.size() < 2) return d;  // Leaf / TooFewNodes by default
    // The root's block is W itself (its members are every node, ascending):
    // no copy of the largest matrix of the run.
    WeightMatrix copied;
    const bool whole = Eigen::Index(members.size()) == W_.rows();
    if (!whole) copied = inducedSubgraph(W_, members, scratch.local_of);
    const WeightMatrix& sub = whole ? W_ : copied;
    if (splitIntoComponents(sub, members, d)) return d;
    const int min_size = std::max(1, options_.min_group_size);
    if (static_cast<int>(members.size()) < 2 * min_size) return d;  // TooFewNodes
    if (current.depth >= options_.max_depth) {
      d.node.outcome = SplitNode::Outcome::MaxDepth;
      return d;
    }
    Bisection b;
    if (!bisect(sub, members, min_size, *scratch.workspace, b, d)) return d;
    judgeBisection(b, members, min_size, current.depth, d);
    return d;
  }

  /// A disconnected graph is split into its components first: their Ncut is
  /// 0, and the eigensolver then never meets a repeated zero eigenvalue.
  static bool splitIntoComponents(const WeightMatrix& sub, const std::vector<int>& members, Decision& d) {
    auto components = connectedComponents(sub);
    if (components.size() < 2) return false;
    d.node.kind = SplitNode::Kind::Components;
    d.node.outcome = SplitNode::Outcome::Accepted;
    d.node.accepted = true;
    d.node.ncut = 0.0;
    for (auto& component : components) {
      for (int& local : component) local = members[local];
      d.children.push_back(std::move(component));
    }
    return true;
  }

  /// The spectral bisection of a connected node (sec. II-A), recorded in the
  /// node; false when no eigenvector could be trusted (the node stays whole).
  bool bisect(const WeightMatrix& sub, const std::vector<int>& members, int min_size, FiedlerWorkspace& workspace,
              Bisection& b, Decision& d) const {
    FiedlerOptions eigen = options_.eigen;
    eigen.elimination_rank.clear();
    if (!rank_.empty())
      for (int i : members) eigen.elimination_rank.push_back(rank_[i]);
    try {
      b = spectralBisection(sub, options_.split, eigen, min_size, workspace);
    } catch (const EigenSolverError& e) {
      // A group left whole is a usable, if coarse, answer; an unchecked
      // eigenvector is not.
      d.node.outcome = SplitNode::Outcome::EigenSolverFailed;
      d.warning = std::string(e.what()) + "; a group of " + std::to_string(members.size()) +
                  " observations (first " + std::to_string(members.front()) + ") was kept whole";
      return false;
    }
    d.node.attempted = true;
    d.node.solver_fell_back = b.fiedler.fell_back;
    if (b.fiedler.fell_back)
      d.warning = "Lanczos did not converge on a group of " + std::to_string(members.size()) +
                  " observations (first " + std::to_string(members.front()) + "); the dense solver was used";
    d.node.ncut = b.cut.ncut;
    d.node.threshold = b.threshold;
    d.node.eigenvalue = b.fiedler.eigenvalue;
    d.node.sparse_solver = b.fiedler.sparse;
    if (options_.keep_eigenvectors) d.node.eigenvector = std::move(b.fiedler.y);
    return true;
  }

  /// Accepts the bisection while Ncut < the threshold and both sides are
  /// large enough (sec. II-B), else says why not.
  void judgeBisection(const Bisection& b, const std::vector<int>& members, int min_size, int depth,
                      Decision& d) const {
    std::vector<int> a, rest;
    for (std::size_t k = 0; k < members.size(); ++k) (b.in_a[k] ? a : rest).push_back(members[k]);
    if (!b.valid) {
      d.node.outcome = SplitNode::Outcome::NoSplit;
    } else if (!(b.cut.ncut < options_.ncut_threshold)) {
      d.node.outcome = SplitNode::Outcome::NcutAboveThreshold;
    } else if (static_cast<int>(a.size()) < min_size || static_cast<int>(rest.size()) < min_size) {
      d.node.outcome = SplitNode::Outcome::GroupTooSmall;
    } else {
      d.node.kind = SplitNode::Kind::Bisection;
      d.node.outcome = SplitNode::Outcome::Accepted;
      d.node.accepted = true;
      // The side holding the smallest observation comes first.
      if (rest.front() < a.front()) std::swap(a, rest);
      d.children = {std::move(a), std::move(rest)};
      d.child_depth = depth + 1;
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
  const std::vector<int> rank_;  // see eliminationRanks
  Reuse* reuse_;
  bool speculate_ = false;            // solve the likely path ahead (guessPath)
  std::unordered_map<std::uint64_t, std::vector<Guessed>> guessed_;  // decisions solved ahead, by ids
  std::vector<int> child_of_;         // guessPath's scratch: a node's child, or -1
  std::vector<int> index_of_id_;      // the node of each id in the graph, or -1
  std::vector<FiedlerWorkspace> own_workspaces_;  // this run's, unless the cache keeps them
  std::vector<FiedlerWorkspace>& workspaces_;
  Partition out_;
};

/// W(col, row) when W holds it, else nullptr: a binary search of column
/// `row`, whose row indices Eigen keeps ascending.
const double* mirrorEntry(const WeightMatrix& W, Eigen::Index row, Eigen::Index col) {
  const int* inner = W.innerIndexPtr();
  const Eigen::Index begin = W.outerIndexPtr()[row];
  const Eigen::Index end = W.isCompressed() ? W.outerIndexPtr()[row + 1] : begin + W.innerNonZeroPtr()[row];
  const int* found = std::lower_bound(inner + begin, inner + end, int(col));
  return found != inner + end && *found == col ? W.valuePtr() + (found - inner) : nullptr;
}

/// Weights are overlaps: finite, non-negative and symmetric. Anything else
/// would make Ncut meaningless, so it is refused rather than partitioned.
/// Each entry's mirror is looked up in place: a transposed copy of W would
/// be the largest allocation of a large run's partition. With `rows`, only
/// the rows flagged in it (and the mirrors of their entries) are checked.
void checkWeights(const WeightMatrix& W, const std::vector<char>* rows = nullptr) {
  for (Eigen::Index c = 0; c < W.outerSize(); ++c) {
    if (rows && !(*rows)[std::size_t(c)]) continue;
    for (WeightMatrix::InnerIterator it(W, c); it; ++it) {
      const double w = it.value();
      if (!std::isfinite(w) || w < 0.0)
        throw std::invalid_argument("recursivePartition: W(" + std::to_string(it.row()) + ", " +
                                    std::to_string(it.col()) + ") = " + std::to_string(w) +
                                    " is not a finite, non-negative weight");
      const double* mirror = mirrorEntry(W, it.row(), c);
      if (!mirror || std::abs(w - *mirror) > 1e-9 * std::max(1.0, w))
        throw std::invalid_argument("recursivePartition: W is not symmetric near (" +
                                    std::to_string(it.row()) + ", " + std::to_string(it.col()) + ")");
    }
  }
}

/// PartitionOptions::boundary_passes: each observation joins the group with
/// the highest mean weight to it (its own group counted without itself),
/// every observation decided from the previous sweep's groups, so that the
/// result does not depend on an order of visit; a tie keeps the observation
/// where it is, else goes to the lowest group index. O(passes * nnz(W)).
/// With a minimum group size above 1, a move that would leave its group
/// smaller is not made (observations in index order), so that the groups keep
/// the size the tree guaranteed; with 1, a group may empty and disappear.
void refineBoundaries(const WeightMatrix& W, int passes, int min_size, int threads, Partition& p) {
  const int n = static_cast<int>(W.rows());
  std::vector<int> group_of = p.group_of;
  const int k_groups = static_cast<int>(p.groups.size());
  // An observation's choice depends on its row, its neighbours' groups and
  // the sizes of those groups and its own. After the first sweep only the
  // observations that moved, their neighbours and the members of a group
  // whose size changed (and those members' neighbours) can choose otherwise:
  // the others are not visited again, their choice would be the same (to
  // stay). With a minimum size above 1 a choice also depends on the moves
  // before it in the sweep, and every sweep visits all, in order.
  std::vector<char> visit(std::size_t(n), 1);
  std::vector<int> size(k_groups, 0);
  for (int g : group_of) ++size[g];
  struct Scratch {
    std::vector<double> sum;
    std::vector<int> touched;
  };
  const auto makeScratch = [k_groups] { return Scratch{std::vector<double>(std::size_t(k_groups), 0.0), {}}; };
  // The group with the highest mean weight to i, its own counted without i.
  const auto bestGroup = [&](int i, Scratch& s) {
    std::vector<double>& sum = s.sum;
    std::vector<int>& touched = s.touched;
    touched.clear();
    for (WeightMatrix::InnerIterator it(W, i); it; ++it) {
      if (it.row() == i) continue;  // the diagonal says nothing of i's group
      const int g = group_of[it.row()];
      if (sum[g] == 0.0) touched.push_back(g);
      sum[g] += it.value();
    }
    const int own = group_of[i];
    const double own_mean = size[own] > 1 ? sum[own] / (size[own] - 1) : 0.0;
    int best = own;
    double best_mean = own_mean;
    std::sort(touched.begin(), touched.end());
    for (int g : touched) {
      if (g == own) continue;
      const double mean = sum[g] / size[g];
      if (mean > best_mean) best = g, best_mean = mean;
    }
    for (int g : touched) sum[g] = 0.0;
    return best;
  };
  // Without a minimum size the observations of a sweep are independent:
  // decided on every thread in blocks, the moves then read in order.
  constexpr int kBlock = 1024;
  const bool in_parallel = min_size <= 1 && n > kBlock && threadCount(threads) > 1;
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<int> next = group_of;
    std::vector<int> moves;
    if (in_parallel) {
      const std::size_t blocks = std::size_t((n + kBlock - 1) / kBlock);
      parallelForWithScratch(blocks, threads, 1, makeScratch, [&](std::size_t b, Scratch& s) {
        const int end = std::min(n, int(b + 1) * kBlock);
        for (int i = int(b) * kBlock; i < end; ++i)
          if (visit[std::size_t(i)]) next[i] = bestGroup(i, s);
      });
      for (int i = 0; i < n; ++i)
        if (next[i] != group_of[i]) moves.push_back(i);
    } else {
      Scratch s = makeScratch();
      std::vector<int> remaining = size;  // as the moves of this sweep leave them
      for (int i = 0; i < n; ++i) {
        if (!visit[std::size_t(i)]) continue;
        const int own = group_of[i], best = bestGroup(i, s);
        if (best == own || (min_size > 1 && remaining[own] - 1 < min_size)) continue;
        --remaining[own];
        next[i] = best;
        moves.push_back(i);
      }
    }
    if (moves.empty()) break;
    std::vector<char> resized(std::size_t(k_groups), 0);
    for (int i : moves) {
      resized[std::size_t(group_of[i])] = resized[std::size_t(next[i])] = 1;
      --size[group_of[i]];
      ++size[next[i]];
    }
    group_of = std::move(next);
    if (min_size > 1) continue;  // every observation visited again
    std::fill(visit.begin(), visit.end(), 0);
    const auto visitWithNeighbours = [&](int i) {
      visit[std::size_t(i)] = 1;
      for (WeightMatrix::InnerIterator it(W, i); it; ++it) visit[std::size_t(it.row())] = 1;
    };
    for (int i : moves) visitWithNeighbours(i);
    for (int i = 0; i < n; ++i)
      if (resized[std::size_t(group_of[i])]) visitWithNeighbours(i);
  }
  std::vector<std::vector<int>> groups(k_groups);
  for (int i = 0; i < n; ++i) groups[group_of[i]].push_back(i);
  groups.erase(std::remove_if(groups.begin(), groups.end(), [](const std::vector<int>& g) { return g.empty(); }),
               groups.end());
  std::sort(groups.begin(), groups.end(),
            [](const std::vector<int>& a, const std::vector<int>& b) { return a.front() < b.front(); });
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (int i : groups[g]) group_of[i] = static_cast<int>(g);
  p.groups = std::move(groups);
  p.group_of = std::move(group_of);
}

void checkOptions(const PartitionOptions& options) {
  if (!(options.ncut_threshold >= 0.0))
    throw std::invalid_argument("recursivePartition: the Ncut threshold must be >= 0");
  if (options.boundary_passes < 0)
    throw std::invalid_argument("recursivePartition: boundary_passes must be >= 0");
  if (options.mutual_neighbours < 0)
    throw std::invalid_argument("recursivePartition: mutual_neighbours must be >= 0");
  if (!(options.mutual_neighbours_share >= 0.0) || !std::isfinite(options.mutual_neighbours_share))
    throw std::invalid_argument("recursivePartition: mutual_neighbours_share must be finite and >= 0");
}

/// The sources of the changes of the mutual-neighbour graph since the run
/// `last` recorded: an entry kept or dropped changes when W_ij does (a
/// source at one end, the caller's) or when the threshold of i or j moves,
/// which an edge entering or leaving a row's k strongest does without a
/// source. Each entry of W whose ends are no source and which the thresholds
/// kept before but not now, or the reverse, makes one of its ends a source.
/// Every node is one when k changed or the cache holds no run.
std::vector<char> keptEntrySources(const WeightMatrix& W, const std::vector<char>& sources,
                                   const std::vector<double>& before, const std::vector<double>& thresholds, int k,
                                   const SplitCache::Store& last) {
  std::vector<char> out = sources;
  if (last.neighbour_count != k) return std::vector<char>(sources.size(), 1);
  for (Eigen::Index j = 0; j < W.outerSize(); ++j) {
    const auto sj = std::size_t(j);
    if (out[sj] || before[sj] == thresholds[sj]) continue;
    if (std::isnan(before[sj])) {  // new to the graph yet no source: nothing to compare it with
      out[sj] = 1;
      continue;
    }
    for (WeightMatrix::InnerIterator it(W, j); it; ++it) {
      const auto si = std::size_t(it.index());
      if (si == sj || sources[si] || out[si]) continue;  // the diagonal stays; an end is a source already
      const double w = it.value();
      const bool was_kept = w >= before[sj] && w >= before[si];
      const bool is_kept = w >= thresholds[sj] && w >= thresholds[si];
      if (was_kept != is_kept) {
        out[sj] = 1;
        break;
      }
    }
  }
  return out;
}

/// Each node's neighbour threshold in the run `last` recorded, by id; NaN
/// for a node it did not hold.
std::vector<double> thresholdsBefore(const std::vector<int>& ids, const SplitCache::Store& last) {
  std::vector<double> before(ids.size(), std::numeric_limits<double>::quiet_NaN());
  std::size_t at = 0;
  for (std::size_t n = 0; n < ids.size(); ++n) {
    while (at < last.threshold_ids.size() && last.threshold_ids[at] < ids[n]) ++at;
    if (at < last.threshold_ids.size() && last.threshold_ids[at] == ids[n]) before[n] = last.thresholds[at];
  }
  return before;
}

/// The mutual-neighbour count of these options on W; 0: W is used as it is.
int neighbourCount(const WeightMatrix& W, const PartitionOptions& options) {
  if (options.mutual_neighbours == 0) return 0;
  return mutualNeighbourCount(W, options.mutual_neighbours, options.mutual_neighbours_share);
}

}  // namespace

Partition recursivePartition(const WeightMatrix& W, const PartitionOptions& options) {
  if (W.rows() != W.cols()) throw std::invalid_argument("recursivePartition: W must be square");
  checkOptions(options);
  checkWeights(W);
  const int k = neighbourCount(W, options);
  WeightMatrix kept;
  if (k > 0) kept = mutualNeighbourGraph(W, neighbourThresholds(W, k));
  const WeightMatrix& graph = k > 0 ? kept : W;
  Partition partition = Partitioner(graph, options).run();
  if (options.boundary_passes > 0)
    refineBoundaries(graph, options.boundary_passes, std::max(1, options.min_group_size), options.threads, partition);
  return partition;
}

Partition recursivePartition(const WeightMatrix& W, const PartitionOptions& options, const std::vector<int>& ids,
                             const std::vector<char>& changed, SplitCache& cache) {
  return recursivePartition(W, options, ids, changed, changed, cache);
}

Partition recursivePartition(const WeightMatrix& W, const PartitionOptions& options, const std::vector<int>& ids,
                             const std::vector<char>& changed, const std::vector<char>& sources, SplitCache& cache) {
  if (W.rows() != W.cols()) throw std::invalid_argument("recursivePartition: W must be square");
  checkOptions(options);
  if (!options.eigen.elimination_rank.empty())
    throw std::invalid_argument("recursivePartition: a split cache needs each node to order itself (no elimination_rank)");
  if (Eigen::Index(ids.size()) != W.rows() || Eigen::Index(changed.size()) != W.rows() ||
      Eigen::Index(sources.size()) != W.rows())
    throw std::invalid_argument("recursivePartition: one id, one changed flag and one source flag per node expected");
  if (!std::is_sorted(ids.begin(), ids.end()) || std::adjacent_find(ids.begin(), ids.end()) != ids.end())
    throw std::invalid_argument("recursivePartition: node ids must ascend");
  // The rows that did not change were checked by the run that filled the
  // cache (or one before it): at 10,000 scans, checking all of W was about
  // 5% of an online update.
  try {
    checkWeights(W, cache.store_->weights_checked ? &changed : nullptr);
  } catch (...) {
    cache.clear();  // the caller may not flag the refused rows again: the next run checks them all
    throw;
  }
  auto next = std::make_shared<SplitCache::Store>();
  next->weights_checked = true;
  next->ids = ids;
  const int k = neighbourCount(W, options);
  WeightMatrix& kept = *cache.kept_;
  std::vector<char> moved_sources;
  if (k > 0) {
    // A row that did not change has the threshold it had, for the same k.
    const SplitCache::Store& last = *cache.store_;
    const std::vector<double> before = thresholdsBefore(ids, last);
    std::vector<double> thresholds = before;
    std::vector<char> rows = changed;
    for (std::size_t n = 0; n < ids.size(); ++n)
      if (last.neighbour_count != k || std::isnan(before[n])) rows[n] = 1;
    updateNeighbourThresholds(W, k, rows, thresholds);
    mutualNeighbourGraph(W, thresholds, kept);
    moved_sources = keptEntrySources(W, sources, before, thresholds, k, last);
    next->neighbour_count = k;
    next->threshold_ids = ids;
    next->thresholds = std::move(thresholds);
  }
  const WeightMatrix& graph = k > 0 ? kept : W;
  Reuse reuse{ids, k > 0 ? moved_sources : sources, *cache.store_, *next, *cache.workspaces_};
  try {
    Partition partition = Partitioner(graph, options, &reuse).run();
    cache.store_ = std::move(next);
    // After the tree, from all of the graph: the same as the batch's, whatever was reused.
    if (options.boundary_passes > 0)
      refineBoundaries(graph, options.boundary_passes, std::max(1, options.min_group_size), options.threads, partition);
    return partition;
  } catch (...) {
    cache.clear();  // partly moved on: the next run computes every node
    throw;
  }
}

}  // namespace obsgroup
