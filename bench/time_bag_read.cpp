// Seconds to read a ROS bag with loadBag, the best and median of REPEATS runs,
// on a bag this program writes first: N sensor_msgs/LaserScan messages of
// 360 beams on /scan, one /tf message (map -> odom -> base_link) per scan and
// a /tf_static mounting, as a ROS 1 .bag or a ROS 2 sqlite3 folder.
//   time_bag_read ros1|ros2 FOLDER [N=10000] [REPEATS=3]
#include <obsgroup/io/errors.h>
#include <obsgroup/io/ros_bag.h>

#include "bag_messages.h"
#include "ros1_bag_writer.h"
#include "ros2_bag_writer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace bag = obsgroup::io::bag;
namespace fs = std::filesystem;

namespace {

bag::Transform transform(const std::string& parent, const std::string& child, double stamp, double x, double yaw) {
  bag::Transform t;
  t.header = {stamp, parent};
  t.child_frame_id = child;
  t.transform = Eigen::Translation3d(x, 0, 0) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
  return t;
}

bag::Scan scan(double stamp, int k) {
  bag::Scan s;
  s.header = {stamp, "laser"};
  s.angle_min = -M_PI;
  s.angle_increment = 2 * M_PI / 360;
  s.range_min = 0.05;
  s.range_max = 30;
  for (int b = 0; b < 360; ++b) s.ranges.push_back(float(2.0 + std::fmod(0.37 * (b + k), 5.0)));
  return s;
}

/// The bag, of either kind (Ros1BagWriter or Ros2BagWriter).
template <typename Writer>
void writeBag(Writer&& out, int n) {
  out.writeTf("/tf_static", {transform("base_link", "laser", 100, 0.2, 0)});
  for (int k = 0; k < n; ++k) {
    const double t = 100 + 0.05 * k;
    out.writeTf("/tf", {transform("map", "odom", t, 1, 0), transform("odom", "base_link", t, 0.1 * k, 0.01 * k)});
    out.write("/scan", scan(t, k));
  }
  out.close();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || (std::string(argv[1]) != "ros1" && std::string(argv[1]) != "ros2")) {
    std::fprintf(stderr, "usage: time_bag_read ros1|ros2 FOLDER [N=10000] [REPEATS=3]\n");
    return 2;
  }
  const bool ros1 = std::string(argv[1]) == "ros1";
  const int n = argc > 3 ? std::max(1, std::atoi(argv[3])) : 10000;
  const int repeats = argc > 4 ? std::max(1, std::atoi(argv[4])) : 3;
  const obsgroup::io::BagVersion version = ros1 ? obsgroup::io::BagVersion::Ros1 : obsgroup::io::BagVersion::Ros2;
  if (!obsgroup::io::bagSupported(version)) {
    std::fprintf(stderr, "time_bag_read: built without %s bags\n", argv[1]);
    return 2;
  }
  fs::create_directories(argv[2]);
  const std::string path = (fs::path(argv[2]) / (ros1 ? "bench.bag" : "bench_ros2")).string();
  fs::remove_all(path);
#ifdef OBSGROUP_HAVE_ROS1
  if (ros1) writeBag(obsgroup::test::Ros1BagWriter(path), n);
#endif
#ifdef OBSGROUP_HAVE_ROS2
  if (!ros1) writeBag(obsgroup::test::Ros2BagWriter(path), n);
#endif
  std::vector<double> seconds;
  std::size_t observations = 0;
  try {
    for (int k = 0; k < repeats; ++k) {
      const auto start = std::chrono::steady_clock::now();
      observations = obsgroup::io::loadBag(path, version).observations.size();
      seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
  } catch (const obsgroup::io::InputError& e) {
    std::fprintf(stderr, "time_bag_read: %s\n", e.what());
    return 3;
  }
  std::sort(seconds.begin(), seconds.end());
  std::printf("%s: %d scans + %d /tf messages, %zu observations, best %.3f s, median %.3f s of %d\n", path.c_str(), n,
              n, observations, seconds.front(), seconds[seconds.size() / 2], repeats);
  return 0;
}
