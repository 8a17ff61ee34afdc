// Inputs for the scaling benchmark: a long building (3 m corridor, 8 x 6 m
// rooms on both sides) whose local density stays bounded however long it is.
//
//   make_scaling_input 2d N FILE.clf   N scans of 360 beams (360 degrees, 20 m) as a CARMEN log
//   make_scaling_input 2d-biased N FILE.clf
//                                      the same scans at the poses of biased odometry: each step
//                                      2% too long and turned 1 degree per metre too far (a 2 km
//                                      route winds round about five times: docs/method.md)
//   make_scaling_input 3d N FOLDER     N depth-camera clouds of 160 x 120 points as PCD files
//   make_scaling_input depth N FOLDER  N 640 x 480 depth images (Redwood layout: depth/*.png,
//                                      trajectory.log) of a hand-held camera circling one
//                                      furnished 6 x 5 m room, 211 frames a turn (a 7 s turn at 30 Hz)
//   make_scaling_input lidar N FOLDER  N sweeps of a 64-beam lidar (120,000 beams) driven through
//                                      the long building (KITTI layout: velodyne/*.bin, poses.txt, calib.txt)
//
// The route is about 0.2 m of building per scan, so 10,000 scans cover 2 km.

#include "floor_plan.h"
#include "png_writer.h"
#include "scenarios.h"
#include "to_cloud.h"

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

using namespace obsgroup::sim;

namespace {

constexpr double kBuildingPerScan = 0.2;  // metres of building per scan

int write2D(int n, const std::string& path, bool biased) {
  const double length = std::max(16.0, n * kBuildingPerScan);
  const FloorPlan plan = longBuilding(length);
  const auto route = longBuildingRoute(length, n);
  // The poses the log gives: the truth, or biased odometry's.
  std::vector<Pose2D> logged = route;
  if (biased) {
    std::vector<Eigen::Isometry3d> truth;
    for (const Pose2D& p : route) truth.push_back(toIsometry(p));
    const std::vector<Eigen::Isometry3d> odometry = biasedDrift(truth);
    for (std::size_t k = 0; k < route.size(); ++k)
      logged[k] = {odometry[k].translation().x(), odometry[k].translation().y(),
                   std::atan2(odometry[k].linear()(1, 0), odometry[k].linear()(0, 0))};
  }
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
    const Pose2D& q = logged[k];
    std::snprintf(buffer, sizeof buffer, " 0 %.6f %.6f %.6f %.6f %.6f %.6f 0 0 0 0 0 %.3f sim %.3f\n", q.x, q.y, q.yaw,
                  q.x, q.y, q.yaw, k * 0.1, k * 0.1);
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

/// One furnished 6 x 5 m room with a door: the one room of a depth recording.
FloorPlan furnishedRoom() {
  FloorPlan plan;
  plan.addWallX(0.0, -0.1, 6.1);
  plan.addWallX(5.0, -0.1, 6.1, {{2.5, 3.5}});
  plan.addWallY(0.0, 0.0, 5.0);
  plan.addWallY(6.0, 0.0, 5.0);
  plan.addBox(0.2, 0.2, 1.8, 0.8);  // a desk
  plan.addBox(5.2, 0.3, 5.8, 2.3);  // a cupboard
  plan.addBox(0.2, 3.6, 0.9, 4.8);  // a shelf
  plan.addBox(2.8, 2.3, 3.2, 2.7);  // a pillar the camera circles
  plan.addRoom("room", 0.0, 0.0, 6.0, 5.0);
  return plan;
}

int writeDepth(int n, const std::string& folder) {
  const FloorPlan plan = furnishedRoom();
  DepthCamera camera;
  camera.width = 640;
  camera.height = 480;
  // PrimeSense's 525-pixel focal length, the Redwood/TUM default intrinsics.
  camera.horizontal_fov = 2.0 * std::atan(320.0 / 525.0);
  camera.height_above_floor = 1.4;
  camera.max_range = 8.0;
  camera.range_noise = 0.005;
  const double f = 525.0, cx = 319.5, cy = 239.5;
  const int per_turn = 211;
  std::filesystem::create_directories(std::filesystem::path(folder) / "depth");
  std::vector<std::string> blocks(static_cast<std::size_t>(n));
  int failed = 0;
#pragma omp parallel for schedule(dynamic, 4) reduction(+ : failed)
  for (int k = 0; k < n; ++k) {
    // Round the pillar 1.2 m off its centre, looking outwards at the walls.
    const double angle = 2.0 * 3.14159265358979323846 * k / per_turn;
    const Pose2D p{3.0 + 1.2 * std::cos(angle), 2.5 + 1.2 * std::sin(angle), angle + 0.3};
    std::vector<std::uint16_t> depth(std::size_t(camera.width) * camera.height, 0);
    for (const Eigen::Vector3d& q : plan.depthImage(p, camera, std::uint64_t(k))) {
      const long u = std::lround(cx - f * q.y() / q.x()), v = std::lround(cy - f * q.z() / q.x());
      if (u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
      depth[std::size_t(v) * camera.width + u] = std::uint16_t(std::lround(q.x() * 1000.0));
    }
    char name[40];
    std::snprintf(name, sizeof name, "/depth/%06d.png", k);
    if (!obsgroup::test::writePng(folder + name, camera.width, camera.height, depth)) ++failed;
    // The optical frame (z ahead, x right, y down) in the world, as trajectory.log holds it.
    Eigen::Matrix3d body_from_optical;
    body_from_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * body_from_optical;
    m.topRightCorner<3, 1>() << p.x, p.y, camera.height_above_floor;
    char line[400];
    std::snprintf(line, sizeof line, "%d %d %d\n", k, k, k + 1);
    blocks[std::size_t(k)] = line;
    for (int r = 0; r < 4; ++r) {
      std::snprintf(line, sizeof line, "%.9f %.9f %.9f %.9f\n", m(r, 0), m(r, 1), m(r, 2), m(r, 3));
      blocks[std::size_t(k)] += line;
    }
  }
  if (failed) {
    std::cerr << "error: " << failed << " depth images could not be written to " << folder << "\n";
    return 1;
  }
  std::ofstream log(std::filesystem::path(folder) / "trajectory.log");
  for (const auto& block : blocks) log << block;
  std::cout << "wrote " << n << " 640 x 480 depth images of one room (" << n / double(per_turn) << " turns) to "
            << folder << "\n";
  return 0;
}

int writeLidar(int n, const std::string& folder) {
  const double length = std::max(16.0, n * kBuildingPerScan * 2);
  const FloorPlan plan = longBuilding(length);
  const auto route = longBuildingRoute(length, n);
  Lidar lidar;
  lidar.range_noise = 0.01;
  namespace fs = std::filesystem;
  fs::create_directories(fs::path(folder) / "velodyne");
  // KITTI's velodyne-to-camera rotation: camera z ahead, x right, y down.
  Eigen::Isometry3d tr = Eigen::Isometry3d::Identity();
  tr.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  std::vector<std::string> pose_lines(route.size());
  int failed = 0;
#pragma omp parallel for schedule(dynamic, 4) reduction(+ : failed)
  for (std::size_t k = 0; k < route.size(); ++k) {
    const Pose2D& p = route[k];
    std::vector<float> values;
    for (const Eigen::Vector3d& q : plan.lidarSweep(p, lidar, k))
      values.insert(values.end(), {float(q.x()), float(q.y()), float(q.z()), 0.5f});
    char name[40];
    std::snprintf(name, sizeof name, "/velodyne/%06zu.bin", k);
    std::ofstream out(folder + name, std::ios::binary);
    out.write(reinterpret_cast<const char*>(values.data()), std::streamsize(values.size() * sizeof(float)));
    failed += out.good() ? 0 : 1;
    // poses.txt holds camera 0's poses: the reader's Tr^-1 * P * Tr gives the lidar's back.
    Eigen::Isometry3d lidar_pose = Eigen::Isometry3d::Identity();
    lidar_pose.linear() = Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    lidar_pose.translation() << p.x, p.y, 0.0;
    const Eigen::Matrix4d camera = (tr * lidar_pose * tr.inverse()).matrix();
    char line[400];
    std::snprintf(line, sizeof line, "%.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e\n", camera(0, 0),
                  camera(0, 1), camera(0, 2), camera(0, 3), camera(1, 0), camera(1, 1), camera(1, 2), camera(1, 3),
                  camera(2, 0), camera(2, 1), camera(2, 2), camera(2, 3));
    pose_lines[k] = line;
  }
  if (failed) {
    std::cerr << "error: " << failed << " sweeps could not be written to " << folder << "\n";
    return 1;
  }
  std::ofstream poses(fs::path(folder) / "poses.txt");
  for (const auto& line : pose_lines) poses << line;
  std::ofstream calib(fs::path(folder) / "calib.txt");
  calib << "Tr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n";
  std::cout << "wrote " << route.size() << " lidar sweeps of a " << length << " m building to " << folder << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string kind = argc == 4 ? argv[1] : "";
  if ((kind != "2d" && kind != "2d-biased" && kind != "3d" && kind != "depth" && kind != "lidar") ||
      std::atoi(argv[2]) < 1) {
    std::cerr << "usage: " << argv[0] << " 2d|2d-biased|3d|depth|lidar N OUTPUT\n";
    return 2;
  }
  if (std::filesystem::exists(argv[3])) {
    std::cerr << "error: " << argv[3] << " exists; not overwriting it\n";
    return 2;
  }
  const int n = std::atoi(argv[2]);
  if (kind == "depth") return writeDepth(n, argv[3]);
  if (kind == "lidar") return writeLidar(n, argv[3]);
  if (kind == "2d" || kind == "2d-biased") return write2D(n, argv[3], kind == "2d-biased");
  return write3D(n, argv[3]);
}
