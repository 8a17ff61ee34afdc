// The readers on their own: in-memory parsing, and the inputs that fuzzing
// found mishandled, each pinned with its expected outcome.
#include <obsgroup/io/carmen_reader.h>
#include <obsgroup/io/depth_sequence.h>
#include <obsgroup/io/errors.h>
#include <obsgroup/io/frame_reading.h>
#include <obsgroup/io/kitti_sequence.h>
#include <obsgroup/io/pcd_sequence.h>
#include <obsgroup/io/pose_file.h>
#include "png_writer.h"
#include "temp_folder.h"

#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <gtest/gtest.h>
#include <omp.h>
#include <zlib.h>

#include <unistd.h>

#include <cmath>
#include <sstream>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <set>
#include <tuple>

using namespace obsgroup::io;
namespace fs = std::filesystem;

namespace {

/// A one-file PCD folder holding `content`, removed afterwards.
class PcdFolder : public obsgroup::test::TempFolderTest {
 protected:

  std::string write(const std::string& content) const {
    const fs::path file = dir_ / "000000.pcd";
    std::ofstream(file, std::ios::binary) << content;
    return file.string();
  }

  /// The InputError message of loading `content`, or "" when it loads.
  std::string errorOf(const std::string& content) const {
    const std::string file = write(content);
    try {
      detectPointKind(file);
      loadPcdSequence<pcl::PointXYZ>({file}, std::nullopt);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
};

std::string header(const std::string& size, const std::string& width, const std::string& height,
                   const std::string& points, const std::string& extra = "") {
  return "VERSION 0.7\nFIELDS x y z\nSIZE " + size + "\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + width + "\nHEIGHT " +
         height + "\nVIEWPOINT 1.5 -2 0 1 0 0 0\n" + extra + "POINTS " + points + "\nDATA ascii\n";
}

}  // namespace

// Found by fuzz_pcd: PCL 1.13's fromPCLPointCloud2 indexes point 0 of an
// empty cloud (undefined behaviour, reported by UBSan). An empty PCD is an
// observation with no points, posed by its VIEWPOINT.
TEST_F(PcdFolder, EmptyCloudLoadsWithItsViewpoint) {
  const std::string file = write(header("4 4 4", "0", "0", "0"));
  const auto sequence = loadPcdSequence<pcl::PointXYZ>({file}, std::nullopt);
  ASSERT_EQ(sequence.observations.size(), 1u);
  EXPECT_TRUE(sequence.observations[0].cloud->empty());
  EXPECT_DOUBLE_EQ(sequence.observations[0].pose.translation().x(), 1.5);
  EXPECT_DOUBLE_EQ(sequence.observations[0].pose.translation().y(), -2.0);
  ASSERT_EQ(sequence.warnings.size(), 1u);
  EXPECT_NE(sequence.warnings[0].find("no point"), std::string::npos);
}

// Found by fuzz_pcd: PCL's readHeader throws std::out_of_range on a float
// field of 2 bytes. It is refused first, naming the line and the field.
TEST_F(PcdFolder, FloatOfTwoBytesIsRefused) {
  const std::string message = errorOf(header("2 4 4", "0", "0", "0"));
  EXPECT_NE(message.find("000000.pcd:4: field 'TYPE': F (float) with SIZE 2"), std::string::npos) << message;
}

// Found by fuzz_pcd (in CI): a field with COUNT 0 made PCL read past the
// end of each point's data (heap-buffer-overflow).
TEST_F(PcdFolder, FieldCountedZeroIsRefused) {
  const std::string message = errorOf(
      "VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 0 1 1 1\nWIDTH 1\nHEIGHT 1\n"
      "POINTS 1\nDATA ascii\n1 2 3\n");
  EXPECT_NE(message.find("000000.pcd:5: field 'COUNT': a field counted 0 holds no value"), std::string::npos)
      << message;
}

// PCL skips a field whose type differs from the point type's, silently:
// double coordinates would all load as 0.
TEST_F(PcdFolder, CoordinatesThatAreNotFloatsAreRefused) {
  const std::string message = errorOf(
      "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n"
      "DATA ascii\n1 2 3\n");
  EXPECT_NE(message.find("field 'x' is not one 4-byte float"), std::string::npos) << message;
}

// Found by fuzz_pcd: PCL reads header keys after DATA (past empty and
// comment lines), so it read the data with fields the check never saw and
// overflowed its buffer.
TEST_F(PcdFolder, HeaderKeysAfterDataAreRefused) {
  const std::string message = errorOf(header("4 4 4", "1", "1", "1") + "\n# a comment\nFIELDS x y z a b c\n1 2 3\n");
  EXPECT_NE(message.find("000000.pcd:13: header field 'FIELDS' after DATA"), std::string::npos) << message;
  EXPECT_EQ(errorOf(header("4 4 4", "1", "1", "1") + "1 2 3\n"), "");
  // However many empty lines come first: PCL reads on through all of them.
  const std::string far = errorOf(header("4 4 4", "1", "1", "1") + std::string(200, '\n') + "FIELDS x y z a\n1 2 3\n");
  EXPECT_NE(far.find(":211: header field 'FIELDS' after DATA"), std::string::npos) << far;
}

// Found by fuzz_pcd: PCL takes a line's first word after any white space,
// vertical tab and form feed included, so a key after DATA behind a vertical
// tab (or behind a comment so led) changed the point size PCL read the data
// with, and readBodyASCII wrote past its buffer.
TEST_F(PcdFolder, HeaderKeysAfterDataBehindAVerticalTabAreRefused) {
  const std::string points = "1 2 3\n1 2 3\n1 2 3\n";
  EXPECT_EQ(errorOf(header("4 4 4", "4", "1", "4") + points + "1 2 3\n"), "");
  const std::string tab = errorOf(header("4 4 4", "4", "1", "4") + "\vSIZE 4 4 8\n" + points);
  EXPECT_NE(tab.find(":11: header field 'SIZE' after DATA"), std::string::npos) << tab;
  const std::string feed = errorOf(header("4 4 4", "4", "1", "4") + "\f COUNT 1 1 2\n" + points);
  EXPECT_NE(feed.find(":11: header field 'COUNT' after DATA"), std::string::npos) << feed;
  const std::string comment = errorOf(header("4 4 4", "4", "1", "4") + "\v# hidden\nSIZE 4 4 8\n" + points);
  EXPECT_NE(comment.find(":12: header field 'SIZE' after DATA"), std::string::npos) << comment;
}

// Found by fuzz_pcd: with 0 points declared, PCL still allocates the
// uncompressed size written in the data (1.3 GB from 8 forged bytes).
TEST_F(PcdFolder, CompressedSizesAreCheckedEvenForNoPoints) {
  const std::string forged("\x22\0\0\0\x40\x49\x4f\x50", 8);
  const std::string message = errorOf("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 4\n"
                                      "HEIGHT 0\nDATA binary_compressed\n" + forged);
  EXPECT_NE(message.find("compressed data"), std::string::npos) << message;
  EXPECT_NE(errorOf("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n"
                    "DATA binary"),
            "") << "DATA as the last line, without data, must be refused as truncated";
}

TEST_F(PcdFolder, HeadersNoFileCouldMatchAreRefused) {
  EXPECT_NE(errorOf(header("4 4 4", "1099511627776", "1099511627776", "0")).find("more points than any file holds"),
            std::string::npos);
  EXPECT_NE(errorOf("VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1048576 1048576 1048576\n"
                    "WIDTH 1099511627776\nHEIGHT 1\nPOINTS 1099511627776\nDATA binary\n")
                .find("more data than any file holds"),
            std::string::npos);
  EXPECT_NE(errorOf(header("4 4 4", "1", "1", "1", "WIDTH 1\n")).find("field 'WIDTH' appears twice"),
            std::string::npos);
  EXPECT_NE(errorOf(header("4 4 4", "3", "1", "3") + "0 0 0\n1 1 1\n").find("truncated"), std::string::npos);
  EXPECT_EQ(errorOf(header("4 4 4", "2", "1", "2") + "0 0 0\n1 1 nan\n"), "");
}

TEST(Readers, InMemoryAndFileReadsAgree) {
  const std::string log =
      "PARAM robot_front_laser_max 30 0 host 0\n"
      "FLASER 3 1.0 nan 2.0 0.5 0.25 0.1 0.5 0.25 0.1 1.0 host 1.0\n";
  const CarmenLog in_memory = parseCarmenLog(log, "log.clf");
  ASSERT_EQ(in_memory.scans.size(), 1u);
  EXPECT_EQ(scanToCloud(in_memory.scans[0])->size(), 2u);  // nan is no return
  EXPECT_DOUBLE_EQ(in_memory.scans[0].laser_pose.translation().x(), 0.5);
  try {
    parseCarmenLog("FLASER 3 1.0 2.0 0.5 0.25 0.1\n", "short.clf");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("short.clf:1: FLASER line is truncated"), std::string::npos) << e.what();
  }
  const auto poses = parsePoses("# t x y z qx qy qz qw\n0 1 2 3 0 0 0 1\n1 4 5 6 0 0 1 0\n", "poses.txt", PoseFormat::Tum);
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_DOUBLE_EQ(poses[1].translation().z(), 6.0);
  try {
    parsePoses("0 1 2 3 0 0 0 1\n0 1 2 nan 0 0 0 1\n", "poses.txt", PoseFormat::Tum);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("poses.txt:2: field 'tz'"), std::string::npos) << e.what();
  }
}

namespace {

/// A CARMEN log of `scans` FLASER lines of 180 beams, over 1 MB, so that it
/// is parsed in slices; line k is replaced where `replace` says.
std::string bigLog(int scans, const std::map<int, std::string>& replace = {}) {
  std::string log = "PARAM robot_front_laser_max 30 0 host 0\n";
  for (int k = 1; k <= scans; ++k) {
    if (const auto it = replace.find(k + 1); it != replace.end()) {
      log += it->second + "\n";
      continue;
    }
    std::string line = "FLASER 180";
    for (int b = 0; b < 180; ++b) line += ' ' + std::to_string(1.0 + 0.01 * ((k + b) % 300));
    line += ' ' + std::to_string(0.1 * k) + " 0.5 0.01 0 0 0 " + std::to_string(k) + " host 0\n";
    log += line;
  }
  return log;
}

std::string errorOfLog(const std::string& log, int threads) {
  CarmenOptions options;
  options.threads = threads;
  try {
    parseCarmenLog(log, "big.clf", options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Readers, LargeLogsParseTheSameOnAnyNumberOfThreads) {
  const std::string log = bigLog(1200, {{900, "PARAM robot_front_laser_max 20 0 host 0"}});
  ASSERT_GT(log.size(), std::size_t(1) << 20);
  CarmenOptions one, four;
  one.threads = 1;
  four.threads = 4;
  const CarmenLog a = parseCarmenLog(log, "big.clf", one), b = parseCarmenLog(log, "big.clf", four);
  ASSERT_EQ(a.scans.size(), 1199u);
  ASSERT_EQ(b.scans.size(), a.scans.size());
  for (std::size_t k = 0; k < a.scans.size(); ++k) {
    EXPECT_EQ(a.scans[k].line, b.scans[k].line);
    EXPECT_EQ(a.scans[k].ranges, b.scans[k].ranges);
    EXPECT_TRUE(a.scans[k].laser_pose.isApprox(b.scans[k].laser_pose, 0.0));
    EXPECT_EQ(b.scans[k].max_range, 20.0);  // the last PARAM applies to all, as with one thread
  }
}

TEST(Readers, TheFirstBadLineOfALargeLogIsReportedOnAnyNumberOfThreads) {
  // Errors in the first and the last slice, and a bad PARAM line between them.
  const std::string log = bigLog(1200, {{1100, "FLASER 2 1.0"},
                                        {700, "PARAM robot_front_laser_max abc 0 host 0"},
                                        {1150, "FLASER 3 1 2 x 0 0 0 0 0 0 0 host 0"}});
  for (int threads : {1, 2, 3, 8}) {
    const std::string error = errorOfLog(log, threads);
    EXPECT_NE(error.find("big.clf:700: field 'PARAM robot_front_laser_max': 'abc'"), std::string::npos)
        << threads << " threads: " << error;
  }
  const std::string later = bigLog(1200, {{1100, "FLASER 2 1.0"}, {1150, "FLASER 3 1 2 x 0 0 0 0 0 0 0 host 0"}});
  for (int threads : {1, 2, 3, 8})
    EXPECT_NE(errorOfLog(later, threads).find("big.clf:1100: FLASER line is truncated"), std::string::npos)
        << threads << " threads";
}

namespace {

/// `text` gzipped, as the gzip tool writes it.
std::string gzipped(const std::string& text) {
  z_stream stream{};
  EXPECT_EQ(deflateInit2(&stream, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&stream, text.size()) + 64, '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  stream.avail_in = static_cast<uInt>(text.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(deflate(&stream, Z_FINISH), Z_STREAM_END);
  out.resize(stream.total_out);
  deflateEnd(&stream);
  return out;
}

/// A ROBOTLASER1 line of n readings of `range`, the laser at (x, y, theta)
/// and the robot at (rx, ry, rtheta).
std::string robotLaser(double start, double fov, double resolution, int n, double range,
                       const std::string& laser_pose = "0 0 0", const std::string& robot_pose = "0 0 0") {
  std::ostringstream line;
  line.precision(17);
  line << "ROBOTLASER1 0 " << start << ' ' << fov << ' ' << resolution << " 30 0.01 0 " << n;
  for (int k = 0; k < n; ++k) line << ' ' << range;
  line << " 0 " << laser_pose << ' ' << robot_pose << " 0 0 0 0 0 1.0 host 1.0\n";
  return line.str();
}

/// A FLASER line of n readings of `range`, the laser at x.
std::string frontLaser(int n, double range, double x = 0.0) {
  std::string line = "FLASER " + std::to_string(n);
  for (int k = 0; k < n; ++k) line += ' ' + std::to_string(range);
  return line + ' ' + std::to_string(x) + " 0 0 0 0 0 1.0 host 1.0\n";
}

constexpr double kPi = 3.14159265358979323846;

/// The angles of a scan's points, radians.
std::vector<double> angles(const LaserScan& scan) {
  std::vector<double> out;
  const auto cloud = scanToCloud(scan);
  for (const auto& p : cloud->points) out.push_back(std::atan2(p.y, p.x));
  return out;
}

}  // namespace

TEST(Readers, AFullTurnRobotLaserHasItsBeamsAtTheResolution) {
  // 360 readings of a full turn: beam k at -pi + k * 2 pi / 360, not k * 2 pi / 359.
  const CarmenLog turn = parseCarmenLog(robotLaser(-kPi, 2 * kPi, 2 * kPi / 360, 360, 5.0), "turn.clf");
  ASSERT_EQ(turn.scans.size(), 1u);
  const auto cloud = scanToCloud(turn.scans[0]);
  ASSERT_EQ(cloud->size(), 360u);
  for (int k = 0; k < 360; ++k) {
    const double angle = -kPi + k * 2 * kPi / 360;
    EXPECT_NEAR(cloud->points[k].x, 5.0 * std::cos(angle), 1e-5) << k;
    EXPECT_NEAR(cloud->points[k].y, 5.0 * std::sin(angle), 1e-5) << k;
  }
  EXPECT_TRUE(turn.warnings.empty());
  EXPECT_NEAR(turn.fov_deg, 360.0, 1e-9);
  // A 180-degree sensor including both ends, its resolution rounded as
  // loggers write it: the field of view spans the 361 beams exactly.
  const CarmenLog half = parseCarmenLog(robotLaser(-kPi / 2, kPi, 0.008727, 361, 5.0), "half.clf");
  EXPECT_DOUBLE_EQ(half.scans[0].angle_step, kPi / 360);
  EXPECT_NEAR(angles(half.scans[0]).back(), kPi / 2, 1e-6);
  EXPECT_TRUE(half.warnings.empty());
  // Neither: the resolution is used, with one warning for all such scans.
  const CarmenLog odd = parseCarmenLog(robotLaser(-kPi / 2, kPi, 0.01, 181, 5.0) +
                                           robotLaser(-kPi / 2, kPi, 0.01, 181, 5.0), "odd.clf");
  EXPECT_DOUBLE_EQ(odd.scans[1].angle_step, 0.01);
  ASSERT_EQ(odd.warnings.size(), 1u);
  EXPECT_NE(odd.warnings[0].find("odd.clf:1: ROBOTLASER1 field_of_view"), std::string::npos) << odd.warnings[0];
  EXPECT_NE(odd.warnings[0].find("(2 scans like this)"), std::string::npos) << odd.warnings[0];
}

TEST(Readers, AFieldOfViewParamInRadiansIsTold) {
  // MIT CSAIL's log: fov 3.14159 (radians) with a 0.5 degree resolution and 361 beams.
  const std::string params = "PARAM laser_front_laser_resolution 0.5 0 host 0\nPARAM laser_front_laser_fov 3.14159 0 host 0\n";
  const CarmenLog log = parseCarmenLog(params + frontLaser(361, 4.0), "csail.log");
  ASSERT_EQ(log.scans.size(), 1u);
  EXPECT_NEAR(log.fov_deg, 180.0, 1e-3);
  const auto a = angles(log.scans[0]);
  EXPECT_NEAR(a.front(), -kPi / 2, 1e-5);
  EXPECT_NEAR(a.back(), kPi / 2, 1e-5);
  EXPECT_NE(log.fov_source.find("read as radians"), std::string::npos) << log.fov_source;
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("laser_front_laser_fov 3.14159 read as radians"), std::string::npos);
  // Without a resolution, a value up to 2 pi is radians too; degrees stay degrees.
  EXPECT_NEAR(parseCarmenLog("PARAM laser_front_laser_fov 4.71239 0 host 0\n" + frontLaser(181, 4.0), "a.log").fov_deg,
              270.0, 1e-3);
  const CarmenLog degrees = parseCarmenLog("PARAM laser_front_laser_fov 90 0 host 0\n" + params.substr(0, params.find('\n') + 1) +
                                               frontLaser(181, 4.0), "d.log");
  EXPECT_DOUBLE_EQ(degrees.fov_deg, 90.0);
  EXPECT_EQ(degrees.fov_source, "PARAM laser_front_laser_fov (degrees)");
  EXPECT_TRUE(degrees.warnings.empty());
  EXPECT_DOUBLE_EQ(parseCarmenLog(frontLaser(181, 4.0), "x.log").fov_deg, 180.0);
}

TEST(Readers, AByteOrderMarkKeepsTheFirstScan) {
  const std::string log = frontLaser(3, 1.0, 1.0) + frontLaser(3, 1.0, 2.0);
  const CarmenLog marked = parseCarmenLog("\xEF\xBB\xBF" + log, "bom.log");
  ASSERT_EQ(marked.scans.size(), 2u);
  EXPECT_DOUBLE_EQ(marked.scans[0].laser_pose.translation().x(), 1.0);
  EXPECT_EQ(parsePoses("\xEF\xBB\xBF" "0 1 2 3 0 0 0 1\n", "p.txt", PoseFormat::Tum).size(), 1u);
}

class GzipFiles : public obsgroup::test::TempFolderTest {};

TEST_F(GzipFiles, AGzippedLogReadsAsThePlainOne) {
  const std::string log = bigLog(1200);  // large enough to be parsed in slices
  const std::string packed = gzipped(log);
  ASSERT_LT(packed.size(), log.size() / 2);
  // Told by the content, not by the name.
  std::ofstream(dir_ / "run.log", std::ios::binary) << packed;
  const CarmenLog plain = parseCarmenLog(log, "run.log"), read = readCarmenLog((dir_ / "run.log").string());
  ASSERT_EQ(read.scans.size(), plain.scans.size());
  for (std::size_t k = 0; k < plain.scans.size(); ++k) {
    EXPECT_EQ(read.scans[k].ranges, plain.scans[k].ranges);
    EXPECT_TRUE(read.scans[k].laser_pose.isApprox(plain.scans[k].laser_pose, 0.0));
  }
  // Concatenated members are one file, as gzip reads them.
  const std::string first = frontLaser(3, 1.0, 1.0), second = frontLaser(3, 1.0, 2.0);
  EXPECT_EQ(parseCarmenLog(gzipped(first) + gzipped(second), "two.log.gz").scans.size(), 2u);
  // A cut or corrupt gzip file is an input error naming the file.
  try {
    parseCarmenLog(packed.substr(0, packed.size() / 2), "cut.log.gz");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.log.gz: the gzip data are cut short"), std::string::npos) << e.what();
  }
  std::string corrupt = packed;
  for (std::size_t k = 20; k < 60; ++k) corrupt[k] = char(0xff);
  EXPECT_THROW(parseCarmenLog(corrupt, "bad.log.gz"), InputError);
  // Pose files too.
  std::ofstream(dir_ / "poses.txt.gz", std::ios::binary) << gzipped("0 1 2 3 0 0 0 1\n1 4 5 6 0 0 0 1\n");
  EXPECT_EQ(readPoses((dir_ / "poses.txt.gz").string(), PoseFormat::Tum).size(), 2u);
}

TEST(Readers, SlamGraphVerticesGiveTheScansPoses) {
  // The laser 0.1 m ahead of the robot; VERTEX2 corrects the robot's pose.
  const std::string log = "VERTEX2 0 10 20 1.5707963267948966\n" +
                          robotLaser(-kPi / 2, kPi, kPi / 180, 181, 3.0, "1.1 2 0", "1 2 0") +
                          "EDGE2 0 1 1 0 0 1 0 1 1 0 0\n" + robotLaser(-kPi / 2, kPi, kPi / 180, 181, 3.0, "5.1 6 0", "5 6 0");
  const CarmenLog graph = parseCarmenLog(log, "graph.log");
  ASSERT_EQ(graph.scans.size(), 2u);
  const Eigen::Vector3d laser = graph.scans[0].laser_pose.translation();
  EXPECT_NEAR(laser.x(), 10.0, 1e-9);
  EXPECT_NEAR(laser.y(), 20.1, 1e-9);  // 0.1 m ahead of a robot facing +y
  EXPECT_NEAR(graph.scans[1].laser_pose.translation().x(), 5.1, 1e-12);  // no vertex: its own pose
  ASSERT_EQ(graph.warnings.size(), 1u);
  EXPECT_NE(graph.warnings[0].find("the poses of 1 of 1 VERTEX2 lines"), std::string::npos) << graph.warnings[0];
  EXPECT_THROW(parseCarmenLog("VERTEX2 0 1\n" + frontLaser(3, 1.0), "short.log"), InputError);
}

TEST(Readers, BadLinesAreSkippedOnlyWhenAsked) {
  const std::string whole = frontLaser(3, 1.0, 1.0) + frontLaser(3, 1.0, 2.0) + frontLaser(3, 1.0, 3.0);
  const std::string cut = whole.substr(0, whole.size() - 20);  // the recording cut off
  try {
    parseCarmenLog(cut, "cut.log");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.log:3: FLASER line is truncated"), std::string::npos) << e.what();
  }
  CarmenOptions skip;
  skip.skip_bad_lines = true;
  const CarmenLog log = parseCarmenLog("FLASER x\n" + cut, "cut.log", skip);
  EXPECT_EQ(log.scans.size(), 2u);
  EXPECT_EQ(log.skipped_lines, 2u);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_EQ(log.warnings[0].rfind("skipped 2 bad lines (first: cut.log:1: field 'num_readings'", 0), 0u)
      << log.warnings[0];
  // Large logs: the same on any number of threads.
  const std::string big = bigLog(1200, {{100, "FLASER 2 1.0"}, {1100, "FLASER 3 1 2 x 0 0 0 0 0 0 0 host 0"}});
  for (int threads : {1, 3}) {
    skip.threads = threads;
    const CarmenLog b = parseCarmenLog(big, "big.clf", skip);
    EXPECT_EQ(b.scans.size(), 1198u);
    EXPECT_NE(b.warnings.at(0).find("first: big.clf:100:"), std::string::npos) << b.warnings.at(0);
  }
  EXPECT_THROW(parseCarmenLog("FLASER x\n", "none.log", skip), InputError);
}

TEST(Readers, EachScanCarriesItsIpcTimestamp) {
  // FLASER ... ipc_timestamp ipc_hostname logger_timestamp; ROBOTLASER1 ... timestamp host logger_timestamp.
  const std::string flaser = "FLASER 2 1 1 0 0 0 0 0 0 1234.5 host 99\nFLASER 2 1 1 0 0 0 0 0 0 1234.75 host 98\n";
  const CarmenLog front = parseCarmenLog(flaser, "f.log");
  ASSERT_EQ(front.scans.size(), 2u);
  EXPECT_DOUBLE_EQ(front.scans[0].timestamp, 1234.5);
  EXPECT_DOUBLE_EQ(front.scans[1].timestamp, 1234.75);
  const CarmenLog robot = parseCarmenLog(robotLaser(-kPi / 2, kPi, kPi / 2, 3, 5.0), "r.clf");
  EXPECT_DOUBLE_EQ(robot.scans.at(0).timestamp, 1.0);
  // A timestamp that is not a number: NaN for a grouping, which does not use
  // it, an error naming file, line and field for a replay that does.
  const std::string bad = "FLASER 2 1 1 0 0 0 0 0 0 soon host 99\n";
  EXPECT_TRUE(std::isnan(parseCarmenLog(bad, "b.log").scans.at(0).timestamp));
  CarmenOptions stamped;
  stamped.require_timestamps = true;
  EXPECT_DOUBLE_EQ(parseCarmenLog(flaser, "f.log", stamped).scans[1].timestamp, 1234.75);
  try {
    parseCarmenLog(flaser + bad, "b.log", stamped);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.log:3: field 'ipc_timestamp': 'soon' is not a number"), std::string::npos)
        << e.what();
  }
  std::string robot_bad = robotLaser(-kPi / 2, kPi, kPi / 2, 3, 5.0);
  robot_bad.replace(robot_bad.find(" 1.0 host"), 4, " nan");
  try {
    parseCarmenLog(robot_bad, "r.clf", stamped);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("r.clf:1: field 'timestamp': 'nan' is not finite"), std::string::npos)
        << e.what();
  }
}

TEST(Readers, APoseLineOfTheOtherFormatSaysWhichItIs) {
  try {
    parsePoses("1 0 0 5 0 1 0 6 0 0 1 7\n", "kitti.txt", PoseFormat::Tum);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--pose-format kitti"), std::string::npos) << e.what();
  }
}

TEST(Readers, VerticesApplyAcrossTheSlicesOfALargeLog) {
  // Every 50th line a vertex; slices cut between a vertex and its scan on some thread counts.
  std::map<int, std::string> vertices;
  for (int line = 50; line < 1200; line += 50) vertices[line] = "VERTEX2 " + std::to_string(line) + " 100 " + std::to_string(line) + " 0";
  const std::string log = bigLog(1200, vertices);
  CarmenOptions options;
  std::vector<CarmenLog> logs;
  for (int threads : {1, 2, 3, 7}) {
    options.threads = threads;
    logs.push_back(parseCarmenLog(log, "graph.clf", options));
  }
  // The scan after line 50 is line 51: its laser pose is the vertex's.
  const LaserScan& after = logs[0].scans.at(48);
  ASSERT_EQ(after.line, 51u);
  EXPECT_DOUBLE_EQ(after.laser_pose.translation().x(), 100.0);
  EXPECT_DOUBLE_EQ(after.laser_pose.translation().y(), 50.0);
  for (const CarmenLog& other : logs) {
    ASSERT_EQ(other.scans.size(), logs[0].scans.size());
    for (std::size_t k = 0; k < other.scans.size(); ++k)
      EXPECT_TRUE(other.scans[k].laser_pose.isApprox(logs[0].scans[k].laser_pose, 0.0)) << k;
    EXPECT_EQ(other.warnings, logs[0].warnings);
  }
}

// ---------------------------------------------------------------------------
// Depth image sequences (TUM RGB-D, Redwood) and KITTI odometry.

namespace {

/// A fresh folder for a synthetic dataset.
class DatasetFolder : public obsgroup::test::TempFolderTest {
 protected:
  void text(const std::string& name, const std::string& content) const {
    fs::create_directories((dir_ / name).parent_path());
    std::ofstream(dir_ / name, std::ios::binary) << content;
  }
  std::string png(const std::string& name, int width, int height, const std::vector<std::uint16_t>& values,
                  int bit_depth = 16, int colour = PNG_COLOR_TYPE_GRAY) const {
    fs::create_directories((dir_ / name).parent_path());
    EXPECT_TRUE(obsgroup::test::writePng((dir_ / name).string(), width, height, values, bit_depth, colour));
    return (dir_ / name).string();
  }
  std::string errorOf(const std::function<void()>& call) const {
    try {
      call();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
};

/// A 4x3 image: depth 1000 + 100 v + 10 u units, pixel (1, 1) no return.
std::vector<std::uint16_t> ramp() {
  std::vector<std::uint16_t> values;
  for (int v = 0; v < 3; ++v)
    for (int u = 0; u < 4; ++u) values.push_back(u == 1 && v == 1 ? 0 : std::uint16_t(1000 + 100 * v + 10 * u));
  return values;
}

std::string tumLine(double t, const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  std::ostringstream s;
  s.precision(17);
  s << t << ' ' << p.x() << ' ' << p.y() << ' ' << p.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' '
    << q.w() << '\n';
  return s.str();
}

}  // namespace

TEST_F(DatasetFolder, DepthPngBackProjectsThroughThePinholeModel) {
  const std::string file = png("depth/0.png", 4, 3, ramp());
  const DepthImage image = readDepthPng(file);
  ASSERT_EQ(image.width, 4);
  ASSERT_EQ(image.height, 3);
  EXPECT_EQ(image.values, ramp());
  const PinholeIntrinsics k{2.0, 3.0, 1.5, 1.0};
  const auto cloud = backProject(image, k, 1000.0, std::nullopt, 1);
  ASSERT_EQ(cloud->size(), 11u);  // 12 pixels, one no return
  std::size_t n = 0;
  for (int v = 0; v < 3; ++v)
    for (int u = 0; u < 4; ++u) {
      if (u == 1 && v == 1) continue;
      const double d = (1000 + 100 * v + 10 * u) / 1000.0;
      const pcl::PointXYZ& p = (*cloud)[n++];
      EXPECT_FLOAT_EQ(p.x, float((u - 1.5) * d / 2.0)) << u << "," << v;
      EXPECT_FLOAT_EQ(p.y, float((v - 1.0) * d / 3.0)) << u << "," << v;
      EXPECT_FLOAT_EQ(p.z, float(d)) << u << "," << v;
    }
  // Deeper than --depth-max: no return. Stride 2: pixels (0,0) (2,0) (0,2) (2,2).
  EXPECT_EQ(backProject(image, k, 1000.0, 1.15, 1)->size(), 7u);  // rows 0 and 1
  const auto strided = backProject(image, k, 1000.0, std::nullopt, 2);
  ASSERT_EQ(strided->size(), 4u);
  EXPECT_FLOAT_EQ((*strided)[3].z, 1.22f);
}

TEST_F(DatasetFolder, DepthPngOfAnotherKindIsRefusedNamingIt) {
  const std::string grey8 = png("a.png", 2, 2, {1, 2, 3, 4}, 8);
  std::string message = errorOf([&] { readDepthPng(grey8); });
  EXPECT_NE(message.find("a.png: field 'IHDR': a 8-bit grey PNG; a depth image is 16-bit grey"), std::string::npos)
      << message;
  const std::string rgb16 = png("b.png", 1, 1, {1, 2, 3}, 16, PNG_COLOR_TYPE_RGB);
  message = errorOf([&] { readDepthPng(rgb16); });
  EXPECT_NE(message.find("b.png: field 'IHDR': a 16-bit RGB PNG"), std::string::npos) << message;
  text("c.png", "not a png at all");
  message = errorOf([&] { readDepthPng((dir_ / "c.png").string()); });
  EXPECT_NE(message.find("c.png: not a PNG file"), std::string::npos) << message;
  // Cut short anywhere: an error, never a crash.
  std::ifstream in(png("d.png", 4, 3, ramp()), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (std::size_t size = 8; size + 12 < bytes.size(); ++size) {
    message = errorOf([&] { decodeDepthPng(std::string_view(bytes).substr(0, size), "cut.png"); });
    EXPECT_EQ(message.rfind("cut.png: ", 0), 0u) << size << ": " << message;
  }
}

TEST_F(DatasetFolder, TumLayoutMatchesPosesByNearestTimestamp) {
  png("depth/1.000000.png", 4, 3, ramp());
  png("depth/1.500000.png", 4, 3, ramp());
  png("depth/2.000000.png", 4, 3, ramp());
  text("depth.txt", "# depth maps\n1.000000 depth/1.000000.png\n1.500000 depth/1.500000.png\n"
                    "2.000000 depth/2.000000.png\n");
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
  text("groundtruth.txt", "# timestamp tx ty tz qx qy qz qw\n" + tumLine(2.004, {3, 0, 0}, q) +
                              tumLine(0.99, {1, 0, 0}, q) + tumLine(0.995, {1.5, 0, 0}, q) +
                              tumLine(1.55, {2, 0, 0}, q));
  ASSERT_EQ(detectDepthLayout(dir_.string()), DepthLayout::TumRgbd);
  DepthOptions options;
  DepthSequence sequence = loadDepthSequence(dir_.string(), DepthLayout::TumRgbd, options);
  EXPECT_EQ(sequence.depth_scale, 5000.0);
  ASSERT_EQ(sequence.observations.size(), 2u);  // 1.5 is 0.05 s from its nearest pose
  EXPECT_EQ(sequence.skipped, 1u);
  EXPECT_DOUBLE_EQ(sequence.observations[0].pose.translation().x(), 1.5);  // 0.995 is nearer 1.0 than 0.99
  EXPECT_DOUBLE_EQ(sequence.observations[1].pose.translation().x(), 3.0);
  // The groundtruth is the optical frame's; the observation is in the body
  // frame (x forward, z up): pose * kOpticalInBody is the optical pose again.
  EXPECT_TRUE((sequence.observations[1].pose.linear() * kOpticalInBody).isApprox(q.toRotationMatrix(), 1e-12));
  EXPECT_NE(sequence.labels[1].find("2.000000.png"), std::string::npos);
  EXPECT_FLOAT_EQ((*sequence.observations[0].cloud)[0].x, 0.2f);  // 1000 / 5000, straight ahead
  ASSERT_EQ(sequence.warnings.size(), 1u);
  EXPECT_NE(sequence.warnings[0].find("1 of 3 depth frames have no pose"), std::string::npos) << sequence.warnings[0];
  options.max_time_difference = 0.1;
  EXPECT_EQ(loadDepthSequence(dir_.string(), DepthLayout::TumRgbd, options).observations.size(), 3u);
  options.max_time_difference = 0.001;
  const std::string message = errorOf([&] { loadDepthSequence(dir_.string(), DepthLayout::TumRgbd, options); });
  EXPECT_NE(message.find("no pose within"), std::string::npos) << message;
}

TEST_F(DatasetFolder, TumLayoutErrorsNameTheFileAndLine) {
  png("depth/1.png", 4, 3, ramp());
  text("groundtruth.txt", tumLine(1, {0, 0, 0}, Eigen::Quaterniond::Identity()));
  text("depth.txt", "1.0 depth/1.png\n2.0 depth/missing.png\n");
  std::string message = errorOf([&] { loadDepthSequence(dir_.string(), DepthLayout::TumRgbd, {}); });
  EXPECT_NE(message.find("depth.txt:2: field 'filename': "), std::string::npos) << message;
  EXPECT_NE(message.find("missing.png: no such file"), std::string::npos) << message;
  text("depth.txt", "1.0 depth/1.png\nabc depth/1.png\n");
  message = errorOf([&] { loadDepthSequence(dir_.string(), DepthLayout::TumRgbd, {}); });
  EXPECT_NE(message.find("depth.txt:2: field 'timestamp': 'abc' is not a number"), std::string::npos) << message;
  png("depth/2.png", 2, 2, {1, 2, 3, 4}, 8);
  text("depth.txt", "1.0 depth/2.png\n");
  message = errorOf([&] { loadDepthSequence(dir_.string(), DepthLayout::TumRgbd, {}); });
  EXPECT_NE(message.find("2.png: field 'IHDR': a 8-bit grey PNG"), std::string::npos) << message;
}

namespace {

std::string redwoodBlock(int i, const Eigen::Matrix4d& m) {
  std::ostringstream s;
  s.precision(17);
  s << i << ' ' << i << ' ' << i + 1 << '\n';
  for (int r = 0; r < 4; ++r) s << m(r, 0) << ' ' << m(r, 1) << ' ' << m(r, 2) << ' ' << m(r, 3) << '\n';
  return s.str();
}

}  // namespace

TEST_F(DatasetFolder, ARedwoodWorldWithYUpIsTurnedToPutItOnZ) {
  png("depth/0.png", 4, 3, ramp());
  png("depth/1.png", 4, 3, ramp());
  // Upright cameras in a world with +y up: the image's y axis (down) is the
  // world's -y; one looks along -z, the other along +x.
  Eigen::Matrix4d a = Eigen::Matrix4d::Identity(), b = Eigen::Matrix4d::Identity();
  a.topLeftCorner<3, 3>() << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  b.topLeftCorner<3, 3>() << 0, 0, 1, 0, -1, 0, 1, 0, 0;
  a.topRightCorner<3, 1>() << 1, 1.5, 2;
  text("trajectory.log", redwoodBlock(0, a) + redwoodBlock(1, b));
  EXPECT_EQ(camerasUpAxis({Eigen::Isometry3d(a), Eigen::Isometry3d(b)}), UpAxis::PlusY);
  const DepthSequence turned = loadDepthSequence(dir_.string(), DepthLayout::Redwood, {});
  EXPECT_EQ(turned.up, UpAxis::PlusY);
  ASSERT_EQ(turned.warnings.size(), 1u);
  EXPECT_NE(turned.warnings[0].find("its world has y up (from the cameras' image axes"), std::string::npos)
      << turned.warnings[0];
  for (const auto& o : turned.observations)  // the body frames stand upright in the turned world
    EXPECT_TRUE(o.pose.linear().col(2).isApprox(Eigen::Vector3d::UnitZ(), 1e-12)) << o.pose.matrix();
  EXPECT_NEAR(turned.observations[0].pose.translation().z(), 1.5, 1e-12);  // the camera's height
  // Level: its forward axis lies in the horizontal plane.
  EXPECT_NEAR(turned.observations[0].pose.linear().col(0).z(), 0.0, 1e-12);
  DepthOptions keep;
  keep.up = UpAxis::PlusZ;
  const DepthSequence kept = loadDepthSequence(dir_.string(), DepthLayout::Redwood, keep);
  EXPECT_TRUE(kept.warnings.empty());
  EXPECT_NEAR(kept.observations[0].pose.translation().z(), 2.0, 1e-12);
  for (UpAxis axis : {UpAxis::PlusX, UpAxis::MinusX, UpAxis::PlusY, UpAxis::MinusY, UpAxis::MinusZ, UpAxis::PlusZ}) {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    const int index = axis == UpAxis::PlusX || axis == UpAxis::MinusX ? 0 : axis == UpAxis::PlusY || axis == UpAxis::MinusY ? 1 : 2;
    v[index] = axis == UpAxis::MinusX || axis == UpAxis::MinusY || axis == UpAxis::MinusZ ? -1 : 1;
    EXPECT_TRUE((upToZ(axis) * v).isApprox(Eigen::Vector3d::UnitZ(), 1e-12)) << toString(axis);
  }
}

TEST_F(DatasetFolder, RedwoodLayoutPosesEachImageInNameOrder) {
  png("depth/2.png", 4, 3, ramp());
  png("depth/10.png", 4, 3, std::vector<std::uint16_t>(12, 2000));
  Eigen::Matrix4d a = Eigen::Matrix4d::Identity(), b = Eigen::Matrix4d::Identity();
  a.topRightCorner<3, 1>() << 1, 2, 3;
  b.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  b.topRightCorner<3, 1>() << -1, 0, 0.5;
  text("trajectory.log", redwoodBlock(0, a) + redwoodBlock(1, b));
  ASSERT_EQ(detectDepthLayout(dir_.string()), DepthLayout::Redwood);
  DepthOptions as_given;  // these cameras look along z with y down: auto would turn -y up onto z
  as_given.up = UpAxis::PlusZ;
  const DepthSequence sequence = loadDepthSequence(dir_.string(), DepthLayout::Redwood, as_given);
  EXPECT_EQ(sequence.depth_scale, 1000.0);
  ASSERT_EQ(sequence.observations.size(), 2u);
  Eigen::Matrix4d body = Eigen::Matrix4d::Identity();
  body.topLeftCorner<3, 3>() = kOpticalInBody.transpose();
  EXPECT_TRUE(sequence.observations[0].pose.matrix().isApprox(a * body, 1e-12));
  EXPECT_TRUE(sequence.observations[1].pose.matrix().isApprox(b * body, 1e-12));
  EXPECT_NE(sequence.labels[1].find("10.png"), std::string::npos);  // 2 before 10
  EXPECT_EQ(sequence.observations[1].cloud->size(), 12u);
  EXPECT_FLOAT_EQ((*sequence.observations[1].cloud)[0].x, 2.0f);
  // The same point in the world as the optical frame's back-projection gives.
  const Eigen::Vector3f optical = backProject(readDepthPng((dir_ / "depth" / "10.png").string()), {}, 1000.0,
                                              std::nullopt, 1)->points[5].getVector3fMap();
  const Eigen::Vector3f body_point = (*sequence.observations[1].cloud)[5].getVector3fMap();
  EXPECT_TRUE((sequence.observations[1].pose * body_point.cast<double>())
                  .isApprox(Eigen::Isometry3d(b) * optical.cast<double>(), 1e-6));

  text("trajectory.log", redwoodBlock(0, a));
  std::string message = errorOf([&] { loadDepthSequence(dir_.string(), DepthLayout::Redwood, {}); });
  EXPECT_NE(message.find("trajectory.log: 1 trajectory entries for 2 depth images"), std::string::npos) << message;
  text("trajectory.log", redwoodBlock(0, a) + "1 1 2\n1 0 0 0\n0 1 0 0\n0 0 1 0\n");
  message = errorOf([&] { loadDepthSequence(dir_.string(), DepthLayout::Redwood, {}); });
  EXPECT_NE(message.find("trajectory.log:6: frame 1: the block has 3 matrix rows, expected 4"), std::string::npos)
      << message;
  text("trajectory.log", redwoodBlock(0, a) + "1 1 2\n1 0 0 0\n0 1 0 0\n0 0 1 x\n0 0 0 1\n");
  message = errorOf([&] { loadDepthSequence(dir_.string(), DepthLayout::Redwood, {}); });
  EXPECT_NE(message.find("trajectory.log:9: field 'm34': 'x' is not a number"), std::string::npos) << message;
  text("trajectory.log", redwoodBlock(0, a) + "1 1 2\n2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  message = errorOf([&] { loadDepthSequence(dir_.string(), DepthLayout::Redwood, {}); });
  EXPECT_NE(message.find("trajectory.log:7: frame 1: the 3x3 part is not a rotation"), std::string::npos) << message;
  text("trajectory.log", redwoodBlock(0, a) + "1 0 0 0\n");
  message = errorOf([&] { loadDepthSequence(dir_.string(), DepthLayout::Redwood, {}); });
  EXPECT_NE(message.find("trajectory.log:6: frame 1: a block starts with a line of 3 numbers"), std::string::npos)
      << message;
}

namespace {

void writeBin(const fs::path& file, const std::vector<float>& values) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(values.data()),
                                              std::streamsize(values.size() * sizeof(float)));
}

}  // namespace

TEST_F(DatasetFolder, KittiLidarPosesAreCameraPosesInTheFirstVelodyneFrame) {
  writeBin(dir_ / "velodyne" / "000000.bin", {1, 2, 3, 0.5f, 4, 5, 6, 0.25f});
  writeBin(dir_ / "velodyne" / "000001.bin", {7, 8, 9, 1});
  // The usual Tr: velodyne x forward, y left, z up to camera z forward, x right, y down; plus an offset.
  text("calib.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: 0 -1 0 -0.01 0 0 -1 -0.08 1 0 0 -0.27\n");
  text("poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n0 0 1 2 0 1 0 0 -1 0 0 5\n");
  ASSERT_TRUE(isKittiFolder(dir_.string()));
  const KittiSequence sequence = loadKittiSequence(dir_.string(), std::nullopt);
  ASSERT_EQ(sequence.observations.size(), 2u);
  Eigen::Matrix4d tr;
  tr << 0, -1, 0, -0.01, 0, 0, -1, -0.08, 1, 0, 0, -0.27, 0, 0, 0, 1;
  Eigen::Matrix4d cam1;
  cam1 << 0, 0, 1, 2, 0, 1, 0, 0, -1, 0, 0, 5, 0, 0, 0, 1;
  // Tr^-1 P Tr: the first scan is the world's origin, z up; the camera's
  // turn about its y axis (down) is a turn about the lidar's -z.
  EXPECT_TRUE(sequence.observations[0].pose.matrix().isApprox(Eigen::Matrix4d::Identity(), 1e-12));
  EXPECT_TRUE(sequence.observations[1].pose.matrix().isApprox(tr.inverse() * cam1 * tr, 1e-12));
  EXPECT_NEAR(sequence.observations[1].pose.linear()(2, 2), 1.0, 1e-12);  // still upright
  EXPECT_NEAR(sequence.observations[1].pose.translation().z(), 0.0, 1e-12);  // on the same ground
  ASSERT_EQ(sequence.observations[0].cloud->size(), 2u);
  const pcl::PointXYZI& p = (*sequence.observations[0].cloud)[1];
  EXPECT_EQ(p.x, 4.0f);
  EXPECT_EQ(p.y, 5.0f);
  EXPECT_EQ(p.z, 6.0f);
  EXPECT_EQ(p.intensity, 0.25f);

  std::ofstream(dir_ / "velodyne" / "000001.bin", std::ios::binary | std::ios::app) << "abc";
  std::string message = errorOf([&] { loadKittiSequence(dir_.string(), std::nullopt); });
  EXPECT_NE(message.find("000001.bin: 19 bytes, not a multiple of 16"), std::string::npos) << message;
  writeBin(dir_ / "velodyne" / "000001.bin", {7, 8, 9, 1});
  text("calib.txt", "Tr: 1 0 0\n");
  message = errorOf([&] { loadKittiSequence(dir_.string(), std::nullopt); });
  EXPECT_NE(message.find("calib.txt:1: field 'Tr': 3 values, expected 12"), std::string::npos) << message;
  fs::remove(dir_ / "calib.txt");
  message = errorOf([&] { loadKittiSequence(dir_.string(), std::nullopt); });
  EXPECT_NE(message.find("calib.txt: no such file"), std::string::npos) << message;
  text("calib.txt", "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  text("poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
  message = errorOf([&] { loadKittiSequence(dir_.string(), std::nullopt); });
  EXPECT_NE(message.find("poses.txt: 1 poses for 2 velodyne scans"), std::string::npos) << message;
}

TEST(Readers, PoseFormatIsToldByTheColumnCount) {
  EXPECT_EQ(detectPoseFormat("# c\n\n1 0 0 0 0 0 0 1\n", "a.txt"), PoseFormat::Tum);
  EXPECT_EQ(detectPoseFormat("1 0 0 0 0 1 0 0 0 0 1 0\n", "a.txt"), PoseFormat::Kitti);
  try {
    detectPoseFormat("# c\n1 2 3\n", "a.txt");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a.txt:2: a pose line has 3 values"), std::string::npos) << e.what();
  }
  const auto poses = parseStampedPoses("5.5 1 2 3 0 0 0 1\n6 0 0 0 0 0 0 1\n", "a.txt");
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_DOUBLE_EQ(poses[0].stamp, 5.5);
  EXPECT_DOUBLE_EQ(poses[0].pose.translation().z(), 3.0);
  EXPECT_EQ(nearestStamp(poses, 5.6, 0.2), std::optional<std::size_t>(0));
  EXPECT_EQ(nearestStamp(poses, 5.9, 0.2), std::optional<std::size_t>(1));
  EXPECT_EQ(nearestStamp(poses, 5.75, 0.2), std::nullopt);
  EXPECT_EQ(nearestStamp(poses, 100, 0.2), std::nullopt);
}

// A header declaring more pixels than its data could ever inflate to is
// refused before the image is allocated (8000 x 8000 pixels from 90 bytes).
TEST_F(DatasetFolder, APngHeaderLargerThanItsDataIsRefusedBeforeAllocating) {
  std::ifstream in(png("small.png", 4, 3, ramp()), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (int k = 0; k < 2; ++k) {  // width, height: 8000, big-endian
    bytes[16 + 4 * k] = 0;
    bytes[17 + 4 * k] = 0;
    bytes[18 + 4 * k] = char(8000 >> 8);
    bytes[19 + 4 * k] = char(8000 & 0xff);
  }
  const unsigned long crc = crc32(0, reinterpret_cast<const Bytef*>(bytes.data() + 12), 17);
  for (int k = 0; k < 4; ++k) bytes[29 + k] = char((crc >> (24 - 8 * k)) & 0xff);
  const std::string message = errorOf([&] { decodeDepthPng(bytes, "big.png"); });
  EXPECT_NE(message.find("big.png: cannot decode the PNG: 8000x8000 pixels: more than obsgroup reads or than the "
                         "file can hold"),
            std::string::npos)
      << message;
}

// ---------------------------------------------------------------------------
// Dense frames reduced as they are read.

namespace {

/// The voxel keys of a cloud at `leaf`, as pcl::VoxelGrid numbers them.
std::set<std::tuple<long, long, long>> voxelKeys(const pcl::PointCloud<pcl::PointXYZ>& cloud, double leaf) {
  std::set<std::tuple<long, long, long>> keys;
  for (const auto& p : cloud)
    keys.emplace(long(std::floor(p.x / leaf)), long(std::floor(p.y / leaf)), long(std::floor(p.z / leaf)));
  return keys;
}

pcl::PointCloud<pcl::PointXYZ> scattered(std::size_t count, float spread, unsigned seed) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  std::srand(seed);
  for (std::size_t k = 0; k < count; ++k)
    cloud.push_back({spread * float(std::rand()) / float(RAND_MAX), spread * float(std::rand()) / float(RAND_MAX),
                     0.5f * spread * float(std::rand()) / float(RAND_MAX)});
  return cloud;
}

}  // namespace

TEST(FrameReading, EachOccupiedVoxelBecomesOnePointAndAgainChangesNothing) {
  pcl::PointCloud<pcl::PointXYZ> cloud = scattered(20000, 2.0f, 1);
  cloud.push_back({std::nanf(""), 0.0f, 0.0f});
  const auto keys = voxelKeys(scattered(20000, 2.0f, 1), 0.1);
  const FrameReading reduction{0.1, 0, {}};
  ASSERT_TRUE(reduceFrame(cloud, cloud.size(), reduction));
  EXPECT_EQ(cloud.size(), keys.size());           // one point per occupied voxel, the NaN gone
  EXPECT_EQ(voxelKeys(cloud, 0.1), keys);          // each inside its own voxel
  EXPECT_EQ(cloud.height, 1u);
  const pcl::PointCloud<pcl::PointXYZ> once = cloud;
  ASSERT_TRUE(reduceFrame(cloud, cloud.size(), reduction));
  ASSERT_EQ(cloud.size(), once.size());  // so the grouping's own filter at the same leaf is a no-op
}

TEST(FrameReading, OnlyDenseFramesAreReducedByDefault) {
  const FrameReading reduction = FrameReading::denseDefault();
  pcl::PointCloud<pcl::PointXYZ> cloud = scattered(5000, 2.0f, 2);
  EXPECT_FALSE(reduceFrame(cloud, kDenseFramePoints - 1, reduction));  // a light sensor: every point kept
  EXPECT_EQ(cloud.size(), 5000u);
  EXPECT_TRUE(reduceFrame(cloud, kDenseFramePoints, reduction));  // a dense one, whatever is left of it
  EXPECT_LT(cloud.size(), 5000u);
  EXPECT_FALSE(reduceFrame(cloud, 1000000, FrameReading{0.0, 0, {}}));  // --voxel 0 keeps everything
}

TEST(FrameReading, ACloudTooWideForVoxelGridIsFilteredInPartsWithTheSameVoxels) {
  // 4 km by 4 km by 400 m at 1 cm: far beyond VoxelGrid's 2^31 voxels, which
  // would hand the cloud back unfiltered.
  pcl::PointCloud<pcl::PointXYZ> cloud = scattered(3000, 0.05f, 3);
  for (const auto& p : scattered(3000, 0.05f, 4)) cloud.push_back({p.x + 4000.0f, p.y - 4000.0f, p.z + 400.0f});
  const auto keys = voxelKeys(cloud, 0.01);
  ASSERT_TRUE(reduceFrame(cloud, cloud.size(), FrameReading{0.01, 0, {}}));
  EXPECT_EQ(cloud.size(), keys.size());
  EXPECT_EQ(voxelKeys(cloud, 0.01), keys);
}

TEST(FrameReading, TheFirstFailingFrameIsReportedOnAnyNumberOfThreads) {
  const auto read = [](std::size_t k) {
    if (k == 7 || k == 30) throw InputError("frame " + std::to_string(k));
  };
  for (int threads : {1, 2, 4}) {
    omp_set_num_threads(threads);
    std::vector<std::size_t> progress;
    FrameReading reading;
    reading.progress = [&](std::size_t done, std::size_t total) {
      EXPECT_EQ(total, 50u);
      progress.push_back(done);
    };
    std::string message;
    try {
      readFramesInParallel(50, read, reading);
    } catch (const InputError& e) {
      message = e.what();
    }
    EXPECT_EQ(message, "frame 7") << threads << " threads";
    EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
    // --skip-bad-files: both left out, in frame order, the rest read.
    reading.skip_bad_files = true;
    progress.clear();
    const std::vector<SkippedFrame> skipped = readFramesInParallel(50, read, reading);
    ASSERT_EQ(skipped.size(), 2u) << threads << " threads";
    EXPECT_EQ(skipped[0].index, 7u);
    EXPECT_EQ(skipped[1].message, "frame 30");
    EXPECT_EQ(progress.back(), 50u);
    // Anything but a bad file still ends the read.
    EXPECT_THROW(readFramesInParallel(50, [](std::size_t k) { if (k == 3) throw std::bad_alloc(); }, reading),
                 std::bad_alloc);
  }
  omp_set_num_threads(omp_get_num_procs());
  std::vector<std::size_t> read_frames(100, 0);
  readFramesInParallel(100, [&](std::size_t k) { read_frames[k] = k + 1; }, {});
  for (std::size_t k = 0; k < read_frames.size(); ++k) EXPECT_EQ(read_frames[k], k + 1);
  std::vector<int> values{0, 1, 2, 3, 4};
  eraseSkipped(values, {{1, "a"}, {4, "b"}});
  EXPECT_EQ(values, (std::vector<int>{0, 2, 3}));
  EXPECT_EQ(skippedWarning({}, 5), "");
  EXPECT_NE(skippedWarning({{1, "x.pcd: broken"}}, 5).find("left out 1 of 5 files that could not be read: x.pcd: broken"),
            std::string::npos);
  EXPECT_THROW(skippedWarning({{0, "a"}, {1, "b"}}, 2), InputError);
}

TEST_F(DatasetFolder, DepthFramesAreReducedAsTheyAreReadTheSameOnAnyNumberOfThreads) {
  // A 200 x 120 image (24,000 pixels: dense) of a wall 2 m away, three frames.
  const std::vector<std::uint16_t> wall(200 * 120, 2000);
  Eigen::Matrix4d a = Eigen::Matrix4d::Identity();
  std::string log;
  for (int k = 0; k < 3; ++k) {
    png("depth/" + std::to_string(k) + ".png", 200, 120, wall);
    a(0, 3) = 0.1 * k;
    log += redwoodBlock(k, a);
  }
  text("trajectory.log", log);
  DepthOptions options;
  options.up = UpAxis::PlusZ;
  options.intrinsics = {100.0, 100.0, 99.5, 59.5};
  const DepthSequence whole = loadDepthSequence(dir_.string(), DepthLayout::Redwood, options);
  EXPECT_EQ(whole.reduced, 0u);
  EXPECT_EQ(whole.observations[0].cloud->size(), 24000u);
  options.reduction = FrameReading::denseDefault();
  std::size_t calls = 0;
  options.reduction.progress = [&](std::size_t done, std::size_t total) {
    ++calls;
    EXPECT_LE(done, total);
  };
  std::vector<std::vector<float>> coordinates;
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    const DepthSequence reduced = loadDepthSequence(dir_.string(), DepthLayout::Redwood, options);
    EXPECT_EQ(reduced.reduced, 3u);
    ASSERT_EQ(reduced.observations.size(), 3u);
    // A 4 x 2.4 m patch of wall at 5 cm: about 80 x 48 voxels, not 24,000 points.
    EXPECT_LT(reduced.observations[0].cloud->size(), 5000u);
    EXPECT_GT(reduced.observations[0].cloud->size(), 3000u);
    std::vector<float> all;
    for (const auto& o : reduced.observations)
      for (const auto& p : *o.cloud) all.insert(all.end(), {p.x, p.y, p.z});
    coordinates.push_back(all);
  }
  omp_set_num_threads(omp_get_num_procs());
  EXPECT_EQ(coordinates[0], coordinates[1]);
  EXPECT_EQ(calls, 6u);
}

TEST(FrameReading, AMessageCloudIsReducedToTheSameVoxelsKeepingItsFields) {
  for (float spread : {2.0f, 0.0f}) {  // 0: also two clusters 4 km apart, filtered in parts
    pcl::PointCloud<pcl::PointXYZI> cloud;
    for (const auto& p : scattered(30000, spread > 0 ? spread : 0.05f, 5)) cloud.push_back({p.x, p.y, p.z, 0.5f});
    if (spread == 0.0f)
      for (const auto& p : scattered(3000, 0.05f, 6)) cloud.push_back({p.x + 4000.0f, p.y, p.z, 0.25f});
    cloud.push_back({std::nanf(""), 0.0f, 0.0f, 1.0f});
    pcl::PCLPointCloud2 message;
    pcl::toPCLPointCloud2(cloud, message);
    const double leaf = spread > 0 ? 0.1 : 0.001;
    const FrameReading reduction{leaf, kDenseFramePoints, {}};
    ASSERT_TRUE(reduceFrame(message, reduction));
    pcl::PointCloud<pcl::PointXYZI> from_message;
    pcl::fromPCLPointCloud2(message, from_message);
    ASSERT_TRUE(reduceFrame(cloud, cloud.size(), reduction));
    pcl::PointCloud<pcl::PointXYZ> a, b;
    pcl::copyPointCloud(from_message, a);
    pcl::copyPointCloud(cloud, b);
    EXPECT_EQ(message.width * message.height, cloud.size());
    EXPECT_EQ(voxelKeys(a, leaf), voxelKeys(b, leaf));
    bool intensity = false;
    for (const auto& field : message.fields) intensity = intensity || field.name == "intensity";
    EXPECT_TRUE(intensity);
    for (const auto& p : from_message) EXPECT_TRUE(p.intensity == 0.5f || p.intensity == 0.25f);
  }
  // A light message, or one without float coordinates, is left as it is.
  pcl::PCLPointCloud2 light;
  pcl::toPCLPointCloud2(scattered(100, 1.0f, 7), light);
  EXPECT_FALSE(reduceFrame(light, FrameReading::denseDefault()));
  pcl::PCLPointCloud2 no_z = light;
  no_z.fields.pop_back();
  EXPECT_FALSE(reduceFrame(no_z, FrameReading{0.1, 0, {}}));
}

TEST(Readers, BeamDirectionsGiveScanToCloudsPointsBitForBit) {
  const CarmenLog log = readCarmenLog(std::string(OBSGROUP_DATA_DIR) + "/real/sena_odometry/sena_odometry.clf");
  const BeamDirections beams(log.scans.front());
  for (const LaserScan& scan : log.scans) {
    const auto expected = scanToCloud(scan);
    const auto cloud = beams.cloudOf(scan);
    ASSERT_EQ(cloud->size(), expected->size());
    ASSERT_EQ(cloud->width, expected->width);
    for (std::size_t i = 0; i < cloud->size(); ++i) {
      ASSERT_EQ((*cloud)[i].x, (*expected)[i].x);
      ASSERT_EQ((*cloud)[i].y, (*expected)[i].y);
      ASSERT_EQ((*cloud)[i].z, 0.0f);
    }
  }
  // A scan of another geometry: computed on its own, not from the table.
  const CarmenLog turn = parseCarmenLog(robotLaser(-kPi, 2 * kPi, 2 * kPi / 360, 360, 5.0), "turn.clf");
  const auto other = beams.cloudOf(turn.scans[0]);
  const auto expected = scanToCloud(turn.scans[0]);
  ASSERT_EQ(other->size(), expected->size());
  for (std::size_t i = 0; i < other->size(); ++i) EXPECT_EQ((*other)[i].x, (*expected)[i].x);
}
