// Seconds to read a ROS bag with loadBag, the best and median of REPEATS runs,
// on a bag this program writes first: N sensor_msgs/LaserScan messages of
// 360 beams on /scan, one /tf message (map -> odom -> base_link) per scan and
// a /tf_static mounting, as a ROS 1 .bag or a ROS 2 sqlite3 folder.
//   time_bag_read ros1|ros2 FOLDER [N=10000] [REPEATS=3]
#include <obsgroup/io/errors.h>
#include <obsgroup/io/ros_bag.h>

#include "bag_messages.h"
#ifdef OBSGROUP_HAVE_ROS1
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>
#endif
#ifdef OBSGROUP_HAVE_ROS2
#include "ros2_bag_writer.h"
#endif

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

#ifdef OBSGROUP_HAVE_ROS1
geometry_msgs::TransformStamped ros1(const bag::Transform& t) {
  geometry_msgs::TransformStamped m;
  m.header.frame_id = t.header.frame_id;
  m.header.stamp = ros::Time(t.header.stamp);
  m.child_frame_id = t.child_frame_id;
  const Eigen::Quaterniond q(t.transform.rotation());
  m.transform.translation.x = t.transform.translation().x();
  m.transform.rotation.z = q.z();
  m.transform.rotation.w = q.w();
  return m;
}

void writeRos1(const std::string& path, int n) {
  rosbag::Bag out(path, rosbag::bagmode::Write);
  tf2_msgs::TFMessage mount;
  mount.transforms.push_back(ros1(transform("base_link", "laser", 100, 0.2, 0)));
  out.write("/tf_static", ros::Time(100), mount);
  for (int k = 0; k < n; ++k) {
    const double t = 100 + 0.05 * k;
    tf2_msgs::TFMessage tf;
    tf.transforms = {ros1(transform("map", "odom", t, 1, 0)), ros1(transform("odom", "base_link", t, 0.1 * k, 0.01 * k))};
    out.write("/tf", ros::Time(t), tf);
    const bag::Scan s = scan(t, k);
    sensor_msgs::LaserScan m;
    m.header.frame_id = s.header.frame_id;
    m.header.stamp = ros::Time(t);
    m.angle_min = float(s.angle_min);
    m.angle_increment = float(s.angle_increment);
    m.range_min = float(s.range_min);
    m.range_max = float(s.range_max);
    m.ranges = s.ranges;
    out.write("/scan", ros::Time(t), m);
  }
}
#endif

#ifdef OBSGROUP_HAVE_ROS2
void writeRos2(const std::string& folder, int n) {
  obsgroup::test::Ros2BagWriter out(folder);
  out.writeTf("/tf_static", {transform("base_link", "laser", 100, 0.2, 0)});
  for (int k = 0; k < n; ++k) {
    const double t = 100 + 0.05 * k;
    out.writeTf("/tf", {transform("map", "odom", t, 1, 0), transform("odom", "base_link", t, 0.1 * k, 0.01 * k)});
    out.write("/scan", scan(t, k));
  }
  out.close();
}
#endif

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
  if (ros1) writeRos1(path, n);
#endif
#ifdef OBSGROUP_HAVE_ROS2
  if (!ros1) writeRos2(path, n);
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
