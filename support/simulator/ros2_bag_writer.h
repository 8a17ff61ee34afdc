#pragma once
// Writes a ROS 2 bag in rosbag2's sqlite3 storage (a folder with
// metadata.yaml and .db3 files) from obsgroup's neutral message structs,
// CDR-serialised with Fast CDR as rosbag2 does. Header only; needs SQLite and
// Fast CDR (OBSGROUP_HAVE_ROS2). Used by the tests, make_datasets and the
// bag benchmark.
//
//   obsgroup::test::Ros2BagWriter bag(dir / "bag");   // creates the folder
//   bag.write("/scan", scan);                         // sensor_msgs/msg/LaserScan
//   bag.write("/points", cloud);                      // sensor_msgs/msg/PointCloud2
//   bag.writeTf("/tf", {t1, t2});                     // tf2_msgs/msg/TFMessage (also /tf_static)
//   bag.write("/odom", pose, /*odometry=*/true);      // nav_msgs/msg/Odometry (false: PoseStamped)
//   bag.split();                                      // later messages go to the next .db3 file
//   bag.writeRaw("/scan", "sensor_msgs/msg/LaserScan", 5'000'000'000, bytes);  // any bytes
//   bag.close();                                      // or the destructor: writes metadata.yaml
//
// Each message's timestamp is its header stamp in nanoseconds (a TFMessage:
// its first transform's; an empty one: 0) unless a timestamp_ns is given.
// A topic's type is fixed by its first message. Files are bag_0.db3,
// bag_1.db3, ... Static serialisers (Ros2BagWriter::serialize(scan),
// serialize(cloud), serialize(transforms), serialize(pose, odometry)) give the
// CDR bytes of one message, with the encapsulation header; for hand-made
// messages, serialized([](eprosima::fastcdr::Cdr& cdr) { header(cdr, h);
// cdr << ...; }, endianness) writes the header then whatever the lambda does.

#ifdef OBSGROUP_HAVE_ROS2

#include "bag_messages.h"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <sqlite3.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace obsgroup::test {

class Ros2BagWriter {
 public:
  using Bytes = std::vector<unsigned char>;

  explicit Ros2BagWriter(const std::filesystem::path& folder) : folder_(folder) {
    std::filesystem::create_directories(folder_);
    openFile();
  }
  ~Ros2BagWriter() {
    try {
      close();
    } catch (...) {
    }
  }
  Ros2BagWriter(const Ros2BagWriter&) = delete;
  Ros2BagWriter& operator=(const Ros2BagWriter&) = delete;

  void write(const std::string& topic, const io::bag::Scan& scan, std::optional<std::int64_t> timestamp_ns = {}) {
    writeRaw(topic, "sensor_msgs/msg/LaserScan", timestamp_ns.value_or(nanoseconds(scan.header.stamp)), serialize(scan));
  }
  void write(const std::string& topic, const io::bag::Cloud& cloud, std::optional<std::int64_t> timestamp_ns = {}) {
    writeRaw(topic, "sensor_msgs/msg/PointCloud2", timestamp_ns.value_or(nanoseconds(cloud.header.stamp)),
             serialize(cloud));
  }
  /// nav_msgs/Odometry when `odometry`, else geometry_msgs/PoseStamped.
  void write(const std::string& topic, const io::bag::Pose& pose, bool odometry,
             std::optional<std::int64_t> timestamp_ns = {}) {
    writeRaw(topic, odometry ? "nav_msgs/msg/Odometry" : "geometry_msgs/msg/PoseStamped",
             timestamp_ns.value_or(nanoseconds(pose.header.stamp)), serialize(pose, odometry));
  }
  void writeTf(const std::string& topic, const std::vector<io::bag::Transform>& transforms,
               std::optional<std::int64_t> timestamp_ns = {}) {
    const std::int64_t stamp = transforms.empty() ? 0 : nanoseconds(transforms.front().header.stamp);
    writeRaw(topic, "tf2_msgs/msg/TFMessage", timestamp_ns.value_or(stamp), serialize(transforms));
  }

  /// Any bytes as a message of `type` (ROS 2 spelling) on `topic`.
  void writeRaw(const std::string& topic, const std::string& type, std::int64_t timestamp_ns, const Bytes& data,
                const std::string& serialization_format = "cdr") {
    const std::int64_t id = topicId(topic, type, serialization_format);
    Statement insert(db_, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?1, ?2, ?3)");
    sqlite3_bind_int64(insert.get(), 1, id);
    sqlite3_bind_int64(insert.get(), 2, timestamp_ns);
    sqlite3_bind_blob(insert.get(), 3, data.data(), int(data.size()), SQLITE_TRANSIENT);
    insert.run();
    ++topics_[topic].count;
    ++message_count_;
  }

  /// Closes the current .db3 file; later messages go to the next one (each
  /// file has its own topics table, as rosbag2's split files do).
  void split() {
    closeFile();
    openFile();
  }

  /// Writes metadata.yaml. Nothing may be written after.
  void close() {
    if (!db_) return;
    closeFile();
    std::ofstream out(folder_ / "metadata.yaml");
    out << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
        << "  duration:\n    nanoseconds: 0\n  starting_time:\n    nanoseconds_since_epoch: 0\n"
        << "  message_count: " << message_count_ << "\n  topics_with_message_count:\n";
    for (const auto& [name, topic] : topics_)
      out << "    - topic_metadata:\n        name: " << name << "\n        type: " << topic.type
          << "\n        serialization_format: " << topic.format << "\n        offered_qos_profiles: \"\"\n"
          << "      message_count: " << topic.count << "\n";
    out << "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n";
    for (const std::string& file : files_) out << "    - " << file << "\n";
    out << "  files:\n";
    for (const std::string& file : files_)
      out << "    - path: " << file << "\n      starting_time:\n        nanoseconds_since_epoch: 0\n"
          << "      duration:\n        nanoseconds: 0\n      message_count: 0\n";
    if (!out) throw std::runtime_error("cannot write " + (folder_ / "metadata.yaml").string());
  }

  // --- CDR, as rosidl's Fast RTPS type support writes it -------------------

  static Bytes serialize(const io::bag::Scan& scan) {
    return serialized([&](eprosima::fastcdr::Cdr& cdr) {
      header(cdr, scan.header);
      const std::size_t n = scan.ranges.size();
      cdr << float(scan.angle_min) << float(scan.angle_min + (n ? double(n - 1) : 0.0) * scan.angle_increment)
          << float(scan.angle_increment) << 0.0f << 0.0f << float(scan.range_min) << float(scan.range_max);
      cdr << std::uint32_t(n);
      if (n) cdr.serializeArray(scan.ranges.data(), n);
      cdr << std::uint32_t(0);  // no intensities
    });
  }

  static Bytes serialize(const io::bag::Cloud& message) {
    const pcl::PCLPointCloud2& cloud = message.cloud;
    return serialized([&](eprosima::fastcdr::Cdr& cdr) {
      header(cdr, message.header);
      cdr << std::uint32_t(cloud.height) << std::uint32_t(cloud.width) << std::uint32_t(cloud.fields.size());
      for (const pcl::PCLPointField& field : cloud.fields)
        cdr << field.name << std::uint32_t(field.offset) << std::uint8_t(field.datatype) << std::uint32_t(field.count);
      cdr << bool(cloud.is_bigendian) << std::uint32_t(cloud.point_step) << std::uint32_t(cloud.row_step);
      cdr << std::uint32_t(cloud.data.size());
      if (!cloud.data.empty()) cdr.serializeArray(cloud.data.data(), cloud.data.size());
      cdr << bool(cloud.is_dense);
    });
  }

  static Bytes serialize(const std::vector<io::bag::Transform>& transforms) {
    return serialized([&](eprosima::fastcdr::Cdr& cdr) {
      cdr << std::uint32_t(transforms.size());
      for (const io::bag::Transform& t : transforms) {
        header(cdr, t.header);
        cdr << t.child_frame_id;
        pose(cdr, t.transform);
      }
    });
  }

  static Bytes serialize(const io::bag::Pose& message, bool odometry) {
    return serialized([&](eprosima::fastcdr::Cdr& cdr) {
      header(cdr, message.header);
      if (odometry) cdr << message.child_frame_id;
      pose(cdr, message.pose);
      if (!odometry) return;
      for (int k = 0; k < 36; ++k) cdr << 0.0;  // pose covariance
      for (int k = 0; k < 6 + 36; ++k) cdr << 0.0;  // twist and its covariance
    });
  }

  /// The encapsulation header then whatever `fill(cdr)` serialises: for
  /// hand-made (odd or corrupt) messages.
  template <typename Fill>
  static Bytes serialized(Fill fill,
                          eprosima::fastcdr::Cdr::Endianness endianness = eprosima::fastcdr::Cdr::DEFAULT_ENDIAN) {
    eprosima::fastcdr::FastBuffer buffer;  // grows as needed
    eprosima::fastcdr::Cdr cdr(buffer, endianness, eprosima::fastcdr::Cdr::DDS_CDR);
    cdr.serialize_encapsulation();
    fill(cdr);
    const auto* begin = reinterpret_cast<const unsigned char*>(buffer.getBuffer());
    return Bytes(begin, begin + cdr.getSerializedDataLength());
  }

  /// Header stamp in nanoseconds, as rosbag2 would time the message.
  static std::int64_t nanoseconds(double stamp) { return std::int64_t(std::llround(stamp * 1e9)); }

  /// Pieces of messages, for hand-made ones.
  static void header(eprosima::fastcdr::Cdr& cdr, const io::bag::Header& header) {
    const std::int64_t ns = nanoseconds(header.stamp);
    std::int64_t sec = ns / 1000000000, nanosec = ns % 1000000000;
    if (nanosec < 0) {
      nanosec += 1000000000;
      --sec;
    }
    cdr << std::int32_t(sec) << std::uint32_t(nanosec) << header.frame_id;
  }

  static void pose(eprosima::fastcdr::Cdr& cdr, const Eigen::Isometry3d& pose) {
    const Eigen::Quaterniond q(pose.rotation());
    const Eigen::Vector3d t = pose.translation();
    cdr << t.x() << t.y() << t.z() << q.x() << q.y() << q.z() << q.w();
  }

 private:
  struct TopicEntry {
    std::string type, format;
    std::size_t count = 0;
  };

  class Statement {
   public:
    Statement(sqlite3* db, const char* sql) {
      if (sqlite3_prepare_v2(db, sql, -1, &statement_, nullptr) != SQLITE_OK)
        throw std::runtime_error(std::string("sqlite: ") + sqlite3_errmsg(db));
    }
    ~Statement() { sqlite3_finalize(statement_); }
    sqlite3_stmt* get() const { return statement_; }
    void run() {
      if (sqlite3_step(statement_) != SQLITE_DONE)
        throw std::runtime_error(std::string("sqlite: ") + sqlite3_errmsg(sqlite3_db_handle(statement_)));
    }

   private:
    sqlite3_stmt* statement_ = nullptr;
  };

  void openFile() {
    const std::string name = "bag_" + std::to_string(files_.size()) + ".db3";
    files_.push_back(name);
    const std::string path = (folder_ / name).string();
    if (sqlite3_open(path.c_str(), &db_) != SQLITE_OK) throw std::runtime_error("cannot create " + path);
    exec("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
         "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
         "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
         "data BLOB NOT NULL);"
         "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
         "BEGIN TRANSACTION;");
    file_topics_.clear();
  }

  void closeFile() {
    exec("COMMIT;");
    sqlite3_close(db_);
    db_ = nullptr;
  }

  void exec(const char* sql) {
    char* error = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &error) != SQLITE_OK) {
      const std::string message = error ? error : "?";
      sqlite3_free(error);
      throw std::runtime_error("sqlite: " + message);
    }
  }

  std::int64_t topicId(const std::string& topic, const std::string& type, const std::string& format) {
    if (!db_) throw std::logic_error("Ros2BagWriter: write after close");
    auto known = file_topics_.find(topic);
    if (known != file_topics_.end()) return known->second;
    TopicEntry& entry = topics_[topic];
    if (entry.type.empty()) {
      entry.type = type;
      entry.format = format;
    }
    Statement insert(db_,
                     "INSERT INTO topics (name, type, serialization_format, offered_qos_profiles) VALUES (?1, ?2, ?3, '')");
    sqlite3_bind_text(insert.get(), 1, topic.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(insert.get(), 2, entry.type.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(insert.get(), 3, entry.format.c_str(), -1, SQLITE_TRANSIENT);
    insert.run();
    return file_topics_[topic] = sqlite3_last_insert_rowid(db_);
  }

  std::filesystem::path folder_;
  sqlite3* db_ = nullptr;
  std::vector<std::string> files_;
  std::map<std::string, TopicEntry> topics_;         ///< whole bag
  std::map<std::string, std::int64_t> file_topics_;  ///< id in the current file
  std::size_t message_count_ = 0;
};

}  // namespace obsgroup::test

#endif  // OBSGROUP_HAVE_ROS2
