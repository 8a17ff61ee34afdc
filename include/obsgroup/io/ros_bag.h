#pragma once
// ROS bags as observations: sensor_msgs/LaserScan or sensor_msgs/PointCloud2
// messages of one topic, each posed at its header stamp from /tf (the
// sensor's frame in a fixed frame) or from a nav_msgs/Odometry or
// geometry_msgs/PoseStamped topic with the sensor's mounting from
// /tf_static. ROS 1 bags (.bag) are read with rosbag's storage library; ROS 2
// bags in the default sqlite3 storage (a folder with metadata.yaml and
// *.db3) with SQLite and Fast CDR. Neither needs a ROS installation.

#include "obsgroup/io/frame_reading.h"
#include <obsgroup/cloud/observation.h>
#include <obsgroup/common/enum_names.h>
#include <obsgroup/io/pcd_sequence.h>
#include <obsgroup/io/pose_file.h>

#include <pcl/point_types.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace obsgroup::io {

enum class BagVersion { Ros1, Ros2 };

inline constexpr EnumName<BagVersion> kBagVersionNames[] = {{BagVersion::Ros1, "ros1"}, {BagVersion::Ros2, "ros2"}};
inline std::string toString(BagVersion version) { return nameOf(kBagVersionNames, version); }

/// Whether this build reads bags of `version` (its libraries were found).
bool bagSupported(BagVersion version);

struct BagOptions {
  /// The LaserScan or PointCloud2 topic; default: the only topic of either type.
  std::optional<std::string> topic;
  /// An Odometry or PoseStamped topic giving the poses; default: /tf.
  std::optional<std::string> pose_topic;
  /// The frame /tf poses are taken in; default: map, else odom (with a warning).
  std::optional<std::string> fixed_frame;
  /// A TUM trajectory of the sensor (timestamp tx ty tz qx qy qz qw, gzipped
  /// or not) instead: each message takes the pose nearest its stamp within
  /// max_time_difference, as a SLAM system's output would give it.
  std::optional<std::string> poses_file;
  double max_time_difference = kDefaultMaxTimeDifference;  ///< seconds
  /// Each PointCloud2's reduction as it is converted (its sensor points:
  /// width x height), and the progress over the messages.
  FrameReading reduction;
};

/// The observations of a bag, with what was read and how.
template <typename PointT>
struct BagSequenceOf {
  BagVersion version = BagVersion::Ros1;
  std::vector<Observation<PointT>> observations;  ///< points in the sensor frame, posed in the fixed frame
  std::vector<std::string> labels;  ///< "BAG: message N on TOPIC" of each observation
  std::vector<double> stamps;       ///< header stamp of each observation's message, seconds
  std::vector<std::string> warnings;
  std::string topic;         ///< the data topic read
  std::string message_type;  ///< sensor_msgs/LaserScan or sensor_msgs/PointCloud2
  std::string pose_source;   ///< "/tf", the pose topic or the poses file
  std::string fixed_frame;   ///< the frame of the poses ("" for a poses file: its own)
  std::size_t reduced = 0;   ///< clouds voxel-filtered as they were converted
  std::size_t skipped = 0;   ///< messages with no pose at their stamp (outside the poses' time span, or none in the file within the tolerance)
};
using BagSequence = BagSequenceOf<pcl::PointXYZ>;

/// A bag read once: the data topic's messages with their poses, as
/// observations of whichever point type the caller asks for. PointCloud2
/// fields that map onto the point type (intensity, rgb) are kept; a scan
/// gives x, y, z only.
///
/// \code
///   obsgroup::io::BagReader bag("run.bag", obsgroup::io::BagVersion::Ros1, {});
///   if (bag.pointKind() == obsgroup::io::PointKind::XYZI)
///     auto clouds = bag.observations<pcl::PointXYZI>();  // a lidar's intensities kept
/// \endcode
class BagReader {
 public:
  /// Reads the bag. Throws InputError naming the bag, the topic and the
  /// message number (and the field) of anything that cannot be read, a topic
  /// that is missing or ambiguous (the topics present are listed), a fixed
  /// frame or mounting that /tf does not hold, or no message with a pose;
  /// UsageError for options that do not go together.
  BagReader(const std::string& path, BagVersion version, const BagOptions& options);
  ~BagReader();
  BagReader(BagReader&&) noexcept;
  BagReader& operator=(BagReader&&) noexcept;

  /// The point type the data's fields give (pointKindOfFields of the first
  /// cloud); XYZ for scans.
  PointKind pointKind() const;

  /// The posed observations (PointXYZ, PointXYZI, PointXYZRGB).
  template <typename PointT>
  BagSequenceOf<PointT> observations() const;

 private:
  struct Contents;
  std::unique_ptr<Contents> contents_;
};

/// ROS 1 when `path` is a file starting with "#ROSBAG V2.0", ROS 2 when it
/// is a folder holding metadata.yaml or one .db3 SQLite file of such a
/// folder; else nothing. An MCAP file is an InputError saying it is not read.
std::optional<BagVersion> detectBag(const std::string& path);

/// BagReader(path, version, options).observations<pcl::PointXYZ>().
BagSequence loadBag(const std::string& path, BagVersion version, const BagOptions& options = {});

}  // namespace obsgroup::io
