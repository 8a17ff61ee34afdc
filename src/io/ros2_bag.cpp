// ROS 2 bags in rosbag2's default sqlite3 storage: a folder with
// metadata.yaml and one or more .db3 SQLite files whose `messages` table
// holds each message CDR-serialised. Read with the SQLite C API and Fast CDR
// (both in Debian) rather than rosbag2 itself, which Debian does not ship.
#include "bag_messages.h"

#include <obsgroup/io/errors.h>
#include <obsgroup/io/pcd_sequence.h>

#ifdef OBSGROUP_HAVE_ROS2
#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastcdr/exceptions/Exception.h>
#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#endif

namespace obsgroup::io::bag {

#ifdef OBSGROUP_HAVE_ROS2

namespace {

namespace fs = std::filesystem;
namespace cdr = eprosima::fastcdr;

// ---------------------------------------------------------------------------
// Types: rosbag2 spells them "sensor_msgs/msg/LaserScan", obsgroup (and
// ROS 1) "sensor_msgs/LaserScan".

std::string ros1Spelling(const std::string& type) {
  const std::size_t first = type.find('/');
  if (first == std::string::npos || type.compare(first, 5, "/msg/") != 0) return type;
  return type.substr(0, first) + type.substr(first + 4);
}

const char* roleName(Role role) {
  switch (role) {
    case Role::Data: return "data";
    case Role::Pose: return "pose";
    case Role::Tf: return "/tf";
    case Role::TfStatic: return "/tf_static";
  }
  return "";
}

// ---------------------------------------------------------------------------
// CDR. Fast CDR checks every read against the end of the buffer and throws;
// this reader turns that into an InputError naming the field. Sequence
// lengths are checked against the bytes left before anything is allocated:
// a corrupt length must not become a gigabyte vector.

class CdrReader {
 public:
  CdrReader(const unsigned char* data, std::size_t size, const std::string& context)
      : data_(data),
        size_(size),
        // Fast CDR wants a mutable buffer but only reads it when deserialising.
        buffer_(const_cast<char*>(reinterpret_cast<const char*>(data)), size),
        cdr_(buffer_, cdr::Cdr::DEFAULT_ENDIAN, cdr::Cdr::DDS_CDR),
        context_(context) {}

  /// The 4-byte encapsulation header: plain CDR, either byte order
  /// (ROS 2 writes no parameter lists or XCDR2 for these messages).
  void readEncapsulation() {
    if (size_ < 4)
      fail("encapsulation", std::to_string(size_) + " bytes, fewer than the 4 of the CDR encapsulation header");
    if (data_[0] != 0 || data_[1] > 1)
      fail("encapsulation", "header bytes " + std::to_string(data_[0]) + " " + std::to_string(data_[1]) +
                                " are not plain CDR (0 0 big-endian or 0 1 little-endian)");
    guarded("encapsulation", [&] { cdr_.read_encapsulation(); });
  }

  template <typename T>
  T read(const char* field) {
    T value{};
    guarded(field, [&] { cdr_.deserialize(value); });
    return value;
  }

  double stamp(const char* sec_field, const char* nanosec_field) {
    const auto sec = read<std::int32_t>(sec_field);
    const auto nanosec = read<std::uint32_t>(nanosec_field);
    return double(sec) + double(nanosec) * 1e-9;
  }

  Header header() {
    Header header;
    header.stamp = stamp("header.stamp.sec", "header.stamp.nanosec");
    header.frame_id = read<std::string>("header.frame_id");
    return header;
  }

  /// A sequence length, refused when even `min_element_size` bytes per
  /// element cannot fit the bytes left.
  std::uint32_t length(const char* field, std::size_t min_element_size) {
    const auto n = read<std::uint32_t>(field);
    const std::size_t left = size_ - cdr_.getSerializedDataLength();
    if (std::uint64_t(n) * min_element_size > left)
      fail(field, "a length of " + std::to_string(n) + " elements (at least " + std::to_string(min_element_size) +
                      " bytes each) but " + std::to_string(left) + " bytes left in the message");
    return n;
  }

  template <typename T>
  void sequence(const char* field, std::vector<T>& into) {
    into.resize(length(field, sizeof(T)));
    if (!into.empty()) guarded(field, [&] { cdr_.deserializeArray(into.data(), into.size()); });
  }

  /// A sequence of `element_size`-byte numbers not kept (their alignment is
  /// that of the length before them: 4 bytes or less).
  void skipSequence(const char* field, std::size_t element_size) {
    const std::uint32_t n = length(field, element_size);
    if (n > 0 && !cdr_.jump(std::size_t(n) * element_size)) fail(field, "the message ends inside it");
  }

  /// A geometry_msgs Point or Vector3 then a Quaternion (x y z w).
  Eigen::Isometry3d pose(const std::string& position, const std::string& orientation) {
    Eigen::Vector3d t;
    for (int k = 0; k < 3; ++k) guarded(position, "xyz"[k], [&] { cdr_.deserialize(t[k]); });
    double q[4];
    for (int k = 0; k < 4; ++k) guarded(orientation, "xyzw"[k], [&] { cdr_.deserialize(q[k]); });
    return checkedRigid(t, Eigen::Quaterniond(q[3], q[0], q[1], q[2]), context_, prefix_ + position,
                        prefix_ + orientation);
  }

  const std::string& context() const { return context_; }

  /// Errors inside a sequence element name it: "transforms[2]." is prepended.
  void setPrefix(std::string prefix) { prefix_ = std::move(prefix); }

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw InputError(context_ + ": field " + prefix_ + field + ": " + what);
  }

 private:
  template <typename Read>
  void guarded(const char* field, Read read) {
    try {
      read();
    } catch (const cdr::exception::Exception& e) {
      fail(field, e.what());
    }
  }

  template <typename Read>
  void guarded(const std::string& field, char member, Read read) {
    try {
      read();
    } catch (const cdr::exception::Exception& e) {
      fail(field + "." + member, e.what());
    }
  }

  const unsigned char* data_;
  std::size_t size_;
  cdr::FastBuffer buffer_;
  cdr::Cdr cdr_;
  const std::string& context_;
  std::string prefix_;
};

Scan decodeScan(CdrReader& in) {
  Scan scan;
  scan.header = in.header();
  scan.angle_min = in.read<float>("angle_min");
  in.read<float>("angle_max");  // implied by angle_min, angle_increment and the ranges
  scan.angle_increment = in.read<float>("angle_increment");
  in.read<float>("time_increment");
  in.read<float>("scan_time");
  scan.range_min = in.read<float>("range_min");
  scan.range_max = in.read<float>("range_max");
  in.sequence("ranges", scan.ranges);
  in.skipSequence("intensities", sizeof(float));
  checkScan(scan, in.context());
  return scan;
}

void readPointFields(CdrReader& in, pcl::PCLPointCloud2& cloud) {
  // name (4-byte length), offset, datatype, count: 13 bytes at least.
  const std::uint32_t n = in.length("fields", 13);
  cloud.fields.resize(n);
  for (std::uint32_t k = 0; k < n; ++k) {
    in.setPrefix("fields[" + std::to_string(k) + "].");
    pcl::PCLPointField& field = cloud.fields[k];
    field.name = in.read<std::string>("name");
    field.offset = in.read<std::uint32_t>("offset");
    field.datatype = in.read<std::uint8_t>("datatype");
    field.count = in.read<std::uint32_t>("count");
    if (pointFieldSize(field.datatype) == 0)
      in.fail("datatype", std::to_string(field.datatype) + " is not a PointField datatype (1 INT8 ... 8 FLOAT64)");
  }
  in.setPrefix("");
}

Cloud decodeCloud(CdrReader& in) {
  Cloud message;
  pcl::PCLPointCloud2& cloud = message.cloud;
  // Seconds and nanoseconds kept whole for PCL's microsecond stamp.
  const auto sec = in.read<std::int32_t>("header.stamp.sec");
  const auto nanosec = in.read<std::uint32_t>("header.stamp.nanosec");
  message.header.stamp = double(sec) + double(nanosec) * 1e-9;
  message.header.frame_id = in.read<std::string>("header.frame_id");
  cloud.header.frame_id = message.header.frame_id;
  if (sec >= 0) cloud.header.stamp = std::uint64_t(sec) * 1000000u + nanosec / 1000u;
  cloud.height = in.read<std::uint32_t>("height");
  cloud.width = in.read<std::uint32_t>("width");
  readPointFields(in, cloud);
  if (in.read<bool>("is_bigendian")) in.fail("is_bigendian", "big-endian point data is not supported");
  cloud.is_bigendian = false;
  cloud.point_step = in.read<std::uint32_t>("point_step");
  cloud.row_step = in.read<std::uint32_t>("row_step");
  in.sequence("data", cloud.data);
  cloud.is_dense = in.read<bool>("is_dense");
  checkCloudLayout(cloud, in.context());
  return message;
}

void decodeTf(CdrReader& in, std::size_t number, std::vector<Numbered<Transform>>& into) {
  // header (sec, nanosec, frame_id length), child_frame_id length, 7 doubles.
  const std::uint32_t n = in.length("transforms", 4 + 4 + 4 + 4 + 7 * 8);
  for (std::uint32_t k = 0; k < n; ++k) {
    in.setPrefix("transforms[" + std::to_string(k) + "].");
    Numbered<Transform>& t = into.emplace_back();
    t.number = number;
    t.message.header = in.header();
    t.message.child_frame_id = in.read<std::string>("child_frame_id");
    t.message.transform = in.pose("transform.translation", "transform.rotation");
  }
  in.setPrefix("");
}

Pose decodeOdometry(CdrReader& in) {
  Pose pose;
  pose.header = in.header();
  pose.child_frame_id = in.read<std::string>("child_frame_id");
  // The covariance and the twist after it are not needed.
  pose.pose = in.pose("pose.pose.position", "pose.pose.orientation");
  return pose;
}

Pose decodePoseStamped(CdrReader& in) {
  Pose pose;
  pose.header = in.header();
  pose.pose = in.pose("pose.position", "pose.orientation");
  return pose;
}

// ---------------------------------------------------------------------------
// SQLite, through small owners of its handles.

struct DatabaseCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
struct StatementFinalizer {
  void operator()(sqlite3_stmt* statement) const { sqlite3_finalize(statement); }
};
using Statement = std::unique_ptr<sqlite3_stmt, StatementFinalizer>;

/// One .db3 file of the bag: its topics as that file numbers them (each
/// split file has its own topics table).
struct Database {
  struct FileTopic {
    std::int64_t id = 0;
    std::string name, type, serialization_format;
    std::size_t messages = 0;
  };

  std::string path;
  std::unique_ptr<sqlite3, DatabaseCloser> db;
  std::vector<FileTopic> topics;

  [[noreturn]] void fail(const std::string& what) const { throw InputError(path + ": " + what); }

  Statement prepare(const char* sql) const {
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db.get(), sql, -1, &statement, nullptr) != SQLITE_OK) {
      const int code = sqlite3_errcode(db.get());
      const std::string message = sqlite3_errmsg(db.get());
      if (code == SQLITE_NOTADB) fail("not an SQLite database (" + message + "): not a ROS 2 bag file");
      fail("not a ROS 2 sqlite3 bag file (" + message + ")");
    }
    return Statement(statement);
  }
};

std::string columnText(sqlite3_stmt* statement, int column) {
  const unsigned char* text = sqlite3_column_text(statement, column);
  return text ? reinterpret_cast<const char*>(text) : "";
}

Database openDatabase(const std::string& path) {
  Database database;
  database.path = path;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) database.fail("no such file (listed in the bag's metadata.yaml)");
  sqlite3* db = nullptr;
  const int status = sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
  database.db.reset(db);
  if (status != SQLITE_OK)
    database.fail(std::string("cannot be opened (") + (db ? sqlite3_errmsg(db) : sqlite3_errstr(status)) + ")");
  // The messages table is named here too so that a file without it is
  // refused now, not when the first message is read.
  const Statement statement = database.prepare(
      "SELECT topics.id, topics.name, topics.type, topics.serialization_format, COUNT(messages.id) "
      "FROM topics LEFT JOIN messages ON messages.topic_id = topics.id GROUP BY topics.id ORDER BY topics.id");
  int step;
  while ((step = sqlite3_step(statement.get())) == SQLITE_ROW) {
    Database::FileTopic& topic = database.topics.emplace_back();
    topic.id = sqlite3_column_int64(statement.get(), 0);
    topic.name = columnText(statement.get(), 1);
    topic.type = columnText(statement.get(), 2);
    topic.serialization_format = columnText(statement.get(), 3);
    topic.messages = std::size_t(sqlite3_column_int64(statement.get(), 4));
  }
  if (step != SQLITE_DONE) database.fail(std::string("reading its topics: ") + sqlite3_errmsg(database.db.get()));
  return database;
}

// ---------------------------------------------------------------------------
// metadata.yaml, read line by line for the two keys needed: no YAML library
// for a file rosbag2 always writes the same way.

struct Metadata {
  bool found = false;
  std::string storage;
  std::string compression;
  std::vector<std::string> files;
};

std::string trimmed(std::string text) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!text.empty() && space(text.back())) text.pop_back();
  std::size_t start = 0;
  while (start < text.size() && space(text[start])) ++start;
  text.erase(0, start);
  if (text.size() >= 2 && (text[0] == '"' || text[0] == '\'') && text.back() == text[0])
    text = text.substr(1, text.size() - 2);
  return text;
}

/// The value of "key: value" on this line (trimmed, unquoted), if the key is it.
std::optional<std::string> valueOf(const std::string& line, const std::string& key) {
  const std::string text = trimmed(line);
  if (text.compare(0, key.size() + 1, key + ":") != 0) return std::nullopt;
  return trimmed(text.substr(key.size() + 1));
}

/// "[a.db3, b.db3]", the flow spelling of a list.
std::vector<std::string> flowList(const std::string& value) {
  std::vector<std::string> items;
  std::string inner = value.substr(1, value.find(']') == std::string::npos ? std::string::npos : value.find(']') - 1);
  for (std::size_t start = 0; start <= inner.size();) {
    std::size_t comma = inner.find(',', start);
    if (comma == std::string::npos) comma = inner.size();
    const std::string item = trimmed(inner.substr(start, comma - start));
    if (!item.empty()) items.push_back(item);
    start = comma + 1;
  }
  return items;
}

Metadata readMetadata(const fs::path& folder) {
  Metadata metadata;
  std::ifstream in(folder / "metadata.yaml");
  if (!in) return metadata;
  metadata.found = true;
  std::string line;
  bool in_files = false;
  while (std::getline(in, line)) {
    const std::string text = trimmed(line);
    if (in_files && text.size() >= 2 && text[0] == '-' && text[1] == ' ') {
      metadata.files.push_back(trimmed(text.substr(2)));
      continue;
    }
    in_files = false;
    if (auto value = valueOf(line, "storage_identifier")) metadata.storage = *value;
    if (auto value = valueOf(line, "compression_format")) metadata.compression = *value;
    if (auto value = valueOf(line, "relative_file_paths")) {
      if (!value->empty() && (*value)[0] == '[')
        metadata.files = flowList(*value);
      else
        in_files = true;
    }
  }
  return metadata;
}

/// The bag's .db3 files, in the order metadata.yaml lists them (time order).
std::vector<std::string> bagFiles(const std::string& folder) {
  const fs::path path(folder);
  std::error_code ec;
  if (fs::is_regular_file(path, ec) && path.extension() == ".db3") return {folder};  // one file given alone
  if (!fs::is_directory(path, ec)) throw InputError(folder + ": no such folder (a ROS 2 bag is a folder)");
  const Metadata metadata = readMetadata(path);
  const auto isMcap = [](const std::string& file) { return fs::path(file).extension() == ".mcap"; };
  if (metadata.storage == "mcap" || std::any_of(metadata.files.begin(), metadata.files.end(), isMcap))
    throw InputError(folder + ": MCAP storage is not supported (Debian ships no MCAP library); " + kConvertToSqlite);
  if (!metadata.storage.empty() && metadata.storage != "sqlite3")
    throw InputError(folder + ": storage '" + metadata.storage + "' is not supported (only sqlite3)");
  if (!metadata.compression.empty())
    throw InputError(folder + ": compressed bags (" + metadata.compression +
                     ") are not supported; decompress with `ros2 bag convert`");
  std::vector<std::string> files;
  for (const std::string& name : metadata.files) {
    // Early rosbag2 versions wrote the paths with the bag folder's name in front.
    const fs::path listed = path / name;
    files.push_back(fs::exists(listed, ec) ? listed.string() : (path / fs::path(name).filename()).string());
  }
  if (files.empty()) files = filesWithExtension(path.string(), ".db3");  // natural order: bag_2 before bag_10
  if (files.empty())
    throw InputError(folder + (metadata.found ? ": metadata.yaml lists no file and the folder has no .db3 file"
                                              : ": no metadata.yaml and no .db3 file: not a ROS 2 bag"));
  return files;
}

// ---------------------------------------------------------------------------
// The bag: its files and its topics merged across them.

struct Bag {
  std::string folder;
  std::vector<Database> files;
  std::vector<Topic> topics;  ///< by name
  std::map<std::string, std::string> formats;  ///< serialization_format by topic
};

Bag openBag(const std::string& folder) {
  Bag bag;
  bag.folder = folder;
  for (const std::string& file : bagFiles(folder)) bag.files.push_back(openDatabase(file));
  std::map<std::string, Topic> topics;
  for (const Database& file : bag.files)
    for (const Database::FileTopic& entry : file.topics) {
      Topic& topic = topics[entry.name];
      const std::string type = ros1Spelling(entry.type);
      if (topic.name.empty()) {
        topic.name = entry.name;
        topic.type = type;
        bag.formats[entry.name] = entry.serialization_format;
      } else if (topic.type != type) {
        throw InputError(file.path + ": topic " + entry.name + " has type " + type + ", " + topic.type +
                         " in an earlier file of the bag");
      }
      topic.messages += entry.messages;
    }
  for (auto& [name, topic] : topics) bag.topics.push_back(std::move(topic));
  return bag;
}

std::string topicList(const Bag& bag) {
  if (bag.topics.empty()) return "none";
  std::string list;
  for (const Topic& topic : bag.topics)
    list += (list.empty() ? "" : ", ") + topic.name + " (" + topic.type + ", " + std::to_string(topic.messages) +
            " messages)";
  return list;
}

const Topic* findTopic(const Bag& bag, const std::string& name) {
  for (const Topic& topic : bag.topics)
    if (topic.name == name) return &topic;
  return nullptr;
}

/// One file's messages of a topic, in (timestamp, id) order.
struct Cursor {
  const Database* file = nullptr;
  Statement statement;
  bool row = false;
  std::int64_t timestamp = 0;

  void step(const std::string& topic) {
    const int status = sqlite3_step(statement.get());
    row = status == SQLITE_ROW;
    if (row)
      timestamp = sqlite3_column_int64(statement.get(), 0);
    else if (status != SQLITE_DONE)
      file->fail("reading the messages of " + topic + ": " + sqlite3_errmsg(file->db.get()));
  }
};

/// Decodes every message of `topic` in time order across the files: each
/// file is in order already, so their cursors are merged (on equal
/// timestamps the earlier file first).
void readTopic(const Bag& bag, const Topic& topic, Role role, Messages& into) {
  if (!roleAccepts(role, topic.type))
    throw InputError(bag.folder + ": topic " + topic.name + " is a " + topic.type + ", not the " + typesOfRole(role) +
                     " its use as the " + roleName(role) + " topic needs");
  const std::string& format = bag.formats.at(topic.name);
  if (format != "cdr")
    throw InputError(bag.folder + ": topic " + topic.name + " is serialised as '" + format + "', not 'cdr'");
  if (role == Role::Data && topic.type == kLaserScanType) into.scans.reserve(into.scans.size() + topic.messages);
  if (role == Role::Data && topic.type == kPointCloud2Type) into.clouds.reserve(into.clouds.size() + topic.messages);
  if (role == Role::Pose) into.poses.reserve(into.poses.size() + topic.messages);
  // A TFMessage holds one transform or a few: room for one each, the vector
  // grows geometrically past that.
  if (role == Role::Tf) into.tf.reserve(into.tf.size() + topic.messages);
  if (role == Role::TfStatic) into.tf_static.reserve(into.tf_static.size() + topic.messages);

  std::vector<Cursor> cursors;
  for (const Database& file : bag.files)
    for (const Database::FileTopic& entry : file.topics) {
      if (entry.name != topic.name || entry.messages == 0) continue;
      Cursor& cursor = cursors.emplace_back();
      cursor.file = &file;
      cursor.statement =
          file.prepare("SELECT timestamp, data FROM messages WHERE topic_id = ?1 ORDER BY timestamp, id");
      sqlite3_bind_int64(cursor.statement.get(), 1, entry.id);
      cursor.step(topic.name);
    }
  const std::string where = bag.folder + ": message ";
  const std::string what = " on " + topic.name + " (" + topic.type + ")";
  for (std::size_t number = 1;; ++number) {
    Cursor* next = nullptr;
    for (Cursor& cursor : cursors)
      if (cursor.row && (!next || cursor.timestamp < next->timestamp)) next = &cursor;
    if (!next) break;
    // The blob is SQLite's until the next step: decoded right here.
    const void* blob = sqlite3_column_blob(next->statement.get(), 1);
    const int size = sqlite3_column_bytes(next->statement.get(), 1);
    decodeRos2Message(topic.type, role, static_cast<const unsigned char*>(blob), std::size_t(size),
                      where + std::to_string(number) + what, number, into);
    next->step(topic.name);
  }
}

}  // namespace

void decodeRos2Message(const std::string& type_name, Role role, const unsigned char* data, std::size_t size,
                       const std::string& context, std::size_t number, Messages& into) {
  const std::string type = ros1Spelling(type_name);
  if (!roleAccepts(role, type))
    throw InputError(context + ": a " + type + " cannot be read as the " + roleName(role) + " topic (expected " +
                     typesOfRole(role) + ")");
  CdrReader in(data, size, context);
  in.readEncapsulation();
  if (type == kLaserScanType) {
    into.scans.push_back({number, decodeScan(in)});
  } else if (type == kPointCloud2Type) {
    into.clouds.push_back({number, decodeCloud(in)});
    keepReduced(into.clouds.back().message, into.reduce_clouds);
  } else if (type == kTfType) {
    decodeTf(in, number, role == Role::TfStatic ? into.tf_static : into.tf);
  } else if (type == kOdometryType) {
    into.poses.push_back({number, decodeOdometry(in)});
  } else {
    into.poses.push_back({number, decodePoseStamped(in)});
  }
}

std::vector<Topic> listRos2Topics(const std::string& folder) { return openBag(folder).topics; }

Messages readRos2Messages(const std::string& folder, const Request& request) {
  const Bag bag = openBag(folder);
  const auto required = [&](const std::string& name) -> const Topic& {
    const Topic* topic = findTopic(bag, name);
    if (!topic) throw InputError(folder + ": no topic " + name + " in the bag; its topics: " + topicList(bag));
    return *topic;
  };
  Messages messages;
  messages.reduce_clouds = request.reduction;
  readTopic(bag, required(request.data_topic), Role::Data, messages);
  if (request.pose_topic) readTopic(bag, required(*request.pose_topic), Role::Pose, messages);
  if (!request.tf) return messages;
  if (const Topic* tf = findTopic(bag, "/tf")) readTopic(bag, *tf, Role::Tf, messages);
  if (const Topic* tf_static = findTopic(bag, "/tf_static")) readTopic(bag, *tf_static, Role::TfStatic, messages);
  return messages;
}

#else  // built without SQLite or Fast CDR

namespace {
InputError notBuilt(const std::string& path) {
  return InputError(path + ": obsgroup was built without ROS 2 bag support (libsqlite3-dev, libfastcdr-dev)");
}
}  // namespace

void decodeRos2Message(const std::string&, Role, const unsigned char*, std::size_t, const std::string& context,
                       std::size_t, Messages&) {
  throw notBuilt(context);
}

std::vector<Topic> listRos2Topics(const std::string& folder) { throw notBuilt(folder); }

Messages readRos2Messages(const std::string& folder, const Request&) { throw notBuilt(folder); }

#endif

}  // namespace obsgroup::io::bag
