#include "local_maps.h"

#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include "obsgroup/common/parallel_for.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
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
      if (cloud.empty()) {
        if (pcl::io::savePCDFileASCII(temporary, cloud) < 0) throw std::runtime_error(temporary + ": cannot write");
        return;
      }
      // The same bytes as savePCDFileBinaryCompressed, written through a
      // stream: that one maps each file into memory under a file lock, and
      // two threads writing thousands of small maps then wait on each other
      // in the kernel (100,100 scans: 5,004 maps).
      pcl::PCLPointCloud2 blob;
      pcl::toPCLPointCloud2(cloud, blob);
      std::ostringstream bytes;
      if (pcl::PCDWriter().writeBinaryCompressed(bytes, blob, cloud.sensor_origin_, cloud.sensor_orientation_) < 0)
        throw std::runtime_error(temporary + ": cannot write");
      std::ofstream file(temporary, std::ios::binary);
      file << bytes.str();
      file.close();
      if (!file) throw std::runtime_error(temporary + ": cannot write");
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
  std::size_t total = 0;
  for (const auto& map : maps) total += map.cloud->size();
  if (total > std::size_t(std::numeric_limits<int>::max()))
    throw std::runtime_error("map_labelled.pcd: more than 2^31 - 1 points, beyond what a PCD header counts");
  // Written map by map in PCL's binary layout (each field packed, padding
  // left out, as PCDWriter::writeBinary writes it), never as one cloud of
  // the whole map: that cloud and a compressed copy would double the run's
  // memory at scale (docs/performance.md).
  std::vector<pcl::PCLPointField> fields;
  std::size_t packed = 0;
  for (const pcl::PCLPointField& field : pcl::getFields<Labelled>())
    if (field.name != "_") {
      fields.push_back(field);
      packed += std::size_t(std::max<int>(1, int(field.count))) * std::size_t(pcl::getFieldSize(field.datatype));
    }
  out.write("map_labelled.pcd", [&](const std::string& temporary) {
    if (total == 0) {  // PCL refuses to write an empty cloud in binary; an ASCII header with 0 points is valid.
      if (pcl::io::savePCDFileASCII(temporary, pcl::PointCloud<Labelled>()) < 0)
        throw std::runtime_error(temporary + ": cannot write");
      return;
    }
    std::ofstream file(temporary, std::ios::binary);
    file << pcl::PCDWriter::generateHeader(pcl::PointCloud<Labelled>(), int(total)) << "DATA binary\n";
    std::vector<char> bytes;
    for (std::size_t g = 0; g < maps.size() && file; ++g) {
      const Eigen::Isometry3f pose = maps[g].frame.pose.template cast<float>();
      const auto label = std::uint32_t(place_ids.at(g));
      bytes.resize(maps[g].cloud->size() * packed);
      char* to = bytes.data();
      for (const PointT& p : maps[g].cloud->points) {
        const Labelled point = labelledPoint(p, pose, label);
        for (const pcl::PCLPointField& field : fields) {
          const std::size_t size = std::size_t(std::max<int>(1, int(field.count))) * pcl::getFieldSize(field.datatype);
          std::memcpy(to, reinterpret_cast<const char*>(&point) + field.offset, size);
          to += size;
        }
      }
      file.write(bytes.data(), std::streamsize(bytes.size()));
    }
    file.close();
    if (!file) throw std::runtime_error(temporary + ": cannot write");
  });
  return total;
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
