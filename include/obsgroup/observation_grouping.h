#pragma once
/// \file
/// ObservationGrouping: the whole method of the paper behind one PCL-style
/// class. Observations in, groups (future local maps) out.

#include "obsgroup/graph/observation_graph.h"
#include "obsgroup/cloud/observation.h"
#include "obsgroup/grouping_parameters.h"
#include "obsgroup/overlap/sensed_space_overlap.h"
#include "obsgroup/partition/open_floor.h"
#include "obsgroup/partition/recursive_partitioner.h"
#include "obsgroup/places/place_map.h"

#include <functional>
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

/// The overlap stage with the sensed-space settings of `params` (model,
/// regions, delta, voxel leaf, neighbour search, threads): how
/// ObservationGrouping and OnlineGrouping filter and measure observations.
template <typename PointT>
SensedSpaceOverlap<PointT> sensedSpaceOverlapOf(const GroupingParameters& params) {
  SensedSpaceOverlap<PointT> overlap;
  overlap.setSensedSpaceModel(params.model);
  overlap.setRegionParameters(params.regions);
  overlap.setMatchDistance(params.match_distance);
  overlap.setVoxelLeafSize(params.voxel_leaf);
  overlap.setNeighbourSearch(params.neighbour_search);
  overlap.setNumberOfThreads(params.threads);
  return overlap;
}

/// Groups observations into consistent local maps (Blanco, Gonzalez,
/// Fernandez-Madrigal, ICRA 2006): W_ij = Psi(n_i, n_j) (eq. 18) of the
/// sensed-space model set (sensed_regions.h), then recursive spectral
/// bisection by minimum normalized cut (sec. II).
///
/// \code
///   obsgroup::ObservationGrouping<pcl::PointXYZ> grouping;
///   for (const auto& [cloud, pose] : scans) grouping.addObservation(cloud, pose);
///   grouping.setParameters(obsgroup::GroupingParameters::paper());  // or keep the defaults
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

  /// The settings of the method, all at once (checked here: throws
  /// std::invalid_argument as GroupingParameters::check()). The defaults are
  /// GroupingParameters'; the setters below change one setting each, and
  /// compute() checks them together.
  void setParameters(const GroupingParameters& params) {
    params.check();
    params_ = params;
  }
  const GroupingParameters& getParameters() const { return params_; }

  /// The paper's method exactly: the points model of eq. (16)-(18), the mean
  /// split of sec. II-A and the Ncut threshold 1 of sec. II-B (the other
  /// settings, delta among them, as set). See GroupingParameters::paper().
  void usePaperMethod() { params_.usePaperMethod(); }

  /// Adds an observation: points in the sensor frame and the sensor's pose.
  void addObservation(const PointCloudConstPtr& cloud, const Eigen::Isometry3d& pose);
  /// Adds an observation whose pose is the cloud's own sensor_origin_ and
  /// sensor_orientation_ (a PCD file's VIEWPOINT).
  void addObservation(const PointCloudConstPtr& cloud);
  const std::vector<Observation<PointT>>& getObservations() const { return observations_; }
  /// Removes all observations and results.
  void clear();

  // --- sensed-space overlap (sec. IV-A); GroupingParameters says which model uses what ---
  void setSensedSpaceModel(SensedSpaceModel model) { params_.model = model; }
  SensedSpaceModel getSensedSpaceModel() const { return params_.model; }
  void setRegionParameters(const RegionParameters& params) { params_.regions = params; }
  const RegionParameters& getRegionParameters() const { return params_.regions; }
  void setMatchDistance(double delta) { params_.match_distance = delta; }
  double getMatchDistance() const { return params_.match_distance; }
  void setVoxelLeafSize(double leaf) { params_.voxel_leaf = leaf; }
  double getVoxelLeafSize() const { return params_.voxel_leaf; }
  void setNeighbourSearch(NeighbourSearch method) { params_.neighbour_search = method; }
  NeighbourSearch getNeighbourSearch() const { return params_.neighbour_search; }
  /// Points model: a PCL search object, as PCL algorithms take one (see
  /// SensedSpaceOverlap::setSearchMethod). Selects NeighbourSearch::PclSearch.
  void setSearchMethod(const SearchMethodPtr& search) {
    search_ = search;
    params_.neighbour_search = NeighbourSearch::PclSearch;
  }
  SearchMethodPtr getSearchMethod() const { return search_; }
  /// Threads for the overlap and the partition; the result does not depend on it.
  void setNumberOfThreads(int threads) { params_.threads = threads; }
  int getNumberOfThreads() const { return params_.threads; }
  void setProgressCallback(ProgressCallback callback) { progress_ = std::move(callback); }
  const ProgressCallback& getProgressCallback() const { return progress_; }
  /// A flag polled during compute() (see interrupt.h); when it is set,
  /// compute() stops and throws Interrupted. Not owned.
  void setInterruptFlag(const InterruptFlag* flag) { interrupt_ = flag; }
  const InterruptFlag* getInterruptFlag() const { return interrupt_; }

  // --- graph and partition (sec. II, III) ---
  /// W_ii; 0 by default instead of the paper's 1 (see kDefaultDiagonalWeight).
  void setDiagonalWeight(double value) { params_.diagonal_weight = value; }
  double getDiagonalWeight() const { return params_.diagonal_weight; }
  void setBoundaryPasses(int passes) { params_.boundary_passes = passes; }
  int getBoundaryPasses() const { return params_.boundary_passes; }
  void setNcutThreshold(double threshold) { params_.ncut_threshold = threshold; }
  double getNcutThreshold() const { return params_.ncut_threshold; }
  void setSplitCriterion(SplitCriterion criterion) { params_.split = criterion; }
  SplitCriterion getSplitCriterion() const { return params_.split; }
  void setMinGroupSize(int size) { params_.min_group_size = size; }
  int getMinGroupSize() const { return params_.min_group_size; }
  void setMaxDepth(int depth) { params_.max_depth = depth; }
  int getMaxDepth() const { return params_.max_depth; }
  void setEigenSolver(EigenSolver solver) { params_.eigen_solver = solver; }
  EigenSolver getEigenSolver() const { return params_.eigen_solver; }
  /// The options compute() partitions with (GroupingParameters::
  /// partitionOptions() and this object's interrupt flag).
  PartitionOptions getPartitionOptions() const {
    PartitionOptions options = params_.partitionOptions();
    options.interrupt = interrupt_;
    return options;
  }

  /// Computes the overlap, builds W and partitions it. Throws
  /// std::invalid_argument on bad parameters or observations.
  Partition compute();

  /// The weight matrix W of the last compute() (diagonal as configured).
  const WeightMatrix& getWeightMatrix() const { return W_; }
  /// Pi, Psi and work statistics of the last compute() (without
  /// setKeepOverlapMatrix: the statistics only, Pi and the pairs empty).
  const OverlapResult& getOverlap() const { return overlap_result_; }
  /// Keep Pi and the pairs of Psi after W is built from them (on by
  /// default). Off, compute() frees them once W stands: on a large run they
  /// take twice W's memory and nothing after the graph needs them.
  void setKeepOverlapMatrix(bool keep) { keep_overlap_matrix_ = keep; }
  bool getKeepOverlapMatrix() const { return keep_overlap_matrix_; }
  /// The overlap stage as configured (model, voxel leaf, regions, threads),
  /// e.g. to compute the observations' regions for a picture.
  SensedSpaceOverlap<PointT> getSensedSpaceOverlap() const;
  /// Keep the observations' points in the common frame, as the overlap saw
  /// them (filtered, at the input poses), after compute(): off by default,
  /// as they are as large as the clouds.
  void setKeepWorldPoints(bool keep) { keep_world_points_ = keep; }
  bool getKeepWorldPoints() const { return keep_world_points_; }
  /// The points kept by the last compute() (empty unless setKeepWorldPoints(true)).
  const WorldPoints& getWorldPoints() const { return world_; }
  /// Keep the sensed regions the overlap was measured on (free-space and
  /// visibility models) after compute(), to draw them or cut places from
  /// them without computing them again: off by default (they are the largest
  /// part of the overlap stage's memory).
  void setKeepRegions(bool keep) { keep_regions_ = keep; }
  bool getKeepRegions() const { return keep_regions_; }
  /// The regions kept by the last compute() (empty unless setKeepRegions(true)
  /// and a region model).
  const ObservationRegions& getRegions() const { return regions_; }
  /// Called by compute() with the regions it keeps (setKeepRegions; empty for
  /// the points model) once the overlap is measured, before W and the
  /// partition: a caller can start work that needs the regions alone on a
  /// thread of its own while the partition runs (the places' pass over every
  /// beam, observeFloor). They stay as they are until the next compute() or
  /// clear(). What the callback throws leaves compute().
  using RegionsCallback = std::function<void(const ObservationRegions& regions)>;
  void setRegionsCallback(RegionsCallback callback) { regions_callback_ = std::move(callback); }
  /// Time spent in each stage of the last compute().
  const GroupingTimings& getTimings() const { return timings_; }
  /// What the user should know about the last compute(), deterministic and
  /// in order: observations with no point (each forms a group of its own),
  /// then the partition's eigen-solver fallbacks (Partition::warnings).
  const std::vector<std::string>& getWarnings() const { return warnings_; }
  /// The groups the last compute() joined across open floor
  /// (GroupingParameters::open_floor_width), as indices of the groups before.
  const std::vector<OpenFloorJoin>& getOpenFloorJoins() const { return open_floor_joins_; }

 private:
  std::vector<Observation<PointT>> observations_;
  GroupingParameters params_;
  SearchMethodPtr search_;
  ProgressCallback progress_;
  const InterruptFlag* interrupt_ = nullptr;
  OverlapResult overlap_result_;
  bool keep_overlap_matrix_ = true;
  WeightMatrix W_;
  bool keep_world_points_ = false;
  WorldPoints world_;
  bool keep_regions_ = false;
  ObservationRegions regions_;
  RegionsCallback regions_callback_;
  GroupingTimings timings_;
  std::vector<std::string> warnings_;
  std::vector<OpenFloorJoin> open_floor_joins_;
};

/// The step `obsgroup partition` and `stream` take after the grouping, with
/// the visibility model and params.join_passages (else it does nothing):
/// the places of `partition` (buildPlaceMap over the visibility regions of
/// `observations`, as the grouping measured them) and the groups whose
/// places meet through a passage, a corridor cut across rather than a door,
/// joined (joinThroughPassages; docs/method.md, "Passages"). Returns the
/// passages that joined two groups, their places named by the indices of
/// the groups before the join. Throws what buildPlaceMap throws.
template <typename PointT>
std::vector<Door> joinGroupsThroughPassages(const std::vector<Observation<PointT>>& observations,
                                            const GroupingParameters& params, Partition& partition);

}  // namespace obsgroup

#if defined(PCL_NO_PRECOMPILE) || defined(OBSGROUP_NO_PRECOMPILE)
#include "obsgroup/impl/observation_grouping.hpp"
#endif
