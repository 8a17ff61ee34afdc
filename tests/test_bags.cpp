// ROS bags as observations, on small bags written by the tests with the same
// libraries a robot's recorder uses: rosbag's storage library and the
// message types of the ROS 1 headers; SQLite and Fast CDR for ROS 2.
#include <obsgroup/io/errors.h>
#include <obsgroup/io/ros_bag.h>

#include "bag_messages.h"
#include "temp_folder.h"

#ifdef OBSGROUP_HAVE_ROS1
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>
#endif

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <fstream>
#include <limits>

using namespace obsgroup::io;
namespace fs = std::filesystem;

namespace {

::testing::AssertionResult throwsMentioning(const std::function<void()>& action, std::vector<std::string> parts) {
  try {
    action();
  } catch (const InputError& e) {
    const std::string message = e.what();
    for (const auto& part : parts)
      if (message.find(part) == std::string::npos)
        return ::testing::AssertionFailure() << "'" << message << "' does not mention '" << part << "'";
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "no InputError";
}

Eigen::Isometry3d planar(double x, double y, double yaw) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(x, y, 0);
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return pose;
}

void expectPose(const Eigen::Isometry3d& actual, const Eigen::Isometry3d& expected, double tolerance = 1e-6) {
  EXPECT_LE((actual.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), tolerance)
      << "actual\n" << actual.matrix() << "\nexpected\n" << expected.matrix();
}

class BagDetection : public obsgroup::test::TempFolderTest {};

TEST_F(BagDetection, TellsRos1FilesAndRos2FoldersFromOthers) {
  const fs::path dir = dir_;
  fs::create_directories(dir / "ros2");
  std::ofstream(dir / "ros2" / "bag_0.db3", std::ios::binary) << std::string("SQLite format 3\0", 16) << "...";
  std::ofstream(dir / "run.mcap", std::ios::binary) << "\x89MCAP0\r\n....";
  EXPECT_EQ(detectBag((dir / "ros2" / "bag_0.db3").string()), BagVersion::Ros2);
  EXPECT_TRUE(throwsMentioning([&] { detectBag((dir / "run.mcap").string()); }, {"run.mcap", "MCAP storage is not supported", "`ros2 bag convert`"}));
  std::ofstream(dir / "ros2" / "metadata.yaml") << "rosbag2_bagfile_information:\n";
  std::ofstream(dir / "a.bag", std::ios::binary) << "#ROSBAG V2.0\n....";
  std::ofstream(dir / "b.bag", std::ios::binary) << "FLASER 3 1 1 1\n";
  EXPECT_EQ(detectBag((dir / "ros2").string()), BagVersion::Ros2);
  EXPECT_EQ(detectBag((dir / "a.bag").string()), BagVersion::Ros1);
  EXPECT_EQ(detectBag((dir / "b.bag").string()), std::nullopt);
  EXPECT_EQ(detectBag(dir.string()), std::nullopt);
}

#ifdef OBSGROUP_HAVE_ROS1

ros::Time rosTime(double seconds) { return ros::Time(seconds); }

geometry_msgs::TransformStamped transformMessage(const std::string& parent, const std::string& child, double stamp,
                                                 const Eigen::Isometry3d& pose) {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = parent;
  t.header.stamp = rosTime(stamp);
  t.child_frame_id = child;
  t.transform.translation.x = pose.translation().x();
  t.transform.translation.y = pose.translation().y();
  t.transform.translation.z = pose.translation().z();
  const Eigen::Quaterniond q(pose.rotation());
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  return t;
}

/// A scan of three beams at -90, 0 and +90 degrees: 1, 2 and 3 m.
sensor_msgs::LaserScan scanMessage(const std::string& frame, double stamp) {
  sensor_msgs::LaserScan scan;
  scan.header.frame_id = frame;
  scan.header.stamp = rosTime(stamp);
  scan.angle_min = float(-M_PI / 2);
  scan.angle_max = float(M_PI / 2);
  scan.angle_increment = float(M_PI / 2);
  scan.range_min = 0.1f;
  scan.range_max = 10.0f;
  scan.ranges = {1.0f, 2.0f, 3.0f};
  return scan;
}

/// An empty cloud whose points are the FLOAT32 `fields`, packed in order
/// (point_step set; height, width, row_step and data left to the caller).
sensor_msgs::PointCloud2 floatCloud(const std::string& frame, double stamp, std::vector<std::string> fields) {
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = frame;
  cloud.header.stamp = rosTime(stamp);
  for (const std::string& name : fields) {
    sensor_msgs::PointField f;
    f.name = name;
    f.offset = std::uint32_t(4 * cloud.fields.size());
    f.datatype = sensor_msgs::PointField::FLOAT32;
    f.count = 1;
    cloud.fields.push_back(f);
  }
  cloud.point_step = std::uint32_t(4 * fields.size());
  return cloud;
}

/// The laser 0.2 m ahead of base_link; base_link moves in odom from (0,0)
/// at t=10 to (2,0) facing left at t=12; odom sits at (100, 0) in map.
class Ros1Bag : public obsgroup::test::TempFolderTest {
 protected:
  std::string path() const { return (dir_ / "run.bag").string(); }

  void writeRun(bool with_map = true, bool with_mount = true,
                rosbag::compression::CompressionType compression = rosbag::compression::Uncompressed) {
    rosbag::Bag bag(path(), rosbag::bagmode::Write);
    bag.setCompression(compression);
    if (with_mount) {
      tf2_msgs::TFMessage mount;
      mount.transforms.push_back(transformMessage("base_link", "laser", 0, planar(0.2, 0, 0)));
      bag.write("/tf_static", rosTime(10), mount);
    }
    for (int k = 0; k <= 2; ++k) {
      const double t = 10 + k;
      tf2_msgs::TFMessage tf;
      tf.transforms.push_back(transformMessage("odom", "base_link", t, planar(k, 0, k * M_PI / 4)));
      if (with_map) tf.transforms.push_back(transformMessage("map", "odom", t, planar(100, 0, 0)));
      bag.write("/tf", rosTime(t), tf);
    }
    for (double t : {10.0, 11.5, 12.0, 13.0}) bag.write("/scan", rosTime(t), scanMessage("laser", t));
  }
};

TEST_F(Ros1Bag, ScansArePosedByTfInterpolatedAtTheirStamps) {
  writeRun();
  const BagSequence read = loadBag(path(), BagVersion::Ros1);
  EXPECT_EQ(read.topic, "/scan");
  EXPECT_EQ(read.message_type, "sensor_msgs/LaserScan");
  EXPECT_EQ(read.pose_source, "/tf");
  EXPECT_EQ(read.fixed_frame, "map");
  // The scan at t=13 is after the last /tf: skipped, never extrapolated.
  ASSERT_EQ(read.observations.size(), 3u);
  EXPECT_EQ(read.skipped, 1u);
  ASSERT_EQ(read.warnings.size(), 1u);
  EXPECT_NE(read.warnings[0].find("1 of 4 messages on /scan"), std::string::npos) << read.warnings[0];
  const Eigen::Isometry3d mount = planar(0.2, 0, 0), map_odom = planar(100, 0, 0);
  expectPose(read.observations[0].pose, map_odom * planar(0, 0, 0) * mount);
  expectPose(read.observations[1].pose, map_odom * planar(1.5, 0, 1.5 * M_PI / 4) * mount);
  expectPose(read.observations[2].pose, map_odom * planar(2, 0, M_PI / 2) * mount);
  EXPECT_EQ(read.labels[1], path() + ": message 2 on /scan");
  // Points in the laser frame: beam k at -90 + 90k degrees.
  const auto& cloud = *read.observations[0].cloud;
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_NEAR(cloud[0].x, 0, 1e-6);
  EXPECT_NEAR(cloud[0].y, -1, 1e-6);
  EXPECT_NEAR(cloud[1].x, 2, 1e-6);
  EXPECT_NEAR(cloud[2].y, 3, 1e-6);
}

TEST_F(Ros1Bag, CompressedChunksReadAsPlainOnes) {
  writeRun();
  const BagSequence plain = loadBag(path(), BagVersion::Ros1);
  for (const auto compression : {rosbag::compression::BZ2, rosbag::compression::LZ4}) {
    writeRun(true, true, compression);
    const BagSequence read = loadBag(path(), BagVersion::Ros1);
    ASSERT_EQ(read.observations.size(), plain.observations.size());
    for (std::size_t i = 0; i < read.observations.size(); ++i) {
      expectPose(read.observations[i].pose, plain.observations[i].pose, 0.0);
      EXPECT_EQ(read.observations[i].cloud->size(), plain.observations[i].cloud->size());
    }
  }
}

TEST_F(Ros1Bag, WithoutAMapFrameThePosesAreInOdomWithAWarning) {
  writeRun(/*with_map=*/false);
  const BagSequence read = loadBag(path(), BagVersion::Ros1);
  EXPECT_EQ(read.fixed_frame, "odom");
  ASSERT_EQ(read.observations.size(), 3u);
  expectPose(read.observations[0].pose, planar(0.2, 0, 0));
  ASSERT_FALSE(read.warnings.empty());
  EXPECT_NE(read.warnings[0].find("'odom'"), std::string::npos);
  BagOptions options;
  options.fixed_frame = "world";
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1, options); },
                               {"no frame 'world'", "--fixed-frame", "its frames: ", "'odom'"}));
  // The sensor's own frame as the fixed frame would make every pose the identity.
  options.fixed_frame = "laser";
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1, options); },
                               {"'laser' is the sensor's own frame", "--fixed-frame"}));
  options.fixed_frame = "base_link";  // the robot's base, to which /tf_static fixes the laser
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1, options); },
                               {"'base_link' moves with the sensor", "--fixed-frame"}));
  // A topic named without its leading slash is found.
  options = BagOptions{};
  options.topic = "scan";
  EXPECT_EQ(loadBag(path(), BagVersion::Ros1, options).topic, "/scan");
}

TEST_F(Ros1Bag, APoseTopicMovesTheBodyAndTfStaticMountsTheSensor) {
  {
    rosbag::Bag bag(path(), rosbag::bagmode::Write);
    tf2_msgs::TFMessage mount;
    mount.transforms.push_back(transformMessage("base_link", "laser", 0, planar(0.2, 0.1, M_PI)));
    bag.write("/tf_static", rosTime(1), mount);
    for (int k = 0; k < 3; ++k) {
      nav_msgs::Odometry odom;
      odom.header.frame_id = "odom";
      odom.header.stamp = rosTime(1 + k);
      odom.child_frame_id = "base_link";
      odom.pose.pose.position.x = k;
      odom.pose.pose.orientation.w = 1;
      bag.write("/odom", rosTime(1 + k), odom);
      geometry_msgs::PoseStamped slam;
      slam.header = odom.header;
      slam.header.frame_id = "map";
      slam.pose.position.y = 5 + k;
      slam.pose.orientation.w = 1;
      bag.write("/slam_pose", rosTime(1 + k), slam);
    }
    bag.write("/scan", rosTime(1.5), scanMessage("laser", 1.5));
  }
  BagOptions options;
  options.pose_topic = "/odom";
  const BagSequence odom = loadBag(path(), BagVersion::Ros1, options);
  EXPECT_EQ(odom.pose_source, "/odom");
  EXPECT_EQ(odom.fixed_frame, "odom");
  ASSERT_EQ(odom.observations.size(), 1u);
  expectPose(odom.observations[0].pose, planar(0.5, 0, 0) * planar(0.2, 0.1, M_PI));
  // PoseStamped carries no child frame: the pose is that of the root of the
  // sensor's /tf_static chain (base_link).
  options.pose_topic = "odom";  // without the slash
  EXPECT_EQ(loadBag(path(), BagVersion::Ros1, options).pose_source, "/odom");
  options.pose_topic = "/slam_pose";
  const BagSequence slam = loadBag(path(), BagVersion::Ros1, options);
  EXPECT_EQ(slam.fixed_frame, "map");
  expectPose(slam.observations[0].pose, planar(0, 5.5, 0) * planar(0.2, 0.1, M_PI));
  options.pose_topic = "/scan";
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1, options); },
                               {"/scan is a sensor_msgs/LaserScan", "--pose-topic"}));
  options.pose_topic = "/gps";
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1, options); },
                               {"no topic /gps", "/odom (nav_msgs/Odometry, 3)"}));
}

TEST_F(Ros1Bag, SeveralScanTopicsNeedTopicAndAMissingOneListsThem) {
  {
    rosbag::Bag bag(path(), rosbag::bagmode::Write);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(transformMessage("map", "laser", 1, planar(0, 0, 0)));
    tf.transforms.push_back(transformMessage("map", "rear", 1, planar(0, 0, M_PI)));
    bag.write("/tf", rosTime(1), tf);
    bag.write("/front_scan", rosTime(1), scanMessage("laser", 1));
    bag.write("/rear_scan", rosTime(1), scanMessage("rear", 1));
  }
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1); },
                               {"several scan or cloud topics", "/front_scan", "/rear_scan", "--topic"}));
  BagOptions options;
  options.topic = "/rear_scan";
  const BagSequence rear = loadBag(path(), BagVersion::Ros1, options);
  ASSERT_EQ(rear.observations.size(), 1u);
  expectPose(rear.observations[0].pose, planar(0, 0, M_PI));
  options.topic = "/scan";
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1, options); },
                               {"no topic /scan", "/front_scan (sensor_msgs/LaserScan, 1)", "/tf (tf2_msgs/TFMessage, 1)"}));
}

TEST_F(Ros1Bag, PointCloudsKeepTheirFiniteXyzAcrossPaddedRows) {
  {
    rosbag::Bag bag(path(), rosbag::bagmode::Write);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(transformMessage("map", "camera", 5, planar(1, 2, 0)));
    bag.write("/tf", rosTime(5), tf);
    sensor_msgs::PointCloud2 cloud = floatCloud("camera", 5, {"x", "y", "z", "intensity"});
    cloud.height = 2;
    cloud.width = 2;
    cloud.row_step = 40;  // 8 bytes of padding per row
    cloud.data.assign(cloud.row_step * cloud.height, 0);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float points[4][4] = {{1, 2, 3, 9}, {4, 5, 6, 9}, {nan, nan, nan, 9}, {7, 8, 9, 9}};
    for (int k = 0; k < 4; ++k)
      std::memcpy(&cloud.data[(k / 2) * cloud.row_step + (k % 2) * cloud.point_step], points[k], 16);
    cloud.is_dense = false;
    bag.write("/points", rosTime(5), cloud);
  }
  const BagReader reader(path(), BagVersion::Ros1, {});
  EXPECT_EQ(reader.pointKind(), PointKind::XYZI);  // the intensity field, FLOAT32
  const auto with_intensity = reader.observations<pcl::PointXYZI>();
  ASSERT_EQ(with_intensity.observations.size(), 1u);
  ASSERT_EQ(with_intensity.observations[0].cloud->size(), 3u);
  EXPECT_EQ((*with_intensity.observations[0].cloud)[2].intensity, 9.0f);
  EXPECT_EQ((*with_intensity.observations[0].cloud)[2].x, 7.0f);
  const BagSequence read = loadBag(path(), BagVersion::Ros1);
  EXPECT_EQ(read.message_type, "sensor_msgs/PointCloud2");
  ASSERT_EQ(read.observations.size(), 1u);
  const auto& cloud = *read.observations[0].cloud;
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(cloud[1].x, 4);
  EXPECT_EQ(cloud[2].z, 9);
  expectPose(read.observations[0].pose, planar(1, 2, 0));
}

TEST_F(Ros1Bag, DenseCloudsAreReducedAsTheyAreDecoded) {
  {
    rosbag::Bag bag(path(), rosbag::bagmode::Write);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(transformMessage("map", "lidar", 5, planar(0, 0, 0)));
    tf.transforms.push_back(transformMessage("map", "lidar", 7, planar(1, 0, 0)));
    bag.write("/tf", rosTime(5), tf);
    for (double stamp : {5.0, 6.0}) {
      // 200 x 120 points (dense) on a 4 x 2.4 m wall 2 m ahead, rows padded by 4 bytes.
      sensor_msgs::PointCloud2 cloud = floatCloud("lidar", stamp, {"x", "y", "z"});
      cloud.height = 120;
      cloud.width = 200;
      cloud.row_step = cloud.width * cloud.point_step + 4;
      cloud.data.assign(cloud.row_step * cloud.height, 0);
      for (std::uint32_t v = 0; v < cloud.height; ++v)
        for (std::uint32_t u = 0; u < cloud.width; ++u) {
          const float point[3] = {2.0f, 0.02f * float(u) - 2.0f, 0.02f * float(v) - 1.2f};
          std::memcpy(&cloud.data[v * cloud.row_step + u * cloud.point_step], point, sizeof point);
        }
      bag.write("/points", rosTime(stamp), cloud);
    }
  }
  const BagSequence whole = loadBag(path(), BagVersion::Ros1);
  ASSERT_EQ(whole.observations.size(), 2u);
  EXPECT_EQ(whole.observations[0].cloud->size(), 24000u);
  EXPECT_EQ(whole.reduced, 0u);
  BagOptions options;
  options.reduction = FrameReading::denseDefault();
  const BagSequence reduced = loadBag(path(), BagVersion::Ros1, options);
  EXPECT_EQ(reduced.reduced, 2u);
  ASSERT_EQ(reduced.observations.size(), 2u);
  // About 80 x 48 voxels of 5 cm, each within the wall's extent.
  EXPECT_GT(reduced.observations[0].cloud->size(), 3000u);
  EXPECT_LT(reduced.observations[0].cloud->size(), 5000u);
  for (const auto& p : *reduced.observations[1].cloud) {
    EXPECT_NEAR(p.x, 2.0f, 1e-4f);
    EXPECT_GE(p.y, -2.0f);
    EXPECT_LE(p.y, 2.0f);
  }
}

TEST_F(Ros1Bag, CloudsInAnOpticalFrameAreTurnedIntoTheBodyFrame) {
  {
    rosbag::Bag bag(path(), rosbag::bagmode::Write);
    tf2_msgs::TFMessage tf;
    // A camera 1 m up looking along the world's x: its optical z is the world's x, its y the world's -z.
    Eigen::Isometry3d optical = Eigen::Isometry3d::Identity();
    optical.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    optical.translation() << 0, 0, 1;
    tf.transforms.push_back(transformMessage("map", "camera_depth_optical_frame", 5, optical));
    bag.write("/tf", rosTime(5), tf);
    sensor_msgs::PointCloud2 cloud = floatCloud("camera_depth_optical_frame", 5, {"x", "y", "z"});
    cloud.height = 1;
    cloud.width = 1;
    cloud.row_step = 12;
    const float point[3] = {0.5f, -0.25f, 2.0f};  // right 0.5, up 0.25, 2 m ahead
    cloud.data.resize(12);
    std::memcpy(cloud.data.data(), point, 12);
    bag.write("/camera/depth/points", rosTime(5), cloud);
  }
  const BagSequence read = loadBag(path(), BagVersion::Ros1);
  ASSERT_EQ(read.observations.size(), 1u);
  const auto& o = read.observations[0];
  const pcl::PointXYZ& p = (*o.cloud)[0];
  EXPECT_FLOAT_EQ(p.x, 2.0f);    // ahead
  EXPECT_FLOAT_EQ(p.y, -0.5f);   // right is -y
  EXPECT_FLOAT_EQ(p.z, 0.25f);   // up
  expectPose(o.pose, Eigen::Isometry3d(Eigen::Translation3d(0, 0, 1)), 1e-12);  // upright, looking along x
  const Eigen::Vector3d world = o.pose * p.getVector3fMap().cast<double>();
  EXPECT_TRUE(world.isApprox(Eigen::Vector3d(2, -0.5, 1.25), 1e-6)) << world.transpose();
}

/// The serialised bytes of a ROS 1 message, as a bag holds them.
template <typename Message>
std::vector<unsigned char> serialised(const Message& message) {
  std::vector<unsigned char> bytes(ros::serialization::serializationLength(message));
  ros::serialization::OStream out(bytes.data(), std::uint32_t(bytes.size()));
  ros::serialization::serialize(out, message);
  return bytes;
}

TEST(Ros1Message, ACutMessageNamesItsField) {
  sensor_msgs::LaserScan scan = scanMessage("laser", 3);
  scan.ranges.assign(100, 1.5f);
  const auto bytes = serialised(scan);
  bag::Messages into;
  bag::decodeRos1Message(bag::kLaserScanType, bag::Role::Data, bytes.data(), bytes.size(), "x.bag: message 7", 7, into);
  ASSERT_EQ(into.scans.size(), 1u);
  EXPECT_EQ(into.scans[0].number, 7u);
  EXPECT_EQ(into.scans[0].message.ranges.size(), 100u);
  EXPECT_DOUBLE_EQ(into.scans[0].message.header.stamp, 3.0);
  EXPECT_TRUE(throwsMentioning(
      [&] { bag::decodeRos1Message(bag::kLaserScanType, bag::Role::Data, bytes.data(), bytes.size() - 200, "x.bag: message 7", 7, into); },
      {"x.bag: message 7", "field ranges"}));
}

TEST(Ros1Message, ALengthBeyondTheDataIsRefusedBeforeAllocating) {
  sensor_msgs::LaserScan scan = scanMessage("laser", 3);
  auto bytes = serialised(scan);
  // The ranges' count sits 12 bytes before the end (3 floats) and 4 before
  // the intensities' count: claim 4 billion ranges.
  const std::size_t count_at = bytes.size() - 4 - 12 - 4;
  const std::uint32_t huge = 0xFFFFFFF0u;
  std::memcpy(&bytes[count_at], &huge, 4);
  bag::Messages into;
  EXPECT_TRUE(throwsMentioning(
      [&] { bag::decodeRos1Message(bag::kLaserScanType, bag::Role::Data, bytes.data(), bytes.size(), "b", 1, into); },
      {"field ranges", "elements claimed"}));
}

TEST(Ros1Message, ACloudWhoseDataDoNotFitItsRowsIsRefused) {
  sensor_msgs::PointCloud2 cloud = floatCloud("c", 0, {"x"});
  cloud.height = 1;
  cloud.width = 10;
  cloud.row_step = 40;
  cloud.data.assign(36, 0);
  bag::Messages into;
  auto bytes = serialised(cloud);
  EXPECT_TRUE(throwsMentioning(
      [&] { bag::decodeRos1Message(bag::kPointCloud2Type, bag::Role::Data, bytes.data(), bytes.size(), "c", 1, into); },
      {"field data", "36 bytes, fewer than row_step x height = 40 x 1 = 40"}));
  cloud.data.assign(44, 0);  // more than row_step * height: read, the rest ignored (as the fuzzer found)
  bytes = serialised(cloud);
  bag::decodeRos1Message(bag::kPointCloud2Type, bag::Role::Data, bytes.data(), bytes.size(), "c", 1, into);
  ASSERT_EQ(into.clouds.size(), 1u);
  cloud.data.assign(40, 0);
  cloud.is_bigendian = true;
  bytes = serialised(cloud);
  EXPECT_TRUE(throwsMentioning(
      [&] { bag::decodeRos1Message(bag::kPointCloud2Type, bag::Role::Data, bytes.data(), bytes.size(), "c", 1, into); },
      {"big-endian"}));
}

TEST(Ros1Message, AZeroQuaternionIsNotARotation) {
  tf2_msgs::TFMessage tf;
  tf.transforms.push_back(transformMessage("map", "laser", 1, planar(0, 0, 0)));
  tf.transforms[0].transform.rotation.w = 0;
  const auto bytes = serialised(tf);
  bag::Messages into;
  EXPECT_TRUE(throwsMentioning(
      [&] { bag::decodeRos1Message(bag::kTfType, bag::Role::Tf, bytes.data(), bytes.size(), "t", 1, into); },
      {"transforms.transform.rotation", "is no rotation"}));
}

TEST_F(Ros1Bag, ARangeAtRangeMaxIsNoReturn) {
  {
    rosbag::Bag bag(path(), rosbag::bagmode::Write);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(transformMessage("map", "laser", 1, planar(0, 0, 0)));
    bag.write("/tf", rosTime(1), tf);
    sensor_msgs::LaserScan scan = scanMessage("laser", 1);
    scan.ranges = {1.0f, 10.0f, std::numeric_limits<float>::infinity(), 0.05f, 3.0f};  // range_min 0.1, range_max 10
    bag.write("/scan", rosTime(1), scan);
  }
  const BagSequence read = loadBag(path(), BagVersion::Ros1);
  ASSERT_EQ(read.observations.size(), 1u);
  EXPECT_EQ(read.observations[0].cloud->size(), 2u);
}

TEST_F(Ros1Bag, WithoutTfAPoseTopicIsAskedFor) {
  {
    rosbag::Bag bag(path(), rosbag::bagmode::Write);
    geometry_msgs::PoseStamped pose;
    pose.header.frame_id = "world";
    pose.header.stamp = rosTime(1);
    pose.pose.orientation.w = 1;
    bag.write("/mocap/pose", rosTime(1), pose);
    bag.write("/scan", rosTime(1), scanMessage("laser", 1));
  }
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1); },
                               {"no /tf in the bag", "--pose-topic", "candidates: /mocap/pose"}));
  BagOptions options;
  options.pose_topic = "/mocap/pose";
  const BagSequence read = loadBag(path(), BagVersion::Ros1, options);
  ASSERT_EQ(read.observations.size(), 1u);
  EXPECT_EQ(read.fixed_frame, "world");
  ASSERT_EQ(read.warnings.size(), 1u);  // no mounting: the sensor is at the pose
  EXPECT_NE(read.warnings[0].find("no /tf_static from the body to the sensor's frame 'laser'"), std::string::npos)
      << read.warnings[0];
}

TEST_F(Ros1Bag, ATumTrajectoryPosesTheMessagesByTimestamp) {
  writeRun();
  std::ofstream(dir_ / "trajectory.txt") << "# timestamp tx ty tz qx qy qz qw\n"
                                         << "10.005 1 2 0 0 0 0 1\n11.49 3 4 0 0 0 0.7071067811865476 0.7071067811865476\n";
  BagOptions options;
  options.poses_file = (dir_ / "trajectory.txt").string();
  const BagSequence read = loadBag(path(), BagVersion::Ros1, options);
  // t=10 and 11.5 have a pose within 0.02 s; 12 and 13 do not.
  ASSERT_EQ(read.observations.size(), 2u);
  EXPECT_EQ(read.skipped, 2u);
  EXPECT_EQ(read.fixed_frame, "");
  expectPose(read.observations[0].pose, planar(1, 2, 0));
  expectPose(read.observations[1].pose, planar(3, 4, M_PI / 2), 1e-9);
  ASSERT_EQ(read.warnings.size(), 1u);
  EXPECT_NE(read.warnings[0].find("2 of 4 messages on /scan have no pose in"), std::string::npos) << read.warnings[0];
  options.max_time_difference = 1.6;  // 13 is 1.51 s from 11.49
  EXPECT_EQ(loadBag(path(), BagVersion::Ros1, options).observations.size(), 4u);
  options.pose_topic = "/odom";
  EXPECT_THROW(loadBag(path(), BagVersion::Ros1, options), UsageError);
  // The trajectory gives the poses: /tf is not even read (here it could not be).
  {
    rosbag::Bag bag(path(), rosbag::bagmode::Write);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(transformMessage("map", "laser", 10, planar(0, 0, 0)));
    tf.transforms[0].transform.rotation.w = 0;
    bag.write("/tf", rosTime(10), tf);
    bag.write("/scan", rosTime(10), scanMessage("laser", 10));
  }
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1); }, {"on /tf", "is no rotation"}));
  BagOptions trajectory_only;
  trajectory_only.poses_file = (dir_ / "trajectory.txt").string();
  EXPECT_EQ(loadBag(path(), BagVersion::Ros1, trajectory_only).observations.size(), 1u);
}

TEST_F(Ros1Bag, AFileThatIsNotABagIsAnInputError) {
  std::ofstream(path(), std::ios::binary) << "#ROSBAG V2.0\nthis is not a bag at all";
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1); }, {path(), "not a readable ROS 1 bag"}));
}

TEST_F(Ros1Bag, AScanInAFrameTfDoesNotConnectIsNamed) {
  {
    rosbag::Bag bag(path(), rosbag::bagmode::Write);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(transformMessage("map", "base_link", 1, planar(0, 0, 0)));
    bag.write("/tf", rosTime(1), tf);
    bag.write("/scan", rosTime(1), scanMessage("laser", 1));
  }
  EXPECT_TRUE(throwsMentioning([&] { loadBag(path(), BagVersion::Ros1); },
                               {"message 1 on /scan", "'laser'", "'map'"}));
}

#endif

}  // namespace
