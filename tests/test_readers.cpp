// The readers on their own: in-memory parsing, and the inputs that fuzzing
// found mishandled, each pinned with its expected outcome.
#include "carmen_reader.h"
#include "errors.h"
#include "pcd_sequence.h"
#include "pose_file.h"
#include "temp_folder.h"

#include <pcl/point_types.h>

#include <gtest/gtest.h>
#include <zlib.h>

#include <unistd.h>

#include <cmath>
#include <sstream>

#include <filesystem>
#include <fstream>
#include <map>

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
