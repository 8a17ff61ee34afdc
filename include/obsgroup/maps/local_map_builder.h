#pragma once
/// \file
/// LocalMapBuilder: one consistent local map per group (paper sec. IV-A,
/// step 3): the group's observations relative to a reference observation,
/// optionally refined by scan alignment, merged into one cloud.

#include "obsgroup/interrupt.h"
#include "obsgroup/maps/topological_map.h"
#include "obsgroup/observation.h"

#include <memory>
#include <string>
#include <vector>

namespace obsgroup {

/// How the members' relative poses are refined.
enum class Refinement {
  None,  ///< Keep the input poses.
  Icp,   ///< Pairwise ICP along the group's maximum spanning tree of W, from the reference outwards.
  Lum    ///< Icp, then Lu & Milios multi-view alignment (pcl::registration::LUM) over all overlapping pairs, as the paper.
};

std::string toString(Refinement refinement);
/// Parses "none", "icp" or "lum"; throws std::invalid_argument otherwise.
Refinement refinementFromString(const std::string& name);

template <typename PointT>
struct LocalMap {
  LocalMapFrame frame;  ///< Members, reference and (refined) member poses.
  /// The members' points merged in the reference frame, voxel-filtered.
  typename pcl::PointCloud<PointT>::Ptr cloud;
  /// False when the cloud was too large for the voxel filter's indices and was kept unfiltered.
  bool filtered = true;
  /// True when Refinement::Lum diverged and the ICP result was kept instead.
  bool fell_back = false;
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
  /// Largest distance of a point correspondence in ICP and LUM, metres.
  void setMaxCorrespondenceDistance(double distance) { max_correspondence_distance_ = distance; }
  double getMaxCorrespondenceDistance() const { return max_correspondence_distance_; }
  /// ICP iterations per pair; LUM iterations in all (over three rounds of correspondences).
  void setMaximumIterations(int iterations) { max_iterations_ = iterations; }
  int getMaximumIterations() const { return max_iterations_; }
  /// Threads over groups; the result does not depend on it.
  void setNumberOfThreads(int threads) { threads_ = threads; }
  int getNumberOfThreads() const { return threads_; }
  /// A flag polled between groups; when set, build() throws Interrupted.
  void setInterruptFlag(const InterruptFlag* flag) { interrupt_ = flag; }
  const InterruptFlag* getInterruptFlag() const { return interrupt_; }

  /// The local map of one group (observation indices, ascending); W chooses
  /// the reference and the pairs to align.
  LocalMap<PointT> build(const std::vector<Observation<PointT>>& observations, const std::vector<int>& group,
                         const WeightMatrix& W) const;
  /// The local maps of every group of a partition, in group order.
  std::vector<LocalMap<PointT>> build(const std::vector<Observation<PointT>>& observations,
                                      const Partition& partition, const WeightMatrix& W) const;

 private:
  LocalMap<PointT> buildGroup(const std::vector<Observation<PointT>>& observations, const std::vector<int>& group,
                              const WeightMatrix& W, const std::vector<Eigen::Isometry3d>& poses) const;
  void refineIcp(const std::vector<Observation<PointT>>& observations, const WeightMatrix& W,
                 LocalMapFrame& frame) const;
  /// False (frame unchanged) when LUM moved a pose further than twice the
  /// correspondence distance or 0.2 rad: it has diverged.
  bool refineLum(const std::vector<Observation<PointT>>& observations, const WeightMatrix& W,
                 LocalMapFrame& frame) const;

  Refinement refinement_ = Refinement::None;
  double voxel_leaf_ = 0.05;
  double max_correspondence_distance_ = 0.25;
  int max_iterations_ = 30;
  int threads_ = 0;
  const InterruptFlag* interrupt_ = nullptr;
};

}  // namespace obsgroup

#if defined(PCL_NO_PRECOMPILE) || defined(OBSGROUP_NO_PRECOMPILE)
#include "obsgroup/maps/impl/local_map_builder.hpp"
#endif
