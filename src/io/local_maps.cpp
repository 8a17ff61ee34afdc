#include "local_maps.h"

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <omp.h>

#include <cstdio>
#include <exception>
#include <stdexcept>

namespace obsgroup::io {

template <typename PointT>
std::size_t writeLocalMaps(const OutputFolder& out, const std::vector<LocalMap<PointT>>& maps, int threads) {
  // Compressing and writing a thousand files is worth two threads; the files
  // do not depend on each other.
  const int n = static_cast<int>(maps.size());
  std::vector<std::exception_ptr> failures(maps.size());
  std::size_t total = 0;
#pragma omp parallel for num_threads(threads > 0 ? threads : omp_get_max_threads()) schedule(dynamic, 4) \
    reduction(+ : total)
  for (int g = 0; g < n; ++g) {
    try {
      const pcl::PointCloud<PointT>& cloud = *maps[g].cloud;
      char name[64];
      std::snprintf(name, sizeof name, "local_maps/group_%03d.pcd", g);
      // PCL writes VIEWPOINT with 6 significant digits; topology.json keeps the full pose.
      out.write(name, [&cloud](const std::string& temporary) {
        // PCL refuses to write an empty cloud in binary; an ASCII header with 0 points is valid.
        const int status = cloud.empty() ? pcl::io::savePCDFileASCII(temporary, cloud)
                                         : pcl::io::savePCDFileBinaryCompressed(temporary, cloud);
        if (status < 0) throw std::runtime_error(temporary + ": cannot write");
      });
      total += cloud.size();
    } catch (...) {
      failures[g] = std::current_exception();
    }
  }
  for (const auto& failure : failures)
    if (failure) std::rethrow_exception(failure);
  return total;
}

template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZ>>&, int);
template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZI>>&, int);
template std::size_t writeLocalMaps(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZRGB>>&, int);

}  // namespace obsgroup::io
