#pragma once
// A local map's member made ready for alignment: thinned, a surface normal
// per point, a search tree; and the point-to-surface residual against it.

#include "obsgroup/maps/refinement.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <flann/util/result_set.h>

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace obsgroup::refinement {

/// A member thinned for alignment, with a surface normal per point (zero
/// where the neighbourhood is no line or plane) and a search tree. The tree
/// is FLANN's single-tree index queried directly: its knnSearch opens an
/// OpenMP region per call, which cost more than the search for one point.
struct PreparedMember {
  using Index = flann::KDTreeSingleIndex<flann::L2_Simple<float>>;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud;
  std::vector<Eigen::Vector3d> normals;
  std::unique_ptr<Index> index;  ///< null when the cloud is too small to match against

  /// The `k` nearest points of `query` (fewer if the cloud is smaller), by
  /// squared distance; `result` is the caller's, reused across queries.
  void nearest(const Eigen::Vector3f& query, flann::KNNSimpleResultSet<float>& result) const {
    result.clear();
    index->findNeighbors(result, query.data(), flann::SearchParams(-1));
  }
};

/// The member's points thinned to `voxel` metres (0: all), with their
/// normals: lines fitted in the plane for `planar` scans, planes otherwise.
std::unique_ptr<PreparedMember> prepare(const MemberPoints& points, double voxel, bool planar);

/// Point-to-surface residual of `x` (in the target's frame, its surface
/// normal `source_normal` turned into that frame too, zero if it has none)
/// against its nearest target point; false when none lies within `gate`,
/// the target point has no normal, or the normals differ by more than about
/// 35 degrees. Normals face their sensor, so this rejects a floor point
/// matched to a wall and, above all, the far face of a thin wall seen
/// through a door: that pulled exact depth-camera poses up to 30 cm away.
/// `nearest` is a one-point result set the caller reuses.
bool residual(const PreparedMember& target, const Eigen::Vector3d& x, const Eigen::Vector3d& source_normal,
              double gate, double& r, Eigen::Vector3d& normal, flann::KNNSimpleResultSet<float>& nearest);

}  // namespace obsgroup::refinement
