// libFuzzer target: the ROS 2 (CDR) message decoder on arbitrary bytes. The
// first byte picks the message type and the role it is read for; the rest is
// the serialised message, encapsulation header included. Whatever it
// decodes must be consistent enough for the code after it to use unchecked.
#include "bag_messages.h"

#include <obsgroup/io/errors.h>

#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

using namespace obsgroup::io;
using namespace obsgroup::io::bag;

namespace {

struct Choice {
  const char* type;
  Role role;
};

// The five types in their roles (both spellings), /tf_static, and a few
// types in a role they do not fit, which must be refused.
constexpr Choice kChoices[] = {
    {"sensor_msgs/msg/LaserScan", Role::Data},  {"sensor_msgs/PointCloud2", Role::Data},
    {"tf2_msgs/msg/TFMessage", Role::Tf},       {"nav_msgs/Odometry", Role::Pose},
    {"geometry_msgs/msg/PoseStamped", Role::Pose}, {"tf2_msgs/TFMessage", Role::TfStatic},
    {"sensor_msgs/LaserScan", Role::Pose},      {"nav_msgs/msg/Odometry", Role::Tf},
};

std::size_t datatypeSize(std::uint8_t datatype) {
  static constexpr std::size_t sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
  return datatype < 9 ? sizes[datatype] : 0;
}

bool isRotation(const Eigen::Isometry3d& t) {
  return t.matrix().allFinite() && (t.linear() * t.linear().transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-9) &&
         std::abs(t.linear().determinant() - 1.0) < 1e-9;
}

void checkCloud(const pcl::PCLPointCloud2& cloud) {
  if (cloud.is_bigendian) std::abort();
  const std::uint64_t points = std::uint64_t(cloud.width) * cloud.height;
  if (points > 0 && cloud.point_step == 0) std::abort();
  if (std::uint64_t(cloud.point_step) * cloud.width > cloud.row_step) std::abort();
  if (std::uint64_t(cloud.row_step) * cloud.height > cloud.data.size()) std::abort();
  bool x = false, y = false, z = false;
  for (const pcl::PCLPointField& field : cloud.fields) {
    const std::size_t size = datatypeSize(field.datatype);
    if (size == 0) std::abort();
    if (std::uint64_t(field.offset) + size * std::max<std::uint64_t>(field.count, 1) > cloud.point_step) std::abort();
    const bool float1 = field.datatype == pcl::PCLPointField::FLOAT32 && field.count == 1;
    x |= float1 && field.name == "x";
    y |= float1 && field.name == "y";
    z |= float1 && field.name == "z";
  }
  // The layout was accepted: PCL's conversion must stay inside the data
  // (the sanitizer watches). Only with x y z, else PCL warns on every input;
  // and only with points: PCL 1.13 takes &cloud[0] of the empty point vector
  // (undefined behaviour, found by this fuzzer), so callers skip empty clouds.
  if (x && y && z && points > 0) {
    pcl::PointCloud<pcl::PointXYZ> points_xyz;
    pcl::fromPCLPointCloud2(cloud, points_xyz);
    if (points_xyz.size() != points) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const Choice& choice = kChoices[data[0] % (sizeof kChoices / sizeof kChoices[0])];
  Messages into;
  try {
    decodeRos2Message(choice.type, choice.role, data + 1, size - 1, "fuzz", 3, into);
  } catch (const InputError& e) {
    if (std::string(e.what()).rfind("fuzz: ", 0) != 0) std::abort();  // errors start with the context
    return 0;
  }
  const std::size_t decoded =
      into.scans.size() + into.clouds.size() + into.tf.size() + into.tf_static.size() + into.poses.size();
  const bool tf = choice.role == Role::Tf || choice.role == Role::TfStatic;
  if (!tf && decoded != 1) std::abort();
  if (choice.role == Role::Tf && !into.tf_static.empty()) std::abort();
  if (choice.role == Role::TfStatic && !into.tf.empty()) std::abort();
  for (const auto& scan : into.scans) {
    if (scan.number != 3 || !std::isfinite(scan.message.header.stamp)) std::abort();
    if (!std::isfinite(scan.message.angle_min) || !std::isfinite(scan.message.angle_increment)) std::abort();
    if (scan.message.ranges.size() * 4 > size) std::abort();
  }
  for (const auto& cloud : into.clouds) {
    if (cloud.number != 3 || cloud.message.cloud.data.size() > size) std::abort();
    checkCloud(cloud.message.cloud);
  }
  for (const auto* transforms : {&into.tf, &into.tf_static})
    for (const auto& t : *transforms)
      if (t.number != 3 || !std::isfinite(t.message.header.stamp) || !isRotation(t.message.transform)) std::abort();
  for (const auto& pose : into.poses)
    if (pose.number != 3 || !std::isfinite(pose.message.header.stamp) || !isRotation(pose.message.pose)) std::abort();
  return 0;
}
