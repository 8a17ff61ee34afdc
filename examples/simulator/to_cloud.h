#pragma once
/// \file
/// Simulated scans as PCL clouds.

#include "floor_plan.h"

#include <pcl/point_cloud.h>

namespace obsgroup::sim {

/// A scan's points as a cloud in the sensor frame; z = `z` for every point.
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr toCloud(const std::vector<Eigen::Vector2d>& points, float z = 0.0f) {
  typename pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
  cloud->reserve(points.size());
  for (const auto& p : points) {
    PointT q;
    q.x = static_cast<float>(p.x());
    q.y = static_cast<float>(p.y());
    q.z = z;
    cloud->push_back(q);
  }
  return cloud;
}

}  // namespace obsgroup::sim
