// ROS bags as observations: the topic chosen, each message posed at its
// stamp by /tf or a pose topic, its points in the sensor frame.
#include <obsgroup/io/ros_bag.h>

#include "bag_messages.h"

#include <obsgroup/io/depth_sequence.h>
#include <obsgroup/io/errors.h>
#include <obsgroup/io/input_file.h>
#include <obsgroup/io/pose_file.h>

#include <pcl/PCLPointField.h>
#include <pcl/conversions.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <type_traits>

namespace obsgroup::io {

namespace bag {

bool roleAccepts(Role role, const std::string& type) {
  switch (role) {
    case Role::Data: return type == kLaserScanType || type == kPointCloud2Type;
    case Role::Pose: return type == kOdometryType || type == kPoseStampedType;
    case Role::Tf:
    case Role::TfStatic: return type == kTfType;
  }
  return false;
}

const char* typesOfRole(Role role) {
  switch (role) {
    case Role::Data: return "sensor_msgs/LaserScan or sensor_msgs/PointCloud2";
    case Role::Pose: return "nav_msgs/Odometry or geometry_msgs/PoseStamped";
    case Role::Tf:
    case Role::TfStatic: return "tf2_msgs/TFMessage";
  }
  return "";
}

void checkRole(const std::string& type, Role role, const std::string& context) {
  if (!roleAccepts(role, type))
    throw InputError(context + ": a " + type + " where a " + typesOfRole(role) + " is read");
}

void checkScan(const Scan& scan, const std::string& context) {
  auto fail = [&](const char* field, const char* what) { throw InputError(context + ": field " + field + ": " + what); };
  if (!std::isfinite(scan.angle_min)) fail("angle_min", "not finite");
  if (!std::isfinite(scan.angle_increment)) fail("angle_increment", "not finite");
  if (std::isnan(scan.range_min)) fail("range_min", "not a number");
  if (std::isnan(scan.range_max)) fail("range_max", "not a number");
}

namespace {
std::string numbers(const double* values, int n) {
  std::string text;
  for (int k = 0; k < n; ++k) text += (k ? " " : "") + std::to_string(values[k]);
  return text;
}
}  // namespace

Eigen::Isometry3d checkedRigid(const Eigen::Vector3d& translation, const Eigen::Quaterniond& rotation,
                               const std::string& context, const std::string& translation_field,
                               const std::string& rotation_field) {
  auto fail = [&](const std::string& field, const std::string& what) {
    throw InputError(context + ": field " + field + ": " + what);
  };
  if (!translation.allFinite()) fail(translation_field, "not finite (" + numbers(translation.data(), 3) + ")");
  const double norm = rotation.coeffs().norm();  // x y z w
  if (!std::isfinite(norm)) fail(rotation_field, "not finite (" + numbers(rotation.coeffs().data(), 4) + ")");
  if (norm < 1e-6) fail(rotation_field, "a zero quaternion (" + numbers(rotation.coeffs().data(), 4) + ") is no rotation");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation.normalized().toRotationMatrix();
  pose.translation() = translation;
  return pose;
}

std::size_t pointFieldSize(std::uint8_t datatype) {
  static constexpr std::size_t sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
  return datatype < 9 ? sizes[datatype] : 0;
}

void checkCloudLayout(const pcl::PCLPointCloud2& cloud, const std::string& context) {
  auto fail = [&](const std::string& field, const std::string& what) {
    throw InputError(context + ": field " + field + ": " + what);
  };
  if (cloud.is_bigendian) fail("is_bigendian", "big-endian point data is not supported");
  for (std::size_t k = 0; k < cloud.fields.size(); ++k) {
    const pcl::PCLPointField& field = cloud.fields[k];
    const std::size_t size = pointFieldSize(field.datatype);
    const std::string name = "fields[" + std::to_string(k) + "]";
    if (size == 0)
      fail(name + ".datatype", std::to_string(field.datatype) + " is not a PointField datatype (1 INT8 ... 8 FLOAT64)");
    // A count of 0 still has readers (PCL) read one element.
    const std::uint64_t end = std::uint64_t(field.offset) + std::uint64_t(size) * std::max<std::uint32_t>(field.count, 1);
    if (end > cloud.point_step)
      fail(name + ".offset", "field '" + field.name + "' (offset " + std::to_string(field.offset) + ", " +
                                 std::to_string(field.count) + " x " + std::to_string(size) +
                                 " bytes) ends beyond point_step " + std::to_string(cloud.point_step));
  }
  const std::uint64_t points = std::uint64_t(cloud.width) * cloud.height;
  if (points > 0 && cloud.point_step == 0) fail("point_step", "0 bytes per point for " + std::to_string(points) + " points");
  const std::uint64_t row = std::uint64_t(cloud.width) * cloud.point_step;
  if (row > cloud.row_step)
    fail("row_step", std::to_string(cloud.row_step) + " bytes, fewer than point_step x width = " +
                         std::to_string(cloud.point_step) + " x " + std::to_string(cloud.width) + " = " + std::to_string(row));
  const std::uint64_t bytes = std::uint64_t(cloud.row_step) * cloud.height;
  if (bytes > cloud.data.size())
    fail("data", std::to_string(cloud.data.size()) + " bytes, fewer than row_step x height = " +
                     std::to_string(cloud.row_step) + " x " + std::to_string(cloud.height) + " = " + std::to_string(bytes));
}

}  // namespace bag

namespace {

using bag::Numbered;

/// A pose that changes with time: samples in time order, interpolated
/// (translation linearly, rotation by slerp), never extrapolated.
class PoseTrack {
 public:
  void add(double stamp, const Eigen::Isometry3d& pose) { samples_.push_back({stamp, pose}); }
  void sort() {
    std::stable_sort(samples_.begin(), samples_.end(), [](const Sample& a, const Sample& b) { return a.stamp < b.stamp; });
  }
  std::optional<Eigen::Isometry3d> at(double stamp) const {
    if (samples_.empty() || stamp < samples_.front().stamp || stamp > samples_.back().stamp) return std::nullopt;
    const auto after = std::lower_bound(samples_.begin(), samples_.end(), stamp,
                                        [](const Sample& s, double t) { return s.stamp < t; });
    if (after->stamp == stamp || after == samples_.begin()) return after->pose;
    const Sample& before = *std::prev(after);
    const double f = (stamp - before.stamp) / (after->stamp - before.stamp);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = (1 - f) * before.pose.translation() + f * after->pose.translation();
    pose.linear() = Eigen::Quaterniond(before.pose.rotation())
                        .slerp(f, Eigen::Quaterniond(after->pose.rotation()))
                        .toRotationMatrix();
    return pose;
  }

 private:
  struct Sample {
    double stamp;
    Eigen::Isometry3d pose;
  };
  std::vector<Sample> samples_;
};

/// The frames of /tf and /tf_static: each child has one parent, by a fixed
/// transform (/tf_static) or one that changes with time (/tf).
class FrameTree {
 public:
  FrameTree(const bag::Messages& messages, const std::string& bag_name) {
    for (const auto& t : messages.tf_static) add(t, true, bag_name + ": message " + std::to_string(t.number) + " on /tf_static");
    for (const auto& t : messages.tf) add(t, false, bag_name + ": message " + std::to_string(t.number) + " on /tf");
    for (auto& [child, edge] : edges_) edge.track.sort();
  }

  bool has(const std::string& frame) const { return frames_.count(frame) > 0; }
  bool hasParent(const std::string& frame) const { return edges_.count(frame) > 0; }
  /// "a, b, c": every frame of the tree, for messages.
  std::string frameList() const {
    std::string list;
    for (const auto& f : frames_) list += (list.empty() ? "'" : ", '") + f + "'";
    return list;
  }
  /// Whether `frame` is `ancestor` or hangs below it.
  bool isAtOrBelow(std::string frame, const std::string& ancestor) const {
    for (std::size_t depth = 0; depth <= edges_.size(); ++depth) {
      if (frame == ancestor) return true;
      const auto e = edges_.find(frame);
      if (e == edges_.end()) return false;
      frame = e->second.parent;
    }
    return false;
  }
  /// The topmost ancestor of `frame` through /tf_static edges only.
  std::string staticRoot(std::string frame) const {
    for (auto e = edges_.find(frame); e != edges_.end() && e->second.fixed; e = edges_.find(frame))
      frame = e->second.parent;
    return frame;
  }

  /// The pose of `source` in `target` at `stamp`, when both hang in one tree
  /// and every moving edge between them has samples around the stamp.
  std::optional<Eigen::Isometry3d> lookup(const std::string& target, const std::string& source, double stamp) const {
    if (target == source) return Eigen::Isometry3d::Identity();
    const auto from_source = toRoot(source, stamp);
    const auto from_target = toRoot(target, stamp);
    if (!from_source || !from_target || from_source->root != from_target->root) return std::nullopt;
    return from_target->pose.inverse() * from_source->pose;
  }
  /// Whether `source` and `target` hang in one tree at all.
  bool connected(const std::string& target, const std::string& source) const {
    return rootOf(target) == rootOf(source);
  }

 private:
  struct Edge {
    std::string parent;
    bool fixed = false;
    Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // fixed edges
    PoseTrack track;                                              // moving edges
  };
  struct Chain {
    std::string root;
    Eigen::Isometry3d pose;  // of the frame in its root
  };

  void add(const Numbered<bag::Transform>& numbered, bool fixed, const std::string& context) {
    const bag::Transform& t = numbered.message;
    if (t.header.frame_id.empty() || t.child_frame_id.empty())
      throw InputError(context + ": field " + (t.header.frame_id.empty() ? "header.frame_id" : "child_frame_id") +
                       ": empty");
    frames_.insert(t.header.frame_id);
    frames_.insert(t.child_frame_id);
    auto [it, fresh] = edges_.try_emplace(t.child_frame_id);
    Edge& edge = it->second;
    if (fresh) {
      edge.parent = t.header.frame_id;
      edge.fixed = fixed;
    } else if (edge.parent != t.header.frame_id) {
      throw InputError(context + ": frame '" + t.child_frame_id + "' has two parents, '" + edge.parent + "' and '" +
                       t.header.frame_id + "'");
    }
    if (edge.fixed) {
      edge.transform = t.transform;  // a later /tf_static message replaces an earlier one
    } else {
      edge.track.add(t.header.stamp, t.transform);
    }
  }

  std::string rootOf(std::string frame) const {
    for (std::size_t depth = 0; depth <= edges_.size(); ++depth) {
      const auto e = edges_.find(frame);
      if (e == edges_.end()) return frame;
      frame = e->second.parent;
    }
    return {};  // a cycle: no root
  }

  std::optional<Chain> toRoot(std::string frame, double stamp) const {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    for (std::size_t depth = 0; depth <= edges_.size(); ++depth) {
      const auto e = edges_.find(frame);
      if (e == edges_.end()) return Chain{frame, pose};
      const Edge& edge = e->second;
      if (edge.fixed) {
        pose = edge.transform * pose;
      } else {
        const auto moving = edge.track.at(stamp);
        if (!moving) return std::nullopt;
        pose = *moving * pose;
      }
      frame = edge.parent;
    }
    return std::nullopt;  // a cycle
  }

  std::map<std::string, Edge> edges_;  // by child frame
  std::set<std::string> frames_;
};

std::string topicList(const std::vector<bag::Topic>& topics) {
  if (topics.empty()) return "the bag has no topics";
  std::string list = "topics:";
  for (const auto& t : topics) list += " " + t.name + " (" + t.type + ", " + std::to_string(t.messages) + ")";
  return list;
}

/// The topic named `name`, or `/name` when the user left out the leading
/// slash (`--topic scan` for /scan).
const bag::Topic* findTopic(const std::vector<bag::Topic>& topics, const std::string& name) {
  for (const auto& t : topics)
    if (t.name == name) return &t;
  if (!name.empty() && name[0] != '/')
    for (const auto& t : topics)
      if (t.name == "/" + name) return &t;
  return nullptr;
}

const bag::Topic& chooseDataTopic(const std::vector<bag::Topic>& topics, const std::optional<std::string>& asked,
                                  const std::string& bag_name) {
  auto isData = [](const bag::Topic& t) { return t.type == bag::kLaserScanType || t.type == bag::kPointCloud2Type; };
  if (asked) {
    const bag::Topic* topic = findTopic(topics, *asked);
    if (!topic) throw InputError(bag_name + ": no topic " + *asked + " (--topic); " + topicList(topics));
    if (!isData(*topic))
      throw InputError(bag_name + ": topic " + *asked + " is a " + topic->type +
                       ", not a sensor_msgs/LaserScan or sensor_msgs/PointCloud2 (--topic)");
    return *topic;
  }
  std::vector<const bag::Topic*> data;
  for (const auto& t : topics)
    if (isData(t)) data.push_back(&t);
  if (data.empty())
    throw InputError(bag_name + ": no sensor_msgs/LaserScan or sensor_msgs/PointCloud2 topic; " + topicList(topics));
  if (data.size() > 1) {
    std::string names;
    for (const auto* t : data) names += " " + t->name;
    throw InputError(bag_name + ": several scan or cloud topics (" + names.substr(1) + "): choose one with --topic");
  }
  return *data.front();
}

/// The pose topic's name as the bag spells it; throws when it is not one.
std::string checkPoseTopic(const std::vector<bag::Topic>& topics, const std::string& asked, const std::string& bag_name) {
  const bag::Topic* topic = findTopic(topics, asked);
  if (!topic) throw InputError(bag_name + ": no topic " + asked + " (--pose-topic); " + topicList(topics));
  if (topic->type != bag::kOdometryType && topic->type != bag::kPoseStampedType)
    throw InputError(bag_name + ": topic " + asked + " is a " + topic->type +
                     ", not a nav_msgs/Odometry or geometry_msgs/PoseStamped (--pose-topic)");
  return topic->name;
}

/// A scan's returns as points in its frame (x ahead, y left): finite ranges
/// within [range_min, range_max).
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr scanPoints(const bag::Scan& scan) {
  auto cloud = pcl::make_shared<pcl::PointCloud<PointT>>();
  cloud->reserve(scan.ranges.size());
  for (std::size_t k = 0; k < scan.ranges.size(); ++k) {
    const double r = scan.ranges[k];
    // As laser_geometry projects scans: range_max itself is the no-return
    // value of Stage, Gazebo and several drivers.
    if (!std::isfinite(r) || r < scan.range_min || r >= scan.range_max || r <= 0) continue;
    const double angle = scan.angle_min + double(k) * scan.angle_increment;
    PointT p;
    p.x = float(r * std::cos(angle));
    p.y = float(r * std::sin(angle));
    p.z = 0.0f;
    cloud->push_back(p);
  }
  return cloud;
}

/// The points of a PointCloud2 with finite x, y, z (FLOAT32 fields), the
/// other fields PointT has (intensity, rgb) as PCL maps them.
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr cloudPoints(const bag::Cloud& message, const std::string& context) {
  for (const char* axis : {"x", "y", "z"}) {
    const auto field = std::find_if(message.cloud.fields.begin(), message.cloud.fields.end(),
                                    [&](const pcl::PCLPointField& f) { return f.name == axis; });
    if (field == message.cloud.fields.end())
      throw InputError(context + ": field fields: no '" + axis + "' field (x, y, z are read)");
    if (field->datatype != pcl::PCLPointField::FLOAT32)
      throw InputError(context + ": field fields: '" + axis + "' is not FLOAT32 (datatype " +
                       std::to_string(field->datatype) + ")");
  }
  auto cloud = pcl::make_shared<pcl::PointCloud<PointT>>();
  // PCL 1.13 indexes the first point of an empty cloud (undefined behaviour).
  if (std::uint64_t(message.cloud.width) * message.cloud.height == 0) return cloud;
  pcl::PointCloud<PointT> all;
  pcl::fromPCLPointCloud2(message.cloud, all);
  cloud->reserve(all.size());
  for (const auto& p : all)
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) cloud->push_back(p);
  return cloud;
}

/// REP 103: a frame named *_optical_frame (or *_optical) has z forward, x
/// right, y down.
bool isOpticalFrame(const std::string& frame) {
  const auto endsWith = [&](const std::string& tail) {
    return frame.size() >= tail.size() && frame.compare(frame.size() - tail.size(), tail.size(), tail) == 0;
  };
  return endsWith("_optical_frame") || endsWith("_optical");
}

/// Where the poses come from: /tf in a fixed frame, or a pose topic and the
/// sensor's mounting on the body it gives.
class PoseSource {
 public:
  PoseSource(const bag::Messages& messages, const BagOptions& options, const std::string& bag_name,
             const std::vector<bag::Topic>& topics, std::vector<std::string>& warnings)
      : tree_(messages, bag_name), bag_name_(bag_name), warnings_(warnings) {
    if (options.poses_file) {
      const std::string name = inputName(*options.poses_file);
      stamped_.emplace(parseStampedPoses(readInputBytes(*options.poses_file, "poses file"), name),
                       options.max_time_difference);
      description_ = name;
      fixed_frame_ = "";  // whatever frame the file's poses are in
      return;
    }
    if (options.pose_topic) {
      for (const auto& p : messages.poses) {
        track_.add(p.message.header.stamp, p.message.pose);
        body_ = p.message.child_frame_id;
        fixed_frame_ = p.message.header.frame_id;
      }
      track_.sort();
      if (messages.poses.empty()) throw InputError(bag_name + ": no message on " + *options.pose_topic);
      description_ = *options.pose_topic;
      return;
    }
    description_ = "/tf";
    if (messages.tf.empty() && messages.tf_static.empty()) {
      std::string pose_topics;
      for (const auto& t : topics)
        if (t.type == bag::kOdometryType || t.type == bag::kPoseStampedType) pose_topics += " " + t.name;
      throw InputError(bag_name + ": no /tf in the bag to pose the scans by; give a pose topic with --pose-topic" +
                       (pose_topics.empty() ? std::string(" (the bag has no nav_msgs/Odometry or geometry_msgs/PoseStamped topic)")
                                            : " (candidates:" + pose_topics + ")"));
    }
    fixed_frame_ = options.fixed_frame.value_or("map");
    if (tree_.has(fixed_frame_)) return;
    if (options.fixed_frame || !tree_.has("odom"))
      throw InputError(bag_name + ": /tf has no frame '" + fixed_frame_ + "'" +
                       (options.fixed_frame ? std::string(" (--fixed-frame)") : " nor 'odom'") +
                       "; its frames: " + tree_.frameList() +
                       "; give the frame the poses are in with --fixed-frame, or a pose topic with --pose-topic");
    warnings_.push_back(bag_name + ": /tf has no 'map' frame: the poses are taken in 'odom' (odometry, which drifts)");
    fixed_frame_ = "odom";
  }

  const std::string& description() const { return description_; }
  const std::string& fixedFrame() const { return fixed_frame_; }

  /// The sensor's pose at the stamp, or nothing when the poses do not span it.
  std::optional<Eigen::Isometry3d> at(const std::string& sensor, double stamp, const std::string& context) {
    if (stamped_) return stamped_->at(stamp);
    if (description_ == "/tf") {
      if (!tree_.connected(fixed_frame_, sensor))
        throw InputError(context + ": /tf does not connect the sensor's frame '" + sensor + "' to '" + fixed_frame_ + "'");
      // The sensor's own frame, one below it, or one fixed to it by /tf_static (the robot's base).
      if (tree_.isAtOrBelow(fixed_frame_, sensor) || tree_.staticRoot(fixed_frame_) == tree_.staticRoot(sensor))
        throw InputError(context + ": the fixed frame '" + fixed_frame_ + "' " +
                         (fixed_frame_ == sensor ? std::string("is the sensor's own frame") : "moves with the sensor ('" + sensor + "')") +
                         ": every pose would be the same; give the frame the robot moves in with --fixed-frame (the bag's "
                         "frames: " + tree_.frameList() + ")");
      return tree_.lookup(fixed_frame_, sensor, stamp);
    }
    const auto body = track_.at(stamp);
    if (!body) return std::nullopt;
    const auto mount = mounting(sensor, stamp);
    if (!mount) return std::nullopt;
    return *body * *mount;
  }

 private:
  /// The sensor's pose on the body the pose topic moves: /tf from the
  /// Odometry's child frame; for PoseStamped (no child frame) the root of the
  /// sensor's /tf_static chain. No such transform: the sensor is the body.
  std::optional<Eigen::Isometry3d> mounting(const std::string& sensor, double stamp) {
    const std::string body = body_.empty() ? tree_.staticRoot(sensor) : body_;
    if (body == sensor && !body_.empty()) return Eigen::Isometry3d::Identity();  // the odometry is the sensor's
    if (body == sensor || !tree_.connected(body, sensor)) {
      if (!warned_unmounted_)
        warnings_.push_back(bag_name_ + ": no /tf_static from " + (body == sensor ? std::string("the body") : "'" + body + "'") +
                            " to the sensor's frame '" + sensor + "': the sensor is taken to be at the poses of " +
                            description_);
      warned_unmounted_ = true;
      return Eigen::Isometry3d::Identity();
    }
    return tree_.lookup(body, sensor, stamp);
  }

  FrameTree tree_;
  PoseTrack track_;
  std::optional<StampedPoseIndex> stamped_;  // a poses file's
  std::string body_;
  std::string fixed_frame_;
  std::string description_;
  std::string bag_name_;
  std::vector<std::string>& warnings_;
  bool warned_unmounted_ = false;
};

template <typename PointT, typename Message>
void addObservations(const std::vector<Numbered<Message>>& messages, const std::string& topic, PoseSource& poses,
                     const std::string& bag_name, const FrameReading& reduction, BagSequenceOf<PointT>& sequence) {
  std::size_t done = 0;
  for (const auto& [number, message] : messages) {
    if (reduction.progress) reduction.progress(++done, messages.size());
    const std::string label = bag_name + ": message " + std::to_string(number) + " on " + topic;
    if (message.header.frame_id.empty()) throw InputError(label + ": field header.frame_id: empty");
    const auto pose = poses.at(message.header.frame_id, message.header.stamp, label);
    if (!pose) {
      ++sequence.skipped;
      continue;
    }
    if constexpr (std::is_same_v<Message, bag::Scan>) {
      sequence.observations.push_back({scanPoints<PointT>(message), *pose});
    } else {
      auto cloud = cloudPoints<PointT>(message, label);
      // Reduced as it was decoded, or now when the reader was given no reduction then.
      sequence.reduced += message.reduced || reduceFrame(*cloud, message.sensor_points, reduction);
      Eigen::Isometry3d body_pose = *pose;
      if (isOpticalFrame(message.header.frame_id)) {  // as depth images: into the body frame, z up
        const Eigen::Matrix3f to_body = kOpticalInBody.cast<float>();
        for (auto& p : cloud->points) p.getVector3fMap() = to_body * p.getVector3fMap();
        body_pose.linear() = pose->linear() * kOpticalInBody.transpose();
      }
      sequence.observations.push_back({cloud, body_pose});
    }
    sequence.labels.push_back(label);
    sequence.stamps.push_back(message.header.stamp);
  }
}

}  // namespace

bool bagSupported(BagVersion version) {
#ifdef OBSGROUP_HAVE_ROS1
  if (version == BagVersion::Ros1) return true;
#endif
#ifdef OBSGROUP_HAVE_ROS2
  if (version == BagVersion::Ros2) return true;
#endif
  (void)version;
  return false;
}

std::optional<BagVersion> detectBag(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    if (fs::exists(fs::path(path) / "metadata.yaml", ec)) return BagVersion::Ros2;
    return std::nullopt;
  }
  std::ifstream in(path, std::ios::binary);
  char magic[16] = {};
  in.read(magic, 16);
  const std::string start(magic, std::size_t(in.gcount()));
  if (start.rfind("#ROSBAG V2.0\n", 0) == 0) return BagVersion::Ros1;
  // One file of a ROS 2 bag: an SQLite database named .db3.
  if (start == std::string("SQLite format 3\0", 16) && fs::path(path).extension() == ".db3") return BagVersion::Ros2;
  if (start.rfind("\x89MCAP", 0) == 0)
    throw InputError(path + ": an MCAP file: MCAP storage is not supported (Debian ships no MCAP library); " +
                     bag::kConvertToSqlite);
  return std::nullopt;
}

struct BagReader::Contents {
  std::string path;
  BagVersion version = BagVersion::Ros1;
  BagOptions options;
  std::vector<bag::Topic> topics;
  bag::Topic data;
  bag::Messages messages;
};

BagReader::BagReader(const std::string& path, BagVersion version, const BagOptions& options)
    : contents_(std::make_unique<Contents>()) {
  if (options.pose_topic && options.fixed_frame)
    throw UsageError("--fixed-frame applies to poses from /tf; a pose topic gives its own frame");
  if (options.poses_file && (options.pose_topic || options.fixed_frame))
    throw UsageError("--poses gives the poses itself: no --pose-topic or --fixed-frame with it");
  Contents& c = *contents_;
  c.path = path;
  c.version = version;
  c.options = options;
  const bool ros1 = version == BagVersion::Ros1;
  c.topics = ros1 ? bag::listRos1Topics(path) : bag::listRos2Topics(path);
  c.data = chooseDataTopic(c.topics, options.topic, path);
  // The topics as the bag spells them (a name given without its leading slash).
  c.options.topic = c.data.name;
  if (options.pose_topic) c.options.pose_topic = checkPoseTopic(c.topics, *options.pose_topic, path);
  const bag::Request request{c.data.name, c.options.pose_topic, !options.poses_file, &c.options.reduction};
  c.messages = ros1 ? bag::readRos1Messages(path, request) : bag::readRos2Messages(path, request);
}

BagReader::~BagReader() = default;
BagReader::BagReader(BagReader&&) noexcept = default;
BagReader& BagReader::operator=(BagReader&&) noexcept = default;

PointKind BagReader::pointKind() const {
  const auto& clouds = contents_->messages.clouds;
  return clouds.empty() ? PointKind::XYZ : pointKindOfFields(clouds.front().message.cloud.fields);
}

template <typename PointT>
BagSequenceOf<PointT> BagReader::observations() const {
  const Contents& c = *contents_;
  BagSequenceOf<PointT> sequence;
  sequence.version = c.version;
  sequence.topic = c.data.name;
  sequence.message_type = c.data.type;
  PoseSource poses(c.messages, c.options, c.path, c.topics, sequence.warnings);
  sequence.pose_source = poses.description();
  sequence.fixed_frame = poses.fixedFrame();
  addObservations(c.messages.scans, c.data.name, poses, c.path, c.options.reduction, sequence);
  addObservations(c.messages.clouds, c.data.name, poses, c.path, c.options.reduction, sequence);
  const std::size_t total = c.messages.scans.size() + c.messages.clouds.size();
  if (sequence.observations.empty())
    throw InputError(c.path + ": none of the " + std::to_string(total) + " messages on " + c.data.name +
                     " has a pose from " + poses.description() + " at its stamp");
  if (sequence.skipped > 0)
    sequence.warnings.push_back(
        std::to_string(sequence.skipped) + " of " + std::to_string(total) + " messages on " + c.data.name +
        (c.options.poses_file ? " have no pose in " + poses.description() + " within " +
                                    std::to_string(c.options.max_time_difference) + " s of their stamp"
                              : " are outside the time span of " + poses.description() + " (no pose is extrapolated)") +
        ": skipped");
  return sequence;
}

template BagSequenceOf<pcl::PointXYZ> BagReader::observations<pcl::PointXYZ>() const;
template BagSequenceOf<pcl::PointXYZI> BagReader::observations<pcl::PointXYZI>() const;
template BagSequenceOf<pcl::PointXYZRGB> BagReader::observations<pcl::PointXYZRGB>() const;

BagSequence loadBag(const std::string& path, BagVersion version, const BagOptions& options) {
  return BagReader(path, version, options).observations<pcl::PointXYZ>();
}

}  // namespace obsgroup::io
