#include "local_maps.h"

#include <pcl/common/common.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace obsgroup::io {

namespace {

/// The group's clouds in the reference frame; transforms composed in double.
template <typename PointT>
pcl::PointCloud<PointT> mergeGroup(const std::vector<Observation<PointT>>& observations, const std::vector<int>& group) {
  const Eigen::Isometry3d reference_inverse = observations[group.front()].pose.inverse();
  pcl::PointCloud<PointT> merged;
  for (int i : group) {
    const Eigen::Isometry3d relative = reference_inverse * observations[i].pose;
    for (PointT p : observations[i].cloud->points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
      const Eigen::Vector3f q = (relative * Eigen::Vector3d(p.x, p.y, p.z)).template cast<float>();
      p.x = q.x();
      p.y = q.y();
      p.z = q.z();
      merged.push_back(p);
    }
  }
  return merged;
}

template <typename PointT>
bool voxelFilter(pcl::PointCloud<PointT>& cloud, double leaf) {
  if (leaf <= 0.0 || cloud.empty()) return true;
  Eigen::Vector4f lo, hi;
  pcl::getMinMax3D(cloud, lo, hi);
  const Eigen::Array3d cells = ((hi - lo).head<3>().cast<double>() / leaf).array().floor() + 1.0;
  if (cells.prod() > double(std::numeric_limits<std::int32_t>::max())) return false;
  typename pcl::PointCloud<PointT>::Ptr input(new pcl::PointCloud<PointT>(std::move(cloud)));
  pcl::VoxelGrid<PointT> voxel;
  voxel.setLeafSize(float(leaf), float(leaf), float(leaf));
  voxel.setInputCloud(input);
  voxel.filter(cloud);
  return true;
}

}  // namespace

template <typename PointT>
std::size_t writeLocalMaps(const OutputFolder& out, const std::vector<Observation<PointT>>& observations,
                           const Partition& partition, double leaf, std::vector<std::string>& warnings) {
  std::size_t total = 0;
  for (std::size_t g = 0; g < partition.groups.size(); ++g) {
    pcl::PointCloud<PointT> map = mergeGroup(observations, partition.groups[g]);
    char name[64];
    std::snprintf(name, sizeof name, "local_maps/group_%03zu.pcd", g);
    if (!voxelFilter(map, leaf))
      warnings.push_back(std::string(name) + ": too large for a " + std::to_string(leaf) +
                         " m voxel filter; written unfiltered");
    const Eigen::Isometry3d& reference = observations[partition.groups[g].front()].pose;
    // PCL writes VIEWPOINT with 6 significant digits; topology.json keeps the full pose.
    map.sensor_origin_ << reference.translation().cast<float>(), 0.0f;
    map.sensor_orientation_ = Eigen::Quaternionf(reference.linear().cast<float>());
    map.width = static_cast<std::uint32_t>(map.size());
    map.height = 1;
    out.write(name, [&map](const std::string& temporary) {
      if (map.empty()) {
        // PCL refuses to write an empty cloud in binary; an ASCII header with 0 points is valid.
        if (pcl::io::savePCDFileASCII(temporary, map) < 0) throw std::runtime_error(temporary + ": cannot write");
      } else if (pcl::io::savePCDFileBinaryCompressed(temporary, map) < 0) {
        throw std::runtime_error(temporary + ": cannot write");
      }
    });
    total += map.size();
  }
  return total;
}

template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<Observation<pcl::PointXYZ>>&,
                                    const Partition&, double, std::vector<std::string>&);
template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<Observation<pcl::PointXYZI>>&,
                                    const Partition&, double, std::vector<std::string>&);
template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<Observation<pcl::PointXYZRGB>>&,
                                    const Partition&, double, std::vector<std::string>&);

}  // namespace obsgroup::io
