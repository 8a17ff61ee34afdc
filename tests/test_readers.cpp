// The readers on their own: in-memory parsing, and the inputs that fuzzing
// found mishandled, each pinned with its expected outcome.
#include "carmen_reader.h"
#include "errors.h"
#include "pcd_sequence.h"
#include "pose_file.h"
#include "temp_folder.h"

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <unistd.h>

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
