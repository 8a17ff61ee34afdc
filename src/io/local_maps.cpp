#include "local_maps.h"

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cstdio>
#include <stdexcept>

namespace obsgroup::io {

template <typename PointT>
std::size_t writeLocalMaps(const OutputFolder& out, const std::vector<LocalMap<PointT>>& maps) {
  std::size_t total = 0;
  for (std::size_t g = 0; g < maps.size(); ++g) {
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
    total += cloud.size();
  }
  return total;
}

template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZ>>&);
template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZI>>&);
template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZRGB>>&);

}  // namespace obsgroup::io
