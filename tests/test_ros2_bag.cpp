// The ROS 2 bag backend (sqlite3 storage, CDR) on bags written by
// ros2_bag_writer.h: listing, reading in time order across files, and the
// errors on bags and messages it cannot read.
#include "bag_messages.h"
#include "temp_folder.h"

#include <obsgroup/io/errors.h>

#include <gtest/gtest.h>

#include <string>

using obsgroup::io::InputError;
namespace bag = obsgroup::io::bag;

/// `text` contains `part` (shown in full when not).
#define EXPECT_CONTAINS(text, part)                                        \
  do {                                                                     \
    const std::string text_ = (text);                                      \
    EXPECT_NE(text_.find(part), std::string::npos) << "'" << text_ << "'"; \
  } while (false)

/// The InputError message `run` throws ("" if none).
template <typename Run>
std::string inputErrorOf(Run run) {
  try {
    run();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#ifdef OBSGROUP_HAVE_ROS2

#include "ros2_bag_writer.h"

#include <cmath>
#include <cstring>
#include <fstream>

namespace {

using obsgroup::test::Ros2BagWriter;

bag::Scan makeScan(double stamp, std::size_t beams, float first_range = 1.0f) {
  bag::Scan scan;
  scan.header = {stamp, "laser"};
  scan.angle_min = -1.5;
  scan.angle_increment = 0.25;
  scan.range_min = 0.1;
  scan.range_max = 30.0;
  for (std::size_t k = 0; k < beams; ++k) scan.ranges.push_back(first_range + 0.5f * float(k));
  return scan;
}

void addField(pcl::PCLPointCloud2& cloud, const std::string& name, std::uint32_t offset, std::uint8_t datatype) {
  pcl::PCLPointField field;
  field.name = name;
  field.offset = offset;
  field.datatype = datatype;
  field.count = 1;
  cloud.fields.push_back(field);
}

/// width x height points of float32 x y z (12 bytes each).
bag::Cloud makeCloud(double stamp, std::uint32_t width, std::uint32_t height) {
  bag::Cloud message;
  message.header = {stamp, "velodyne"};
  pcl::PCLPointCloud2& cloud = message.cloud;
  cloud.width = width;
  cloud.height = height;
  addField(cloud, "x", 0, pcl::PCLPointField::FLOAT32);
  addField(cloud, "y", 4, pcl::PCLPointField::FLOAT32);
  addField(cloud, "z", 8, pcl::PCLPointField::FLOAT32);
  cloud.point_step = 12;
  cloud.row_step = 12 * width;
  cloud.is_dense = 1;
  for (std::uint32_t k = 0; k < width * height * 3; ++k) {
    const float v = 0.5f * float(k);
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(&v);
    cloud.data.insert(cloud.data.end(), bytes, bytes + 4);
  }
  return message;
}

Eigen::Isometry3d makePose(double x, double y, double yaw) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(x, y, 0.25);
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return pose;
}

bag::Pose poseMessage(double stamp, const std::string& frame, const std::string& child, const Eigen::Isometry3d& pose) {
  bag::Pose message;
  message.header.stamp = stamp;
  message.header.frame_id = frame;
  message.child_frame_id = child;
  message.pose = pose;
  return message;
}

bag::Transform makeTransform(double stamp, const std::string& parent, const std::string& child,
                             const Eigen::Isometry3d& pose) {
  bag::Transform t;
  t.header = {stamp, parent};
  t.child_frame_id = child;
  t.transform = pose;
  return t;
}

bag::Messages decode(const std::string& type, bag::Role role, const Ros2BagWriter::Bytes& bytes) {
  bag::Messages into;
  bag::decodeRos2Message(type, role, bytes.data(), bytes.size(), "ctx", 7, into);
  return into;
}

/// The ranges of an n-beam scan start after its length, 4 bytes before
/// them; the intensities' empty length closes the message.
std::size_t rangesLengthOffset(const Ros2BagWriter::Bytes& scan, std::size_t beams) {
  return scan.size() - 4 - 4 * beams - 4;
}

void expectNear(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  EXPECT_TRUE(a.isApprox(b, 1e-9)) << a.matrix() << "\nvs\n" << b.matrix();
}

class Ros2BagTest : public obsgroup::test::TempFolderTest {
 protected:
  std::string bagPath() const { return (dir_ / "bag").string(); }
};

// ---------------------------------------------------------------------------
// Round trips

TEST_F(Ros2BagTest, ScansRoundTripInTimeOrderWithTopicsListedInRos1Spelling) {
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/scan", makeScan(12.5, 5, 2.0f));
    writer.write("/scan", makeScan(10.25, 3, 1.0f));  // written later, earlier in time
    writer.write("/scan", makeScan(11.0, 4, 3.0f));
    writer.write("/odom", poseMessage(10.0, "odom", "base_link", makePose(1, 2, 0.5)), true);
  }
  const std::vector<bag::Topic> topics = bag::listRos2Topics(bagPath());
  ASSERT_EQ(topics.size(), 2u);
  EXPECT_EQ(topics[0].name, "/odom");
  EXPECT_EQ(topics[0].type, "nav_msgs/Odometry");
  EXPECT_EQ(topics[0].messages, 1u);
  EXPECT_EQ(topics[1].name, "/scan");
  EXPECT_EQ(topics[1].type, "sensor_msgs/LaserScan");
  EXPECT_EQ(topics[1].messages, 3u);

  const bag::Messages messages = bag::readRos2Messages(bagPath(), {"/scan", std::nullopt});
  ASSERT_EQ(messages.scans.size(), 3u);
  EXPECT_TRUE(messages.clouds.empty() && messages.poses.empty() && messages.tf.empty());
  const double stamps[] = {10.25, 11.0, 12.5};
  const std::size_t beams[] = {3, 4, 5};
  for (std::size_t k = 0; k < 3; ++k) {
    const bag::Scan& scan = messages.scans[k].message;
    EXPECT_EQ(messages.scans[k].number, k + 1);
    EXPECT_NEAR(scan.header.stamp, stamps[k], 1e-9);
    EXPECT_EQ(scan.header.frame_id, "laser");
    EXPECT_FLOAT_EQ(float(scan.angle_min), -1.5f);
    EXPECT_FLOAT_EQ(float(scan.angle_increment), 0.25f);
    EXPECT_FLOAT_EQ(float(scan.range_min), 0.1f);
    EXPECT_FLOAT_EQ(float(scan.range_max), 30.0f);
    EXPECT_EQ(scan.ranges.size(), beams[k]);
  }
  EXPECT_FLOAT_EQ(messages.scans[0].message.ranges[2], 2.0f);
  EXPECT_FLOAT_EQ(messages.scans[2].message.ranges[0], 2.0f);
}

TEST_F(Ros2BagTest, EqualTimestampsKeepTheirWritingOrder) {
  {
    Ros2BagWriter writer(bagPath());
    for (int k = 0; k < 4; ++k) writer.write("/scan", makeScan(5.0, 2, float(k)));
  }
  const bag::Messages messages = bag::readRos2Messages(bagPath(), {"/scan", std::nullopt});
  ASSERT_EQ(messages.scans.size(), 4u);
  for (int k = 0; k < 4; ++k) EXPECT_FLOAT_EQ(messages.scans[k].message.ranges[0], float(k));
}

TEST_F(Ros2BagTest, PointCloud2RoundTrip) {
  bag::Cloud written = makeCloud(3.000001, 3, 2);
  addField(written.cloud, "intensity", 12, pcl::PCLPointField::UINT8);
  written.cloud.point_step = 16;
  written.cloud.row_step = 16 * 3 + 4;  // rows padded
  written.cloud.data.assign(written.cloud.row_step * 2, 0);
  for (std::size_t k = 0; k < written.cloud.data.size(); ++k) written.cloud.data[k] = std::uint8_t(k * 7);
  written.cloud.is_dense = 0;
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/points", written);
  }
  const bag::Messages messages = bag::readRos2Messages(bagPath(), {"/points", std::nullopt});
  ASSERT_EQ(messages.clouds.size(), 1u);
  EXPECT_EQ(messages.clouds[0].number, 1u);
  const bag::Cloud& read = messages.clouds[0].message;
  EXPECT_NEAR(read.header.stamp, 3.000001, 1e-9);
  EXPECT_EQ(read.header.frame_id, "velodyne");
  const pcl::PCLPointCloud2& cloud = read.cloud;
  EXPECT_EQ(cloud.header.frame_id, "velodyne");
  EXPECT_EQ(cloud.header.stamp, 3000001u);  // microseconds
  EXPECT_EQ(cloud.width, 3u);
  EXPECT_EQ(cloud.height, 2u);
  EXPECT_EQ(cloud.point_step, 16u);
  EXPECT_EQ(cloud.row_step, 52u);
  EXPECT_EQ(cloud.is_bigendian, 0);
  EXPECT_EQ(cloud.is_dense, 0);
  EXPECT_EQ(cloud.data, written.cloud.data);
  ASSERT_EQ(cloud.fields.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(cloud.fields[k].name, written.cloud.fields[k].name);
    EXPECT_EQ(cloud.fields[k].offset, written.cloud.fields[k].offset);
    EXPECT_EQ(cloud.fields[k].datatype, written.cloud.fields[k].datatype);
    EXPECT_EQ(cloud.fields[k].count, 1u);
  }
}

TEST_F(Ros2BagTest, TfAndTfStaticEachTransformNumberedByItsMessage) {
  const Eigen::Isometry3d a = makePose(1, 2, 0.3), b = makePose(-4, 0.5, -2.0), c = makePose(0.1, 0, 0);
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/scan", makeScan(1.0, 2));
    writer.writeTf("/tf", {makeTransform(2.0, "odom", "base_link", b)});
    writer.writeTf("/tf", {makeTransform(1.0, "map", "odom", a), makeTransform(1.0, "odom", "base_link", b)});
    writer.writeTf("/tf_static", {makeTransform(0.0, "base_link", "laser", c)});
  }
  const bag::Messages messages = bag::readRos2Messages(bagPath(), {"/scan", std::nullopt});
  ASSERT_EQ(messages.tf.size(), 3u);
  EXPECT_EQ(messages.tf[0].number, 1u);
  EXPECT_EQ(messages.tf[1].number, 1u);
  EXPECT_EQ(messages.tf[2].number, 2u);
  EXPECT_EQ(messages.tf[0].message.header.frame_id, "map");
  EXPECT_EQ(messages.tf[0].message.child_frame_id, "odom");
  EXPECT_NEAR(messages.tf[0].message.header.stamp, 1.0, 1e-12);
  expectNear(messages.tf[0].message.transform, a);
  EXPECT_EQ(messages.tf[1].message.child_frame_id, "base_link");
  expectNear(messages.tf[1].message.transform, b);
  EXPECT_NEAR(messages.tf[2].message.header.stamp, 2.0, 1e-12);
  ASSERT_EQ(messages.tf_static.size(), 1u);
  EXPECT_EQ(messages.tf_static[0].number, 1u);
  EXPECT_EQ(messages.tf_static[0].message.header.frame_id, "base_link");
  EXPECT_EQ(messages.tf_static[0].message.child_frame_id, "laser");
  expectNear(messages.tf_static[0].message.transform, c);
}

TEST_F(Ros2BagTest, OdometryAndPoseStampedRoundTrip) {
  const Eigen::Isometry3d p = makePose(3, -1, 1.2), q = makePose(0, 7, -0.4);
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/scan", makeScan(1.0, 2));
    writer.write("/odom", poseMessage(1.5, "odom", "base_footprint", p), true);
    writer.write("/pose", poseMessage(2.5, "map", "", q), false);
  }
  EXPECT_EQ(bag::listRos2Topics(bagPath())[1].type, "geometry_msgs/PoseStamped");
  const bag::Messages odometry = bag::readRos2Messages(bagPath(), {"/scan", std::string("/odom")});
  ASSERT_EQ(odometry.poses.size(), 1u);
  EXPECT_EQ(odometry.poses[0].number, 1u);
  EXPECT_NEAR(odometry.poses[0].message.header.stamp, 1.5, 1e-12);
  EXPECT_EQ(odometry.poses[0].message.header.frame_id, "odom");
  EXPECT_EQ(odometry.poses[0].message.child_frame_id, "base_footprint");
  expectNear(odometry.poses[0].message.pose, p);

  const bag::Messages stamped = bag::readRos2Messages(bagPath(), {"/scan", std::string("/pose")});
  ASSERT_EQ(stamped.poses.size(), 1u);
  EXPECT_EQ(stamped.poses[0].message.header.frame_id, "map");
  EXPECT_EQ(stamped.poses[0].message.child_frame_id, "");
  expectNear(stamped.poses[0].message.pose, q);
}

TEST_F(Ros2BagTest, QuaternionsAreNormalised) {
  const auto bytes = Ros2BagWriter::serialized([](eprosima::fastcdr::Cdr& cdr) {
    Ros2BagWriter::header(cdr, {1.0, "map"});
    cdr << 1.0 << 2.0 << 3.0 << 0.0 << 0.0 << 0.0 << 2.0;  // position, orientation x y z w
  });
  const bag::Messages messages = decode("geometry_msgs/msg/PoseStamped", bag::Role::Pose, bytes);
  ASSERT_EQ(messages.poses.size(), 1u);
  EXPECT_EQ(messages.poses[0].number, 7u);
  EXPECT_TRUE(messages.poses[0].message.pose.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_TRUE(messages.poses[0].message.pose.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
}

TEST_F(Ros2BagTest, BigEndianCdrIsRead) {
  const bag::Scan scan = makeScan(4.5, 3);
  const auto bytes = Ros2BagWriter::serialized(
      [&](eprosima::fastcdr::Cdr& cdr) {
        Ros2BagWriter::header(cdr, scan.header);
        cdr << -1.5f << 0.0f << 0.25f << 0.0f << 0.0f << 0.1f << 30.0f << std::uint32_t(3);
        cdr.serializeArray(scan.ranges.data(), 3);
        cdr << std::uint32_t(0);
      },
      eprosima::fastcdr::Cdr::BIG_ENDIANNESS);
  ASSERT_EQ(bytes[1], 0);  // the big-endian encapsulation
  const bag::Messages messages = decode("sensor_msgs/LaserScan", bag::Role::Data, bytes);
  ASSERT_EQ(messages.scans.size(), 1u);
  EXPECT_NEAR(messages.scans[0].message.header.stamp, 4.5, 1e-12);
  EXPECT_EQ(messages.scans[0].message.ranges, scan.ranges);
}

TEST_F(Ros2BagTest, SplitFilesAreMergedInTimeOrder) {
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/scan", makeScan(1.0, 1, 1.0f));
    writer.write("/scan", makeScan(3.0, 1, 3.0f));
    writer.writeTf("/tf", {makeTransform(1.0, "map", "laser", makePose(0, 0, 0))});
    writer.split();
    writer.write("/scan", makeScan(2.0, 1, 2.0f));  // a late write in the second file
    writer.write("/scan", makeScan(4.0, 1, 4.0f));
    writer.split();
    writer.writeTf("/tf", {makeTransform(5.0, "map", "laser", makePose(1, 0, 0))});
  }
  ASSERT_TRUE(std::filesystem::exists(dir_ / "bag" / "bag_2.db3"));
  const std::vector<bag::Topic> topics = bag::listRos2Topics(bagPath());
  ASSERT_EQ(topics.size(), 2u);
  EXPECT_EQ(topics[0].messages, 4u);
  EXPECT_EQ(topics[1].name, "/tf");
  EXPECT_EQ(topics[1].messages, 2u);
  const bag::Messages messages = bag::readRos2Messages(bagPath(), {"/scan", std::nullopt});
  ASSERT_EQ(messages.scans.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(messages.scans[k].number, k + 1);
    EXPECT_FLOAT_EQ(messages.scans[k].message.ranges[0], float(k + 1));
  }
  ASSERT_EQ(messages.tf.size(), 2u);
  EXPECT_EQ(messages.tf[1].number, 2u);
  EXPECT_NEAR(messages.tf[1].message.header.stamp, 5.0, 1e-12);
}

TEST_F(Ros2BagTest, MetadataWithoutFilesFallsBackToTheFoldersDb3Files) {
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/scan", makeScan(1.0, 1, 1.0f));
    writer.split();
    writer.write("/scan", makeScan(2.0, 1, 2.0f));
  }
  std::ofstream(dir_ / "bag" / "metadata.yaml") << "rosbag2_bagfile_information:\n  version: 4\n"
                                                   "  storage_identifier: sqlite3\n  relative_file_paths: []\n";
  const bag::Messages messages = bag::readRos2Messages(bagPath(), {"/scan", std::nullopt});
  ASSERT_EQ(messages.scans.size(), 2u);
  EXPECT_FLOAT_EQ(messages.scans[1].message.ranges[0], 2.0f);
}

TEST_F(Ros2BagTest, McapStorageIsRefused) {
  std::filesystem::create_directories(dir_ / "bag");
  std::ofstream(dir_ / "bag" / "metadata.yaml") << "rosbag2_bagfile_information:\n  version: 8\n"
                                                   "  storage_identifier: mcap\n  relative_file_paths:\n"
                                                   "    - bag_0.mcap\n";
  const std::string error = inputErrorOf([&] { bag::listRos2Topics(bagPath()); });
  EXPECT_CONTAINS(error, "MCAP storage is not supported");
  EXPECT_CONTAINS(error, "ros2 bag convert");
}

TEST_F(Ros2BagTest, AMissingTopicListsTheTopicsPresent) {
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/scan", makeScan(1.0, 1));
    writer.writeTf("/tf", {makeTransform(1.0, "map", "laser", makePose(0, 0, 0))});
  }
  const std::string error = inputErrorOf([&] { bag::readRos2Messages(bagPath(), {"/points", std::nullopt}); });
  EXPECT_CONTAINS(error, "no topic /points");
  EXPECT_CONTAINS(error, "/scan (sensor_msgs/LaserScan, 1 messages)");
  EXPECT_CONTAINS(error, "/tf (tf2_msgs/TFMessage");
  const std::string pose_error =
      inputErrorOf([&] { bag::readRos2Messages(bagPath(), {"/scan", std::string("/odom")}); });
  EXPECT_CONTAINS(pose_error, "no topic /odom");
}

TEST_F(Ros2BagTest, AFileThatIsNotADatabaseIsNamed) {
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/scan", makeScan(1.0, 1));
  }
  const std::string db3 = (dir_ / "bag" / "bag_0.db3").string();
  std::ofstream(db3, std::ios::trunc) << "this is not an SQLite file, just some text long enough to be looked at\n";
  const std::string error = inputErrorOf([&] { bag::listRos2Topics(bagPath()); });
  EXPECT_CONTAINS(error, db3 + ": not an SQLite database");
}

TEST_F(Ros2BagTest, ADatabaseWithoutTheBagTablesIsNamed) {
  std::filesystem::create_directories(dir_ / "bag");
  const std::string db3 = (dir_ / "bag" / "other.db3").string();
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(db3.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "CREATE TABLE things(id INTEGER PRIMARY KEY, name TEXT);", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  const std::string error = inputErrorOf([&] { bag::listRos2Topics(bagPath()); });
  EXPECT_CONTAINS(error, db3 + ": not a ROS 2 sqlite3 bag file");
  EXPECT_CONTAINS(error, "topics");
}

TEST_F(Ros2BagTest, AFolderWithoutBagFilesIsRefused) {
  std::filesystem::create_directories(dir_ / "bag");
  EXPECT_CONTAINS(inputErrorOf([&] { bag::listRos2Topics(bagPath()); }), "not a ROS 2 bag");
  EXPECT_CONTAINS(inputErrorOf([&] { bag::listRos2Topics((dir_ / "nothing").string()); }), "no such folder");
}

TEST_F(Ros2BagTest, AListedFileThatIsMissingIsNamed) {
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/scan", makeScan(1.0, 1));
    writer.split();
    writer.write("/scan", makeScan(2.0, 1));
  }
  std::filesystem::remove(dir_ / "bag" / "bag_1.db3");
  EXPECT_CONTAINS(inputErrorOf([&] { bag::listRos2Topics(bagPath()); }), "bag_1.db3: no such file");
}

TEST_F(Ros2BagTest, CompressedBagsAreRefused) {
  std::filesystem::create_directories(dir_ / "bag");
  std::ofstream(dir_ / "bag" / "metadata.yaml")
      << "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  compression_format: zstd\n"
         "  compression_mode: FILE\n  relative_file_paths:\n    - bag_0.db3.zstd\n";
  EXPECT_CONTAINS(inputErrorOf([&] { bag::listRos2Topics(bagPath()); }), "compressed bags (zstd)");
}

// ---------------------------------------------------------------------------
// Messages that cannot be read

TEST_F(Ros2BagTest, ATruncatedMessageNamesItsNumberTopicAndField) {
  const auto full = Ros2BagWriter::serialize(makeScan(2.0, 10));
  const Ros2BagWriter::Bytes cut(full.begin(), full.end() - 4 - 20);  // inside the ranges
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/scan", makeScan(1.0, 10));
    writer.writeRaw("/scan", "sensor_msgs/msg/LaserScan", 2'000'000'000, cut);
  }
  const std::string error = inputErrorOf([&] { bag::readRos2Messages(bagPath(), {"/scan", std::nullopt}); });
  EXPECT_CONTAINS(error, bagPath() + ": message 2 on /scan (sensor_msgs/LaserScan): field ranges: ");
}

TEST_F(Ros2BagTest, EveryCutOfEveryMessageIsAnInputErrorNamingAField) {
  bag::Cloud cloud = makeCloud(1.0, 2, 1);
  const Ros2BagWriter::Bytes messages[] = {
      Ros2BagWriter::serialize(makeScan(1.0, 3)),
      Ros2BagWriter::serialize(cloud),
      Ros2BagWriter::serialize({makeTransform(1.0, "map", "odom", makePose(1, 2, 3))}),
      Ros2BagWriter::serialize(poseMessage(1.0, "odom", "base", makePose(1, 2, 3)), true),
      Ros2BagWriter::serialize(poseMessage(1.0, "odom", "", makePose(1, 2, 3)), false)};
  const char* types[] = {"sensor_msgs/LaserScan", "sensor_msgs/PointCloud2", "tf2_msgs/TFMessage",
                         "nav_msgs/Odometry", "geometry_msgs/PoseStamped"};
  const bag::Role roles[] = {bag::Role::Data, bag::Role::Data, bag::Role::Tf, bag::Role::Pose, bag::Role::Pose};
  for (int m = 0; m < 5; ++m) {
    std::size_t needed = messages[m].size();
    if (m == 3) needed = 4 + 4 + 4 + 4 + 5 + 3 + 4 + 5 + 3 + 7 * 8;  // Odometry: read up to its pose
    EXPECT_NO_THROW(decode(types[m], roles[m], messages[m])) << types[m];
    for (std::size_t size = 0; size < needed; ++size) {
      const Ros2BagWriter::Bytes cut(messages[m].begin(), messages[m].begin() + std::ptrdiff_t(size));
      const std::string error = inputErrorOf([&] { decode(types[m], roles[m], cut); });
      EXPECT_EQ(error.rfind("ctx: field ", 0), 0u) << types[m] << " cut to " << size << " bytes: '" << error << "'";
    }
  }
}

TEST_F(Ros2BagTest, ASequenceLengthBeyondTheDataIsRefusedBeforeAllocating) {
  auto bytes = Ros2BagWriter::serialize(makeScan(1.0, 4));
  const std::uint32_t huge = 0xFFFFFFF0u;
  std::memcpy(bytes.data() + rangesLengthOffset(bytes, 4), &huge, 4);
  const std::string error = inputErrorOf([&] { decode("sensor_msgs/LaserScan", bag::Role::Data, bytes); });
  EXPECT_CONTAINS(error, "ctx: field ranges: a length of 4294967280 elements");

  auto tf = Ros2BagWriter::serialize({makeTransform(1.0, "map", "odom", makePose(1, 2, 3))});
  std::memcpy(tf.data() + 4, &huge, 4);
  EXPECT_CONTAINS(inputErrorOf([&] { decode("tf2_msgs/TFMessage", bag::Role::Tf, tf); }), "field transforms: a length of");

  auto cloud = Ros2BagWriter::serialize(makeCloud(1.0, 1, 1));
  const std::uint32_t data_length = 12;
  const auto at = std::search(cloud.begin(), cloud.end(), reinterpret_cast<const unsigned char*>(&data_length),
                              reinterpret_cast<const unsigned char*>(&data_length) + 4);
  // point_step 12, row_step 12, then the data's length 12: the third 12.
  auto data = std::search(at + 4, cloud.end(), at, at + 4);
  data = std::search(data + 4, cloud.end(), at, at + 4);
  ASSERT_NE(data, cloud.end());
  std::memcpy(&*data, &huge, 4);
  EXPECT_CONTAINS(inputErrorOf([&] { decode("sensor_msgs/PointCloud2", bag::Role::Data, cloud); }), "field data: a length of 4294967280");
}

TEST_F(Ros2BagTest, AnIntensitiesLengthBeyondTheDataIsRefused) {
  auto bytes = Ros2BagWriter::serialize(makeScan(1.0, 2));
  const std::uint32_t length = 3;
  std::memcpy(bytes.data() + bytes.size() - 4, &length, 4);
  EXPECT_CONTAINS(inputErrorOf([&] { decode("sensor_msgs/LaserScan", bag::Role::Data, bytes); }), "field intensities: a length of 3");
}

TEST_F(Ros2BagTest, PointCloudLayoutsThatDoNotFitTheirDataAreRefused) {
  const auto errorFor = [](const bag::Cloud& cloud) {
    return inputErrorOf([&] { decode("sensor_msgs/PointCloud2", bag::Role::Data, Ros2BagWriter::serialize(cloud)); });
  };
  bag::Cloud short_data = makeCloud(1.0, 4, 2);
  short_data.cloud.data.resize(short_data.cloud.data.size() - 1);
  EXPECT_CONTAINS(errorFor(short_data), "ctx: field data: 95 bytes, fewer than row_step x height = 48 x 2 = 96");

  bag::Cloud short_rows = makeCloud(1.0, 4, 2);
  short_rows.cloud.row_step = 40;
  EXPECT_CONTAINS(errorFor(short_rows), "field row_step: 40 bytes, fewer than point_step x width = 12 x 4 = 48");

  bag::Cloud zero_rows = makeCloud(1.0, 4, 2);
  zero_rows.cloud.row_step = 0;
  EXPECT_CONTAINS(errorFor(zero_rows), "field row_step: 0 bytes");

  bag::Cloud outside = makeCloud(1.0, 4, 2);
  outside.cloud.fields[2].offset = 9;
  EXPECT_CONTAINS(errorFor(outside), "field fields[2].offset: field 'z' (offset 9, 1 x 4 bytes) ends beyond "
                                           "point_step 12");

  bag::Cloud wide = makeCloud(1.0, 4, 2);
  wide.cloud.fields[0].count = 4;
  EXPECT_CONTAINS(errorFor(wide), "field fields[0].offset");

  bag::Cloud bad_type = makeCloud(1.0, 4, 2);
  bad_type.cloud.fields[1].datatype = 9;
  EXPECT_CONTAINS(errorFor(bad_type), "field fields[1].datatype: 9 is not a PointField datatype");

  bag::Cloud no_step = makeCloud(1.0, 4, 2);
  no_step.cloud.fields.clear();
  no_step.cloud.point_step = 0;
  EXPECT_CONTAINS(errorFor(no_step), "field point_step: 0 bytes per point for 8 points");

  bag::Cloud empty = makeCloud(1.0, 0, 0);  // an empty cloud is fine
  EXPECT_EQ(errorFor(empty), "");
}

// Found by fuzz_ros2_message: a 0 x 0 cloud with x y z fields and odd steps
// is a valid empty message; pcl::fromPCLPointCloud2 must not be given it
// (PCL 1.13 takes &points[0] of an empty vector).
TEST_F(Ros2BagTest, AnEmptyCloudWithFieldsDecodesToNoPoints) {
  bag::Cloud written = makeCloud(2.25, 0, 0);
  written.cloud.point_step = 1048576;
  written.cloud.row_step = 1622618368;
  const bag::Messages messages =
      decode("sensor_msgs/PointCloud2", bag::Role::Data, Ros2BagWriter::serialize(written));
  ASSERT_EQ(messages.clouds.size(), 1u);
  const pcl::PCLPointCloud2& cloud = messages.clouds[0].message.cloud;
  EXPECT_EQ(std::uint64_t(cloud.width) * cloud.height, 0u);
  EXPECT_TRUE(cloud.data.empty());
  EXPECT_EQ(cloud.fields.size(), 3u);
}

TEST_F(Ros2BagTest, BigEndianPointDataIsRefused) {
  bag::Cloud cloud = makeCloud(1.0, 2, 1);
  cloud.cloud.is_bigendian = 1;
  EXPECT_CONTAINS(inputErrorOf([&] { decode("sensor_msgs/PointCloud2", bag::Role::Data, Ros2BagWriter::serialize(cloud)); }), "ctx: field is_bigendian: big-endian point data is not supported");
}

TEST_F(Ros2BagTest, ATypeNotFittingItsRoleIsRefused) {
  {
    Ros2BagWriter writer(bagPath());
    writer.write("/scan", makeScan(1.0, 1));
    writer.write("/odom", poseMessage(1.0, "odom", "base", makePose(0, 0, 0)), true);
  }
  EXPECT_CONTAINS(inputErrorOf([&] { bag::readRos2Messages(bagPath(), {"/odom", std::nullopt}); }), "topic /odom is a nav_msgs/Odometry, not the sensor_msgs/LaserScan or "
                        "sensor_msgs/PointCloud2 its use as the data topic needs");
  EXPECT_CONTAINS(inputErrorOf([&] { bag::readRos2Messages(bagPath(), {"/scan", std::string("/scan")}); }), "topic /scan is a sensor_msgs/LaserScan, not the nav_msgs/Odometry or");
  const auto scan = Ros2BagWriter::serialize(makeScan(1.0, 1));
  EXPECT_CONTAINS(inputErrorOf([&] { decode("sensor_msgs/msg/LaserScan", bag::Role::Tf, scan); }), "ctx: a sensor_msgs/LaserScan cannot be read as the /tf topic (expected tf2_msgs/TFMessage)");
  EXPECT_CONTAINS(inputErrorOf([&] { decode("sensor_msgs/Image", bag::Role::Data, scan); }), "a sensor_msgs/Image cannot be read as the data topic");
}

TEST_F(Ros2BagTest, ASerialisationOtherThanCdrIsRefused) {
  {
    Ros2BagWriter writer(bagPath());
    writer.writeRaw("/scan", "sensor_msgs/msg/LaserScan", 1, {1, 2, 3}, "json");
  }
  EXPECT_CONTAINS(inputErrorOf([&] { bag::readRos2Messages(bagPath(), {"/scan", std::nullopt}); }), "topic /scan is serialised as 'json', not 'cdr'");
}

TEST_F(Ros2BagTest, ABadEncapsulationIsRefused) {
  EXPECT_CONTAINS(inputErrorOf([&] { decode("sensor_msgs/LaserScan", bag::Role::Data, {0, 1}); }), "ctx: field encapsulation: 2 bytes, fewer than the 4");
  EXPECT_CONTAINS(inputErrorOf([&] { decode("sensor_msgs/LaserScan", bag::Role::Data, {0, 3, 0, 0, 1, 2, 3, 4}); }), "ctx: field encapsulation: header bytes 0 3 are not plain CDR");
}

TEST_F(Ros2BagTest, ZeroOrNonFiniteGeometryIsRefused) {
  const auto pose = [](double x, double qw) {
    return Ros2BagWriter::serialized([&](eprosima::fastcdr::Cdr& cdr) {
      Ros2BagWriter::header(cdr, {1.0, "map"});
      cdr << x << 0.0 << 0.0 << 0.0 << 0.0 << 0.0 << qw;
    });
  };
  EXPECT_CONTAINS(inputErrorOf([&] { decode("geometry_msgs/PoseStamped", bag::Role::Pose, pose(0, 0)); }), "ctx: field pose.orientation: a zero quaternion");
  EXPECT_CONTAINS(inputErrorOf([&] { decode("geometry_msgs/PoseStamped", bag::Role::Pose, pose(0, NAN)); }), "ctx: field pose.orientation: not finite");
  EXPECT_CONTAINS(inputErrorOf([&] { decode("geometry_msgs/PoseStamped", bag::Role::Pose, pose(INFINITY, 1)); }), "ctx: field pose.position: not finite");
  const auto tf = Ros2BagWriter::serialized([&](eprosima::fastcdr::Cdr& cdr) {
    cdr << std::uint32_t(2);
    Ros2BagWriter::header(cdr, {1.0, "map"});
    cdr << std::string("odom");
    Ros2BagWriter::pose(cdr, makePose(0, 0, 0));
    Ros2BagWriter::header(cdr, {1.0, "odom"});
    cdr << std::string("base") << 0.0 << double(NAN) << 0.0 << 0.0 << 0.0 << 0.0 << 1.0;
  });
  EXPECT_CONTAINS(inputErrorOf([&] { decode("tf2_msgs/TFMessage", bag::Role::TfStatic, tf); }), "ctx: field transforms[1].transform.translation: not finite");
  bag::Scan scan = makeScan(1.0, 2);
  scan.angle_increment = NAN;
  EXPECT_CONTAINS(inputErrorOf([&] { decode("sensor_msgs/LaserScan", bag::Role::Data, Ros2BagWriter::serialize(scan)); }), "field angle_increment: not finite");
}

// The fuzzer's seeds (first byte: the type, as fuzz_ros2_message.cpp picks
// it) are valid messages, so that fuzzing starts from decodable inputs.
TEST(Ros2BagSeeds, EveryFuzzSeedDecodes) {
  const std::filesystem::path corpus =
      std::filesystem::path(__FILE__).parent_path().parent_path() / "fuzz" / "corpus" / "ros2_message";
  if (!std::filesystem::is_directory(corpus)) GTEST_SKIP() << corpus << " not found";
  const std::pair<const char*, bag::Role> choices[] = {
      {"sensor_msgs/LaserScan", bag::Role::Data}, {"sensor_msgs/PointCloud2", bag::Role::Data},
      {"tf2_msgs/TFMessage", bag::Role::Tf},      {"nav_msgs/Odometry", bag::Role::Pose},
      {"geometry_msgs/PoseStamped", bag::Role::Pose}, {"tf2_msgs/TFMessage", bag::Role::TfStatic}};
  std::size_t seeds = 0;
  for (const auto& entry : std::filesystem::directory_iterator(corpus)) {
    std::ifstream in(entry.path(), std::ios::binary);
    const Ros2BagWriter::Bytes bytes{std::istreambuf_iterator<char>(in), {}};
    ASSERT_FALSE(bytes.empty());
    ASSERT_LT(bytes[0], 6) << entry.path();
    const Ros2BagWriter::Bytes message(bytes.begin() + 1, bytes.end());
    EXPECT_NO_THROW(decode(choices[bytes[0]].first, choices[bytes[0]].second, message)) << entry.path();
    ++seeds;
  }
  EXPECT_GE(seeds, 6u);
}

// ---------------------------------------------------------------------------
// A long bag is read whole and in order (its speed is measured by
// bench/time_bag_read, never here: a test must pass on a busy machine).

TEST_F(Ros2BagTest, ThousandsOfScansAreReadWholeAndInOrder) {
  {
    Ros2BagWriter writer(bagPath());
    const bag::Scan scan = makeScan(0.0, 360);
    const auto bytes = Ros2BagWriter::serialize(scan);
    for (int k = 0; k < 3000; ++k) writer.writeRaw("/scan", "sensor_msgs/msg/LaserScan", 1000000000 + k * 25000000LL, bytes);
    for (int k = 0; k < 300; ++k)
      writer.writeTf("/tf", {makeTransform(1.0 + 0.25 * k, "odom", "laser", makePose(0.01 * k, 0, 0))});
  }
  const bag::Messages messages = bag::readRos2Messages(bagPath(), {"/scan", std::nullopt});
  ASSERT_EQ(messages.scans.size(), 3000u);
  for (std::size_t k = 0; k < messages.scans.size(); ++k) ASSERT_EQ(messages.scans[k].number, k + 1);
  EXPECT_EQ(messages.scans.back().message.ranges.size(), 360u);
  EXPECT_EQ(messages.tf.size(), 300u);
}

}  // namespace

#else  // built without SQLite or Fast CDR

TEST(Ros2Bag, BuiltWithoutSupportSaysSo) {
  const std::string error = inputErrorOf([] { bag::listRos2Topics("some/bag"); });
  EXPECT_EQ(error, "some/bag: obsgroup was built without ROS 2 bag support (libsqlite3-dev, libfastcdr-dev)");
  EXPECT_FALSE(inputErrorOf([] { bag::readRos2Messages("some/bag", {"/scan", std::nullopt}); }).empty());
  bag::Messages into;
  EXPECT_FALSE(inputErrorOf([&] { bag::decodeRos2Message("sensor_msgs/LaserScan", bag::Role::Data, nullptr, 0, "ctx", 1,
                                                           into); })
                   .empty());
}

#endif
