#pragma once
/// \file
/// An observation of the paper's eq. (14): the sensed data o_i (a PCL cloud in
/// the sensor frame) and the pose p_i it was taken from.

#include "obsgroup/common/invalid_observation.h"

#include <pcl/point_cloud.h>
#include <pcl/types.h>

#include <type_traits>
#include <vector>

#include <Eigen/Geometry>

namespace obsgroup {

// A group (Partition::groups, a local map's members) is a list of
// observation indices: with PCL's default 32-bit index_t it is a
// pcl::Indices, and the PCL layer takes groups as such.
static_assert(std::is_same_v<pcl::Indices, std::vector<int>>,
              "obsgroup's groups are pcl::Indices: PCL must be built with its default 32-bit signed index_t");

template <typename PointT>
struct Observation {
  using PointCloud = pcl::PointCloud<PointT>;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;

  /// Points in the sensor frame: a 2D scan (z = 0) or a 3D cloud.
  PointCloudConstPtr cloud;
  /// Pose of the sensor frame in the common (world) frame.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

/// A planar pose (x, y, heading yaw in radians) as an isometry about z.
inline Eigen::Isometry3d pose2D(double x, double y, double yaw) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() << x, y, 0.0;
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return pose;
}

/// The pose a PCD file stores in its VIEWPOINT field, read back by PCL into
/// the cloud's sensor_origin_ and sensor_orientation_.
template <typename PointT>
Eigen::Isometry3d poseFromSensorOrigin(const pcl::PointCloud<PointT>& cloud) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = cloud.sensor_origin_.template head<3>().template cast<double>();
  pose.linear() = cloud.sensor_orientation_.template cast<double>().normalized().toRotationMatrix();
  return pose;
}

}  // namespace obsgroup
