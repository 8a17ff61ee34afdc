#include "local_maps.h"

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include "obsgroup/common/parallel_for.h"

#include <cstdio>
#include <stdexcept>

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

template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZ>>&, int);
template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZI>>&, int);
template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZRGB>>&, int);

}  // namespace obsgroup::io
