#pragma once
/// \file
/// The points of a cloud with finite x, y and z: the only ones that carry
/// sensed space or belong in a map.

#include <pcl/common/point_tests.h>
#include <pcl/point_cloud.h>

namespace obsgroup {

/// The points of `cloud` for which pcl::isXYZFinite holds, in order. Not
/// pcl::removeNaNFromPointCloud: it copies a cloud marked is_dense untouched,
/// and clouds from readers and users are marked dense with NaN or Inf
/// returns in them, so every point is tested.
template <typename PointT>
pcl::PointCloud<PointT> finitePoints(const pcl::PointCloud<PointT>& cloud) {
  pcl::PointCloud<PointT> finite;
  finite.reserve(cloud.size());
  for (const PointT& p : cloud.points)
    if (pcl::isXYZFinite(p)) finite.push_back(p);
  finite.header = cloud.header;
  finite.sensor_origin_ = cloud.sensor_origin_;
  finite.sensor_orientation_ = cloud.sensor_orientation_;
  return finite;
}

}  // namespace obsgroup
