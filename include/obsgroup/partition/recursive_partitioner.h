#pragma once
/// \file
/// RecursivePart of paper sec. II-B: recursive spectral bisection while the
/// minimum normalized cut stays below a threshold.

#include "obsgroup/graph/observation_graph.h"
#include "obsgroup/common/interrupt.h"
#include "obsgroup/spectral/spectral_bisection.h"

#include <cstddef>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace obsgroup {

struct PartitionOptions {
  /// A bisection is accepted while Ncut < threshold. The paper derives 1 from
  /// the geometric mean of the intra-group cohesions, eq. (12)-(13).
  double ncut_threshold = 1.0;
  SplitCriterion split = SplitCriterion::Mean;
  /// A bisection giving a group smaller than this is rejected.
  int min_group_size = 1;
  /// Bisections deeper than this are not attempted (components still split).
  int max_depth = std::numeric_limits<int>::max();
  /// Sweeps of the boundary refinement after the split tree (0: none, the
  /// paper's; the split tree's leaves are then the groups). In a sweep every
  /// observation joins the group whose other members it overlaps most on
  /// average (mean Psi, eq. 18), all at once from the previous sweep's
  /// groups; sweeps stop early when nothing moves. A scan standing in a
  /// doorway sees both sides, and the bisection puts it on either; its mean
  /// overlap is higher with the members of its own room (docs/method.md).
  int boundary_passes = 0;
  /// The split tree and the boundary refinement work on W's mutual-neighbour
  /// graph: W_ij kept when j is among the k observations i overlaps most and
  /// i among j's (mutualNeighbourGraph), k = max(mutual_neighbours,
  /// mutual_neighbours_share x the median number of neighbours). 0: W as
  /// it is, the paper's (the share is then not used). In a building whose corridor the robot drove
  /// many times, a small room's scans each overlap a hundred corridor scans
  /// a little, which adds up to more than the room's own few; none of those
  /// corridor scans counts the room's among its k nearest (docs/method.md).
  int mutual_neighbours = 0;
  double mutual_neighbours_share = 0.0;
  /// Keep each node's eigenvector in the split tree (for plots and analysis).
  bool keep_eigenvectors = true;
  /// Threads over the nodes of one level of the split tree (0: OpenMP's
  /// default). The result is the same for any value.
  int threads = 0;
  FiedlerOptions eigen;
  /// Polled between the levels of the split tree; when set, recursivePartition
  /// throws Interrupted.
  const InterruptFlag* interrupt = nullptr;
};

/// One node of the split tree.
struct SplitNode {
  enum class Kind {
    Leaf,        ///< Not split: it is a group. `outcome` says why.
    Components,  ///< Disconnected: split into its connected components (Ncut 0).
    Bisection    ///< Spectral bisection accepted.
  };
  /// Why a node ended as it did.
  enum class Outcome {
    Accepted,          ///< Split (Components or Bisection).
    NcutAboveThreshold,///< Bisection computed, Ncut >= threshold.
    GroupTooSmall,     ///< Bisection computed, a side below min_group_size.
    NoSplit,           ///< Bisection computed, all nodes on one side.
    MaxDepth,          ///< Not attempted: max_depth reached.
    TooFewNodes,       ///< Not attempted: a single node, or fewer than 2 * min_group_size.
    EigenSolverFailed  ///< No eigen solver converged: kept whole, with a warning.
  };
  std::vector<int> members;   ///< Observation indices, ascending.
  Kind kind = Kind::Leaf;
  Outcome outcome = Outcome::TooFewNodes;
  bool accepted = false;      ///< A split was made (kind != Leaf).
  bool attempted = false;     ///< A spectral bisection was computed at this node.
  double ncut = std::numeric_limits<double>::quiet_NaN();  ///< Eq. (1); 0 for components.
  double threshold = 0.0;     ///< Eigenvector threshold of the bisection.
  double eigenvalue = std::numeric_limits<double>::quiet_NaN();
  bool sparse_solver = false;
  bool solver_fell_back = false;  ///< Lanczos failed; the dense solver gave the eigenvector.
  Eigen::VectorXd eigenvector;  ///< y over `members` (empty unless kept).
  int depth = 0;              ///< Number of accepted bisections above this node.
  int parent = -1;
  std::vector<int> children;  ///< Indices into Partition::splits.
};

std::string toString(SplitNode::Kind kind);
std::string toString(SplitNode::Outcome outcome);

struct Partition {
  /// Groups of observation indices: each ascending, every index exactly once,
  /// groups ordered by their first (smallest) observation.
  std::vector<std::vector<int>> groups;
  /// group_of[i] is the group of observation i.
  std::vector<int> group_of;
  /// The split tree in breadth-first order; splits[0] is the root. Its
  /// leaves are the groups unless PartitionOptions::boundary_passes moved
  /// observations between them.
  std::vector<SplitNode> splits;
  /// Things the user should know, in split-tree order: an eigen solve that
  /// fell back to the dense solver, or failed and left a node whole.
  std::vector<std::string> warnings;
};

/// Partitions the graph W (with its diagonal as configured) recursively.
/// Throws std::invalid_argument when W is not square, symmetric, finite and
/// non-negative, and Interrupted when options.interrupt is set.
Partition recursivePartition(const WeightMatrix& W, const PartitionOptions& options = {});

/// The decisions of the split tree of one recursivePartition, kept for the
/// next on a graph that differs in the rows of a few nodes (online grouping:
/// observations inserted, moved or removed). A node's decision depends only
/// on its members' block of W and the options (each node orders its own
/// elimination, see FiedlerOptions::elimination_rank), and on its depth only
/// where PartitionOptions::max_depth reaches; so a node with the same
/// members, none of whose rows changed, is decided as before, at any depth
/// below max_depth (a split added above a part of the tree moves that part
/// down a level; its depth then only numbers its children): its decision is
/// copied, bit for bit, instead of solved. The result is then the one
/// recursivePartition gives from scratch.
class SplitCache {
 public:
  SplitCache();
  /// Forgets every decision (e.g. after the options changed).
  void clear();
  /// Nodes of the last run whose decision was copied / computed.
  std::size_t reusedNodes() const;
  std::size_t computedNodes() const;
  /// Of the computed nodes, those solved ahead of their level, beside the
  /// level's own on another thread, from a guess of the path the run would
  /// take (its members in the previous run's tree); and of those, the ones
  /// the run then met. A node's decision depends on its block of W alone, so
  /// one solved ahead is the decision it gets in turn: the result is the same
  /// for any thread count. One thread solves nothing ahead.
  std::size_t aheadNodes() const;
  std::size_t aheadNodesUsed() const;

  struct Store;  ///< opaque

 private:
  friend Partition recursivePartition(const WeightMatrix&, const PartitionOptions&, const std::vector<int>&,
                                      const std::vector<char>&, const std::vector<char>&, SplitCache&);
  std::shared_ptr<Store> store_;
  /// The eigen solves' buffers, one per thread, kept from one run to the
  /// next: the nodes solved again after an insert are about as large as
  /// last time's (see FiedlerWorkspace).
  std::shared_ptr<std::vector<FiedlerWorkspace>> workspaces_;
  /// The mutual-neighbour graph of the last run, its storage reused by the next.
  std::shared_ptr<WeightMatrix> kept_;
};

/// recursivePartition reusing `cache`'s decisions, then leaving this run's in
/// it. Node k of W has the stable id ids[k] (ascending: the ids of the run
/// that filled the cache keep their order), and changed[k] != 0 when its row
/// of W may differ from that run's. The options must be those of that run
/// (the cache does not check them; clear it when they change), and
/// options.eigen.elimination_rank must be empty. Weights are refused as by
/// the overload above, but once the cache holds a run's decisions only the
/// rows flagged changed (and the mirrors of their entries) are checked: an
/// unflagged row is taken to be the one checked before, so an entry of an
/// unflagged row whose mirror a changed row no longer holds is not found. A
/// caller that flags every row that differs cannot make one from a W that
/// was symmetric. After a refusal the cache is cleared, and the next run
/// checks every row.
Partition recursivePartition(const WeightMatrix& W, const PartitionOptions& options, const std::vector<int>& ids,
                             const std::vector<char>& changed, SplitCache& cache);

/// As above, with fewer nodes solved again when the caller knows where the
/// changes came from: sources[k] != 0 for each node whose own data changed
/// (an observation inserted or moved, a region recomputed to other cells),
/// such that every entry of W that may differ from the cached run's has a
/// source at one end or both. A node none of whose members is a source then
/// has the same block of W, even where its rows changed through entries
/// that lead out of it (a new observation's entries change its neighbours'
/// rows, not the block of a node without it), and its decision is copied.
/// `changed` still flags every row that differs (the weights check reads
/// it). The overload above is this one with sources = changed.
Partition recursivePartition(const WeightMatrix& W, const PartitionOptions& options, const std::vector<int>& ids,
                             const std::vector<char>& changed, const std::vector<char>& sources, SplitCache& cache);

}  // namespace obsgroup
