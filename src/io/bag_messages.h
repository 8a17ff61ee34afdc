#pragma once
// The messages of a ROS bag that obsgroup reads, decoded into plain structs
// whatever the bag's version: ROS 1 (.bag, rosbag's storage library) and
// ROS 2 (sqlite3 storage, CDR). Each backend lists its topics and decodes the
// messages asked; bag_sequence.cpp turns them into observations.

#include <Eigen/Geometry>
#include <pcl/PCLPointCloud2.h>

#include "obsgroup/io/frame_reading.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace obsgroup::io::bag {

/// A topic and its type in ROS 1 spelling ("sensor_msgs/LaserScan"; ROS 2's
/// "sensor_msgs/msg/LaserScan" loses its "/msg").
struct Topic {
  std::string name;
  std::string type;
  std::size_t messages = 0;
};

/// What to do with a bag in MCAP storage.
inline const std::string kConvertToSqlite = "convert the bag to sqlite3 storage with `ros2 bag convert`";

inline constexpr const char* kLaserScanType = "sensor_msgs/LaserScan";
inline constexpr const char* kPointCloud2Type = "sensor_msgs/PointCloud2";
inline constexpr const char* kTfType = "tf2_msgs/TFMessage";
inline constexpr const char* kOdometryType = "nav_msgs/Odometry";
inline constexpr const char* kPoseStampedType = "geometry_msgs/PoseStamped";

struct Header {
  double stamp = 0.0;  ///< seconds (sec + nanosec / 1e9)
  std::string frame_id;
};

/// sensor_msgs/LaserScan: beam k at angle_min + k * angle_increment in the
/// frame of header.frame_id; a range outside [range_min, range_max] or not
/// finite is no return.
struct Scan {
  Header header;
  double angle_min = 0.0;
  double angle_increment = 0.0;
  double range_min = 0.0;
  double range_max = 0.0;
  std::vector<float> ranges;
};

/// sensor_msgs/PointCloud2, its fields and data copied as they are into
/// PCL's own twin of the message (pcl::fromPCLPointCloud2 reads it).
struct Cloud {
  Header header;
  pcl::PCLPointCloud2 cloud;
  std::size_t sensor_points = 0;  ///< width x height as recorded, before any reduction
  bool reduced = false;           ///< voxel-filtered as it was decoded
};

/// One geometry_msgs/TransformStamped of a tf2_msgs/TFMessage: the pose of
/// child_frame_id in header.frame_id.
struct Transform {
  Header header;
  std::string child_frame_id;
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
};

/// nav_msgs/Odometry (pose.pose, child_frame_id) or
/// geometry_msgs/PoseStamped (pose, child_frame_id empty): the pose of the
/// child in header.frame_id.
struct Pose {
  Header header;
  std::string child_frame_id;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

/// A message with its number: 1-based, in bag (time) order within its topic;
/// errors name it so.
template <typename Message>
struct Numbered {
  std::size_t number = 0;
  Message message;
};

/// What to decode. The data topic is a LaserScan or PointCloud2 topic (its
/// type says which); /tf and /tf_static are read when present (and asked);
/// the pose topic, if any, is an Odometry or PoseStamped topic.
struct Request {
  std::string data_topic;
  std::optional<std::string> pose_topic;
  bool tf = true;  ///< false when the poses come from elsewhere (a trajectory file): /tf is not read
  const FrameReading* reduction = nullptr;  ///< how each PointCloud2 is reduced as it is decoded
};

struct Messages {
  /// Set by the caller: each PointCloud2 is reduced so as it is decoded, so
  /// that a long recording is never held at full resolution.
  const FrameReading* reduce_clouds = nullptr;
  std::vector<Numbered<Scan>> scans;
  std::vector<Numbered<Cloud>> clouds;
  std::vector<Numbered<Transform>> tf;         ///< /tf, every transform of every message
  std::vector<Numbered<Transform>> tf_static;  ///< /tf_static
  std::vector<Numbered<Pose>> poses;           ///< the pose topic
};

/// What a decoded message is for: the data topic, /tf, /tf_static or the
/// pose topic. Its type must be one this role reads.
enum class Role { Data, Tf, TfStatic, Pose };

/// Decodes one serialised message (ROS 1 serialisation, or ROS 2 CDR with
/// its 4-byte encapsulation header) of `type` and appends it, numbered
/// `number`, to `into` (a TFMessage: each of its transforms). Throws
/// InputError starting with `context` and naming the field that could not
/// be read (cut short, a length beyond the data, a point layout that does
/// not fit its data). The readers and the fuzzers call these.
void decodeRos1Message(const std::string& type, Role role, const unsigned char* data, std::size_t size,
                       const std::string& context, std::size_t number, Messages& into);
void decodeRos2Message(const std::string& type, Role role, const unsigned char* data, std::size_t size,
                       const std::string& context, std::size_t number, Messages& into);

// Checks both backends make of what they decoded (bag_sequence.cpp); each
// throws InputError starting with `context`.

/// Whether `role` reads `type` (LaserScan or PointCloud2 for the data,
/// TFMessage for /tf and /tf_static, Odometry or PoseStamped for poses), and
/// those types in words.
bool roleAccepts(Role role, const std::string& type);
const char* typesOfRole(Role role);
/// roleAccepts, or an InputError.
void checkRole(const std::string& type, Role role, const std::string& context);
/// The beams' geometry: finite angles, range bounds that are numbers.
void checkScan(const Scan& scan, const std::string& context);
/// A finite translation and a non-zero finite quaternion, normalised
/// (writers round; a few only approximately normalise).
Eigen::Isometry3d checkedRigid(const Eigen::Vector3d& translation, const Eigen::Quaterniond& rotation,
                               const std::string& context, const std::string& translation_field,
                               const std::string& rotation_field);
/// Bytes of a sensor_msgs/PointField datatype (1 INT8 ... 8 FLOAT64), 0
/// for any other (PCL's 9, BOOL, is not ROS's).
std::size_t pointFieldSize(std::uint8_t datatype);
/// Little-endian data, each field's datatype known and within point_step, a
/// point_step for any points, width * point_step within row_step, and at
/// least row_step * height bytes of data: whoever reads a point by its
/// offsets stays inside the buffer.
void checkCloudLayout(const pcl::PCLPointCloud2& cloud, const std::string& context);

/// ROS 1 bags (a .bag file). Throw InputError naming the file, the topic
/// and the message number (and the field where one is known) on a bag or
/// message that cannot be read.
std::vector<Topic> listRos1Topics(const std::string& path);
Messages readRos1Messages(const std::string& path, const Request& request);

/// ROS 2 bags in sqlite3 storage (a folder with metadata.yaml and *.db3).
/// Throw InputError likewise; an MCAP bag is refused with an error saying
/// that storage is not supported.
std::vector<Topic> listRos2Topics(const std::string& folder);
Messages readRos2Messages(const std::string& folder, const Request& request);

/// Records the cloud's sensor points and reduces it as `reduction` says
/// (null: kept whole).
inline void keepReduced(Cloud& cloud, const FrameReading* reduction) {
  cloud.sensor_points = std::size_t(cloud.cloud.width) * cloud.cloud.height;
  if (reduction) cloud.reduced = reduceFrame(cloud.cloud, *reduction);
}

}  // namespace obsgroup::io::bag
