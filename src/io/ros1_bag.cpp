// ROS 1 bags: the container (chunks, compression, index, connections) is read
// by rosbag's storage library; each message is decoded here from its bytes.
//
// Why not ros::serialization::deserialize into sensor_msgs::LaserScan: it
// resizes a vector to the length the message claims before checking that the
// bytes are there, so one corrupt length asks for up to 16 GB. The decoder
// below checks every length against the bytes left. The message headers
// still serve: a connection whose MD5 sum differs from the definition they
// carry has another layout and is refused instead of misread.
#include "bag_messages.h"

#include <obsgroup/io/errors.h>

#ifdef OBSGROUP_HAVE_ROS1
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>
#endif

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <map>

namespace obsgroup::io::bag {

namespace {

/// Little-endian reads of ROS 1 serialisation (no alignment, uint32 lengths),
/// each checked against the bytes left.
class Ros1Stream {
 public:
  Ros1Stream(const unsigned char* data, std::size_t size, const std::string& context)
      : data_(data), left_(size), context_(context) {}

  template <typename T>
  T read(const char* field) {
    T value;
    std::memcpy(&value, take(sizeof(T), field), sizeof(T));
    return value;
  }
  std::string string(const char* field) {
    const std::uint32_t length = read<std::uint32_t>(field);
    const unsigned char* bytes = take(length, field);
    return std::string(reinterpret_cast<const char*>(bytes), length);
  }
  /// The element count of an array whose elements take at least
  /// `min_element_bytes` each: a count the bytes left cannot hold is refused
  /// before anything is allocated.
  std::uint32_t count(const char* field, std::size_t min_element_bytes) {
    const std::uint32_t n = read<std::uint32_t>(field);
    if (min_element_bytes > 0 && n > left_ / min_element_bytes)
      fail(field, std::to_string(n) + " elements claimed, " + std::to_string(left_) + " bytes left");
    return n;
  }
  template <typename T>
  std::vector<T> array(const char* field) {
    const std::uint32_t n = count(field, sizeof(T));
    std::vector<T> values(n);
    if (n > 0) std::memcpy(values.data(), take(std::size_t(n) * sizeof(T), field), std::size_t(n) * sizeof(T));
    return values;
  }
  [[noreturn]] void fail(const char* field, const std::string& what) const {
    throw InputError(context_ + ": field " + field + ": " + what);
  }
  const std::string& context() const { return context_; }

 private:
  const unsigned char* take(std::size_t n, const char* field) {
    if (n > left_) fail(field, "the message ends " + std::to_string(n - left_) + " bytes early");
    const unsigned char* at = data_;
    data_ += n;
    left_ -= n;
    return at;
  }

  const unsigned char* data_;
  std::size_t left_;
  const std::string& context_;
};

Header readHeader(Ros1Stream& in) {
  Header header;
  in.read<std::uint32_t>("header.seq");
  const auto sec = in.read<std::uint32_t>("header.stamp.sec");
  const auto nsec = in.read<std::uint32_t>("header.stamp.nsec");
  header.stamp = double(sec) + double(nsec) * 1e-9;
  header.frame_id = in.string("header.frame_id");
  return header;
}

Eigen::Vector3d readVector(Ros1Stream& in, const char* field) {
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) v[k] = in.read<double>(field);
  return v;
}

Eigen::Quaterniond readQuaternion(Ros1Stream& in, const char* field) {
  const double x = in.read<double>(field), y = in.read<double>(field), z = in.read<double>(field),
               w = in.read<double>(field);
  return Eigen::Quaterniond(w, x, y, z);
}

/// geometry_msgs/Pose and /Transform share a layout: a point, a quaternion.
Eigen::Isometry3d readRigid(Ros1Stream& in, const char* position_field, const char* rotation_field) {
  const Eigen::Vector3d t = readVector(in, position_field);
  const Eigen::Quaterniond q = readQuaternion(in, rotation_field);
  return checkedRigid(t, q, in.context(), position_field, rotation_field);
}

Scan readScan(Ros1Stream& in) {
  Scan scan;
  scan.header = readHeader(in);
  scan.angle_min = in.read<float>("angle_min");
  in.read<float>("angle_max");
  scan.angle_increment = in.read<float>("angle_increment");
  in.read<float>("time_increment");
  in.read<float>("scan_time");
  scan.range_min = in.read<float>("range_min");
  scan.range_max = in.read<float>("range_max");
  scan.ranges = in.array<float>("ranges");
  return scan;  // intensities are not used
}

Cloud readCloud(Ros1Stream& in) {
  Cloud cloud;
  cloud.header = readHeader(in);
  pcl::PCLPointCloud2& c = cloud.cloud;
  c.header.frame_id = cloud.header.frame_id;
  c.height = in.read<std::uint32_t>("height");
  c.width = in.read<std::uint32_t>("width");
  const std::uint32_t fields = in.count("fields", 4 + 4 + 1 + 4);
  for (std::uint32_t k = 0; k < fields; ++k) {
    pcl::PCLPointField field;
    field.name = in.string("fields.name");
    field.offset = in.read<std::uint32_t>("fields.offset");
    field.datatype = in.read<std::uint8_t>("fields.datatype");
    field.count = in.read<std::uint32_t>("fields.count");
    c.fields.push_back(std::move(field));
  }
  c.is_bigendian = in.read<std::uint8_t>("is_bigendian");
  c.point_step = in.read<std::uint32_t>("point_step");
  c.row_step = in.read<std::uint32_t>("row_step");
  c.data = in.array<std::uint8_t>("data");
  c.is_dense = in.read<std::uint8_t>("is_dense");
  checkCloudLayout(c, in.context());
  return cloud;
}

void readTransforms(Ros1Stream& in, std::size_t number, std::vector<Numbered<Transform>>& into) {
  const std::uint32_t n = in.count("transforms", 4 * 4 + 4 + 7 * 8);
  for (std::uint32_t k = 0; k < n; ++k) {
    Transform t;
    t.header = readHeader(in);
    t.child_frame_id = in.string("transforms.child_frame_id");
    t.transform = readRigid(in, "transforms.transform.translation", "transforms.transform.rotation");
    into.push_back({number, std::move(t)});
  }
}

Pose readPose(Ros1Stream& in, bool odometry) {
  Pose pose;
  pose.header = readHeader(in);
  if (odometry) pose.child_frame_id = in.string("child_frame_id");
  pose.pose = readRigid(in, "pose.position", "pose.orientation");
  return pose;  // Odometry's covariance and twist are not used
}

}  // namespace

void decodeRos1Message(const std::string& type, Role role, const unsigned char* data, std::size_t size,
                       const std::string& context, std::size_t number, Messages& into) {
  checkRole(type, role, context);
  Ros1Stream in(data, size, context);
  if (type == kLaserScanType) {
    into.scans.push_back({number, readScan(in)});
    checkScan(into.scans.back().message, context);
  } else if (type == kPointCloud2Type) {
    into.clouds.push_back({number, readCloud(in)});
    keepReduced(into.clouds.back().message, into.reduce_clouds);
  } else if (type == kTfType) {
    readTransforms(in, number, role == Role::TfStatic ? into.tf_static : into.tf);
  } else {
    into.poses.push_back({number, readPose(in, type == kOdometryType)});
  }
}

#ifdef OBSGROUP_HAVE_ROS1

namespace {

/// The MD5 sum of the layout decoded for each type, from the message headers.
const std::map<std::string, std::string>& knownLayouts() {
  namespace mt = ros::message_traits;
  static const std::map<std::string, std::string> sums = {
      {kLaserScanType, mt::MD5Sum<sensor_msgs::LaserScan>::value()},
      {kPointCloud2Type, mt::MD5Sum<sensor_msgs::PointCloud2>::value()},
      {kTfType, mt::MD5Sum<tf2_msgs::TFMessage>::value()},
      {kOdometryType, mt::MD5Sum<nav_msgs::Odometry>::value()},
      {kPoseStampedType, mt::MD5Sum<geometry_msgs::PoseStamped>::value()}};
  return sums;
}

/// rosbag reports a damaged or foreign file by its own exceptions.
template <typename Action>
auto withBagErrors(const std::string& path, Action&& action) {
  try {
    return action();
  } catch (const InputError&) {
    throw;
  } catch (const rosbag::BagException& e) {
    throw InputError(path + ": not a readable ROS 1 bag: " + e.what());
  } catch (const ros::Exception& e) {
    throw InputError(path + ": not a readable ROS 1 bag: " + e.what());
  }
}

/// The index sits at the end of a bag: a recording stopped before it was
/// closed has none, and rosbag says only that a read came short.
void openBag(rosbag::Bag& bag, const std::string& path) {
  try {
    withBagErrors(path, [&] {
      bag.open(path, rosbag::bagmode::Read);
      return 0;
    });
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) +
                     " (a recording cut off before it was closed? `rosbag reindex` rebuilds its index)");
  }
}

}  // namespace

std::vector<Topic> listRos1Topics(const std::string& path) {
  rosbag::Bag bag;
  openBag(bag, path);
  return withBagErrors(path, [&] {
    rosbag::View view(bag);
    std::map<std::string, Topic> topics;
    for (const rosbag::ConnectionInfo* c : view.getConnections()) {
      Topic& t = topics[c->topic];
      t.name = c->topic;
      t.type = c->datatype;
    }
    for (auto& [name, topic] : topics) topic.messages = rosbag::View(bag, rosbag::TopicQuery(name)).size();
    std::vector<Topic> list;
    for (auto& [name, topic] : topics) list.push_back(std::move(topic));
    return list;
  });
}

Messages readRos1Messages(const std::string& path, const Request& request) {
  rosbag::Bag bag;
  openBag(bag, path);
  return withBagErrors(path, [&] {
    std::map<std::string, Role> roles = {{request.data_topic, Role::Data}};
    if (request.pose_topic) roles[*request.pose_topic] = Role::Pose;
    std::vector<std::string> present;
    for (const rosbag::ConnectionInfo* c : rosbag::View(bag).getConnections()) present.push_back(c->topic);
    for (const char* tf : {"/tf", "/tf_static"})
      if (request.tf && std::find(present.begin(), present.end(), tf) != present.end() && !roles.count(tf))
        roles[tf] = std::string(tf) == "/tf" ? Role::Tf : Role::TfStatic;
    std::vector<std::string> asked;
    for (const auto& [topic, role] : roles) asked.push_back(topic);
    Messages messages;
    messages.reduce_clouds = request.reduction;
    std::map<std::string, std::size_t> numbers;
    std::vector<std::uint8_t> bytes;
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(asked))) {
      const std::size_t number = ++numbers[m.getTopic()];
      const std::string context = path + ": message " + std::to_string(number) + " on " + m.getTopic() + " (" +
                                  m.getDataType() + ")";
      const auto known = knownLayouts().find(m.getDataType());
      if (known != knownLayouts().end() && m.getMD5Sum() != known->second)
        throw InputError(context + ": its MD5 sum " + m.getMD5Sum() + " is not that of " + m.getDataType() + " (" +
                         known->second + "): another message definition");
      bytes.resize(m.size());
      ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
      m.write(out);
      decodeRos1Message(m.getDataType(), roles.at(m.getTopic()), bytes.data(), bytes.size(), context, number,
                        messages);
    }
    return messages;
  });
}

#else

std::vector<Topic> listRos1Topics(const std::string& path) {
  throw InputError(path + ": obsgroup was built without ROS 1 bag support (librosbag-storage-dev)");
}
Messages readRos1Messages(const std::string& path, const Request&) { return (listRos1Topics(path), Messages{}); }

#endif

}  // namespace obsgroup::io::bag
