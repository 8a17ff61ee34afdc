#include "local_maps.h"

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include "obsgroup/common/parallel_for.h"

#include <cstdio>
#include <stdexcept>
#include <type_traits>

namespace obsgroup::io {

template <typename PointT>
std::size_t writeLocalMaps(const OutputFolder& out, const std::vector<LocalMap<PointT>>& maps, int threads) {
  // Compressing and writing a thousand files is worth two threads; the files
  // do not depend on each other.
  parallelFor(maps.size(), threads, 4, [&](std::size_t g) {
    const pcl::PointCloud<PointT>& cloud = *maps[g].cloud;
    char name[64];
    std::snprintf(name, sizeof name, "local_maps/group_%03zu.pcd", g);
    // PCL writes VIEWPOINT with 6 significant digits; topology.json keeps the full pose.
    out.write(name, [&cloud](const std::string& temporary) {
      // PCL refuses to write an empty cloud in binary; an ASCII header with 0 points is valid.
      const int status = cloud.empty() ? pcl::io::savePCDFileASCII(temporary, cloud)
                                       : pcl::io::savePCDFileBinaryCompressed(temporary, cloud);
      if (status < 0) throw std::runtime_error(temporary + ": cannot write");
    });
  });
  std::size_t total = 0;
  for (const auto& map : maps) total += map.cloud->size();
  return total;
}

namespace {

/// The labelled point of a map's point moved to the world frame.
template <typename PointT>
auto labelledPoint(const PointT& p, const Eigen::Isometry3f& pose, std::uint32_t label) {
  const Eigen::Vector3f q = pose * p.getVector3fMap();
  if constexpr (std::is_same_v<PointT, pcl::PointXYZRGB>) {
    pcl::PointXYZRGBL out;
    out.x = q.x(), out.y = q.y(), out.z = q.z();
    out.rgba = p.rgba;
    out.label = label;
    return out;
  } else {
    pcl::PointXYZL out;
    out.x = q.x(), out.y = q.y(), out.z = q.z();
    out.label = label;
    return out;
  }
}

}  // namespace

template <typename PointT>
std::size_t writeLabelledMap(const OutputFolder& out, const std::vector<LocalMap<PointT>>& maps,
                             const std::vector<int>& place_ids) {
  using Labelled = decltype(labelledPoint(PointT{}, Eigen::Isometry3f::Identity(), 0));
  pcl::PointCloud<Labelled> cloud;
  std::size_t total = 0;
  for (const auto& map : maps) total += map.cloud->size();
  cloud.reserve(total);
  for (std::size_t g = 0; g < maps.size(); ++g) {
    const Eigen::Isometry3f pose = maps[g].frame.pose.template cast<float>();
    const auto label = std::uint32_t(place_ids.at(g));
    for (const PointT& p : maps[g].cloud->points) cloud.push_back(labelledPoint(p, pose, label));
  }
  out.write("map_labelled.pcd", [&cloud](const std::string& temporary) {
    const int status = cloud.empty() ? pcl::io::savePCDFileASCII(temporary, cloud)
                                     : pcl::io::savePCDFileBinaryCompressed(temporary, cloud);
    if (status < 0) throw std::runtime_error(temporary + ": cannot write");
  });
  return cloud.size();
}

template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZ>>&, int);
template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZI>>&, int);
template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZRGB>>&, int);
template std::size_t writeLabelledMap(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZ>>&,
                                      const std::vector<int>&);
template std::size_t writeLabelledMap(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZI>>&,
                                      const std::vector<int>&);
template std::size_t writeLabelledMap(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZRGB>>&,
                                      const std::vector<int>&);

}  // namespace obsgroup::io
