#pragma once
// Writes a ROS 1 bag with rosbag's storage library and the ROS message types,
// from obsgroup's neutral message structs: the twin of Ros2BagWriter, with
// the same calls, so one function can write either kind. Header only; needs
// the ROS 1 libraries (OBSGROUP_HAVE_ROS1). Used by make_datasets and the bag
// benchmark.
//
//   obsgroup::test::Ros1BagWriter bag(dir / "run.bag");
//   bag.write("/scan", scan);        // sensor_msgs/LaserScan
//   bag.writeTf("/tf", {t1, t2});    // tf2_msgs/TFMessage (also /tf_static)
//   bag.close();                     // or the destructor
//
// Each message is recorded at its header stamp (a TFMessage: its first
// transform's).

#ifdef OBSGROUP_HAVE_ROS1

#include "bag_messages.h"

#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <filesystem>
#include <string>
#include <vector>

namespace obsgroup::test {

class Ros1BagWriter {
 public:
  explicit Ros1BagWriter(const std::filesystem::path& file) : bag_(file.string(), rosbag::bagmode::Write) {}

  static geometry_msgs::TransformStamped message(const io::bag::Transform& t) {
    geometry_msgs::TransformStamped m;
    m.header.frame_id = t.header.frame_id;
    m.header.stamp = ros::Time(t.header.stamp);
    m.child_frame_id = t.child_frame_id;
    const Eigen::Vector3d p = t.transform.translation();
    const Eigen::Quaterniond q(t.transform.rotation());
    m.transform.translation.x = p.x();
    m.transform.translation.y = p.y();
    m.transform.translation.z = p.z();
    m.transform.rotation.x = q.x();
    m.transform.rotation.y = q.y();
    m.transform.rotation.z = q.z();
    m.transform.rotation.w = q.w();
    return m;
  }

  static sensor_msgs::LaserScan message(const io::bag::Scan& s) {
    sensor_msgs::LaserScan m;
    m.header.frame_id = s.header.frame_id;
    m.header.stamp = ros::Time(s.header.stamp);
    m.angle_min = float(s.angle_min);
    m.angle_increment = float(s.angle_increment);
    m.angle_max = float(s.angle_min + s.angle_increment * double(s.ranges.empty() ? 0 : s.ranges.size() - 1));
    m.range_min = float(s.range_min);
    m.range_max = float(s.range_max);
    m.ranges = s.ranges;
    return m;
  }

  void write(const std::string& topic, const io::bag::Scan& scan) {
    const sensor_msgs::LaserScan m = message(scan);
    bag_.write(topic, m.header.stamp, m);
  }

  void writeTf(const std::string& topic, const std::vector<io::bag::Transform>& transforms) {
    tf2_msgs::TFMessage m;
    for (const auto& t : transforms) m.transforms.push_back(message(t));
    bag_.write(topic, transforms.empty() ? ros::Time(0) : ros::Time(transforms.front().header.stamp), m);
  }

  void close() { bag_.close(); }

 private:
  rosbag::Bag bag_;
};

}  // namespace obsgroup::test

#endif
