#pragma once
/// \file
/// OnlineGrouping: the groups of ObservationGrouping kept up to date while
/// observations arrive, move (a loop closure) or leave, for a robot that
/// wants its local maps while it drives.

#include "obsgroup/cloud/observation.h"
#include "obsgroup/common/enum_names.h"
#include "obsgroup/observation_grouping.h"
#include "obsgroup/overlap/incremental_overlap.h"
#include "obsgroup/partition/recursive_partitioner.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace obsgroup {

/// One change of the groups made by OnlineGrouping::update().
struct GroupChange {
  enum class Kind {
    Created,  ///< A new group of observations that were in no group (new ones).
    Grown,    ///< The group kept its id and gained observations.
    Shrunk,   ///< The group kept its id and lost observations.
    Changed,  ///< The group kept its id, gained some observations and lost others.
    Split,    ///< `group`'s observations now lie in the groups `related` (one may still be `group`).
    Merged,   ///< `group` now holds observations of the groups `related` (one may be `group` itself).
    Removed   ///< The group is gone: its observations were removed.
  };
  Kind kind = Kind::Created;
  int group = -1;
  std::vector<int> related;
  std::vector<int> members;  ///< The group's observations after the change (empty for Removed, Split).
};

inline constexpr EnumName<GroupChange::Kind> kGroupChangeNames[] = {
    {GroupChange::Kind::Created, "created"}, {GroupChange::Kind::Grown, "grown"},
    {GroupChange::Kind::Shrunk, "shrunk"},   {GroupChange::Kind::Changed, "changed"},
    {GroupChange::Kind::Split, "split"},     {GroupChange::Kind::Merged, "merged"},
    {GroupChange::Kind::Removed, "removed"}};
inline std::string toString(GroupChange::Kind kind) { return nameOf(kGroupChangeNames, kind); }

/// What one OnlineGrouping::update() did.
struct GroupUpdate {
  std::vector<GroupChange> changes;  ///< Split and Merged first, then the rest, each by group id.
  /// True when the partition was computed exactly (equal to compute()); false
  /// for a local update (OnlineGrouping::setExactInterval).
  bool exact = true;
  std::size_t observations_recomputed = 0;  ///< Observations whose overlaps were recomputed.
  std::size_t split_nodes_reused = 0;       ///< Nodes of the split tree copied from the last update.
  std::size_t split_nodes_computed = 0;     ///< Nodes solved anew by an exact update (0 for a local one).
};

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

  /// ObservationGrouping's defaults (the visibility model, best-Ncut split,
  /// threshold 0.7).
  OnlineGrouping();

  /// The paper's method exactly (ObservationGrouping::usePaperMethod).
  void usePaperMethod();

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
  /// exact). With n > 1, update() re-partitions only the groups that hold a
  /// changed observation, the new observations and the groups next to them
  /// in W, and leaves the other groups as they are; it is exact again once n
  /// observations were inserted or moved since the last exact update. The
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
  const std::map<int, std::vector<int>>& getGroups() const { return groups_; }
  /// The group of an observation after the last update() (-1: none yet).
  int getGroupOf(int id) const;
  /// The partition of the last update(), over getIds() positions, as
  /// ObservationGrouping::compute() returns it.
  const Partition& getPartition() const { return partition_; }
  /// W of the last update(), over getIds() positions.
  const WeightMatrix& getWeightMatrix() const { return W_; }
  /// What the user should know about the last update() (as ObservationGrouping's).
  const std::vector<std::string>& getWarnings() const { return warnings_; }

  // --- parameters: as ObservationGrouping's; changing one recomputes all at the next update() ---
  void setSensedSpaceModel(SensedSpaceModel model) { config_.setSensedSpaceModel(model); reconfigure(); }
  SensedSpaceModel getSensedSpaceModel() const { return config_.getSensedSpaceModel(); }
  void setRegionParameters(const RegionParameters& params) { config_.setRegionParameters(params); reconfigure(); }
  const RegionParameters& getRegionParameters() const { return config_.getRegionParameters(); }
  void setMatchDistance(double delta) { config_.setMatchDistance(delta); reconfigure(); }
  double getMatchDistance() const { return config_.getMatchDistance(); }
  void setVoxelLeafSize(double leaf) { config_.setVoxelLeafSize(leaf); reconfigure(); }
  double getVoxelLeafSize() const { return config_.getVoxelLeafSize(); }
  void setDiagonalWeight(double value) { diagonal_ = value; reconfigure(); }
  double getDiagonalWeight() const { return diagonal_; }
  void setPartitionOptions(const PartitionOptions& options) { options_ = options; reconfigure(); }
  /// The partition options (thread count and interrupt flag: this object's).
  PartitionOptions getPartitionOptions() const;
  void setNcutThreshold(double threshold) { options_.ncut_threshold = threshold; reconfigure(); }
  double getNcutThreshold() const { return options_.ncut_threshold; }
  void setSplitCriterion(SplitCriterion criterion) { options_.split = criterion; reconfigure(); }
  SplitCriterion getSplitCriterion() const { return options_.split; }
  void setMinGroupSize(int size) { options_.min_group_size = size; reconfigure(); }
  int getMinGroupSize() const { return options_.min_group_size; }
  void setMaxDepth(int depth) { options_.max_depth = depth; reconfigure(); }
  int getMaxDepth() const { return options_.max_depth; }
  /// Sweeps of the boundary refinement (PartitionOptions::boundary_passes).
  void setBoundaryPasses(int passes) { options_.boundary_passes = passes; reconfigure(); }
  int getBoundaryPasses() const { return options_.boundary_passes; }
  /// Threads for update(); the result does not depend on it.
  void setNumberOfThreads(int threads) { config_.setNumberOfThreads(threads); }
  int getNumberOfThreads() const { return config_.getNumberOfThreads(); }
  void setInterruptFlag(const InterruptFlag* flag) { config_.setInterruptFlag(flag); }
  const InterruptFlag* getInterruptFlag() const { return config_.getInterruptFlag(); }
  /// Sets every parameter to `grouping`'s (model, regions, delta, voxel,
  /// diagonal, partition options), e.g. those of a command line.
  void setParametersFrom(const ObservationGrouping<PointT>& grouping);

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
  struct GroupMatch {
    std::vector<std::map<int, int>> from_old;  // new group -> old id -> members it took
    std::map<int, std::map<int, int>> to_new;  // old id -> new group -> members it gave
    std::vector<int> new_id;                   // the id of each new group
  };
  GroupMatch matchGroups(const std::vector<std::vector<int>>& groups);
  std::vector<GroupChange> changesOf(const std::vector<std::vector<int>>& groups, const GroupMatch& match) const;
  void assignGroupIds(const std::vector<std::vector<int>>& groups, GroupUpdate& out);
  std::vector<std::vector<int>> partitionExactly(const std::vector<int>& ids, GroupUpdate& out);
  std::vector<std::vector<int>> partitionLocally(const std::vector<int>& ids, const std::vector<int>& changed_slots);
  GroupUpdate run(bool force_exact);

  std::vector<Slot> slots_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // the first present observation's position
  SensedSpaceOverlap<PointT> config_;                 // overlap parameters (and their checks)
  double diagonal_ = kDefaultDiagonalWeight;
  PartitionOptions options_;
  std::unique_ptr<IncrementalOverlap> overlap_;
  bool reconfigure_ = true;
  SplitCache cache_;
  Partition partition_;
  WeightMatrix W_;
  std::map<int, std::vector<int>> groups_;
  std::vector<int> group_of_;  // by id
  int next_group_id_ = 0;
  std::vector<std::string> warnings_;
  int exact_interval_ = 1;
  int changes_since_exact_ = 0;       // observations inserted or moved since the last exact update
  std::vector<char> pending_;         // by id: row changed since the last exact update
  bool exact_once_ = false;           // an exact update has been made (the cache holds its tree)
};

}  // namespace obsgroup

#if defined(PCL_NO_PRECOMPILE) || defined(OBSGROUP_NO_PRECOMPILE)
#include "obsgroup/impl/online_grouping.hpp"
#endif
