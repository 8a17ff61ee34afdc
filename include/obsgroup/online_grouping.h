#pragma once
/// \file
/// OnlineGrouping: the groups of ObservationGrouping kept up to date while
/// observations arrive, move (a loop closure) or leave, for a robot that
/// wants its local maps while it drives.

#include "obsgroup/cloud/observation.h"
#include "obsgroup/grouping_parameters.h"
#include "obsgroup/observation_grouping.h"
#include "obsgroup/overlap/incremental_overlap.h"
#include "obsgroup/partition/group_tracking.h"
#include "obsgroup/partition/open_floor.h"
#include "obsgroup/partition/recursive_partitioner.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace obsgroup {

/// Online grouping: insert(), updatePose() and remove() record the change;
/// update() brings the groups up to date and says what changed.
///
/// update() is exact: its groups are those ObservationGrouping::compute()
/// gives for the observations present (in id order) with the same
/// parameters. It recomputes only what a change can reach (see
/// IncrementalOverlap) and re-partitions only the nodes of the split tree
/// that hold a changed row of W (see SplitCache). Group ids are stable: a
/// group whose members did not change keeps its id, and a group that
/// changed keeps the id of the old group it holds most of.
///
/// \code
///   obsgroup::OnlineGrouping<pcl::PointXYZ> online;
///   for (const auto& [cloud, pose] : scans) {
///     online.insert(cloud, pose);
///     for (const auto& change : online.update().changes) react(change);
///   }
/// \endcode
template <typename PointT>
class OnlineGrouping {
 public:
  using Ptr = std::shared_ptr<OnlineGrouping<PointT>>;
  using ConstPtr = std::shared_ptr<const OnlineGrouping<PointT>>;
  using PointCloud = pcl::PointCloud<PointT>;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;

  /// The defaults of GroupingParameters, as ObservationGrouping's.
  OnlineGrouping() = default;

  /// The settings of the method, all at once (checked here: throws
  /// std::invalid_argument as GroupingParameters::check()). Changing any but
  /// the thread count recomputes everything at the next update().
  /// GroupingParameters::neighbour_search is the batch's back-end only: the
  /// online grouping has its own matcher, with the same W.
  void setParameters(const GroupingParameters& params);
  const GroupingParameters& getParameters() const { return params_; }

  /// The paper's method exactly (GroupingParameters::usePaperMethod).
  void usePaperMethod() { params_.usePaperMethod(); reconfigure(); }

  /// Adds an observation and returns its id (0, 1, 2, ... in insertion
  /// order, never reused). Throws InvalidObservation naming that id on a null
  /// cloud, a non-finite pose or a cloud the overlap cannot use; nothing
  /// changes then.
  int insert(const PointCloudConstPtr& cloud, const Eigen::Isometry3d& pose);
  /// Moves an observation (a loop closure corrected it). Throws
  /// std::out_of_range for an id not present, InvalidObservation for a
  /// non-finite pose; nothing changes then.
  void updatePose(int id, const Eigen::Isometry3d& pose);
  /// Removes an observation (std::out_of_range for an id not present).
  void remove(int id);
  /// Brings the groups up to date with every change since the last update().
  GroupUpdate update();
  /// update(), exact whatever setExactInterval says.
  GroupUpdate updateExact();

  /// An approximation for speed, off by default (1: every update() is
  /// exact). With n > 1, update() re-partitions only the groups that hold an
  /// observation inserted, moved or removed since the last update, the new
  /// observations and the groups these observations overlap in W, and leaves
  /// the other groups as they are; it is exact again once n observations were
  /// inserted or moved since the last exact update, and after a change of the
  /// common frame (the first observation moved or removed). The
  /// overlaps (W) stay exact. A local update's partition has no split tree
  /// (Partition::splits is empty). docs/performance.md measures how far its
  /// groups drift from the exact ones.
  void setExactInterval(int n) { exact_interval_ = n < 1 ? 1 : n; }
  int getExactInterval() const { return exact_interval_; }

  /// Ids of the observations present, ascending.
  std::vector<int> getIds() const;
  bool contains(int id) const { return id >= 0 && id < int(slots_.size()) && slots_[id].present; }
  const Observation<PointT>& getObservation(int id) const;
  /// The observations present, in id order (node k of the partition is getIds()[k]).
  std::vector<Observation<PointT>> getObservations() const;
  /// The groups of the last update(): id -> member ids, ascending.
  const std::map<int, std::vector<int>>& getGroups() const { return group_ids_.groups(); }
  /// The group of an observation after the last update() (-1: none yet).
  int getGroupOf(int id) const { return group_ids_.groupOf(id); }
  /// The partition of the last update(), over getIds() positions, as
  /// ObservationGrouping::compute() returns it.
  const Partition& getPartition() const { return partition_; }
  /// W of the last update(), over getIds() positions.
  const WeightMatrix& getWeightMatrix() const { return W_; }
  /// What the user should know about the last update() (as ObservationGrouping's).
  const std::vector<std::string>& getWarnings() const { return warnings_; }
  /// The groups the last update() joined across open floor, as indices of
  /// its partition's groups before the joins (as ObservationGrouping's).
  const std::vector<OpenFloorJoin>& getOpenFloorJoins() const { return open_floor_joins_; }

  // --- one setting at a time: as ObservationGrouping's; changing one recomputes all at the next update() ---
  void setSensedSpaceModel(SensedSpaceModel model) { params_.model = model; reconfigure(); }
  SensedSpaceModel getSensedSpaceModel() const { return params_.model; }
  void setRegionParameters(const RegionParameters& params) { params_.regions = params; reconfigure(); }
  const RegionParameters& getRegionParameters() const { return params_.regions; }
  void setMatchDistance(double delta) { params_.match_distance = delta; reconfigure(); }
  double getMatchDistance() const { return params_.match_distance; }
  void setVoxelLeafSize(double leaf) { params_.voxel_leaf = leaf; reconfigure(); }
  double getVoxelLeafSize() const { return params_.voxel_leaf; }
  void setDiagonalWeight(double value) { params_.diagonal_weight = value; reconfigure(); }
  double getDiagonalWeight() const { return params_.diagonal_weight; }
  void setNcutThreshold(double threshold) { params_.ncut_threshold = threshold; reconfigure(); }
  double getNcutThreshold() const { return params_.ncut_threshold; }
  void setSplitCriterion(SplitCriterion criterion) { params_.split = criterion; reconfigure(); }
  SplitCriterion getSplitCriterion() const { return params_.split; }
  void setMinGroupSize(int size) { params_.min_group_size = size; reconfigure(); }
  int getMinGroupSize() const { return params_.min_group_size; }
  void setMaxDepth(int depth) { params_.max_depth = depth; reconfigure(); }
  int getMaxDepth() const { return params_.max_depth; }
  /// Sweeps of the boundary refinement (PartitionOptions::boundary_passes).
  void setBoundaryPasses(int passes) { params_.boundary_passes = passes; reconfigure(); }
  int getBoundaryPasses() const { return params_.boundary_passes; }
  void setEigenSolver(EigenSolver solver) { params_.eigen_solver = solver; reconfigure(); }
  EigenSolver getEigenSolver() const { return params_.eigen_solver; }
  /// Threads for update(); the result does not depend on it.
  void setNumberOfThreads(int threads) { params_.threads = threads; }
  int getNumberOfThreads() const { return params_.threads; }
  void setInterruptFlag(const InterruptFlag* flag) { interrupt_ = flag; }
  const InterruptFlag* getInterruptFlag() const { return interrupt_; }
  /// The options update() partitions with: GroupingParameters::
  /// partitionOptions() with this object's interrupt flag; each node of the
  /// split tree orders its own elimination (SplitCache).
  PartitionOptions getPartitionOptions() const;

 private:
  struct Slot {
    bool present = false;
    Observation<PointT> observation;
  };
  /// Parameters changed: the overlaps and every cached decision are stale.
  void reconfigure() {
    reconfigure_ = true;
    cache_.clear();
    exact_once_ = false;
  }
  int firstPresent() const;
  std::vector<Eigen::Vector3f> worldPointsOf(int id, const Observation<PointT>& observation,
                                             const Eigen::Vector3d& origin) const;
  void recentreAll();
  std::vector<std::vector<int>> partitionExactly(const std::vector<int>& ids, GroupUpdate& out);
  /// Joins partition_'s groups across open floor, as ObservationGrouping does.
  void joinAcrossOpenFloor(const std::vector<int>& ids);
  GroupUpdate run(bool force_exact);

  std::vector<Slot> slots_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // the first present observation's position
  GroupingParameters params_;
  const InterruptFlag* interrupt_ = nullptr;
  std::unique_ptr<IncrementalOverlap> overlap_;
  bool reconfigure_ = true;
  SplitCache cache_;
  Partition partition_;
  WeightMatrix W_;
  WeightMatrix spare_W_;  // the W before W_, its storage reused for the next
  StableGroupIds group_ids_;
  std::vector<std::string> warnings_;
  std::vector<OpenFloorJoin> open_floor_joins_;
  int exact_interval_ = 1;
  int changes_since_exact_ = 0;       // observations inserted or moved since the last exact update
  std::vector<char> pending_;         // by id: row changed since the last exact update
  std::vector<char> pending_sources_; // by id: own data changed since then (the entries' sources)
  std::vector<int> moved_;            // ids inserted, moved or removed since the last update
  bool exact_once_ = false;           // an exact update has been made (the cache holds its tree)
};

}  // namespace obsgroup

#if defined(PCL_NO_PRECOMPILE) || defined(OBSGROUP_NO_PRECOMPILE)
#include "obsgroup/impl/online_grouping.hpp"
#endif
