#pragma once
/// \file
/// GroupingParameters: every setting of the method in one struct, with the
/// defaults and the paper's preset written once. ObservationGrouping,
/// OnlineGrouping and the command all take it, and partition.json records
/// the one the grouping ran with.

#include "obsgroup/graph/observation_graph.h"
#include "obsgroup/overlap/sensed_regions.h"
#include "obsgroup/partition/recursive_partitioner.h"
#include "obsgroup/spectral/fiedler_vector.h"
#include "obsgroup/spectral/spectral_bisection.h"

#include <limits>

namespace obsgroup {

/// The settings of the method (Blanco, Gonzalez, Fernandez-Madrigal, ICRA
/// 2006) and of how it runs. The defaults measured best across 2D lasers
/// (360 and 180 degrees) and depth cameras with drifted poses
/// (docs/grouping.md); paper() gives the paper's method exactly.
///
/// \code
///   obsgroup::GroupingParameters params;            // the defaults
///   params.regions.cell_size = 0.1;
///   grouping.setParameters(params);                 // checked here
///   grouping.setParameters(obsgroup::GroupingParameters::paper());
/// \endcode
struct GroupingParameters {
  // --- the sensed space (sec. IV-A) ---
  /// The model of the sensed space (sensed_regions.h).
  SensedSpaceModel model = SensedSpaceModel::Visibility;
  /// Free-space and visibility models only (cell, range, clearance, ...).
  RegionParameters regions;
  /// Points model only: the tolerance delta of the match function, eq. (16), metres.
  double match_distance = 0.1;
  /// Points model only: how matches are found (both give the same W).
  NeighbourSearch neighbour_search = NeighbourSearch::SharedGrid;
  /// Every model: leaf of the voxel downsampling of each observation before
  /// its overlap is measured, metres; 0 keeps every point.
  double voxel_leaf = 0.0;

  // --- the graph and its partition (sec. II-III) ---
  /// W_ii; 0 instead of the paper's 1 (see kDefaultDiagonalWeight).
  double diagonal_weight = kDefaultDiagonalWeight;
  /// How each eigenvector is cut: the smallest Ncut over all its thresholds.
  SplitCriterion split = SplitCriterion::BestNcut;
  /// A bisection is accepted while Ncut < this. The paper's 1 splits any group
  /// whose overlap is not uniform (docs/method.md); 0.7 keeps rooms whole.
  double ncut_threshold = 0.7;
  /// Sweeps of the boundary refinement after the split tree
  /// (PartitionOptions::boundary_passes): doorway scans join the room their
  /// overlap says.
  int boundary_passes = 3;
  /// The partition works on W's mutual-neighbour graph, each observation
  /// keeping its k strongest edges that are also among the other end's,
  /// k = max(mutual_neighbours, mutual_neighbours_share x the median number
  /// of neighbours) (PartitionOptions::mutual_neighbours): a small room
  /// whose scans each overlap many scans of a corridor driven again and
  /// again is no longer held to it. mutual_neighbours 0: W as it is (the
  /// paper's), and the share is not used.
  int mutual_neighbours = 60;
  double mutual_neighbours_share = 0.4;
  /// Visibility model: two groups are joined when the route went from one to
  /// the other only through open floor, where the free space is at least
  /// this many metres across in every direction at every step between them
  /// (joinAcrossOpenFloor): a hall or a large room that no view spans, cut
  /// into bands, is one place again; doors and corridors are narrower.
  /// 0: no joins (the paper's).
  double open_floor_width = 4.5;
  /// Visibility model: groups whose places meet through a passage (a
  /// corridor cut across, not a door) are joined. compute() gives the groups
  /// before; joinGroupsThroughPassages() (observation_grouping.h), which the
  /// command runs after it, joins them. false: none (the paper's).
  bool join_passages = true;
  /// A bisection giving a group smaller than this is rejected.
  int min_group_size = 1;
  /// Bisections deeper than this are not attempted.
  int max_depth = std::numeric_limits<int>::max();
  /// The eigen solver of each bisection (the result is the same up to the
  /// last bits of the eigenvector).
  EigenSolver eigen_solver = EigenSolver::Auto;

  // --- how it runs ---
  /// Threads (0: OpenMP's default). The groups are the same for any value.
  int threads = 0;

  /// The paper's method exactly: the points model of eq. (16)-(18) and the
  /// partition of sec. II (PartitionOptions' defaults: the mean split, Ncut
  /// threshold 1, no boundary refinement); every other setting as the defaults.
  static GroupingParameters paper();
  /// Sets the model and the partition to the paper's (as paper()), keeping
  /// the rest of this struct (delta, voxel leaf, threads, ...).
  void usePaperMethod();

  /// Throws std::invalid_argument naming the first setting that is out of
  /// range, or that was changed from its default although the chosen model
  /// does not use it (a cell size under the points model, delta under a
  /// region model): a silently ignored setting is a mistake, not a no-op.
  void check() const;

  /// The options recursivePartition() takes for these settings (no
  /// interrupt flag: the caller's).
  PartitionOptions partitionOptions() const;
};

bool operator==(const GroupingParameters& a, const GroupingParameters& b);
inline bool operator!=(const GroupingParameters& a, const GroupingParameters& b) { return !(a == b); }

}  // namespace obsgroup
