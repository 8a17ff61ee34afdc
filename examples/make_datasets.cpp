// Generates the simulated inputs shipped in data/ with the scan simulator:
//   office_2d/office.clf  a CARMEN log (ROBOTLASER1) of a 180-degree laser along
//                         a corridor and four rooms, 77 scans, with rooms.txt
//                         giving the room each scan was taken in;
//   office_3d/            a depth camera (80 x 60) on the same route, 40 clouds:
//                         pcd/%06d.pcd (pose in VIEWPOINT) and poses.txt (TUM).
//
//   make_datasets OUTDIR [--force]
// The output is deterministic; a test regenerates it and compares with data/.
//
//   make_datasets --tum-rgbd FOLDER
// writes the office_3d run as a TUM RGB-D folder instead (depth.txt,
// depth/*.png at 5000 per metre, groundtruth.txt of the optical frame: z
// forward, x right, y down) and prints the --intrinsics it needs. Not
// shipped; a test reads it and expects the groups of office_3d/pcd.
//
//   make_datasets --ros1-bag FILE | --ros2-bag FOLDER
// writes the office_2d run as a ROS bag (ROS 1 .bag, or ROS 2 sqlite3): its
// scans as sensor_msgs/LaserScan on /scan in frame laser (no return: +inf,
// REP 117), /tf map -> odom -> base_link at each scan's stamp and /tf_static
// base_link -> laser. Not shipped; a test reads it and expects the groups of
// office_2d/office.clf.

#include "floor_plan.h"
#include "png_writer.h"
#include "to_cloud.h"

#include "bag_messages.h"
#include "ros1_bag_writer.h"
#include "ros2_bag_writer.h"

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>

namespace fs = std::filesystem;
using namespace obsgroup::sim;

namespace {

constexpr double kPi = 3.14159265358979323846;

void writeRooms(const FloorPlan& plan, const std::vector<Pose2D>& route, const fs::path& path) {
  std::ofstream out(path);
  out << "# index room (ground truth of the simulated office)\n";
  for (std::size_t i = 0; i < route.size(); ++i) {
    const int room = plan.roomAt(route[i].x, route[i].y);
    out << i << ' ' << (room >= 0 ? plan.roomNames()[room] : "outside") << '\n';
  }
}

void writeOffice2D(const fs::path& folder) {
  const FloorPlan plan = office();
  LaserModel laser;  // 361 beams over 180 degrees, 30 m
  laser.range_noise = 0.01;
  const auto route = officeRoute(77);
  fs::create_directories(folder);
  std::ofstream out(folder / "office.clf");
  out << "# CARMEN log written by obsgroup's scan simulator (examples/make_datasets.cpp)\n"
      << "# a simulated office: a 32 m corridor and four 8 x 6 m rooms; laser at the robot origin\n"
      << "# message format:\n"
      << "# ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range accuracy "
         "remission_mode num_readings [range_readings] num_remissions laser_pose_x laser_pose_y "
         "laser_pose_theta robot_pose_x robot_pose_y robot_pose_theta laser_tv laser_rv "
         "forward_safety_dist side_safety_dist turn_axis timestamp host logger_timestamp\n";
  char buffer[160];
  for (std::size_t k = 0; k < route.size(); ++k) {
    const Pose2D& p = route[k];
    const auto ranges = plan.scan(p, laser, k);
    std::snprintf(buffer, sizeof buffer, "ROBOTLASER1 99 %.9f %.9f %.9f %.6f 0.010000 0 %d", -laser.field_of_view / 2,
                  laser.field_of_view, laser.field_of_view / (laser.beams - 1), laser.max_range, laser.beams);
    out << buffer;
    for (double r : ranges) {
      std::snprintf(buffer, sizeof buffer, " %.3f", r);
      out << buffer;
    }
    // No remissions; the laser pose, then the robot pose (the laser sits at the robot's origin).
    std::snprintf(buffer, sizeof buffer, " 0 %.9f %.9f %.9f %.9f %.9f %.9f", p.x, p.y, p.yaw, p.x, p.y, p.yaw);
    out << buffer;
    std::snprintf(buffer, sizeof buffer, " 0 0 0 0 0 %.6f obsgroup-sim %.6f\n", 1.0e9 + k * 0.5, k * 0.5);
    out << buffer;
  }
  writeRooms(plan, route, folder / "rooms.txt");
}

void writeOffice3D(const fs::path& folder) {
  const FloorPlan plan = office();
  DepthCamera camera;
  camera.range_noise = 0.005;
  const auto route = officeRoute(40);
  fs::create_directories(folder / "pcd");
  std::ofstream poses(folder / "poses.txt");
  poses << "# timestamp tx ty tz qx qy qz qw (camera pose; points: x ahead, y left, z up)\n";
  char buffer[160];
  for (std::size_t k = 0; k < route.size(); ++k) {
    const Pose2D& p = route[k];
    std::snprintf(buffer, sizeof buffer, "%06zu.pcd", k);
    pcl::io::savePCDFileBinaryCompressed((folder / "pcd" / buffer).string(), *depthCloud<pcl::PointXYZ>(plan, p, camera, k));
    std::snprintf(buffer, sizeof buffer, "%.1f %.9f %.9f %.9f 0 0 %.12f %.12f\n", k * 0.5, p.x, p.y,
                  camera.height_above_floor, std::sin(p.yaw / 2), std::cos(p.yaw / 2));
    poses << buffer;
  }
  writeRooms(plan, route, folder / "rooms.txt");
}

/// The office_3d run as TUM RGB-D: the same rays and noise (seed k), each
/// point back at its pixel, its depth along the optical axis.
int writeOffice3DTum(const fs::path& folder) {
  const FloorPlan plan = office();
  DepthCamera camera;
  camera.range_noise = 0.005;
  const auto route = officeRoute(40);
  const double f = (camera.width / 2.0) / std::tan(camera.horizontal_fov / 2);
  const double cx = (camera.width - 1) / 2.0, cy = (camera.height - 1) / 2.0;
  fs::create_directories(folder / "depth");
  std::ofstream list(folder / "depth.txt"), truth(folder / "groundtruth.txt");
  list << "# depth maps of obsgroup's simulated office (examples/make_datasets.cpp)\n# timestamp filename\n";
  truth << "# ground truth of the optical frame (z forward, x right, y down)\n# timestamp tx ty tz qx qy qz qw\n";
  // The optical frame in the sensor's (x ahead, y left, z up).
  Eigen::Matrix3d body_from_optical;
  body_from_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  char buffer[200];
  for (std::size_t k = 0; k < route.size(); ++k) {
    const Pose2D& p = route[k];
    std::vector<std::uint16_t> depth(std::size_t(camera.width) * camera.height, 0);
    for (const Eigen::Vector3d& q : plan.depthImage(p, camera, k)) {
      const long u = std::lround(cx - f * q.y() / q.x()), v = std::lround(cy - f * q.z() / q.x());
      if (u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
      depth[std::size_t(v) * camera.width + u] = std::uint16_t(std::lround(q.x() * 5000.0));
    }
    std::snprintf(buffer, sizeof buffer, "depth/%.6f.png", k * 0.5);
    if (!obsgroup::test::writePng((folder / buffer).string(), camera.width, camera.height, depth)) {
      std::cerr << "error: cannot write " << (folder / buffer).string() << "\n";
      return 1;
    }
    list << std::string(buffer).substr(6, std::string(buffer).size() - 10) << ' ' << buffer << '\n';
    const Eigen::Matrix3d R = Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * body_from_optical;
    const Eigen::Quaterniond q(R);
    std::snprintf(buffer, sizeof buffer, "%.6f %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", k * 0.5, p.x, p.y,
                  camera.height_above_floor, q.x(), q.y(), q.z(), q.w());
    truth << buffer;
  }
  std::printf("wrote %s; read it with --intrinsics %.9f,%.9f,%.9f,%.9f\n", folder.string().c_str(), f, f, cx, cy);
  return 0;
}

namespace bag = obsgroup::io::bag;

/// The office_2d run as bag messages: one scan and its /tf per stamp. The
/// ranges are those of office.clf (millimetres), so both give the same points.
struct BagRun {
  std::vector<bag::Scan> scans;
  std::vector<std::vector<bag::Transform>> tf;  // per scan: map -> odom, odom -> base_link
  bag::Transform mount;                         // base_link -> laser
};

bag::Transform transform(const std::string& parent, const std::string& child, double stamp,
                         const Eigen::Isometry3d& pose) {
  bag::Transform t;
  t.header = {stamp, parent};
  t.child_frame_id = child;
  t.transform = pose;
  return t;
}

Eigen::Isometry3d planarPose(double x, double y, double yaw) {
  return Eigen::Isometry3d(Eigen::Translation3d(x, y, 0) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

BagRun office2DBagRun() {
  const FloorPlan plan = office();
  LaserModel laser;
  laser.range_noise = 0.01;
  const auto route = officeRoute(77);
  BagRun run;
  run.mount = transform("base_link", "laser", 1000.0, Eigen::Isometry3d::Identity());
  // odom is offset from map, as after a SLAM correction; base_link's pose in map is the route's.
  const Eigen::Isometry3d map_odom = planarPose(1.5, -2.0, 0.1);
  for (std::size_t k = 0; k < route.size(); ++k) {
    const Pose2D& p = route[k];
    const double stamp = 1000.0 + 0.5 * double(k);
    bag::Scan scan;
    scan.header = {stamp, "laser"};
    scan.angle_min = -laser.field_of_view / 2;
    scan.angle_increment = laser.field_of_view / (laser.beams - 1);
    scan.range_min = 0.0;
    scan.range_max = laser.max_range;
    for (double r : plan.scan(p, laser, k)) {
      const double mm = std::round(r * 1000.0) / 1000.0;  // as office.clf prints them
      scan.ranges.push_back(mm >= laser.max_range ? std::numeric_limits<float>::infinity() : float(mm));
    }
    run.scans.push_back(std::move(scan));
    run.tf.push_back({transform("map", "odom", stamp, map_odom),
                      transform("odom", "base_link", stamp, map_odom.inverse() * planarPose(p.x, p.y, p.yaw))});
  }
  return run;
}

/// The office_2d run into a bag of either kind (Ros1BagWriter or Ros2BagWriter).
template <typename Writer>
int writeOffice2D(Writer&& out, const std::string& path) {
  const BagRun run = office2DBagRun();
  out.writeTf("/tf_static", {run.mount});
  for (std::size_t k = 0; k < run.scans.size(); ++k) {
    out.writeTf("/tf", run.tf[k]);
    out.write("/scan", run.scans[k]);
  }
  out.close();
  std::printf("wrote %s\n", path.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--tum-rgbd") return writeOffice3DTum(argv[2]);
#ifdef OBSGROUP_HAVE_ROS1
  if (argc == 3 && std::string(argv[1]) == "--ros1-bag")
    return writeOffice2D(obsgroup::test::Ros1BagWriter(argv[2]), argv[2]);
#endif
#ifdef OBSGROUP_HAVE_ROS2
  if (argc == 3 && std::string(argv[1]) == "--ros2-bag")
    return writeOffice2D(obsgroup::test::Ros2BagWriter(argv[2]), argv[2]);
#endif
  const std::string usage =
      "usage: " + std::string(argv[0]) + " OUTDIR [--force] | --tum-rgbd FOLDER | --ros1-bag FILE | --ros2-bag FOLDER\n";
  if (argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::cout << usage;
    return 0;
  }
  // An option where OUTDIR belongs is a mistake (or a bag kind this build lacks), not a folder name.
  if (argc < 2 || argc > 3 || argv[1][0] == '-' || (argc == 3 && std::string(argv[2]) != "--force")) {
    std::cerr << usage;
    return 2;
  }
  const fs::path out = argv[1];
  const bool force = argc == 3;
  for (const char* name : {"office_2d", "office_3d"}) {
    if (fs::exists(out / name) && !force) {
      std::cerr << "error: " << (out / name).string() << " exists; use --force to replace it\n";
      return 2;
    }
  }
  writeOffice2D(out / "office_2d");
  writeOffice3D(out / "office_3d");
  std::cout << "wrote " << (out / "office_2d").string() << " and " << (out / "office_3d").string() << "\n";
  return 0;
}
