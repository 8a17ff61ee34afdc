#pragma once
/// \file
/// LocalMapBuilder: one consistent local map per group (paper sec. IV-A,
/// step 3): the group's observations relative to a reference observation,
/// optionally refined by scan alignment (refinement.h), merged into one cloud.

#include "obsgroup/common/interrupt.h"
#include "obsgroup/maps/refinement.h"
#include "obsgroup/maps/topological_map.h"
#include "obsgroup/cloud/observation.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace obsgroup {

template <typename PointT>
struct LocalMap {
  LocalMapFrame frame;  ///< Members, reference and (refined) member poses.
  /// The members' points merged in the reference frame, voxel-filtered.
  typename pcl::PointCloud<PointT>::Ptr cloud;
  /// False when the cloud was too large for the voxel filter's indices and was kept unfiltered.
  bool filtered = true;
  /// What refinement changed, and why members kept their input poses.
  RefinementReport refinement;
};

template <typename PointT>
class LocalMapBuilder {
 public:
  using Ptr = std::shared_ptr<LocalMapBuilder<PointT>>;
  using ConstPtr = std::shared_ptr<const LocalMapBuilder<PointT>>;
  using PointCloud = pcl::PointCloud<PointT>;

  void setRefinement(Refinement refinement) { refinement_ = refinement; }
  Refinement getRefinement() const { return refinement_; }
  /// Voxel leaf of the merged cloud, metres; 0 keeps every point.
  void setVoxelLeafSize(double leaf) { voxel_leaf_ = leaf; }
  double getVoxelLeafSize() const { return voxel_leaf_; }
  /// Everything refinement is tuned by (refinement.h).
  void setRefinementParameters(const RefinementParameters& parameters) { parameters_ = parameters; }
  const RefinementParameters& getRefinementParameters() const { return parameters_; }
  /// Correspondence gate of the first alignment iteration, metres: bounds the pose error refinement can see.
  /// Planar scans and 3D clouds alike (RefinementParameters keeps one gate for each).
  void setMaxCorrespondenceDistance(double distance) {
    parameters_.max_correspondence_distance = parameters_.max_correspondence_distance_3d = distance;
  }
  /// The planar scans' gate (the 3D clouds' is in getRefinementParameters()).
  double getMaxCorrespondenceDistance() const { return parameters_.max_correspondence_distance; }
  /// Iterations per pairwise alignment.
  void setMaximumIterations(int iterations) { parameters_.max_iterations = iterations; }
  int getMaximumIterations() const { return parameters_.max_iterations; }
  /// Threads over groups; the result does not depend on it.
  void setNumberOfThreads(int threads) { threads_ = threads; }
  int getNumberOfThreads() const { return threads_; }
  /// A flag polled between groups; when set, build() throws Interrupted.
  void setInterruptFlag(const InterruptFlag* flag) { interrupt_ = flag; }
  const InterruptFlag* getInterruptFlag() const { return interrupt_; }
  /// Called by the build of a partition with the maps done so far (never
  /// fewer than the call before) and their total, one thread at a time.
  void setProgressCallback(std::function<void(std::size_t done, std::size_t total)> progress) {
    progress_ = std::move(progress);
  }

  /// The local map of one group (observation indices, ascending); W chooses
  /// the reference and the pairs to align.
  LocalMap<PointT> build(const std::vector<Observation<PointT>>& observations, const pcl::Indices& group,
                         const WeightMatrix& W) const;
  /// The local maps of every group of a partition, in group order, built in
  /// parallel. An error in one group is rethrown naming it ("local map 3:
  /// ..."), std::invalid_argument staying std::invalid_argument.
  std::vector<LocalMap<PointT>> build(const std::vector<Observation<PointT>>& observations,
                                      const Partition& partition, const WeightMatrix& W) const;

 private:
  LocalMap<PointT> buildGroup(const std::vector<Observation<PointT>>& observations, const pcl::Indices& group,
                              const WeightMatrix& W, const std::vector<Eigen::Isometry3d>& poses) const;
  void refine(const std::vector<Observation<PointT>>& observations, const WeightMatrix& W,
              LocalMap<PointT>& map) const;

  Refinement refinement_ = Refinement::None;
  RefinementParameters parameters_;
  double voxel_leaf_ = 0.05;
  int threads_ = 0;
  std::function<void(std::size_t, std::size_t)> progress_;
  const InterruptFlag* interrupt_ = nullptr;
};

}  // namespace obsgroup

#if defined(PCL_NO_PRECOMPILE) || defined(OBSGROUP_NO_PRECOMPILE)
#include "obsgroup/maps/impl/local_map_builder.hpp"
#endif
