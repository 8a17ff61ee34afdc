#pragma once
// Shared helpers of the tests: simulated scans as observations, the real log
// shipped in data/, and a brute-force reference for eq. (16)-(17).

#include "floor_plan.h"
#include "to_cloud.h"

#include <obsgroup/cloud/observation.h>

#include <pcl/io/pcd_io.h>

#include <cstdio>
#include <string>
#include <vector>

namespace obsgroup::test {

/// 2D scans of `plan` from `poses` (noise-free unless told), as observations.
template <typename PointT>
std::vector<Observation<PointT>> simulate(const sim::FloorPlan& plan, const std::vector<sim::Pose2D>& poses,
                                          sim::LaserModel laser = {}, float z = 0.0f) {
  std::vector<Observation<PointT>> out;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const auto points = sim::scanToPoints(plan.scan(poses[k], laser, k), laser);
    out.push_back({sim::toCloud<PointT>(points, z), pose2D(poses[k].x, poses[k].y, poses[k].yaw)});
  }
  return out;
}

/// 3D clouds: each 2D scan repeated at several heights (walls are vertical).
template <typename PointT>
std::vector<Observation<PointT>> simulate3D(const sim::FloorPlan& plan, const std::vector<sim::Pose2D>& poses,
                                            const std::vector<float>& heights) {
  sim::LaserModel laser;
  std::vector<Observation<PointT>> out;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const auto points = sim::scanToPoints(plan.scan(poses[k], laser, k), laser);
    typename pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
    for (float h : heights) *cloud += *sim::toCloud<PointT>(points, h);
    out.push_back({cloud, pose2D(poses[k].x, poses[k].y, poses[k].yaw)});
  }
  return out;
}

/// The first `count` observations of data/real/localization_demo (a real
/// office log, MRPT datasets; pose from each PCD's VIEWPOINT).
inline std::vector<Observation<pcl::PointXYZ>> realLog(int count = 72) {
  std::vector<Observation<pcl::PointXYZ>> out;
  for (int i = 0; i < count; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "/real/localization_demo/pcd/%06d.pcd", i);
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
    if (pcl::io::loadPCDFile(std::string(OBSGROUP_DATA_DIR) + name, *cloud) < 0) return {};
    out.push_back({cloud, poseFromSensorOrigin(*cloud)});
  }
  return out;
}

/// Pi(i, j) of eq. (17) by testing every point pair, in double, in the world
/// frame. Independent of the library's back-ends.
template <typename PointT>
double bruteForceMatchRatio(const Observation<PointT>& a, const Observation<PointT>& b, double delta) {
  std::vector<Eigen::Vector3d> pb;
  for (const auto& q : b.cloud->points) pb.push_back(b.pose * Eigen::Vector3d(q.x, q.y, q.z));
  std::size_t matched = 0, total = 0;
  for (const auto& p : a.cloud->points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    ++total;
    const Eigen::Vector3d w = a.pose * Eigen::Vector3d(p.x, p.y, p.z);
    for (const auto& q : pb) {
      if ((w - q).norm() <= delta) {
        ++matched;
        break;
      }
    }
  }
  return total ? double(matched) / double(total) : 0.0;
}

}  // namespace obsgroup::test
