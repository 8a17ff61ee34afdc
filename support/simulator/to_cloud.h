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

/// One laser scan of `plan` taken at `pose` as a cloud in the sensor frame
/// (z = 0); beams with no return give no point.
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr scanCloud(const FloorPlan& plan, const Pose2D& pose, const LaserModel& laser,
                                                std::uint64_t seed) {
  return toCloud<PointT>(scanToPoints(plan.scan(pose, laser, seed), laser));
}

/// 3D points in the sensor frame as a cloud whose sensor origin stands
/// `height` over `pose`, facing its heading (a PCD file's VIEWPOINT).
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr sensorCloud(const std::vector<Eigen::Vector3d>& points, const Pose2D& pose,
                                                  double height) {
  typename pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
  cloud->reserve(points.size());
  for (const auto& q : points) {
    PointT p;
    p.x = static_cast<float>(q.x());
    p.y = static_cast<float>(q.y());
    p.z = static_cast<float>(q.z());
    cloud->push_back(p);
  }
  cloud->sensor_origin_ << float(pose.x), float(pose.y), float(height), 0.0f;
  cloud->sensor_orientation_ = Eigen::Quaternionf(Eigen::AngleAxisf(float(pose.yaw), Eigen::Vector3f::UnitZ()));
  return cloud;
}

/// One depth image of `plan` as a cloud in the camera frame, its pose (the
/// camera standing over `pose`) in the cloud's sensor origin and orientation,
/// as a PCD file's VIEWPOINT stores it.
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr depthCloud(const FloorPlan& plan, const Pose2D& pose, const DepthCamera& camera,
                                                 std::uint64_t seed) {
  return sensorCloud<PointT>(plan.depthImage(pose, camera, seed), pose, camera.height_above_floor);
}

/// One lidar sweep as a cloud in the sensor frame (x ahead, y left, z up),
/// its sensor origin `lidar.height_above_floor` over the pose.
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr lidarCloud(const FloorPlan& plan, const Pose2D& pose, const Lidar& lidar,
                                                 std::uint64_t seed) {
  return sensorCloud<PointT>(plan.lidarSweep(pose, lidar, seed), pose, lidar.height_above_floor);
}

}  // namespace obsgroup::sim
