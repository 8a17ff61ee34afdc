#pragma once
/// \file
/// Sensed-space overlap (SSO) of paper sec. IV-A, eq. (16)-(18), for any PCL
/// point type with x, y, z.

#include "obsgroup/common/interrupt.h"
#include "obsgroup/cloud/observation.h"
#include "obsgroup/overlap/overlap_matrix.h"
#include "obsgroup/overlap/sensed_regions.h"
#include "obsgroup/overlap/world_points.h"

#include <pcl/search/search.h>

#include <memory>
#include <vector>

namespace obsgroup {

/// Computes Pi (eq. 17) and Psi (eq. 18) for all pairs of observations.
///
/// Each observation's points are cleaned of NaN/Inf, optionally downsampled
/// with pcl::VoxelGrid in the sensor frame, and moved to the world frame. Both
/// neighbour back-ends give the same matrix: they decide a match with the
/// same double-precision predicate on the same coordinates. Pairs whose
/// bounding boxes, grown by delta, do not intersect are never compared.
template <typename PointT>
class SensedSpaceOverlap {
 public:
  using Ptr = std::shared_ptr<SensedSpaceOverlap<PointT>>;
  using ConstPtr = std::shared_ptr<const SensedSpaceOverlap<PointT>>;
  using PointCloud = pcl::PointCloud<PointT>;
  using SearchMethod = pcl::search::Search<PointT>;
  using SearchMethodPtr = typename SearchMethod::Ptr;

  /// Tolerance delta of the match function C, eq. (16), in metres (default 0.1).
  void setMatchDistance(double delta) { delta_ = delta; }
  double getMatchDistance() const { return delta_; }

  /// Leaf size of the voxel downsampling applied to each observation before
  /// matching, in metres; 0 (the default) disables it.
  void setVoxelLeafSize(double leaf) { voxel_leaf_ = leaf; }
  double getVoxelLeafSize() const { return voxel_leaf_; }

  /// The model of the sensed space (see sensed_regions.h): the paper's
  /// points (the default here), free space or visibility.
  void setSensedSpaceModel(SensedSpaceModel model) { model_ = model; }
  SensedSpaceModel getSensedSpaceModel() const { return model_; }
  /// Cell size, range and the rest of the free-space and visibility models.
  void setRegionParameters(const RegionParameters& params) { region_ = params; }
  const RegionParameters& getRegionParameters() const { return region_; }

  void setNeighbourSearch(NeighbourSearch method) { neighbour_search_ = method; }
  NeighbourSearch getNeighbourSearch() const { return neighbour_search_; }

  /// A PCL search object for the PclSearch back-end, as PCL algorithms take
  /// one. It is given each observation in turn with setInputCloud(), so the
  /// back-end then runs on one thread. Without it, each thread makes its own
  /// pcl::search::KdTree. Setting it selects NeighbourSearch::PclSearch.
  void setSearchMethod(const SearchMethodPtr& search) {
    search_ = search;
    neighbour_search_ = NeighbourSearch::PclSearch;
  }
  SearchMethodPtr getSearchMethod() const { return search_; }

  /// Threads for the per-observation work; 0 (the default) uses OpenMP's
  /// default. The result is bit-for-bit the same for any value.
  void setNumberOfThreads(int threads) { threads_ = threads; }
  int getNumberOfThreads() const { return threads_; }

  /// Called as observations are matched (the overlap stage can take minutes
  /// on big logs); empty by default.
  void setProgressCallback(ProgressCallback callback) { progress_ = std::move(callback); }
  const ProgressCallback& getProgressCallback() const { return progress_; }

  /// A flag polled during compute(); when it is set, compute() stops and
  /// throws Interrupted. Not owned; null (the default) disables polling.
  void setInterruptFlag(const InterruptFlag* flag) { interrupt_ = flag; }
  const InterruptFlag* getInterruptFlag() const { return interrupt_; }

  /// Filters and moves every observation to the common frame. Throws
  /// std::invalid_argument on a null cloud, a non-finite pose or a voxel
  /// leaf too small for a cloud's extent.
  WorldPoints toWorld(const std::vector<Observation<PointT>>& observations) const;
  /// The origin toWorld re-centres the points on: the first observation's
  /// position (zero when there is none or it is not finite).
  static Eigen::Vector3d worldOrigin(const std::vector<Observation<PointT>>& observations) {
    if (!observations.empty() && observations[0].pose.translation().allFinite())
      return observations[0].pose.translation();
    return Eigen::Vector3d::Zero();
  }
  /// One observation's points as toWorld gives them, re-centred on `origin`
  /// (worldOrigin, as toWorld does). Throws
  /// std::invalid_argument as toWorld does.
  std::vector<Eigen::Vector3f> observationToWorld(const Observation<PointT>& observation,
                                                  const Eigen::Vector3d& origin) const;

  /// The region of every observation under the free-space or visibility
  /// model (what compute() measures the overlap of), e.g. to draw it.
  ObservationRegions computeRegions(const std::vector<Observation<PointT>>& observations,
                                    const WorldPoints& world) const;

  /// Pi and Psi for all pairs. Throws std::invalid_argument on bad parameters.
  OverlapResult compute(const std::vector<Observation<PointT>>& observations) const;
  /// The same from the observations' points already in the common frame
  /// (toWorld(observations)), e.g. kept to draw them afterwards. With
  /// `regions` (free-space and visibility models), the regions the overlap is
  /// measured on are kept there, as computeRegions() gives them, so that a
  /// caller who draws them or cuts places from them does not compute them
  /// again (the result is the same; the regions are held until it returns).
  OverlapResult compute(const std::vector<Observation<PointT>>& observations, const WorldPoints& world,
                        ObservationRegions* regions = nullptr) const;

 private:
  MatchCounts countMatchesPclSearch(const WorldPoints& world) const;

  double delta_ = 0.1;
  SensedSpaceModel model_ = SensedSpaceModel::Points;
  RegionParameters region_;
  double voxel_leaf_ = 0.0;
  NeighbourSearch neighbour_search_ = NeighbourSearch::SharedGrid;
  SearchMethodPtr search_;
  int threads_ = 0;
  ProgressCallback progress_;
  const InterruptFlag* interrupt_ = nullptr;
};

}  // namespace obsgroup

#if defined(PCL_NO_PRECOMPILE) || defined(OBSGROUP_NO_PRECOMPILE)
#include "obsgroup/overlap/impl/sensed_space_overlap.hpp"
#endif
