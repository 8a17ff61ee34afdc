// Inputs for the scaling benchmark: a long building (3 m corridor, 8 x 6 m
// rooms on both sides) whose local density stays bounded however long it is.
//
//   make_scaling_input 2d N FILE.clf   N scans of 360 beams (360 degrees, 20 m) as a CARMEN log
//   make_scaling_input 3d N FOLDER     N depth-camera clouds of 160 x 120 points as PCD files
//
// The route is about 0.2 m of building per scan, so 10,000 scans cover 2 km.

#include "floor_plan.h"
#include "to_cloud.h"

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

using namespace obsgroup::sim;

namespace {

constexpr double kBuildingPerScan = 0.2;  // metres of building per scan

int write2D(int n, const std::string& path) {
  const double length = std::max(16.0, n * kBuildingPerScan);
  const FloorPlan plan = longBuilding(length);
  const auto route = longBuildingRoute(length, n);
  LaserModel laser;
  laser.beams = 360;
  laser.field_of_view = 2 * 3.14159265358979323846 * 359.0 / 360.0;  // 1 degree apart, no beam twice
  laser.max_range = 20.0;
  laser.range_noise = 0.01;
  std::vector<std::string> lines(route.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (std::size_t k = 0; k < route.size(); ++k) {
    const Pose2D& p = route[k];
    const auto ranges = plan.scan(p, laser, k);
    std::string& line = lines[k];
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, "ROBOTLASER1 99 %.9f %.9f %.9f %.3f 0.01 0 %d", -laser.field_of_view / 2,
                  laser.field_of_view, laser.field_of_view / (laser.beams - 1), laser.max_range, laser.beams);
    line = buffer;
    for (double r : ranges) {
      std::snprintf(buffer, sizeof buffer, " %.3f", r);
      line += buffer;
    }
    std::snprintf(buffer, sizeof buffer, " 0 %.6f %.6f %.6f %.6f %.6f %.6f 0 0 0 0 0 %.3f sim %.3f\n", p.x, p.y, p.yaw,
                  p.x, p.y, p.yaw, k * 0.1, k * 0.1);
    line += buffer;
  }
  std::ofstream out(path);
  for (const auto& line : lines) out << line;
  std::cout << "wrote " << route.size() << " scans of a " << length << " m building to " << path << "\n";
  return 0;
}

int write3D(int n, const std::string& folder) {
  const double length = std::max(16.0, n * kBuildingPerScan * 2);
  const FloorPlan plan = longBuilding(length);
  const auto route = longBuildingRoute(length, n);
  DepthCamera camera;
  camera.width = 160;
  camera.height = 120;
  camera.range_noise = 0.005;
  std::filesystem::create_directories(folder);
#pragma omp parallel for schedule(dynamic, 8)
  for (std::size_t k = 0; k < route.size(); ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "/%06zu.pcd", k);
    pcl::io::savePCDFileBinary(folder + name, *depthCloud<pcl::PointXYZ>(plan, route[k], camera, k));
  }
  std::cout << "wrote " << route.size() << " depth clouds of a " << length << " m building to " << folder << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4 || (std::string(argv[1]) != "2d" && std::string(argv[1]) != "3d") || std::atoi(argv[2]) < 1) {
    std::cerr << "usage: " << argv[0] << " 2d|3d N OUTPUT\n";
    return 2;
  }
  if (std::filesystem::exists(argv[3])) {
    std::cerr << "error: " << argv[3] << " exists; not overwriting it\n";
    return 2;
  }
  return std::string(argv[1]) == "2d" ? write2D(std::atoi(argv[2]), argv[3]) : write3D(std::atoi(argv[2]), argv[3]);
}
