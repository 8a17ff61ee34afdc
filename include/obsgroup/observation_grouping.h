#pragma once
/// \file
/// ObservationGrouping: the whole method of the paper behind one PCL-style
/// class. Observations in, groups (future local maps) out.

#include "obsgroup/graph/observation_graph.h"
#include "obsgroup/cloud/observation.h"
#include "obsgroup/overlap/sensed_space_overlap.h"
#include "obsgroup/partition/recursive_partitioner.h"

#include <memory>
#include <string>
#include <vector>

namespace obsgroup {

/// Wall time of each stage of the last ObservationGrouping::compute().
struct GroupingTimings {
  double overlap_s = 0.0;    ///< filtering, world frame, Pi and Psi (eq. 16-18)
  double graph_s = 0.0;      ///< building W
  double partition_s = 0.0;  ///< recursive spectral bisection (sec. II)
};

/// Groups observations into consistent local maps (Blanco, Gonzalez,
/// Fernandez-Madrigal, ICRA 2006): W_ij = Psi(n_i, n_j) (eq. 18) of the
/// sensed-space model set (sensed_regions.h), then recursive spectral
/// bisection by minimum normalized cut (sec. II).
///
/// \code
///   obsgroup::ObservationGrouping<pcl::PointXYZ> grouping;
///   for (const auto& [cloud, pose] : scans) grouping.addObservation(cloud, pose);
///   grouping.setSensedSpaceModel(obsgroup::SensedSpaceModel::Visibility);  // the default
///   const obsgroup::Partition partition = grouping.compute();
/// \endcode
template <typename PointT>
class ObservationGrouping {
 public:
  using Ptr = std::shared_ptr<ObservationGrouping<PointT>>;
  using ConstPtr = std::shared_ptr<const ObservationGrouping<PointT>>;
  using PointCloud = pcl::PointCloud<PointT>;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;
  using SearchMethodPtr = typename SensedSpaceOverlap<PointT>::SearchMethodPtr;

  /// The defaults measure best across 2D lasers (360 and 180 degrees) and
  /// depth cameras with drifted poses (docs/grouping.md): the visibility
  /// model with the best-Ncut split. usePaperMethod() gives the paper's.
  ObservationGrouping() {
    overlap_.setSensedSpaceModel(SensedSpaceModel::Visibility);
    options_.split = SplitCriterion::BestNcut;
    options_.ncut_threshold = kDefaultNcutThreshold;
    options_.boundary_passes = kDefaultBoundaryPasses;
  }

  /// The Ncut threshold of the defaults: the paper's 1 splits any group whose
  /// overlap is not uniform (see docs/method.md); 0.7 keeps rooms whole.
  static constexpr double kDefaultNcutThreshold = 0.7;
  /// Sweeps of the boundary refinement of the defaults (PartitionOptions::
  /// boundary_passes): doorway scans join the room their overlap says.
  static constexpr int kDefaultBoundaryPasses = 3;

  /// The paper's method exactly: the points model of eq. (16)-(18), the mean
  /// split of sec. II-A and the Ncut threshold 1 of sec. II-B (delta as set).
  void usePaperMethod() {
    overlap_.setSensedSpaceModel(SensedSpaceModel::Points);
    options_.split = SplitCriterion::Mean;
    options_.ncut_threshold = 1.0;
    options_.boundary_passes = 0;
  }

  /// Adds an observation: points in the sensor frame and the sensor's pose.
  void addObservation(const PointCloudConstPtr& cloud, const Eigen::Isometry3d& pose);
  /// Adds an observation whose pose is the cloud's own sensor_origin_ and
  /// sensor_orientation_ (a PCD file's VIEWPOINT).
  void addObservation(const PointCloudConstPtr& cloud);
  const std::vector<Observation<PointT>>& getObservations() const { return observations_; }
  /// Removes all observations and results.
  void clear();

  // --- sensed-space overlap (sec. IV-A) ---
  void setSensedSpaceModel(SensedSpaceModel model) { overlap_.setSensedSpaceModel(model); }
  SensedSpaceModel getSensedSpaceModel() const { return overlap_.getSensedSpaceModel(); }
  void setRegionParameters(const RegionParameters& params) { overlap_.setRegionParameters(params); }
  const RegionParameters& getRegionParameters() const { return overlap_.getRegionParameters(); }
  void setMatchDistance(double delta) { overlap_.setMatchDistance(delta); }
  double getMatchDistance() const { return overlap_.getMatchDistance(); }
  void setVoxelLeafSize(double leaf) { overlap_.setVoxelLeafSize(leaf); }
  double getVoxelLeafSize() const { return overlap_.getVoxelLeafSize(); }
  void setNeighbourSearch(NeighbourSearch method) { overlap_.setNeighbourSearch(method); }
  NeighbourSearch getNeighbourSearch() const { return overlap_.getNeighbourSearch(); }
  void setSearchMethod(const SearchMethodPtr& search) { overlap_.setSearchMethod(search); }
  SearchMethodPtr getSearchMethod() const { return overlap_.getSearchMethod(); }
  /// Threads for the overlap and the partition; the result does not depend on it.
  /// Stored once, in the overlap stage; the partition is given the same.
  void setNumberOfThreads(int threads) { overlap_.setNumberOfThreads(threads); }
  int getNumberOfThreads() const { return overlap_.getNumberOfThreads(); }
  void setProgressCallback(ProgressCallback callback) { overlap_.setProgressCallback(std::move(callback)); }
  const ProgressCallback& getProgressCallback() const { return overlap_.getProgressCallback(); }
  /// A flag polled during compute() (see interrupt.h); when it is set,
  /// compute() stops and throws Interrupted. Not owned.
  void setInterruptFlag(const InterruptFlag* flag) { overlap_.setInterruptFlag(flag); }
  const InterruptFlag* getInterruptFlag() const { return overlap_.getInterruptFlag(); }

  // --- graph and partition (sec. II, III) ---
  /// W_ii; 0 by default instead of the paper's 1 (see kDefaultDiagonalWeight).
  void setDiagonalWeight(double value) { diagonal_ = value; }
  double getDiagonalWeight() const { return diagonal_; }
  void setBoundaryPasses(int passes) { options_.boundary_passes = passes; }
  int getBoundaryPasses() const { return options_.boundary_passes; }
  void setNcutThreshold(double threshold) { options_.ncut_threshold = threshold; }
  double getNcutThreshold() const { return options_.ncut_threshold; }
  void setSplitCriterion(SplitCriterion criterion) { options_.split = criterion; }
  SplitCriterion getSplitCriterion() const { return options_.split; }
  void setMinGroupSize(int size) { options_.min_group_size = size; }
  int getMinGroupSize() const { return options_.min_group_size; }
  void setMaxDepth(int depth) { options_.max_depth = depth; }
  int getMaxDepth() const { return options_.max_depth; }
  void setEigenSolver(EigenSolver solver) { options_.eigen.solver = solver; }
  EigenSolver getEigenSolver() const { return options_.eigen.solver; }
  /// All partition options at once. The thread count and the interrupt flag
  /// are the ones setNumberOfThreads and setInterruptFlag gave (for the
  /// overlap and the partition alike): those of `options` are ignored, so
  /// that setting the options later does not undo them.
  void setPartitionOptions(const PartitionOptions& options) { options_ = options; }
  /// The options compute() partitions with: those set, with this object's
  /// thread count and interrupt flag.
  PartitionOptions getPartitionOptions() const {
    PartitionOptions options = options_;
    options.threads = overlap_.getNumberOfThreads();
    options.interrupt = overlap_.getInterruptFlag();
    return options;
  }

  /// Computes the overlap, builds W and partitions it. Throws
  /// std::invalid_argument on bad parameters or observations.
  Partition compute();

  /// The weight matrix W of the last compute() (diagonal as configured).
  const WeightMatrix& getWeightMatrix() const { return W_; }
  /// Pi, Psi and work statistics of the last compute().
  const OverlapResult& getOverlap() const { return overlap_result_; }
  /// The overlap stage as configured (model, voxel leaf, regions, threads),
  /// e.g. to compute the observations' regions for a picture.
  const SensedSpaceOverlap<PointT>& getSensedSpaceOverlap() const { return overlap_; }
  /// Keep the observations' points in the common frame, as the overlap saw
  /// them (filtered, at the input poses), after compute(): off by default,
  /// as they are as large as the clouds.
  void setKeepWorldPoints(bool keep) { keep_world_points_ = keep; }
  bool getKeepWorldPoints() const { return keep_world_points_; }
  /// The points kept by the last compute() (empty unless setKeepWorldPoints(true)).
  const WorldPoints& getWorldPoints() const { return world_; }
  /// Time spent in each stage of the last compute().
  const GroupingTimings& getTimings() const { return timings_; }
  /// What the user should know about the last compute(), deterministic and
  /// in order: observations with no point (each forms a group of its own),
  /// then the partition's eigen-solver fallbacks (Partition::warnings).
  const std::vector<std::string>& getWarnings() const { return warnings_; }

 private:
  std::vector<Observation<PointT>> observations_;
  SensedSpaceOverlap<PointT> overlap_;
  double diagonal_ = kDefaultDiagonalWeight;
  PartitionOptions options_;
  OverlapResult overlap_result_;
  WeightMatrix W_;
  bool keep_world_points_ = false;
  WorldPoints world_;
  GroupingTimings timings_;
  std::vector<std::string> warnings_;
};

}  // namespace obsgroup

#if defined(PCL_NO_PRECOMPILE) || defined(OBSGROUP_NO_PRECOMPILE)
#include "obsgroup/impl/observation_grouping.hpp"
#endif
