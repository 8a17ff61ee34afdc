// End-to-end tests of `obsgroup partition` on the shipped data, and its
// behaviour on bad input: a one-line error naming file, line and field, exit
// code 2 for usage errors and 3 for input errors.
#include "floor_plan.h"
#include "png_writer.h"
#include "temp_folder.h"

#include <cairo.h>
#include <nlohmann/json.hpp>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <pty.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <cctype>
#include <sstream>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <ctime>
#include <iomanip>
#include <iterator>

namespace fs = std::filesystem;

namespace {

const std::string kData = OBSGROUP_DATA_DIR;

struct Result {
  int code = -1;
  std::string err;
  std::string out;
};

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void writeFile(const fs::path& path, const std::string& content) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << content;
}

/// A fresh folder per test (dir_), removed afterwards.
class Cli : public obsgroup::test::TempFolderTest {
 protected:

  /// `environment`: assignments put before the command, e.g. "GLIBC_TUNABLES=".
  Result run(const std::string& args, const std::string& environment = "") const {
    const fs::path err = dir_ / "stderr.txt", out = dir_ / "stdout.txt";
    const std::string command =
        environment + " " + std::string(OBSGROUP_EXE) + " " + args + " > " + out.string() + " 2> " + err.string();
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readFile(err), readFile(out)};
  }
};

nlohmann::json readJson(const fs::path& path) { return nlohmann::json::parse(readFile(path)); }

void expectValidPng(const fs::path& path) {
  const std::string bytes = readFile(path);
  ASSERT_GT(bytes.size(), 8u) << path;
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << path;
  cairo_surface_t* s = cairo_image_surface_create_from_png(path.c_str());
  EXPECT_EQ(cairo_surface_status(s), CAIRO_STATUS_SUCCESS) << path;
  EXPECT_GT(cairo_image_surface_get_width(s), 100) << path;
  cairo_surface_destroy(s);
}

void expectValidSvg(const fs::path& path) {
  const std::string text = readFile(path);
  EXPECT_EQ(text.rfind("<?xml", 0), 0u) << path;
  EXPECT_NE(text.find("<svg"), std::string::npos) << path;
  EXPECT_NE(text.find("</svg>"), std::string::npos) << path;
}

/// Checks the documented schema of partition.json and returns it.
nlohmann::json expectPartitionSchema(const fs::path& out, std::size_t observations) {
  const nlohmann::json p = readJson(out / "partition.json");
  EXPECT_EQ(p.at("observations").get<std::size_t>(), observations);
  std::vector<int> seen(observations, 0);
  for (const auto& group : p.at("groups")) {
    EXPECT_FALSE(group.empty());
    for (int i : group) ++seen.at(i);
  }
  for (std::size_t i = 0; i < observations; ++i) EXPECT_EQ(seen[i], 1) << "observation " << i;
  EXPECT_FALSE(p.at("splits").empty());
  for (const auto& s : p.at("splits")) {
    for (const char* key : {"id", "parent", "depth", "kind", "outcome", "accepted", "ncut", "members", "children"})
      EXPECT_TRUE(s.contains(key)) << key;
  }
  for (const char* key : {"sso", "voxel", "ncut_threshold", "split", "min_group_size", "max_depth", "diagonal",
                          "format", "map_voxel"})
    EXPECT_TRUE(p.at("parameters").contains(key)) << key;
  // Each model's own parameters, and only those.
  const bool points = p.at("parameters").at("sso") == "points";
  EXPECT_EQ(p.at("parameters").contains("delta"), points);
  EXPECT_EQ(p.at("parameters").contains("cell"), !points);
  EXPECT_EQ(p.at("parameters").contains("range"), !points);
  EXPECT_TRUE(p.at("input").is_string());
  // Every observation traceable to its source (and its stamp, where the format has one).
  EXPECT_EQ(p.at("sources").size(), observations);
  for (const auto& source : p.at("sources")) EXPECT_FALSE(source.get<std::string>().empty());
  EXPECT_TRUE(p.at("stamps").is_null() || p.at("stamps").size() == observations);
  EXPECT_EQ(p.at("place_ids").size(), p.at("groups").size());
  for (const char* key : {"load", "overlap", "graph", "partition", "outputs"})
    EXPECT_TRUE(p.at("timing_s").at(key).is_number()) << key;
  return p;
}

/// places.json/.geojson, the label map and the occupancy map agree with
/// partition.json and with each other.
void expectPlaces(const fs::path& out, const nlohmann::json& partition) {
  const nlohmann::json places = readJson(out / "places.json");
  const auto& ids = partition.at("place_ids");
  ASSERT_EQ(ids.size(), partition.at("groups").size());
  ASSERT_EQ(places.at("places").size(), ids.size());
  std::map<int, std::set<int>> neighbours;
  for (std::size_t g = 0; g < ids.size(); ++g) {
    const auto& place = places.at("places")[g];
    EXPECT_EQ(place.at("id"), ids[g]);
    EXPECT_EQ(place.at("members"), partition.at("groups")[g]);
    EXPECT_GT(place.at("area_m2").get<double>(), 0.0);
    EXPECT_EQ(place.at("bbox").size(), 4u);
    for (const auto& ring : place.at("outline")) EXPECT_GE(ring.size(), 4u);
    neighbours[place.at("id").get<int>()] = place.at("neighbours").get<std::set<int>>();
  }
  for (const auto& door : places.at("doors")) {
    const int a = door.at("places")[0], b = door.at("places")[1];
    EXPECT_TRUE(neighbours[a].count(b) && neighbours[b].count(a)) << door.dump();
    EXPECT_LE(door.at("width_m").get<double>(), 2.0);
  }
  const nlohmann::json geo = readJson(out / "places.geojson");
  EXPECT_EQ(geo.at("type"), "FeatureCollection");
  EXPECT_EQ(geo.at("features").size(), places.at("places").size() + places.at("doors").size());
  // The label map: map_server's YAML naming a PNG of the grid's size.
  const nlohmann::json& grid = places.at("grid");
  const std::string yaml = readFile(out / "places.yaml");
  EXPECT_NE(yaml.find("image: places.png\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("mode: raw\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("origin: ["), std::string::npos) << yaml;
  const std::string png = readFile(out / "places.png");
  ASSERT_GT(png.size(), 25u);
  const auto big_endian = [&png](std::size_t at) {
    return (unsigned(std::uint8_t(png[at])) << 24) | (unsigned(std::uint8_t(png[at + 1])) << 16) |
           (unsigned(std::uint8_t(png[at + 2])) << 8) | unsigned(std::uint8_t(png[at + 3]));
  };
  EXPECT_EQ(big_endian(16), grid.at("width").get<unsigned>());
  EXPECT_EQ(big_endian(20), grid.at("height").get<unsigned>());
  EXPECT_EQ(int(png[24]), 8);  // bit depth: every id below 255
  const std::string pgm = readFile(out / "occupancy.pgm");
  const std::string header = "P5\n" + std::to_string(grid.at("width").get<int>()) + " " +
                             std::to_string(grid.at("height").get<int>()) + "\n255\n";
  EXPECT_EQ(pgm.substr(0, header.size()), header);
  EXPECT_EQ(pgm.size(), header.size() + grid.at("width").get<std::size_t>() * grid.at("height").get<std::size_t>());
  EXPECT_NE(readFile(out / "occupancy.yaml").find("image: occupancy.pgm\n"), std::string::npos);
  // The labelled whole map reloads in PCL with the place ids as labels.
  pcl::PointCloud<pcl::PointXYZL> labelled;
  ASSERT_EQ(pcl::io::loadPCDFile((out / "map_labelled.pcd").string(), labelled), 0);
  EXPECT_EQ(labelled.size(), partition.at("statistics").at("local_map_points").get<std::size_t>());
  const std::set<int> id_set = ids.get<std::set<int>>();
  std::set<int> labels;
  for (const auto& p : labelled.points) labels.insert(int(p.label));
  EXPECT_TRUE(std::includes(id_set.begin(), id_set.end(), labels.begin(), labels.end()));
  EXPECT_FALSE(labels.empty());
  // Map by map in group order: each local map's points moved by its pose
  // (local_maps/poses.txt), labelled with its place's id.
  std::ifstream poses(out / "local_maps" / "poses.txt");
  std::string line;
  std::getline(poses, line);  // the comment
  std::size_t at = 0;
  for (std::size_t g = 0; g < ids.size(); ++g) {
    std::size_t group = 0;
    double x, y, z, qx, qy, qz, qw;
    ASSERT_TRUE(poses >> group >> x >> y >> z >> qx >> qy >> qz >> qw);
    ASSERT_EQ(group, g);
    const Eigen::Isometry3f pose = (Eigen::Translation3d(x, y, z) * Eigen::Quaterniond(qw, qx, qy, qz)).cast<float>();
    char name[32];
    std::snprintf(name, sizeof name, "group_%03zu.pcd", g);
    pcl::PointCloud<pcl::PointXYZ> map;
    ASSERT_EQ(pcl::io::loadPCDFile((out / "local_maps" / name).string(), map), 0) << name;
    ASSERT_LE(at + map.size(), labelled.size());
    for (const auto& p : map.points) {
      const pcl::PointXYZL& q = labelled.points[at++];
      EXPECT_EQ(int(q.label), ids[g].get<int>());
      EXPECT_LT((q.getVector3fMap() - pose * p.getVector3fMap()).norm(), 1e-4f) << name;
    }
  }
  EXPECT_EQ(at, labelled.size());
}

void expectAllOutputs(const fs::path& out, const nlohmann::json& partition) {
  expectPlaces(out, partition);
  const std::size_t groups = partition.at("groups").size();
  for (std::size_t g = 0; g < groups; ++g) {
    char name[32];
    std::snprintf(name, sizeof name, "group_%03zu.pcd", g);
    pcl::PointCloud<pcl::PointXYZ> map;
    EXPECT_EQ(pcl::io::loadPCDFile((out / "local_maps" / name).string(), map), 0) << name;
  }
  // Exactly one map and one picture per group, and the poses: nothing else.
  std::set<std::string> expected{"poses.txt"}, written;
  for (std::size_t g = 0; g < groups; ++g) {
    char name[32];
    std::snprintf(name, sizeof name, "group_%03zu.png", g);
    expectValidPng(out / "local_maps" / name);
    expected.insert(name);
    std::snprintf(name, sizeof name, "group_%03zu.pcd", g);
    expected.insert(name);
  }
  for (const auto& entry : fs::directory_iterator(out / "local_maps")) written.insert(entry.path().filename().string());
  EXPECT_EQ(written, expected);
  const nlohmann::json topology = readJson(out / "topology.json");
  EXPECT_EQ(topology.at("nodes").size(), groups);
  for (const auto& arc : topology.at("arcs")) {
    EXPECT_LT(arc.at("from").get<int>(), arc.at("to").get<int>());
    EXPECT_GT(arc.at("pairs").get<int>(), 0);
    EXPECT_GE(arc.at("spread").at("translation_m").get<double>(), 0.0);
    for (const char* key : {"x", "y", "z", "qw", "qx", "qy", "qz"}) EXPECT_TRUE(arc.at("transform").contains(key));
  }
  // Each local map is written in its reference's frame, with the reference's pose as VIEWPOINT.
  for (std::size_t g = 0; g < groups; ++g) {
    const auto& node = topology.at("nodes").at(g);
    EXPECT_EQ(node.at("members"), partition.at("groups").at(g));
    EXPECT_EQ(node.at("member_poses").size(), node.at("members").size());
    char name[32];
    std::snprintf(name, sizeof name, "group_%03zu.pcd", g);
    pcl::PointCloud<pcl::PointXYZ> map;
    pcl::io::loadPCDFile((out / "local_maps" / name).string(), map);
    EXPECT_NEAR(map.sensor_origin_.x(), node.at("pose").at("x").get<double>(), 1e-3);
    EXPECT_NEAR(map.sensor_origin_.y(), node.at("pose").at("y").get<double>(), 1e-3);
  }
  const std::string dot = readFile(out / "topology.dot");
  EXPECT_EQ(dot.rfind("graph topology {", 0), 0u);
  EXPECT_EQ(dot.find("e-"), std::string::npos) << "labels are fixed-point";
  expectValidPng(out / "map.png");
  expectValidSvg(out / "map.svg");
  // The SVG's labels are text a reader can search and copy, not glyph outlines: every group's
  // number, and the legend.
  const std::string svg = readFile(out / "map.svg");
  for (std::size_t g = 0; g < partition.at("groups").size(); ++g)
    EXPECT_NE(svg.find(">" + std::to_string(g) + "</text>"), std::string::npos) << "group " << g;
  EXPECT_NE(svg.find("observation pose (thinned where dense)</text>"), std::string::npos);
  EXPECT_EQ(svg.find("<symbol"), std::string::npos) << "no glyph outlines";
  expectValidPng(out / "weights.png");
  expectValidPng(out / "fiedler.png");
  // The run committed its staging folder: none is left beside the results.
  for (const auto& entry : fs::directory_iterator(out.parent_path()))
    EXPECT_EQ(entry.path().filename().string().find(".obsgroup-staging-"), std::string::npos)
        << "left over: " << entry.path();
}

/// A CARMEN log line of a simulated scan, in FLASER or ROBOTLASER1 form.
std::string carmenLine(const std::string& kind, const obsgroup::sim::Pose2D& p, const std::vector<double>& ranges) {
  std::ostringstream line;
  line.precision(9);
  const double fov = 3.14159265358979323846;
  if (kind == "FLASER") {
    line << "FLASER " << ranges.size();
    for (double r : ranges) line << ' ' << r;
    line << ' ' << p.x << ' ' << p.y << ' ' << p.yaw << ' ' << p.x << ' ' << p.y << ' ' << p.yaw << " 1.0 host 1.0";
  } else {
    line << "ROBOTLASER1 0 " << -fov / 2 << ' ' << fov << ' ' << fov / (ranges.size() - 1) << " 30 0.01 0 "
         << ranges.size();
    for (double r : ranges) line << ' ' << r;
    line << " 0 " << p.x << ' ' << p.y << ' ' << p.yaw << ' ' << p.x << ' ' << p.y << ' ' << p.yaw
         << " 0 0 0 0 0 1.0 host 1.0";
  }
  return line.str() + "\n";
}

/// The same 24 simulated scans of the office as a CARMEN log.
std::string simulatedLog(const std::string& kind, const std::string& header = "") {
  const auto plan = obsgroup::sim::office();
  obsgroup::sim::LaserModel laser;
  // FLASER carries no maximum range: a PARAM line gives the simulator's 30 m.
  std::string log = (kind == "FLASER" ? "PARAM robot_front_laser_max 30 0 host 0\n" : "") + header;
  const auto route = obsgroup::sim::officeRoute(24);
  for (std::size_t k = 0; k < route.size(); ++k) log += carmenLine(kind, route[k], plan.scan(route[k], laser, k));
  return log;
}

/// A small valid CARMEN log whose line `line` (1-based) is replaced.
std::string logWithLine(int line, const std::string& replacement) {
  std::istringstream in(simulatedLog("ROBOTLASER1"));
  std::string out, text;
  for (int k = 1; std::getline(in, text); ++k) out += (k == line ? replacement : text) + "\n";
  return out;
}

}  // namespace

TEST_F(Cli, OfficeLogEndToEnd) {
  const Result r = run("partition " + kData + "/office_2d/office.clf -o " + (dir_ / "out").string());
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json p = expectPartitionSchema(dir_ / "out", 77);
  expectAllOutputs(dir_ / "out", p);

  // The user guide's sample is this run (scripts/readme-partition-sample.py):
  // its statistics, parameters and first groups are what the run gives.
  const std::string readme = readFile(fs::path(kData).parent_path() / "docs" / "usage.md");
  const std::size_t begin = readme.find("<!-- partition-json:begin -->");
  ASSERT_NE(begin, std::string::npos);
  const auto sampleObject = [&](const std::string& key) {
    const std::size_t at = readme.find("\"" + key + "\": {", begin);
    const std::size_t open = readme.find('{', at), close = readme.find("},\n", open);
    return nlohmann::json::parse(readme.substr(open, close + 1 - open));
  };
  EXPECT_EQ(sampleObject("statistics"), p.at("statistics")) << "regenerate with scripts/readme-partition-sample.py";
  EXPECT_EQ(sampleObject("parameters"), p.at("parameters")) << "regenerate with scripts/readme-partition-sample.py";
  std::string first_group = "\"groups\": [[";
  for (const auto& i : p.at("groups")[0]) first_group += std::to_string(i.get<int>()) + ", ";
  EXPECT_NE(readme.find(first_group.substr(0, first_group.size() - 2) + "]", begin), std::string::npos);
  EXPECT_EQ(p.at("parameters").at("laser"), "robotlaser");
  EXPECT_NE(r.err.find("77 observations"), std::string::npos) << r.err;

  // The groups follow the rooms: nearly every scan shares its group's majority room.
  std::map<int, std::string> room;
  std::ifstream rooms(kData + "/office_2d/rooms.txt");
  std::string line;
  while (std::getline(rooms, line))
    if (!line.empty() && line[0] != '#') {
      std::istringstream fields(line);
      int i;
      std::string name, rest;
      fields >> i >> name >> rest;
      room[i] = name + rest;
    }
  ASSERT_EQ(room.size(), 77u);
  int agreeing = 0;
  for (const auto& group : p.at("groups")) {
    std::map<std::string, int> votes;
    for (int i : group) ++votes[room[i]];
    int best = 0;
    for (const auto& [name, count] : votes) best = std::max(best, count);
    agreeing += best;
  }
  EXPECT_GE(agreeing, 70) << agreeing << " of 77 scans share their group's room";
}

TEST_F(Cli, DepthCameraSequenceWithViewpointsOrPoses) {
  const Result a = run("partition " + kData + "/office_3d/pcd -q -o " + (dir_ / "a").string());
  ASSERT_EQ(a.code, 0) << a.err;
  const nlohmann::json p = expectPartitionSchema(dir_ / "a", 40);
  expectAllOutputs(dir_ / "a", p);
  EXPECT_EQ(p.at("parameters").at("format"), "pcd");
  const Result b = run("partition " + kData + "/office_3d/pcd -q --poses " + kData + "/office_3d/poses.txt -o " +
                       (dir_ / "b").string());
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_EQ(readJson(dir_ / "b" / "partition.json").at("groups"), p.at("groups"));
}

namespace {

std::string shiftedRobotLaserLog(const std::string& log, double dx, double dy);

/// The office log with odometry-like drift: scan k's pose moved by
/// (1.5 k, -1 k) cm, so that members of a local map disagree by centimetres
/// to decimetres and refinement has something to correct.
std::string driftedOfficeLog() {
  std::ifstream in(kData + "/office_2d/office.clf");
  std::string line, out;
  for (int k = 0; std::getline(in, line);) {
    if (line.rfind("ROBOTLASER1 ", 0) != 0) {
      out += line + "\n";
      continue;
    }
    out += shiftedRobotLaserLog(line, 0.015 * k, -0.01 * k);
    ++k;
  }
  return out;
}

}  // namespace

TEST_F(Cli, RefinedLocalMaps) {
  writeFile(dir_ / "drifted.clf", driftedOfficeLog());
  for (const std::string refine : {"icp", "lum"}) {
    const fs::path out = dir_ / refine;
    const Result r = run("partition " + (dir_ / "drifted.clf").string() + " -q --refine " + refine + " -o " + out.string());
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json p = expectPartitionSchema(out, 77);
    expectAllOutputs(out, p);
    EXPECT_EQ(p.at("parameters").at("refine"), refine);
  }
  // Refinement moves member poses, so the arcs' estimates now spread.
  const auto icp = readJson(dir_ / "icp" / "topology.json");
  double spread = 0.0;
  for (const auto& arc : icp.at("arcs")) spread = std::max(spread, arc.at("spread").at("translation_m").get<double>());
  EXPECT_GT(spread, 0.0);
  EXPECT_EQ(run("partition " + kData + "/office_2d/office.clf --refine slam -o " + (dir_ / "x").string()).code, 2);
}

TEST_F(Cli, RealLogsFromMrptDatasets) {
  const Result r = run("partition " + kData + "/real/localization_demo/localization_demo.clf --no-pictures -o " +
                       (dir_ / "out").string());
  ASSERT_EQ(r.code, 0) << r.err;
  expectPartitionSchema(dir_ / "out", 72);
  const Result pcd = run("partition " + kData + "/real/sena_odometry/pcd --no-pictures -q -o " +
                         (dir_ / "pcd").string());
  ASSERT_EQ(pcd.code, 0) << pcd.err;
  expectPartitionSchema(dir_ / "pcd", 224);
}

TEST_F(Cli, FlaserAndRobotlaserOfTheSameScansAgree) {
  writeFile(dir_ / "flaser.log", simulatedLog("FLASER"));
  writeFile(dir_ / "robot.clf", simulatedLog("ROBOTLASER1"));
  ASSERT_EQ(run("partition " + (dir_ / "flaser.log").string() + " -q --no-pictures -o " + (dir_ / "f").string()).code, 0);
  ASSERT_EQ(run("partition " + (dir_ / "robot.clf").string() + " -q --no-pictures -o " + (dir_ / "r").string()).code, 0);
  const auto f = readJson(dir_ / "f" / "partition.json"), r = readJson(dir_ / "r" / "partition.json");
  EXPECT_EQ(f.at("groups"), r.at("groups"));
  EXPECT_EQ(f.at("statistics").at("points"), r.at("statistics").at("points"));
  EXPECT_EQ(f.at("parameters").at("laser"), "front");

  // A PARAM line saying the scans cover 90 degrees changes their geometry...
  writeFile(dir_ / "narrow.log", simulatedLog("FLASER", "PARAM laser_front_laser_fov 90 0 host 0\n"));
  ASSERT_EQ(run("partition " + (dir_ / "narrow.log").string() + " -q --no-pictures -o " + (dir_ / "n").string()).code, 0);
  EXPECT_NE(readJson(dir_ / "n" / "partition.json").at("statistics").at("point_tests"),
            f.at("statistics").at("point_tests"));
  // ...and --fov 180 overrides it back.
  ASSERT_EQ(run("partition " + (dir_ / "narrow.log").string() + " --fov 180 -q --no-pictures -o " +
                (dir_ / "o").string()).code, 0);
  EXPECT_EQ(readJson(dir_ / "o" / "partition.json").at("groups"), f.at("groups"));
}

TEST_F(Cli, LogWithSeveralLasersWarnsAndObeysLaserOption) {
  writeFile(dir_ / "both.log", simulatedLog("FLASER") + simulatedLog("ROBOTLASER1"));
  const Result r = run("partition " + (dir_ / "both.log").string() + " --no-pictures -o " + (dir_ / "a").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("--laser"), std::string::npos) << r.err;
  EXPECT_EQ(readJson(dir_ / "a" / "partition.json").at("observations"), 24);
  const Result rear = run("partition " + (dir_ / "both.log").string() + " --laser rear -o " + (dir_ / "b").string());
  EXPECT_EQ(rear.code, 3);
  EXPECT_NE(rear.err.find("no RLASER"), std::string::npos) << rear.err;
}

TEST_F(Cli, NanAndInfReadingsAreNoReturn) {
  std::istringstream in(simulatedLog("ROBOTLASER1"));
  std::string line, log;
  std::getline(in, line);
  std::vector<std::string> fields;
  std::istringstream split(line);
  for (std::string f; split >> f;) fields.push_back(f);
  fields[9] = "nan";  // the first three ranges
  fields[10] = "inf";
  fields[11] = "-nan";
  for (const auto& f : fields) log += f + " ";
  log += "\n";
  while (std::getline(in, line)) log += line + "\n";
  writeFile(dir_ / "nan.clf", log);
  writeFile(dir_ / "clean.clf", simulatedLog("ROBOTLASER1"));
  Result r = run("partition " + (dir_ / "nan.clf").string() + " -q --no-pictures -o " + (dir_ / "n").string());
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("partition " + (dir_ / "clean.clf").string() + " -q --no-pictures -o " + (dir_ / "c").string());
  ASSERT_EQ(r.code, 0) << r.err;
  // Three readings fewer: they gave no point.
  EXPECT_EQ(readJson(dir_ / "n" / "partition.json").at("statistics").at("points").get<int>() + 3,
            readJson(dir_ / "c" / "partition.json").at("statistics").at("points").get<int>());
}

TEST_F(Cli, ScanWithoutReturnIsAGroupOfItsOwnWithAWarning) {
  std::istringstream in(simulatedLog("ROBOTLASER1"));
  std::string log, line;
  for (int k = 0; std::getline(in, line); ++k) {
    if (k == 1) {  // the second scan: every reading "no return" (nan, or at the maximum range)
      std::istringstream split(line);
      std::vector<std::string> f{std::istream_iterator<std::string>(split), {}};
      const int n = std::stoi(f[8]);
      for (int r = 0; r < n; ++r) f[9 + r] = r % 2 ? "nan" : f[5];
      line.clear();
      for (const auto& field : f) line += field + " ";
    }
    log += line + "\n";
  }
  writeFile(dir_ / "blind.clf", log);
  const Result r = run("partition " + (dir_ / "blind.clf").string() + " --no-pictures -o " + (dir_ / "o").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("blind.clf:2: the scan has no return"), std::string::npos) << r.err;
  const auto partition = readJson(dir_ / "o" / "partition.json");
  EXPECT_NE(std::find(partition.at("groups").begin(), partition.at("groups").end(), nlohmann::json({1})),
            partition.at("groups").end());
  EXPECT_EQ(partition.at("warnings").size(), 1u);
}

TEST_F(Cli, BadCarmenLogs) {
  struct Case {
    std::string name, content, expected;
  };
  const std::string line2 = simulatedLog("ROBOTLASER1").substr(0, simulatedLog("ROBOTLASER1").find('\n'));
  std::vector<Case> cases{
      {"empty", "", "the file is empty"},
      {"blank", "\n  \n", "the file is empty"},
      {"no_laser", "# a comment\nODOM 1 2 3 0 0 0 1 host 1\n", "no FLASER, RLASER or ROBOTLASER1"},
      {"truncated", logWithLine(3, line2.substr(0, line2.size() / 2)), ":3: ROBOTLASER1 line is truncated"},
      {"truncated_tail", logWithLine(2, line2.substr(0, line2.rfind(" 0 0 0 0 0"))), ":2: ROBOTLASER1 line is truncated"},
      {"non_numeric", logWithLine(4, std::string(line2).replace(line2.find(" 361 ") + 5, 0, "abc ")), ":4: "},
      {"n_mismatch", logWithLine(5, std::string(line2).replace(line2.find(" 361 "), 5, " 360 ")), ":5: "},
      {"bad_pose",
       logWithLine(2, carmenLine("ROBOTLASER1", {std::nan(""), 1.0, 0.0}, std::vector<double>(361, 5.0))),
       ":2: field 'laser_pose_x': 'nan' is not finite"},
      {"flaser_short", "FLASER 3 1.0 2.0\n", ":1: FLASER line is truncated"},
      {"flaser_bad_count", "FLASER x 1.0\n", ":1: field 'num_readings'"},
  };
  for (const auto& c : cases) {
    const fs::path log = dir_ / (c.name + ".clf");
    writeFile(log, c.content);
    const Result r = run("partition " + log.string() + " -o " + (dir_ / ("out_" + c.name)).string());
    EXPECT_EQ(r.code, 3) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(log.string()), std::string::npos) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.name << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.name << ": one line expected: " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / ("out_" + c.name) / "partition.json")) << c.name;
  }
  // A non-numeric range names its field; n not matching the ranges says so.
  writeFile(dir_ / "word.clf", logWithLine(2, std::string(line2).replace(line2.find(" 361 ") + 5, 5, "abc ")));
  Result r = run("partition " + (dir_ / "word.clf").string() + " -o " + (dir_ / "w").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find(":2: field 'range 1': 'abc' is not a number"), std::string::npos) << r.err;
  writeFile(dir_ / "count.clf", logWithLine(2, std::string(line2).replace(line2.find(" 361 "), 5, " 360 ")));
  r = run("partition " + (dir_ / "count.clf").string() + " -o " + (dir_ / "c").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("match the number of ranges"), std::string::npos) << r.err;
}

TEST_F(Cli, BadPcdSequences) {
  fs::create_directories(dir_ / "none");
  writeFile(dir_ / "none" / "readme.txt", "no clouds here");
  Result r = run("partition " + (dir_ / "none").string() + " -o " + (dir_ / "o1").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("no .pcd file"), std::string::npos) << r.err;

  // Garbage, and a binary PCD cut in the middle of its data.
  const fs::path seq = dir_ / "seq";
  fs::create_directories(seq);
  fs::copy_file(kData + "/office_3d/pcd/000000.pcd", seq / "000000.pcd");
  fs::copy_file(kData + "/office_3d/pcd/000001.pcd", seq / "000001.pcd");
  writeFile(seq / "000002.pcd", "this is not a point cloud\n");
  r = run("partition " + seq.string() + " -o " + (dir_ / "o2").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("000002.pcd:1: unknown header field 'this'"), std::string::npos) << r.err;
  const std::string whole = readFile(kData + "/office_3d/pcd/000002.pcd");
  writeFile(seq / "000002.pcd", whole.substr(0, whole.size() * 2 / 3));
  r = run("partition " + seq.string() + " -o " + (dir_ / "o3").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("000002.pcd: truncated"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o3" / "partition.json"));
  // Headers that are inconsistent or cut short.
  const std::string head = "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
  const std::vector<std::pair<std::string, std::string>> headers{
      {head + "WIDTH 2\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 2 3\n4 5 6\n", "'POINTS' (3) is not WIDTH * HEIGHT"},
      {head + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n", "truncated"},
      {head + "WIDTH 2\nHEIGHT 1\nPOINTS 2\n", "no DATA line"},
      {"VERSION .7\nFIELDS x y z\nSIZE 4 4\n", ":3: field 'SIZE' has 2 values for 3 FIELDS"},
      {head + "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0\nPOINTS 1\nDATA ascii\n1 2 3\n", ":8: field 'VIEWPOINT'"},
  };
  for (const auto& [text, expected] : headers) {
    writeFile(seq / "000002.pcd", text);
    r = run("partition " + seq.string() + " -o " + (dir_ / "o5").string());
    EXPECT_EQ(r.code, 3) << expected;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  }

  // An empty but valid PCD is an observation with no points: kept, with a warning.
  pcl::PointCloud<pcl::PointXYZ> empty;
  empty.sensor_origin_ << 1.0f, 2.0f, 0.0f, 0.0f;
  pcl::io::savePCDFileASCII((seq / "000002.pcd").string(), empty);
  r = run("partition " + seq.string() + " --no-pictures -o " + (dir_ / "o4").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("000002.pcd: the cloud has no point; kept as an observation (a group of its own)"),
            std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("000002.pcd"), r.err.rfind("000002.pcd")) << "warned twice:\n" << r.err;
  const auto partition = readJson(dir_ / "o4" / "partition.json");
  EXPECT_EQ(partition.at("observations"), 3);
  EXPECT_EQ(partition.at("warnings").size(), 1u);
  EXPECT_NE(std::find(partition.at("groups").begin(), partition.at("groups").end(), nlohmann::json({2})),
            partition.at("groups").end());
}

TEST_F(Cli, BadPoseFiles) {
  const std::string seq = kData + "/office_3d/pcd";
  const std::string poses = readFile(kData + "/office_3d/poses.txt");
  const auto runWith = [&](const std::string& name, const std::string& content, const std::string& format = "tum") {
    writeFile(dir_ / name, content);
    return run("partition " + seq + " --no-pictures -q --poses " + (dir_ / name).string() + " --pose-format " +
               format + " -o " + (dir_ / ("out_" + name)).string());
  };
  const std::string last_removed = poses.substr(0, poses.rfind('\n', poses.size() - 2) + 1);
  Result r = runWith("fewer.txt", last_removed);
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("39 poses for 40 PCD files"), std::string::npos) << r.err;
  r = runWith("more.txt", poses + "99 0 0 0 0 0 0 1\n");
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("41 poses for 40 PCD files"), std::string::npos) << r.err;
  r = runWith("short.txt", "# header\n0 1 2 3 0 0 0\n");
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("short.txt:2: a pose line has 7 values, expected 8"), std::string::npos) << r.err;
  r = runWith("zero.txt", "0 1 2 3 0 0 0 0\n");
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("zero.txt:1: fields 'qx qy qz qw'"), std::string::npos) << r.err;
  r = runWith("far.txt", "0 1 2 3 0 0 0 1.5\n");
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("norm 1.5"), std::string::npos) << r.err;
  r = runWith("word.txt", "0 1 two 3 0 0 0 1\n");
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("word.txt:1: field 'ty': 'two' is not a number"), std::string::npos) << r.err;
  r = runWith("kitti.txt", "1 0 0 0 0 1 0 0 0 0 1\n", "kitti");
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("kitti.txt:1: a pose line has 11 values, expected 12"), std::string::npos) << r.err;
  r = runWith("shear.txt", "1 0.5 0 0 0 1 0 0 0 0 1 0\n", "kitti");
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("not a rotation matrix"), std::string::npos) << r.err;

  // A quaternion a little off unit length is normalised silently.
  std::string nearly;
  std::istringstream in(poses);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream f(line);
    double v[8];
    for (double& x : v) f >> x;
    char buffer[200];
    std::snprintf(buffer, sizeof buffer, "%g %.9f %.9f %.9f 0 0 %.12f %.12f\n", v[0], v[1], v[2], v[3], v[6] * 1.002,
                  v[7] * 1.002);
    nearly += buffer;
  }
  r = runWith("nearly.txt", nearly);
  EXPECT_EQ(r.code, 0) << r.err;
}

TEST_F(Cli, IdentityViewpointsWarn) {
  const fs::path seq = dir_ / "seq";
  fs::create_directories(seq);
  for (int k = 0; k < 3; ++k) {
    pcl::PointCloud<pcl::PointXYZ> cloud;
    pcl::io::loadPCDFile(kData + "/office_3d/pcd/00000" + std::to_string(k) + ".pcd", cloud);
    cloud.sensor_origin_.setZero();
    cloud.sensor_orientation_.setIdentity();
    pcl::io::savePCDFileBinary((seq / ("c" + std::to_string(k) + ".pcd")).string(), cloud);
  }
  const Result r = run("partition " + seq.string() + " --no-pictures -o " + (dir_ / "o").string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("all observations are at the origin"), std::string::npos) << r.err;
}

TEST_F(Cli, ExistingResultsAreNotOverwrittenWithoutForce) {
  const std::string input = kData + "/office_2d/office.clf";
  const std::string out = (dir_ / "out").string();
  ASSERT_EQ(run("partition " + input + " -q --no-pictures -o " + out).code, 0);
  const std::string before = readFile(dir_ / "out" / "partition.json");
  writeFile(dir_ / "out" / "local_maps" / "group_999.pcd", "stale");
  const Result refused = run("partition " + input + " --paper --delta 0.2 -q -o " + out);
  EXPECT_EQ(refused.code, 2);
  EXPECT_NE(refused.err.find("already holds results"), std::string::npos) << refused.err;
  EXPECT_EQ(readFile(dir_ / "out" / "partition.json"), before);
  ASSERT_EQ(run("partition " + input + " --paper --delta 0.2 -q --no-pictures --force -o " + out).code, 0);
  EXPECT_EQ(readJson(dir_ / "out" / "partition.json").at("parameters").at("delta"), 0.2);
  EXPECT_FALSE(fs::exists(dir_ / "out" / "local_maps" / "group_999.pcd"));
}

TEST_F(Cli, UsageErrors) {
  const std::string input = kData + "/office_2d/office.clf";
  const std::string out = " -o " + (dir_ / "out").string();
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("partition " + input).code, 2);                           // no -o
  EXPECT_EQ(run("partition " + input + out + " --delta -1").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --delta abc").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --split median").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --no-such-option").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --poses x.txt").code, 2);  // poses for a log
  EXPECT_EQ(run("partition " + kData + "/office_3d/pcd" + out + " --laser front").code, 2);
  // Options of another sensed-space model are a mistake, not a no-op.
  const Result delta = run("partition " + input + out + " --delta 0.2");  // the default model has cells
  EXPECT_EQ(delta.code, 2);
  EXPECT_NE(delta.err.find("--delta applies to --sso points"), std::string::npos) << delta.err;
  EXPECT_EQ(run("partition " + input + out + " --sso points --cell 0.3").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --sso free-space --clearance 0.5").code, 2);
  for (const char* model : {"points", "free-space"}) {
    const Result door = run("partition " + input + out + " --sso " + model + " --door-width 1");
    EXPECT_EQ(door.code, 2) << model;
    EXPECT_NE(door.err.find("--door-width applies to --sso visibility only"), std::string::npos) << door.err;
  }
  EXPECT_EQ(run("partition " + input + out + " --door-width -1").code, 2);
  // A door of 250 cells or more is refused with the region settings (GroupingParameters::check).
  EXPECT_EQ(run("partition " + input + out + " --cell 0.01 --door-width 3").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --paper --split best").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --paper --ncut-threshold 0.8").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --paper --join-passages on").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --sso points --join-passages off").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --join-passages maybe").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --band 1 0").code, 2);
  EXPECT_EQ(run("partition " + input + out + " --sso voxels").code, 2);
  // A value each option accepts alone, refused together (GroupingParameters::check): a usage error too.
  const Result cells = run("partition " + input + out + " --cell 0.001");
  EXPECT_EQ(cells.code, 2);
  EXPECT_NE(cells.err.find("more than 2000 cells"), std::string::npos) << cells.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  const Result missing = run("partition " + (dir_ / "nothing.clf").string() + out);
  EXPECT_EQ(missing.code, 3);
  EXPECT_NE(missing.err.find("no such file or folder"), std::string::npos) << missing.err;
  EXPECT_EQ(run("--help").code, 0);
  EXPECT_EQ(run("partition --help").code, 0);
}

// What a user reads when an option or a command is wrong: the command's own
// words, prefixed, exit 2, never CLI11's ranges and enum tables.
TEST_F(Cli, UsageMessagesSayWhatIsWrong) {
  const std::string input = kData + "/office_2d/office.clf";
  const std::string out = " -o " + (dir_ / "out").string();
  const auto expectUsage = [&](const std::string& args, const std::string& message) {
    const Result r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(r.err.rfind("obsgroup: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(r.err.find("1797"), std::string::npos) << r.err;
  };
  expectUsage("", "a command is required: partition");
  expectUsage("partiton " + input + out, "unknown command 'partiton' (commands: partition, stream, locate)");
  // A misspelt option is named, with the nearest the command has.
  expectUsage("partition " + input + out + " --refin lum", "unknown option '--refin' (did you mean --refine?)");
  expectUsage("stream " + input + out + " --updat-every 2", "unknown option '--updat-every' (did you mean --update-every?)");
  expectUsage("locate " + input + " " + input + out + " --xyzzy", "unknown option '--xyzzy' (obsgroup locate --help lists the options)");
  expectUsage("partition " + input + out + " --sso points --delta 0", "--delta: must be > 0 (got 0)");
  expectUsage("partition " + input + out + " --sso points --delta 0.2cm", "'0.2cm' is not a number");
  expectUsage("partition " + input + out + " --sso points --delta nan", "'nan' is not a finite number");
  expectUsage("partition " + input + out + " --map-voxel nan", "'nan' is not a finite number");
  expectUsage("partition " + input + out + " --refine slam", "'slam' is not one of none, icp or lum");
  expectUsage("partition " + input + out + " --threads 1.5", "'1.5' is not a whole number");
  expectUsage("partition " + input + out + " --fov 400", "must be between 1 and 360");
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  const Result help = run("partition --help");
  EXPECT_EQ(help.code, 0);
  for (const char* choices : {"none|icp|lum", "points|free-space|visibility", "mean|sign|best", "tum|kitti"})
    EXPECT_NE(help.out.find(choices), std::string::npos) << choices;
  for (const char* noise : {"ENUM", "{false}", "->", "1797"}) EXPECT_EQ(help.out.find(noise), std::string::npos) << noise;
  // Descriptions are wrapped to 100 columns: read them as flowing text.
  std::string flat;
  for (char c : help.out)
    if (!std::isspace(static_cast<unsigned char>(c)) || (!flat.empty() && flat.back() != ' ')) flat += std::isspace(static_cast<unsigned char>(c)) ? ' ' : c;
  EXPECT_NE(flat.find("(default: visibility)"), std::string::npos);
  EXPECT_NE(flat.find("(default: none)"), std::string::npos);
  std::istringstream lines(help.out);
  for (std::string line; std::getline(lines, line);) EXPECT_LE(line.size(), 100u) << line;
  for (const char* group : {"Sensed-space model:", "Partition:", "Local maps:", "Output:", "CARMEN logs:",
                            "Poses (PCD sequences, depth images, KITTI, bags):", "Depth images:", "ROS bags:"})
    EXPECT_NE(help.out.find(group), std::string::npos) << group;
  EXPECT_NE(flat.find("ROS bag"), std::string::npos);  // the description names every input kind
}

// partition.json's timing says how many threads ran, and one group is "1 group".
TEST_F(Cli, ThreadsRecordedAreThoseUsed) {
  const std::string input = kData + "/office_2d/office.clf";
  const Result r = run("partition " + input + " --no-pictures --threads 1 -o " + (dir_ / "one").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readJson(dir_ / "one" / "partition.json").at("timing_s").at("threads"), 1);
  ASSERT_EQ(run("partition " + input + " -q --no-pictures -o " + (dir_ / "all").string()).code, 0);
  EXPECT_GE(readJson(dir_ / "all" / "partition.json").at("timing_s").at("threads").get<int>(), 1);
  const Result one = run("partition " + input + " --no-pictures --ncut-threshold 0 -o " + (dir_ / "whole").string());
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_NE(one.err.find(", 1 group\n"), std::string::npos) << one.err;
}

TEST_F(Cli, SameResultsForOneAndTwoThreads) {
  const std::string input = kData + "/real/localization_demo/localization_demo.clf";
  ASSERT_EQ(run("partition " + input + " -q --no-pictures --threads 1 -o " + (dir_ / "one").string()).code, 0);
  ASSERT_EQ(run("partition " + input + " -q --no-pictures --threads 2 -o " + (dir_ / "two").string()).code, 0);
  const auto strip = [](std::string text) { return text.substr(0, text.find("\"timing_s\"")); };
  EXPECT_EQ(strip(readFile(dir_ / "one" / "partition.json")), strip(readFile(dir_ / "two" / "partition.json")));
  EXPECT_EQ(readFile(dir_ / "one" / "topology.json"), readFile(dir_ / "two" / "topology.json"));
}

TEST_F(Cli, ShippedDatasetsAreWhatTheSimulatorWrites) {
  const std::string command = std::string(MAKE_DATASETS_EXE) + " " + dir_.string() + " > /dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  EXPECT_EQ(readFile(dir_ / "office_2d" / "office.clf"), readFile(kData + "/office_2d/office.clf"));
  EXPECT_EQ(readFile(dir_ / "office_3d" / "poses.txt"), readFile(kData + "/office_3d/poses.txt"));
  EXPECT_EQ(readFile(dir_ / "office_3d" / "pcd" / "000017.pcd"), readFile(kData + "/office_3d/pcd/000017.pcd"));
}

namespace {

/// Every file under `folder`, by relative path, with its content.
std::map<std::string, std::string> snapshot(const fs::path& folder) {
  std::map<std::string, std::string> files;
  if (!fs::exists(folder)) return files;
  for (const auto& entry : fs::recursive_directory_iterator(folder))
    if (entry.is_regular_file()) files[fs::relative(entry.path(), folder).string()] = readFile(entry.path());
  return files;
}

/// Starts the command with its stdout on a pipe (read end returned in
/// `out_fd`, or /dev/null when null) and its stderr on /dev/null.
pid_t startCommand(const std::vector<std::string>& args, int* out_fd, const sigset_t& child_mask) {
  int fds[2] = {-1, -1};
  if (out_fd && ::pipe(fds) != 0) return -1;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::pthread_sigmask(SIG_SETMASK, &child_mask, nullptr);
    std::vector<char*> argv{const_cast<char*>(OBSGROUP_EXE)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (out_fd) {
      ::dup2(fds[1], 1);
      ::close(fds[0]);
      ::close(fds[1]);
    } else {
      std::freopen("/dev/null", "w", stdout);
    }
    std::freopen("/dev/null", "w", stderr);
    ::execv(OBSGROUP_EXE, argv.data());
    std::_Exit(127);
  }
  if (out_fd) {
    ::close(fds[1]);
    if (pid < 0) ::close(fds[0]);  // no command started: nothing to read
    *out_fd = pid < 0 ? -1 : fds[0];
  }
  return pid;
}

/// What a helper returns when the command could not be started (no pipe or
/// no fork: a busy machine out of processes): never a pid to signal.
constexpr int kNotStarted = -1000;

/// The exit code of a finished command: -N when signal N ended it.
int exitCode(int status) {
  if (WIFSIGNALED(status)) return -WTERMSIG(status);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// Runs the command with SIGINT sent after `delay` unless it ended before;
/// returns its exit code, or -SIGINT when the signal came before the command
/// installed its handler. Waits on the command's exit (SIGCHLD), not in a
/// polling loop: `delay` only chooses when to strike.
int runInterruptedAfter(const std::vector<std::string>& args, std::chrono::milliseconds delay) {
  sigset_t child_exit, previous;
  sigemptyset(&child_exit);
  sigaddset(&child_exit, SIGCHLD);
  ::pthread_sigmask(SIG_BLOCK, &child_exit, &previous);
  const pid_t pid = startCommand(args, nullptr, previous);
  if (pid <= 0) {
    ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    return kNotStarted;
  }
  int status = 0;
  bool ended = false;
  timespec timeout{static_cast<time_t>(delay.count() / 1000), static_cast<long>(delay.count() % 1000) * 1000000L};
  while (!ended) {
    siginfo_t info;
    if (::sigtimedwait(&child_exit, &info, &timeout) != SIGCHLD) {
      if (errno == EINTR) continue;
      break;  // the delay passed
    }
    ended = ::waitpid(pid, &status, WNOHANG) == pid;
  }
  if (!ended) {
    ::kill(pid, SIGINT);
    ::waitpid(pid, &status, 0);
  }
  ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);  // a SIGCHLD still pending is discarded (ignored)
  return exitCode(status);
}

/// Runs the command with its standard error on a terminal, where it draws
/// its progress bar, and sends SIGINT as soon as the bar of `stage` shows:
/// the run is then in that stage, its handler installed, whatever the
/// machine's load. Returns its exit code and the stages whose bars it drew
/// (in `stages`); kNotStarted when no terminal or process could be had.
int runInterruptedAtStage(const std::vector<std::string>& args, const std::string& stage,
                          std::vector<std::string>* stages = nullptr) {
  int master = -1, slave = -1;
  if (::openpty(&master, &slave, nullptr, nullptr, nullptr) != 0) return kNotStarted;
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv{const_cast<char*>(OBSGROUP_EXE)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::close(master);
    std::freopen("/dev/null", "w", stdout);
    ::dup2(slave, 2);
    ::close(slave);
    ::execv(OBSGROUP_EXE, argv.data());
    std::_Exit(127);
  }
  ::close(slave);
  if (pid < 0) {
    ::close(master);
    return kNotStarted;
  }
  std::string shown;
  bool sent = false;
  char buffer[4096];
  for (;;) {  // to the end (EIO once the command has closed the terminal), so that it never blocks on it
    const ssize_t n = ::read(master, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    shown.append(buffer, std::size_t(n));
    if (!sent && shown.find("\r" + stage + " [") != std::string::npos) sent = ::kill(pid, SIGINT) == 0;
  }
  ::close(master);
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (stages)
    for (std::size_t at = shown.find('\r'); at != std::string::npos; at = shown.find('\r', at + 1)) {
      const std::size_t bar = shown.find(" [", at);
      if (bar == std::string::npos) break;
      const std::string name = shown.substr(at + 1, bar - at - 1);
      if (!name.empty() && name.find_first_of("\r\n\033") == std::string::npos &&
          std::find(stages->begin(), stages->end(), name) == stages->end())
        stages->push_back(name);
    }
  return exitCode(status);
}

/// Runs the command and sends SIGINT as soon as it prints a line starting
/// with `prefix` on stdout (its handler is installed before it prints
/// anything); returns its exit code. A command that never prints the line
/// is waited for to its end.
int runInterruptedAtLine(const std::vector<std::string>& args, const std::string& prefix) {
  sigset_t none;
  ::pthread_sigmask(SIG_SETMASK, nullptr, &none);
  int fd = -1;
  const pid_t pid = startCommand(args, &fd, none);
  if (pid <= 0) return kNotStarted;
  FILE* out = ::fdopen(fd, "r");
  if (!out) {
    ::close(fd);
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    return kNotStarted;
  }
  char* line = nullptr;
  std::size_t capacity = 0;
  bool sent = false;
  while (::getline(&line, &capacity, out) != -1)  // read to the end, so that the command never blocks on a full pipe
    if (!sent && std::string(line).rfind(prefix, 0) == 0) sent = ::kill(pid, SIGINT) == 0;
  std::free(line);
  std::fclose(out);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return exitCode(status);
}

/// The log with every laser and robot pose moved by (dx, dy): ROBOTLASER1
/// lines, whose pose fields follow the ranges and the remissions.
std::string shiftedRobotLaserLog(const std::string& log, double dx, double dy) {
  std::istringstream in(log);
  std::ostringstream out;
  out.precision(17);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("ROBOTLASER1 ", 0) != 0) {
      out << line << "\n";
      continue;
    }
    std::istringstream words(line);
    std::vector<std::string> f{std::istream_iterator<std::string>(words), {}};
    const std::size_t n = std::stoul(f[8]), tail = 10 + n + std::stoul(f[9 + n]);
    for (std::size_t k : {tail, tail + 3}) {
      f[k] = (std::ostringstream() << std::setprecision(17) << std::stod(f[k]) + dx).str();
      f[k + 1] = (std::ostringstream() << std::setprecision(17) << std::stod(f[k + 1]) + dy).str();
    }
    for (std::size_t k = 0; k < f.size(); ++k) out << (k ? " " : "") << f[k];
    out << "\n";
  }
  return out.str();
}

}  // namespace

TEST_F(Cli, InterruptedRunLeavesTheOldResultsOrTheNewOnes) {
  const std::string input = kData + "/real/localization_demo/localization_demo.clf";
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run("partition " + input + " -q -o " + out.string()).code, 0);
  const auto old_results = snapshot(out);
  ASSERT_GT(old_results.size(), 8u);
  const std::vector<std::string> rerun{"partition", input, "--paper", "--delta", "0.2", "--force", "--threads", "1",
                                       "-o", out.string()};
  // Ctrl-C in each stage of a rerun with other parameters, struck when the
  // stage's progress bar shows (the command's handler is then installed,
  // however busy the machine): the old results stay, whole. The first stage
  // leaves the run much more to do than the test takes to strike, so it must
  // end it; after the last ones the run may have finished first, and then
  // its results must be whole.
  auto results = old_results;
  bool saw_interrupted = false;
  for (const std::string stage : {"overlap", "local maps", "places", "pictures"}) {
    std::vector<std::string> stages;
    const int code = runInterruptedAtStage(rerun, stage, &stages);
    if (code == kNotStarted) break;  // no terminal to draw a bar on
    EXPECT_NE(std::find(stages.begin(), stages.end(), stage), stages.end()) << stage << " never showed";
    if (stage == "overlap") {
      EXPECT_EQ(code, 130) << stage;
    }
    ASSERT_TRUE(code == 130 || code == 0) << "exit code " << code << " in " << stage;
    saw_interrupted = saw_interrupted || code == 130;
    if (code == 130) {
      EXPECT_EQ(snapshot(out), results) << "interrupted in " << stage << " left a changed folder";
    } else {
      results = snapshot(out);
      EXPECT_EQ(nlohmann::json::parse(results.at("partition.json")).at("parameters").at("delta"), 0.2);
    }
  }
  // Ctrl-C at any moment, the swap too: each outcome is whole.
  bool saw_completed = false;
  // Ends at the first completed run: every 30 ms at first, then by half as
  // much again, so that a slow (busy) machine completes one too.
  for (int ms = 0; !saw_completed; ms = ms < 900 ? ms + 30 : ms * 3 / 2) {
    const int code = runInterruptedAfter(rerun, std::chrono::milliseconds(ms));
    ASSERT_TRUE(code == 130 || code == 0 || code == -SIGINT) << "exit code " << code << " at " << ms << " ms";
    const auto now = snapshot(out);
    if (code != 0) {
      saw_interrupted = saw_interrupted || code == 130;
      EXPECT_EQ(now, results) << "interrupted at " << ms << " ms left a changed folder";
    } else {
      saw_completed = true;
      const auto partition = nlohmann::json::parse(now.at("partition.json"));
      EXPECT_EQ(partition.at("parameters").at("delta"), 0.2);
      std::size_t maps = 0, pictures = 0;
      for (const auto& [name, content] : now)
        if (name.rfind("local_maps/group_", 0) == 0) (fs::path(name).extension() == ".png" ? pictures : maps) += 1;
      EXPECT_EQ(maps, partition.at("groups").size());
      EXPECT_EQ(pictures, partition.at("groups").size());
    }
    // Nothing but the results and the test's own files beside them.
    for (const auto& entry : fs::directory_iterator(dir_))
      EXPECT_TRUE(entry.path().filename() == "out" || entry.path().filename() == "stderr.txt" ||
                  entry.path().filename() == "stdout.txt") << entry.path();
  }
  EXPECT_TRUE(saw_interrupted);
  EXPECT_TRUE(saw_completed);
}

TEST_F(Cli, FoldersHoldingOtherFilesAreNeverReplaced) {
  const std::string input = kData + "/office_2d/office.clf";
  writeFile(dir_ / "mine" / "notes.txt", "my notes");
  const Result refused = run("partition " + input + " -q --force -o " + (dir_ / "mine").string());
  EXPECT_EQ(refused.code, 2);
  EXPECT_NE(refused.err.find("notes.txt"), std::string::npos) << refused.err;
  EXPECT_EQ(snapshot(dir_ / "mine").size(), 1u);
  EXPECT_EQ(readFile(dir_ / "mine" / "notes.txt"), "my notes");
  // A staging folder of a killed run (no such process) is cleaned up by the next run.
  fs::create_directories(dir_ / ".out.obsgroup-staging-999999999" / "local_maps");
  ASSERT_EQ(run("partition " + input + " -q --no-pictures -o " + (dir_ / "out").string()).code, 0);
  EXPECT_FALSE(fs::exists(dir_ / ".out.obsgroup-staging-999999999"));
}

TEST_F(Cli, PassagesJoinACorridorsGroupsAndOffKeepsThem) {
  // The office log's corridor is cut across where the robot turned back:
  // no door there, and its two groups are one place.
  const std::string input = kData + "/office_2d/office.clf";
  ASSERT_EQ(run("partition " + input + " -q --no-pictures -o " + (dir_ / "on").string()).code, 0);
  ASSERT_EQ(run("partition " + input + " -q --no-pictures --join-passages off -o " + (dir_ / "off").string()).code, 0);
  const nlohmann::json on = readJson(dir_ / "on" / "partition.json"), off = readJson(dir_ / "off" / "partition.json");
  const int joins = on.at("statistics").at("passage_joins").get<int>();
  EXPECT_GE(joins, 1);
  EXPECT_EQ(off.at("statistics").at("passage_joins"), 0);
  EXPECT_EQ(on.at("parameters").at("join_passages"), true);
  EXPECT_EQ(off.at("parameters").at("join_passages"), false);
  EXPECT_EQ(on.at("groups").size() + std::size_t(joins), off.at("groups").size());
  // Each joined group is a union of groups kept apart with the option off.
  std::map<int, int> joined_group;
  for (std::size_t g = 0; g < on.at("groups").size(); ++g)
    for (int i : on.at("groups")[g]) joined_group[i] = int(g);
  for (const auto& group : off.at("groups"))
    for (int i : group) EXPECT_EQ(joined_group.at(i), joined_group.at(group[0].get<int>()));
  // The place ids stay the group indices, and no door of the places lies between one place.
  EXPECT_EQ(on.at("place_ids").size(), on.at("groups").size());
  for (std::size_t g = 0; g < on.at("place_ids").size(); ++g) EXPECT_EQ(on.at("place_ids")[g], int(g));
  const nlohmann::json places = readJson(dir_ / "on" / "places.json");
  for (const auto& door : places.at("doors")) EXPECT_NE(door.at("places")[0], door.at("places")[1]);
}

TEST_F(Cli, PosesAtUtmCoordinatesAreWrittenAtFullPrecision) {
  // Half a million metres east, five million north: float keeps ~0.5 m
  // there and a PCD VIEWPOINT 6 digits (~5 m).
  const double dx = 512345.678901, dy = 5123456.789012;
  const std::string log = readFile(kData + "/real/localization_demo/localization_demo.clf");
  writeFile(dir_ / "utm.clf", shiftedRobotLaserLog(log, dx, dy));
  ASSERT_EQ(run("partition " + kData + "/real/localization_demo/localization_demo.clf -q --no-pictures -o " +
                (dir_ / "here").string()).code, 0);
  ASSERT_EQ(run("partition " + (dir_ / "utm.clf").string() + " -q --no-pictures -o " + (dir_ / "utm").string()).code, 0);

  // The same groups and arcs: the overlap is computed re-centred.
  const auto here = readJson(dir_ / "here" / "partition.json"), utm = readJson(dir_ / "utm" / "partition.json");
  EXPECT_EQ(here.at("groups"), utm.at("groups"));
  const auto here_topology = readJson(dir_ / "here" / "topology.json");
  const auto utm_topology = readJson(dir_ / "utm" / "topology.json");
  ASSERT_EQ(here_topology.at("nodes").size(), utm_topology.at("nodes").size());
  ASSERT_EQ(here_topology.at("arcs").size(), utm_topology.at("arcs").size());
  for (std::size_t a = 0; a < here_topology.at("arcs").size(); ++a)
    for (const char* key : {"x", "y"})
      EXPECT_NEAR(here_topology["arcs"][a]["transform"][key].get<double>(),
                  utm_topology["arcs"][a]["transform"][key].get<double>(), 1e-6);

  // Read back: topology.json and local_maps/poses.txt hold every reference
  // pose to well under a millimetre; the VIEWPOINT of the PCD does not.
  std::istringstream poses(readFile(dir_ / "utm" / "local_maps" / "poses.txt"));
  std::string line;
  std::size_t k = 0;
  while (std::getline(poses, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double group = 0, x = 0, y = 0;
    fields >> group >> x >> y;
    ASSERT_EQ(group, double(k));
    const auto& expected = here_topology["nodes"][k]["pose"];
    EXPECT_NEAR(x, expected["x"].get<double>() + dx, 1e-6) << line;
    EXPECT_NEAR(y, expected["y"].get<double>() + dy, 1e-6) << line;
    EXPECT_NEAR(utm_topology["nodes"][k]["pose"]["x"].get<double>(), expected["x"].get<double>() + dx, 1e-6);
    EXPECT_NEAR(utm_topology["nodes"][k]["pose"]["y"].get<double>(), expected["y"].get<double>() + dy, 1e-6);
    ++k;
  }
  EXPECT_EQ(k, here_topology.at("nodes").size());
  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  ASSERT_EQ(pcl::io::loadPCDFile((dir_ / "utm" / "local_maps" / "group_000.pcd").string(), blob, origin, orientation), 0);
  EXPECT_GT(std::abs(origin.y() - (here_topology["nodes"][0]["pose"]["y"].get<double>() + dy)), 1e-3)
      << "PCD VIEWPOINTs have become exact: local_maps/poses.txt may no longer be needed";
}

TEST_F(Cli, RunsAreByteIdenticalApartFromTimings) {
  const std::string input = kData + "/office_2d/office.clf";
  ASSERT_EQ(run("partition " + input + " -q -o " + (dir_ / "a").string()).code, 0);
  // The user's own runtime settings change nothing: their malloc's (here none: 4 KiB pages, where the
  // command would ask for huge ones) and OpenMP's idle threads spinning (the command has them sleep).
  ASSERT_EQ(run("partition " + input + " -q -o " + (dir_ / "b").string(), "GLIBC_TUNABLES= OMP_WAIT_POLICY=active").code,
            0);
  auto a = snapshot(dir_ / "a"), b = snapshot(dir_ / "b");
  // How long OpenMP's idle threads spin, as read when the process that ran was loaded (the last of
  // its reports; "0": they sleep at once, which an unset OMP_WAIT_POLICY also reports as PASSIVE).
  const auto spinning = [this, &input](const std::string& environment) {
    const std::string err = run("partition " + input + " -q --no-pictures --force -o " + (dir_ / "c").string(),
                                "OMP_DISPLAY_ENV=verbose " + environment).err;
    const std::size_t at = err.rfind("GOMP_SPINCOUNT = ");
    return at == std::string::npos ? std::string("no report") : err.substr(at, err.find('\n', at) - at);
  };
#if defined(_OPENMP) && defined(__linux__) && !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  EXPECT_EQ(spinning(""), "GOMP_SPINCOUNT = '0'");
  EXPECT_NE(spinning("OMP_WAIT_POLICY=active"), "GOMP_SPINCOUNT = '0'");
  EXPECT_NE(spinning("OMP_WAIT_POLICY=active"), "no report");
#endif
  const auto strip = [](std::string text) { return text.substr(0, text.find("\"timing_s\"")); };
  a["partition.json"] = strip(a["partition.json"]);
  b["partition.json"] = strip(b["partition.json"]);
  // report.html shows the timings too: its "timing_s":{...} object.
  const auto without_timings = [](std::string page) {
    const std::size_t start = page.find("\"timing_s\":{");
    if (start == std::string::npos) return std::string("no timings in report.html");
    return page.erase(start, page.find('}', start) + 1 - start);
  };
  a["report.html"] = without_timings(a["report.html"]);
  b["report.html"] = without_timings(b["report.html"]);
  EXPECT_EQ(a["report.html"].find("no timings"), std::string::npos);
  EXPECT_EQ(a, b);  // every file: JSON, DOT, PCD, PNG, SVG and HTML
}

/// The names in `folder` that start with `prefix` and end with `extension`.
std::set<std::string> namesIn(const fs::path& folder, const std::string& prefix, const std::string& extension) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0 && entry.path().extension() == extension) names.insert(name);
  }
  return names;
}

TEST_F(Cli, OnePicturePerLocalMapOnlyWithPictures) {
  const std::string input = kData + "/office_2d/office.clf";
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run("partition " + input + " -q --threads 1 -o " + out.string()).code, 0);
  const std::size_t groups = readJson(out / "partition.json").at("groups").size();
  const auto clouds = namesIn(out / "local_maps", "group_", ".pcd");
  const auto pictures = namesIn(out / "local_maps", "group_", ".png");
  ASSERT_EQ(clouds.size(), groups);
  ASSERT_EQ(pictures.size(), groups);
  for (const std::string& cloud : clouds) {
    const fs::path picture = out / "local_maps" / fs::path(cloud).replace_extension(".png");
    EXPECT_GT(fs::file_size(picture), 0u) << picture;
    expectValidPng(picture);
  }
  // The same pictures on two threads.
  ASSERT_EQ(run("partition " + input + " -q --threads 2 -o " + (dir_ / "two").string()).code, 0);
  for (const std::string& picture : pictures)
    EXPECT_EQ(readFile(out / "local_maps" / picture), readFile(dir_ / "two" / "local_maps" / picture)) << picture;

  // Without pictures, none at all; the folder holding pictures is replaced as obsgroup's own.
  const Result off = run("partition " + input + " -q --no-pictures --force -o " + out.string());
  ASSERT_EQ(off.code, 0) << off.err;
  EXPECT_EQ(namesIn(out / "local_maps", "group_", ".pcd").size(), groups);
  for (const auto& entry : fs::recursive_directory_iterator(out)) {
    if (entry.path().filename() == "places.png") continue;  // the label map is data, not a picture
    EXPECT_TRUE(entry.path().extension() != ".png" && entry.path().extension() != ".svg") << entry.path();
  }
  EXPECT_TRUE(fs::exists(out / "places.png"));
}

TEST_F(Cli, TheMapPictureShowsTheRefinedPoses) {
  // Refinement moves members of the drifted office's local maps (their
  // poses in topology.json); on exact poses it keeps them.
  writeFile(dir_ / "drifted.clf", driftedOfficeLog());
  const std::string input = (dir_ / "drifted.clf").string();
  for (const std::string refine : {"none", "icp"})
    ASSERT_EQ(run("partition " + input + " -q --refine " + refine + " -o " + (dir_ / refine).string()).code, 0);
  ASSERT_EQ(readJson(dir_ / "none" / "partition.json").at("groups"),
            readJson(dir_ / "icp" / "partition.json").at("groups"));
  EXPECT_NE(readFile(dir_ / "none" / "map.png"), readFile(dir_ / "icp" / "map.png"));
  EXPECT_NE(readFile(dir_ / "none" / "map.svg"), readFile(dir_ / "icp" / "map.svg"));
  EXPECT_EQ(readFile(dir_ / "none" / "weights.png"), readFile(dir_ / "icp" / "weights.png"));
}

TEST_F(Cli, ArcsBetweenGroupsThatDoNotOverlapAreDrawn) {
  // Every scan 100 m from the previous one: each is a group of its own, and
  // every arc joins consecutive scans only, with weight 0.
  std::istringstream in(simulatedLog("ROBOTLASER1"));
  std::string log, line;
  for (int k = 0; std::getline(in, line); ++k) log += shiftedRobotLaserLog(line, 100.0 * k, 0);
  writeFile(dir_ / "apart.clf", log);
  const Result r = run("partition " + (dir_ / "apart.clf").string() + " -q -o " + (dir_ / "o").string());
  ASSERT_EQ(r.code, 0) << r.err;
  const auto topology = readJson(dir_ / "o" / "topology.json");
  ASSERT_EQ(topology.at("nodes").size(), 24u);
  ASSERT_EQ(topology.at("arcs").size(), 23u);
  for (const auto& arc : topology.at("arcs")) EXPECT_EQ(arc.at("weight").get<double>(), 0.0);
  // Each arc is a dark grey stroke of the SVG (a NaN width or opacity drew
  // none), and so is the legend's sample arc.
  const std::string svg = readFile(dir_ / "o" / "map.svg");
  const std::string arc = "stroke:rgb(15%,15%,15%)";
  std::size_t arcs = 0;
  for (auto at = svg.find(arc); at != std::string::npos; at = svg.find(arc, at + 1)) ++arcs;
  EXPECT_EQ(arcs, 23u + 1u);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  expectValidPng(dir_ / "o" / "map.png");
  EXPECT_EQ(namesIn(dir_ / "o" / "local_maps", "group_", ".png").size(), 24u);
}

TEST_F(Cli, AScanFarFromTheOthersIsNamedByItsLine) {
  // One pose 1e12 m away (a corrupt log): beyond the grid's reach at delta 0.1.
  std::istringstream in(simulatedLog("ROBOTLASER1"));
  std::string log, line;
  for (int k = 1; std::getline(in, line); ++k) log += (k == 3 ? shiftedRobotLaserLog(line, 1e12, 0) : line + "\n");
  writeFile(dir_ / "far.clf", log);
  const Result r = run("partition " + (dir_ / "far.clf").string() + " -q -o " + (dir_ / "o").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("far.clf:3: observation 2: region grid: a point lies too far"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
  const Result paper = run("partition " + (dir_ / "far.clf").string() + " --paper -q -o " + (dir_ / "o").string());
  EXPECT_EQ(paper.code, 3);
  EXPECT_NE(paper.err.find("far.clf:3: observation 2: shared grid: a point lies too far"), std::string::npos)
      << paper.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}


TEST_F(Cli, ThePaperPresetGivesThePapersGroups) {
  // tests/expected/paper_groups.json holds the groups of the paper's method
  // (points model, eq. 16-18; mean split, sec. II-A) as obsgroup computed
  // them before the region models existed, checked then against an
  // independent implementation; --paper and its spelled-out options keep them.
  const nlohmann::json expected = readJson(fs::path(kData).parent_path() / "tests" / "expected" / "paper_groups.json");
  const std::vector<std::pair<std::string, std::string>> inputs{
      {"office_2d", "/office_2d/office.clf"},
      {"office_3d", "/office_3d/pcd"},
      {"localization_demo", "/real/localization_demo/localization_demo.clf"},
      {"sena_odometry", "/real/sena_odometry/sena_odometry.clf"}};
  for (const auto& [name, path] : inputs) {
    for (const char* preset : {" --paper", " --sso points --split mean --ncut-threshold 1 --boundary-passes 0 --mutual-neighbours 0 --correct-odometry off"}) {
      const fs::path out = dir_ / name;
      ASSERT_EQ(run("partition " + kData + path + preset + " --force -q --no-pictures -o " + out.string()).code, 0);
      EXPECT_EQ(readJson(out / "partition.json").at("groups"), expected.at(name)) << name << preset;
    }
  }
  // The measured defaults are not the paper's: on the depth camera they keep rooms the points model breaks.
  ASSERT_EQ(run("partition " + kData + "/office_3d/pcd --force -q --no-pictures -o " + (dir_ / "d").string()).code, 0);
  EXPECT_LT(readJson(dir_ / "d" / "partition.json").at("groups").size(), expected.at("office_3d").size());
}

TEST_F(Cli, GzipLogsAndLogsOnAPipeReadAsTheFile) {
  writeFile(dir_ / "office.log", simulatedLog("ROBOTLASER1"));
  const std::string plain = (dir_ / "office.log").string();
  ASSERT_EQ(run("partition " + plain + " -q --no-pictures -o " + (dir_ / "p").string()).code, 0);
  const auto expected = readJson(dir_ / "p" / "partition.json").at("groups");
  // gzip on disk (told by its bytes, whatever its name), on a pipe, and a plain log on a pipe.
  ASSERT_EQ(std::system(("gzip -c " + plain + " > " + (dir_ / "office.log.gz").string() + " && cp " +
                         (dir_ / "office.log.gz").string() + " " + (dir_ / "renamed.clf").string()).c_str()), 0);
  const std::vector<std::pair<std::string, std::string>> inputs{
      {"gz", (dir_ / "office.log.gz").string()},
      {"renamed", (dir_ / "renamed.clf").string()},
      {"pipe", "- < " + plain},
      {"gz_pipe", "- < " + (dir_ / "office.log.gz").string()}};
  for (const auto& [name, input] : inputs) {
    const Result r = run("partition " + input + " -q --no-pictures -o " + (dir_ / name).string());
    ASSERT_EQ(r.code, 0) << name << ": " << r.err;
    EXPECT_EQ(readJson(dir_ / name / "partition.json").at("groups"), expected) << name;
  }
  // Errors on a pipe name it.
  writeFile(dir_ / "bad.log", logWithLine(3, "ROBOTLASER1 0 1"));
  const Result bad = run("partition - -o " + (dir_ / "b").string() + " < " + (dir_ / "bad.log").string());
  EXPECT_EQ(bad.code, 3);
  EXPECT_NE(bad.err.find("<stdin>:3: ROBOTLASER1 line is truncated"), std::string::npos) << bad.err;
  EXPECT_EQ(run("partition - --format pcd -o " + (dir_ / "c").string() + " < " + plain).code, 2);
}

TEST_F(Cli, AFieldOfViewInRadiansIsReadAsSuchAndRecorded) {
  // As MIT CSAIL's log says it: 3.14159 (radians) with a 0.5 degree resolution.
  writeFile(dir_ / "degrees.log", simulatedLog("FLASER"));
  writeFile(dir_ / "radians.log", simulatedLog("FLASER", "PARAM laser_front_laser_fov 3.14159 0 host 0\n"
                                                         "PARAM laser_front_laser_resolution 0.5 0 host 0\n"));
  ASSERT_EQ(run("partition " + (dir_ / "degrees.log").string() + " -q --no-pictures -o " + (dir_ / "d").string()).code, 0);
  const Result r = run("partition " + (dir_ / "radians.log").string() + " --no-pictures -o " + (dir_ / "r").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("read as radians"), std::string::npos) << r.err;
  const auto d = readJson(dir_ / "d" / "partition.json"), p = readJson(dir_ / "r" / "partition.json");
  EXPECT_NEAR(p.at("parameters").at("fov_deg").get<double>(), 180.0, 1e-3);
  EXPECT_NE(p.at("parameters").at("fov_source").get<std::string>().find("read as radians"), std::string::npos);
  EXPECT_EQ(d.at("parameters").at("fov_source"), "default (180 degrees)");
  EXPECT_EQ(p.at("groups"), d.at("groups"));
}

TEST_F(Cli, ATruncatedLastLineIsAnErrorUnlessBadLinesAreSkipped) {
  const std::string log = simulatedLog("ROBOTLASER1");
  writeFile(dir_ / "cut.clf", log.substr(0, log.size() - 300));  // the recording cut off
  const Result strict = run("partition " + (dir_ / "cut.clf").string() + " -o " + (dir_ / "s").string());
  EXPECT_EQ(strict.code, 3);
  EXPECT_NE(strict.err.find("cut.clf:24: ROBOTLASER1 line is truncated"), std::string::npos) << strict.err;
  const Result skip = run("partition " + (dir_ / "cut.clf").string() + " --skip-bad-lines --no-pictures -o " +
                          (dir_ / "k").string());
  ASSERT_EQ(skip.code, 0) << skip.err;
  EXPECT_NE(skip.err.find("skipped 1 bad line (first: " + (dir_ / "cut.clf").string() + ":24: ROBOTLASER1 line"),
            std::string::npos) << skip.err;
  const auto p = readJson(dir_ / "k" / "partition.json");
  EXPECT_EQ(p.at("observations"), 23);
  EXPECT_EQ(run("partition " + kData + "/office_3d/pcd --skip-bad-lines -o " + (dir_ / "x").string()).code, 2);

  // A bad line in the middle shifts no observation silently: each names its line.
  std::istringstream lines(log);
  std::string text, line;
  int bad_line = 0;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (bad_line == 0 && number > 5 && line.rfind("ROBOTLASER1", 0) == 0) {
      bad_line = number;
      line = "ROBOTLASER1 not a number";
    }
    text += line + "\n";
  }
  writeFile(dir_ / "middle.clf", text);
  const Result middle = run("partition " + (dir_ / "middle.clf").string() + " --skip-bad-lines --no-pictures -o " +
                            (dir_ / "m").string());
  ASSERT_EQ(middle.code, 0) << middle.err;
  const auto m = readJson(dir_ / "m" / "partition.json");
  ASSERT_EQ(m.at("sources").size(), m.at("observations").get<std::size_t>());
  int previous = 0;
  for (const auto& source : m.at("sources")) {
    const std::string s = source;
    const int number = std::stoi(s.substr(s.rfind(':') + 1));
    EXPECT_NE(number, bad_line) << s;
    EXPECT_GT(number, previous) << s;
    previous = number;
  }
  EXPECT_EQ(m.at("stamps").size(), m.at("observations").get<std::size_t>());

  // A gzip log cut short: an error, or with --skip-bad-lines every complete line read is kept.
  writeFile(dir_ / "whole.clf", log);
  ASSERT_EQ(std::system(("gzip -c " + (dir_ / "whole.clf").string() + " > " + (dir_ / "whole.clf.gz").string()).c_str()), 0);
  const std::string gz = readFile(dir_ / "whole.clf.gz");
  writeFile(dir_ / "cut.clf.gz", gz.substr(0, gz.size() * 3 / 4));
  const Result cut_gz = run("partition " + (dir_ / "cut.clf.gz").string() + " --no-pictures -o " + (dir_ / "g").string());
  EXPECT_EQ(cut_gz.code, 3);
  EXPECT_NE(cut_gz.err.find("the gzip data are cut short"), std::string::npos) << cut_gz.err;
  const Result salvaged = run("partition " + (dir_ / "cut.clf.gz").string() + " --skip-bad-lines --no-pictures -o " +
                              (dir_ / "g").string());
  ASSERT_EQ(salvaged.code, 0) << salvaged.err;
  EXPECT_NE(salvaged.err.find("the gzip data are cut short: kept the "), std::string::npos) << salvaged.err;
  const auto kept = readJson(dir_ / "g" / "partition.json").at("observations").get<int>();
  EXPECT_GT(kept, 5);
  EXPECT_LT(kept, 24);
}

TEST_F(Cli, AnEmptyFileIsNamedAsEmpty) {
  writeFile(dir_ / "empty.clf", "");
  const Result log = run("partition " + (dir_ / "empty.clf").string() + " -o " + (dir_ / "a").string());
  EXPECT_EQ(log.code, 3);
  EXPECT_NE(log.err.find("empty.clf: the file is empty"), std::string::npos) << log.err;
  writeFile(dir_ / "pcd" / "000000.pcd", "");
  const Result pcd = run("partition " + (dir_ / "pcd").string() + " -o " + (dir_ / "b").string());
  EXPECT_EQ(pcd.code, 3);
  EXPECT_NE(pcd.err.find("000000.pcd: the file is empty (0 bytes)"), std::string::npos) << pcd.err;
}

TEST_F(Cli, APoseFormatWithoutAPosesFileIsRefused) {
  const Result r = run("partition " + kData + "/office_2d/office.clf --pose-format tum -o " + (dir_ / "o").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--pose-format applies to a --poses file"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

// ---------------------------------------------------------------------------
// ROS bags: the office_2d run written as a ROS 1 and a ROS 2 bag.

#if defined(OBSGROUP_HAVE_ROS1) && defined(OBSGROUP_HAVE_ROS2)
TEST_F(Cli, SimulatedRosBagsGroupAsTheSameCarmenLog) {
  const fs::path ros1 = dir_ / "office.bag", ros2 = dir_ / "office_ros2";
  ASSERT_EQ(std::system((std::string(MAKE_DATASETS_EXE) + " --ros1-bag " + ros1.string() + " > /dev/null").c_str()), 0);
  ASSERT_EQ(std::system((std::string(MAKE_DATASETS_EXE) + " --ros2-bag " + ros2.string() + " > /dev/null").c_str()), 0);
  ASSERT_EQ(run("partition " + kData + "/office_2d/office.clf -q --no-pictures -o " + (dir_ / "log").string()).code, 0);
  const nlohmann::json log = readJson(dir_ / "log" / "partition.json");
  for (const auto& [bag, format] : {std::pair{ros1, "ros1"}, std::pair{ros2, "ros2"}}) {
    const fs::path out = dir_ / (std::string("out_") + format);
    const Result r = run("partition " + bag.string() + " --no-pictures -o " + out.string());
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json p = expectPartitionSchema(out, 77);
    EXPECT_EQ(p.at("groups"), log.at("groups")) << format;
    EXPECT_EQ(p.at("statistics").at("points"), log.at("statistics").at("points"));
    const auto& parameters = p.at("parameters");
    EXPECT_EQ(parameters.at("format"), format);
    EXPECT_EQ(parameters.at("topic"), "/scan");
    EXPECT_EQ(parameters.at("message_type"), "sensor_msgs/LaserScan");
    EXPECT_EQ(parameters.at("poses_from"), "/tf");
    EXPECT_EQ(parameters.at("fixed_frame"), "map");
    EXPECT_EQ(parameters.at("skipped_messages"), 0);
    // The poses in odom, rotated 0.1 rad from map: the grid of the sensed
    // regions lies otherwise on the rooms, so the groups may differ a little.
    const Result odom = run("partition " + bag.string() + " -q --no-pictures --fixed-frame odom -o " +
                            (out.string() + "_odom"));
    ASSERT_EQ(odom.code, 0) << odom.err;
    const nlohmann::json in_odom = expectPartitionSchema(out.string() + "_odom", 77);
    EXPECT_EQ(in_odom.at("parameters").at("fixed_frame"), "odom");
  }
  // A topic the bag does not have names the ones it has.
  const Result missing = run("partition " + ros2.string() + " -q --topic /front_scan -o " + (dir_ / "m").string());
  EXPECT_EQ(missing.code, 3);
  EXPECT_NE(missing.err.find("no topic /front_scan (--topic)"), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find("/scan (sensor_msgs/LaserScan, 77)"), std::string::npos) << missing.err;
  const Result frame = run("partition " + ros1.string() + " -q --fixed-frame world -o " + (dir_ / "w").string());
  EXPECT_EQ(frame.code, 3);
  EXPECT_NE(frame.err.find("/tf has no frame 'world' (--fixed-frame)"), std::string::npos) << frame.err;
  EXPECT_FALSE(fs::exists(dir_ / "m"));
}
#endif

TEST_F(Cli, BagOptionsAndBadBags) {
  const std::string out = " -o " + (dir_ / "o").string();
  const Result topic = run("partition " + kData + "/office_2d/office.clf --topic /scan" + out);
  EXPECT_EQ(topic.code, 2);
  EXPECT_NE(topic.err.find("--topic, --pose-topic and --fixed-frame apply to ROS bags only"), std::string::npos)
      << topic.err;
  std::ofstream(dir_ / "fake.bag") << "FLASER 3 1 1 1 0 0 0 0 0 0 0 host 0\n";
  const Result fake = run("partition " + (dir_ / "fake.bag").string() + out);
  EXPECT_EQ(fake.code, 3);
  EXPECT_NE(fake.err.find("not a ROS 1 bag"), std::string::npos) << fake.err;
  std::ofstream(dir_ / "cut.bag") << "#ROSBAG V2.0\n\x04\x00";
  const Result cut = run("partition " + (dir_ / "cut.bag").string() + out);
  EXPECT_EQ(cut.code, 3);
  EXPECT_NE(cut.err.find("cut.bag"), std::string::npos) << cut.err;
  EXPECT_NE(cut.err.find("rosbag reindex"), std::string::npos) << cut.err;
  const Result both = run("partition " + (dir_ / "cut.bag").string() + " --pose-topic /odom --fixed-frame map" + out);
  EXPECT_EQ(both.code, 2);
  const Result tolerance = run("partition " + (dir_ / "cut.bag").string() + " --max-time-difference 0.1" + out);
  EXPECT_EQ(tolerance.code, 2);
  EXPECT_NE(tolerance.err.find("applies to a bag with --poses"), std::string::npos) << tolerance.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

// ---------------------------------------------------------------------------
// Depth image sequences, KITTI odometry and TUM poses matched by timestamp.

TEST_F(Cli, AFolderWithABrokenFileIsSalvagedOnlyWhenAsked) {
  const fs::path folder = dir_ / "pcd";
  fs::create_directories(folder);
  for (const auto& entry : fs::directory_iterator(kData + "/office_3d/pcd"))
    fs::copy_file(entry.path(), folder / entry.path().filename());
  std::ofstream(folder / "000005.pcd", std::ios::trunc) << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\n";  // cut short
  const std::string poses = " --poses " + kData + "/office_3d/poses.txt";
  const Result failed = run("partition " + folder.string() + poses + " -q --no-pictures -o " + (dir_ / "a").string());
  EXPECT_EQ(failed.code, 3);
  EXPECT_NE(failed.err.find("000005.pcd"), std::string::npos) << failed.err;
  // Each file keeps its own pose: the poses file has one per file, the broken one's dropped with it.
  const Result salvaged = run("partition " + folder.string() + poses + " --no-pictures --skip-bad-files -o " +
                              (dir_ / "b").string());
  ASSERT_EQ(salvaged.code, 0) << salvaged.err;
  EXPECT_NE(salvaged.err.find("--skip-bad-files: left out 1 of 40 files that could not be read: "), std::string::npos)
      << salvaged.err;
  EXPECT_NE(salvaged.err.find("000005.pcd"), std::string::npos) << salvaged.err;
  const nlohmann::json p = expectPartitionSchema(dir_ / "b", 39);
  for (const auto& source : p.at("sources")) EXPECT_EQ(source.get<std::string>().find("000005.pcd"), std::string::npos);
  const Result wrong_kind = run("partition " + kData + "/office_2d/office.clf --skip-bad-files -o " + (dir_ / "c").string());
  EXPECT_EQ(wrong_kind.code, 2);
  EXPECT_NE(wrong_kind.err.find("--skip-bad-files applies to folders of files"), std::string::npos) << wrong_kind.err;
}

TEST_F(Cli, KeyframesAreGroupedAndEveryOtherFrameTakesItsKeyframesPlace) {
  const std::string input = kData + "/office_3d/pcd";
  const Result r = run("partition " + input + " -q --no-pictures --keyframes 3,60 -o " + (dir_ / "k").string());
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json p = expectPartitionSchema(dir_ / "k", 40);
  const auto keyframe_of = p.at("keyframe_of").get<std::vector<int>>();
  ASSERT_EQ(keyframe_of.size(), 40u);
  const std::size_t keyframes = p.at("statistics").at("keyframes").get<std::size_t>();
  EXPECT_LT(keyframes, 40u);
  EXPECT_GT(keyframes, 5u);
  EXPECT_EQ(p.at("parameters").at("keyframes").at("distance"), 3.0);
  // Every frame is in the group of its keyframe, and places.json lists it there too.
  std::vector<int> group_of(40, -1);
  const auto groups = p.at("groups").get<std::vector<std::vector<int>>>();
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (int i : groups[g]) group_of[std::size_t(i)] = int(g);
  for (int i = 0; i < 40; ++i) {
    ASSERT_GE(group_of[std::size_t(i)], 0) << i;
    EXPECT_LE(keyframe_of[std::size_t(i)], i);
    EXPECT_EQ(group_of[std::size_t(i)], group_of[std::size_t(keyframe_of[std::size_t(i)])]) << i;
  }
  std::size_t listed = 0;
  const nlohmann::json places = readJson(dir_ / "k" / "places.json");
  for (const auto& place : places.at("places")) listed += place.at("members").size();
  EXPECT_EQ(listed, 40u);
  EXPECT_TRUE(readJson(dir_ / "k" / "partition.json").at("sources").size() == 40u);
  // Without the option every frame is grouped and keyframe_of is null.
  ASSERT_EQ(run("partition " + input + " -q --no-pictures -o " + (dir_ / "all").string()).code, 0);
  EXPECT_TRUE(readJson(dir_ / "all" / "partition.json").at("keyframe_of").is_null());
  for (const char* bad : {"3", "-1,5", "1,x", "nan,5"}) {
    const Result refused = run("partition " + input + " --keyframes " + bad + " -o " + (dir_ / "x").string());
    EXPECT_EQ(refused.code, 2) << bad;
    EXPECT_NE(refused.err.find("DIST,ANGLE"), std::string::npos) << refused.err;
  }
  EXPECT_EQ(run("stream " + input + " --keyframes 3,60 -o " + (dir_ / "x").string()).code, 2);  // every frame online
}

TEST_F(Cli, SimulatedDepthImagesGroupAsTheSamePcdSequence) {
  // The office_3d run written as TUM RGB-D: 16-bit PNGs in the optical frame.
  const fs::path tum = dir_ / "tum";
  const std::string command = std::string(MAKE_DATASETS_EXE) + " --tum-rgbd " + tum.string() + " > /dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const double f = 40.0 / std::tan(58.0 * 3.14159265358979323846 / 360.0);
  char intrinsics[128];
  std::snprintf(intrinsics, sizeof intrinsics, "%.9f,%.9f,39.5,29.5", f, f);
  const Result a = run("partition " + tum.string() + " -q --no-pictures --intrinsics " + intrinsics + " -o " +
                       (dir_ / "a").string());
  ASSERT_EQ(a.code, 0) << a.err;
  const nlohmann::json p = expectPartitionSchema(dir_ / "a", 40);
  EXPECT_EQ(p.at("parameters").at("format"), "tum-rgbd");
  EXPECT_EQ(p.at("parameters").at("depth_scale"), 5000.0);
  EXPECT_EQ(p.at("parameters").at("skipped_frames"), 0);
  // 80 x 60 pixels is not a dense frame: kept whole unless a --voxel is given.
  EXPECT_EQ(p.at("parameters").at("frame_voxel"), 0.05);
  EXPECT_EQ(p.at("parameters").at("frames_reduced"), 0);
  ASSERT_EQ(run("partition " + kData + "/office_3d/pcd -q --no-pictures -o " + (dir_ / "b").string()).code, 0);
  const nlohmann::json q = readJson(dir_ / "b" / "partition.json");
  EXPECT_EQ(p.at("groups"), q.at("groups"));
  EXPECT_EQ(p.at("statistics").at("points"), q.at("statistics").at("points"));
  // Every other pixel: a quarter of the points, the run still goes through.
  const Result strided = run("partition " + tum.string() + " -q --no-pictures --stride 2 --intrinsics " + intrinsics +
                             " -o " + (dir_ / "c").string());
  ASSERT_EQ(strided.code, 0) << strided.err;
  EXPECT_LT(readJson(dir_ / "c" / "partition.json").at("statistics").at("points").get<double>(),
            0.3 * q.at("statistics").at("points").get<double>());
  // --voxel: every frame filtered as it is read, and said so.
  const Result voxel = run("partition " + tum.string() + " -q --no-pictures --voxel 0.1 --intrinsics " + intrinsics +
                           " -o " + (dir_ / "d").string());
  ASSERT_EQ(voxel.code, 0) << voxel.err;
  const nlohmann::json d = readJson(dir_ / "d" / "partition.json");
  EXPECT_EQ(d.at("parameters").at("frame_voxel"), 0.1);
  EXPECT_EQ(d.at("parameters").at("frames_reduced"), 40);
  EXPECT_EQ(d.at("parameters").at("voxel"), 0.1);
  EXPECT_LT(d.at("statistics").at("points").get<double>(), 0.8 * q.at("statistics").at("points").get<double>());
}

namespace {

void writeBinFile(const fs::path& file, const std::vector<float>& values) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(values.data()),
                                              std::streamsize(values.size() * sizeof(float)));
}

/// A lidar ring of points around the sensor, 5 m away.
std::vector<float> ring() {
  std::vector<float> values;
  for (int k = 0; k < 360; ++k)
    for (float z : {-0.5f, 0.0f, 0.5f})
      values.insert(values.end(), {5.0f * std::cos(k * 0.01745f), 5.0f * std::sin(k * 0.01745f), z, 0.5f});
  return values;
}

}  // namespace

TEST_F(Cli, KittiAndRedwoodFoldersAreDetectedAndRead) {
  const fs::path kitti = dir_ / "kitti";
  writeBinFile(kitti / "velodyne" / "000000.bin", ring());
  writeBinFile(kitti / "velodyne" / "000001.bin", ring());
  writeFile(kitti / "calib.txt", "Tr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n");
  writeFile(kitti / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1\n");
  Result r = run("partition " + kitti.string() + " -q --no-pictures -o " + (dir_ / "k").string());
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json p = expectPartitionSchema(dir_ / "k", 2);
  EXPECT_EQ(p.at("parameters").at("format"), "kitti");
  EXPECT_EQ(p.at("parameters").at("point_type"), "PointXYZI");
  // poses.txt given with --poses: the folder is still KITTI.
  fs::rename(kitti / "poses.txt", dir_ / "00.txt");
  r = run("partition " + kitti.string() + " -q --no-pictures --poses " + (dir_ / "00.txt").string() + " -o " +
          (dir_ / "k2").string());
  ASSERT_EQ(r.code, 0) << r.err;
  std::ofstream(kitti / "velodyne" / "000001.bin", std::ios::binary | std::ios::app) << "xyz";
  r = run("partition " + kitti.string() + " -q --format kitti --poses " + (dir_ / "00.txt").string() + " -o " +
          (dir_ / "k3").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("000001.bin: 17283 bytes, not a multiple of 16"), std::string::npos) << r.err;

  const fs::path redwood = dir_ / "redwood";
  std::vector<std::uint16_t> wall(64 * 48, 3000);  // a wall 3 m ahead
  ASSERT_TRUE(obsgroup::test::writePng((redwood / "depth" / "000000.png").string(), 64, 48, wall));
  ASSERT_TRUE(obsgroup::test::writePng((redwood / "depth" / "000001.png").string(), 64, 48, wall));
  writeFile(redwood / "trajectory.log", "0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"
                                        "1 1 2\n1 0 0 0.1\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  r = run("partition " + redwood.string() + " -q --no-pictures --intrinsics 50,50,31.5,23.5 --depth-max 4 -o " +
          (dir_ / "r").string());
  ASSERT_EQ(r.code, 0) << r.err;
  p = expectPartitionSchema(dir_ / "r", 2);
  EXPECT_EQ(p.at("parameters").at("format"), "redwood");
  EXPECT_EQ(p.at("parameters").at("depth_scale"), 1000.0);
  EXPECT_EQ(p.at("statistics").at("points"), 2 * 64 * 48);
  // Deeper than --depth-max: no point at all, each image a group of its own, with a warning.
  r = run("partition " + redwood.string() + " -q --no-pictures --depth-max 2 -o " + (dir_ / "r2").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readJson(dir_ / "r2" / "partition.json").at("groups").size(), 2u);
  writeFile(redwood / "trajectory.log", "0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  r = run("partition " + redwood.string() + " -q -o " + (dir_ / "r3").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("trajectory.log: 1 trajectory entries for 2 depth images"), std::string::npos) << r.err;
  ASSERT_TRUE(obsgroup::test::writePng((redwood / "depth" / "000001.png").string(), 2, 2, {1, 2, 3, 4}, 8));
  r = run("partition " + redwood.string() + " -q --format redwood --poses " + (dir_ / "00.txt").string() + " -o " +
          (dir_ / "r4").string());
  EXPECT_EQ(r.code, 3);  // a KITTI file is not a trajectory.log
  EXPECT_NE(r.err.find("00.txt:1: frame 0: a block starts with a line of 3 numbers"), std::string::npos) << r.err;
}

TEST_F(Cli, DepthOptionsAreCheckedAndOnlyWhereTheyApply) {
  const std::string log = kData + "/office_2d/office.clf";
  const std::string out = " -o " + (dir_ / "out").string();
  Result r = run("partition " + log + out + " --stride 2");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("apply to depth images only"), std::string::npos) << r.err;
  EXPECT_EQ(run("partition " + kData + "/office_3d/pcd" + out + " --depth-scale 1000").code, 2);
  EXPECT_EQ(run("partition " + log + out + " --max-time-difference 0.1").code, 2);
  const fs::path tum = dir_ / "tum";
  ASSERT_TRUE(obsgroup::test::writePng((tum / "depth" / "1.png").string(), 4, 3, std::vector<std::uint16_t>(12, 5000)));
  writeFile(tum / "depth.txt", "1.0 depth/1.png\n");
  writeFile(tum / "groundtruth.txt", "1.01 0 0 0 0 0 0 1\n");
  r = run("partition " + tum.string() + out + " --intrinsics 525,525,319.5");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--intrinsics: 3 values, expected 4"), std::string::npos) << r.err;
  EXPECT_EQ(run("partition " + tum.string() + out + " --intrinsics 0,525,1,1").code, 2);
  EXPECT_EQ(run("partition " + tum.string() + out + " --stride 0").code, 2);
  EXPECT_EQ(run("partition " + tum.string() + out + " --depth-scale -5").code, 2);
  EXPECT_EQ(run("partition " + log + out + " --format tum-rgbd").code, 2);  // a file, not a folder
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  r = run("partition " + tum.string() + " -q --no-pictures" + out);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readJson(dir_ / "out" / "partition.json").at("parameters").at("format"), "tum-rgbd");
  r = run("partition " + tum.string() + " --max-time-difference 0.001 --force" + out);
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("groundtruth.txt: no pose within"), std::string::npos) << r.err;
  writeFile(tum / "depth.txt", "1.0 depth/1.png\n1.5 depth/2.png\n");
  r = run("partition " + tum.string() + " --force" + out);
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("depth.txt:2: field 'filename': "), std::string::npos) << r.err;
}

TEST_F(Cli, PcdFilesNamedByTimestampAreMatchedToTumPosesByTime) {
  const fs::path seq = dir_ / "seq";
  fs::create_directories(seq);
  const std::vector<std::string> stamps = {"1305031102.175304", "1305031102.675304", "1305031103.175304"};
  for (int k = 0; k < 3; ++k)
    fs::copy_file(kData + "/office_3d/pcd/00000" + std::to_string(k) + ".pcd", seq / (stamps[k] + ".pcd"));
  // Out of order, off by a few milliseconds, one pose too many and one cloud without a pose.
  writeFile(dir_ / "poses.txt", "1305031103.9 9 9 9 0 0 0 1\n"
                                "1305031102.68 3.5 1.25 1 0 0 0 1\n"
                                "1305031102.17 1 1.25 1 0 0 0 1\n");
  Result r = run("partition " + seq.string() + " --no-pictures --poses " + (dir_ / "poses.txt").string() + " -o " +
                 (dir_ / "a").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("1 of 3 PCD files have no pose"), std::string::npos) << r.err;
  nlohmann::json p = readJson(dir_ / "a" / "partition.json");
  EXPECT_EQ(p.at("observations"), 2);
  EXPECT_EQ(p.at("parameters").at("poses_matched_by"), "timestamp");
  EXPECT_EQ(p.at("parameters").at("pose_format"), "tum");  // told by the 8 columns
  r = run("partition " + seq.string() + " -q --no-pictures --max-time-difference 1 --poses " +
          (dir_ / "poses.txt").string() + " -o " + (dir_ / "b").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readJson(dir_ / "b" / "partition.json").at("observations"), 3);
  // Files named by index: line order, where a tolerance means nothing.
  r = run("partition " + kData + "/office_3d/pcd -q --max-time-difference 1 --poses " + kData +
          "/office_3d/poses.txt -o " + (dir_ / "c").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("not named by timestamps"), std::string::npos) << r.err;
  writeFile(dir_ / "odd.txt", "1 2 3 4 5\n");
  r = run("partition " + seq.string() + " -q --poses " + (dir_ / "odd.txt").string() + " -o " + (dir_ / "d").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("odd.txt:1: a pose line has 5 values: neither TUM"), std::string::npos) << r.err;
}

namespace {

/// The "groups" of a partition.json as written: the text between its key and "splits".
std::string groupsText(const fs::path& out) {
  const std::string text = readFile(out / "partition.json");
  // The groups, not their ids: the stream's are the online grouping's own.
  const std::size_t begin = text.find("\"groups\":"), end = text.find("\"place_ids\":");
  return begin == std::string::npos || end == std::string::npos ? "" : text.substr(begin, end - begin);
}

/// The first `count` scans of the simulated ROBOTLASER1 log, stamped `stamps` (seconds).
std::string stampedLog(const std::vector<std::string>& stamps) {
  std::istringstream in(simulatedLog("ROBOTLASER1"));
  std::string log, line;
  for (const std::string& stamp : stamps) {
    std::getline(in, line);
    log += line.substr(0, line.rfind(" 1.0 host 1.0")) + " " + stamp + " host " + stamp + "\n";
  }
  return log;
}

}  // namespace

TEST_F(Cli, StreamGivesTheGroupsOfPartitionAndPrintsEachChange) {
  const std::string input = kData + "/office_2d/office.clf";
  ASSERT_EQ(run("partition " + input + " -q --no-pictures -o " + (dir_ / "batch").string()).code, 0);
  const nlohmann::json batch = readJson(dir_ / "batch" / "partition.json");
  const Result r = run("stream " + input + " -o " + (dir_ / "stream").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(groupsText(dir_ / "stream"), groupsText(dir_ / "batch"));
  ASSERT_FALSE(groupsText(dir_ / "batch").empty());
  const nlohmann::json p = readJson(dir_ / "stream" / "partition.json");
  expectAllOutputs(dir_ / "stream", p);
  EXPECT_EQ(p.at("parameters").at("mode"), "stream");
  EXPECT_EQ(p.at("parameters").at("update_every"), 1);
  EXPECT_EQ(p.at("statistics").at("updates"), 77);
  for (const char* key : {"points", "edges", "groups", "local_map_points", "open_floor_joins"})
    EXPECT_EQ(p.at("statistics").at(key), batch.at("statistics").at(key)) << key;
  EXPECT_TRUE(p.at("timing_s").at("stream").is_number());
  EXPECT_NE(r.err.find("77 observations"), std::string::npos) << r.err;
  // One line per observation saying its place (a few more where a later
  // update moved one); each observation's last line gives its place in the results.
  std::map<int, int> final_place;
  for (std::size_t g = 0; g < p.at("groups").size(); ++g)
    for (int i : p.at("groups")[g]) final_place[i] = p.at("place_ids")[g];
  std::istringstream lines(r.out);
  std::string line;
  std::map<int, int> last_place;
  std::size_t count = 0;
  for (; std::getline(lines, line); ++count) {
    std::istringstream words(line);
    std::string observation, id, place;
    int place_id = -1;
    words >> observation >> id >> place >> place_id;
    EXPECT_EQ(observation, "observation") << line;
    ASSERT_EQ(id.back(), ':') << line;
    EXPECT_EQ(place, "place") << line;
    last_place[std::stoi(id)] = place_id;
  }
  EXPECT_GE(count, 77u);
  EXPECT_LE(count, 2 * 77u);
  EXPECT_EQ(last_place, final_place);
  EXPECT_EQ(r.out.rfind("observation 0: place 0 (new place)\n", 0), 0u) << r.out.substr(0, 200);
  EXPECT_NE(r.out.find(" split into "), std::string::npos) << r.out;

  // --verbose: every change of the groups, named after the observation just inserted.
  const Result verbose = run("stream " + input + " --verbose --no-pictures -o " + (dir_ / "verbose").string());
  ASSERT_EQ(verbose.code, 0) << verbose.err;
  EXPECT_EQ(verbose.out.rfind("observation 0: group 0 created (1 observation)\n", 0), 0u) << verbose.out.substr(0, 200);
  EXPECT_NE(verbose.out.find(" grown ("), std::string::npos);

  // Every 10 inserts, quiet: the same groups, nothing printed.
  const Result quiet = run("stream " + input + " -q --no-pictures --update-every 10 -o " + (dir_ / "ten").string());
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.out, "");
  EXPECT_EQ(quiet.err, "");
  EXPECT_EQ(groupsText(dir_ / "ten"), groupsText(dir_ / "batch"));
  const nlohmann::json ten = readJson(dir_ / "ten" / "partition.json");
  EXPECT_EQ(ten.at("statistics").at("updates"), 8);  // after 10, 20, ..., 70 and the last (77)
  EXPECT_EQ(ten.at("parameters").at("update_every"), 10);

  // Local updates in between: the last update is exact, so the groups are still partition's.
  const Result local = run("stream " + input + " -q --no-pictures --exact-every 20 -o " + (dir_ / "local").string());
  ASSERT_EQ(local.code, 0) << local.err;
  EXPECT_EQ(groupsText(dir_ / "local"), groupsText(dir_ / "batch"));
  EXPECT_EQ(readJson(dir_ / "local" / "partition.json").at("parameters").at("exact_every"), 20);
}

TEST_F(Cli, StreamOptionsAndErrors) {
  const std::string input = kData + "/office_2d/office.clf";
  EXPECT_NE(run("--help").out.find("stream"), std::string::npos);
  const Result help = run("stream --help");
  EXPECT_EQ(help.code, 0);
  for (const char* option :
       {"--update-every", "--exact-every", "--realtime", "--refine", "--no-pictures", "--threads", "--quiet"})
    EXPECT_NE(help.out.find(option), std::string::npos) << option;
  EXPECT_EQ(run("stream " + input + " --update-every 0 -o " + (dir_ / "o").string()).code, 2);
  EXPECT_EQ(run("stream " + input + " --exact-every 0 -o " + (dir_ / "o").string()).code, 2);
  // A PCD sequence has no timestamps to replay at.
  const Result pcd = run("stream " + kData + "/office_3d/pcd --realtime -o " + (dir_ / "o").string());
  EXPECT_EQ(pcd.code, 2);
  EXPECT_NE(pcd.err.find("no timestamps"), std::string::npos) << pcd.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
  // An observation the online grouping refuses is named by its line, as partition names it.
  std::istringstream in(simulatedLog("ROBOTLASER1"));
  std::string log, line;
  for (int k = 1; std::getline(in, line); ++k) log += (k == 3 ? shiftedRobotLaserLog(line, 1e12, 0) : line + "\n");
  writeFile(dir_ / "far.clf", log);
  const Result far = run("stream " + (dir_ / "far.clf").string() + " -q -o " + (dir_ / "o").string());
  EXPECT_EQ(far.code, 3);
  EXPECT_NE(far.err.find("far.clf:3: observation 2: region grid: a point lies too far"), std::string::npos) << far.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

TEST_F(Cli, StreamRealtimeReplaysAtTheLogsStamps) {
  // 0.6 s of stamps; the one going back is due at once, not slept on.
  writeFile(dir_ / "short.clf", stampedLog({"100.0", "100.2", "100.1", "100.4", "100.6", "100.6"}));
  // The schedule itself is tested on a fake clock (test_replay_clock.cpp);
  // here, that the command replays and records it, whatever the machine's load.
  const Result r = run("stream " + (dir_ / "short.clf").string() + " --realtime --no-pictures -o " +
                       (dir_ / "rt").string());
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json p = readJson(dir_ / "rt" / "partition.json");
  EXPECT_EQ(p.at("parameters").at("realtime"), true);
  EXPECT_GE(p.at("timing_s").at("realtime_wait").get<double>(), 0.0);
  const std::string batch = "partition " + (dir_ / "short.clf").string() + " -q --no-pictures -o ";
  ASSERT_EQ(run(batch + (dir_ / "b").string()).code, 0);
  EXPECT_EQ(groupsText(dir_ / "rt"), groupsText(dir_ / "b"));
  EXPECT_NE(r.out.find("observation 5:"), std::string::npos) << r.out;

  // A stamp that is not a number: an error naming line and field when
  // replaying at the stamps, nothing otherwise.
  writeFile(dir_ / "bad.clf", stampedLog({"100.0", "later"}));
  const Result bad = run("stream " + (dir_ / "bad.clf").string() + " --realtime -q -o " + (dir_ / "x").string());
  EXPECT_EQ(bad.code, 3);
  EXPECT_NE(bad.err.find("bad.clf:2: field 'timestamp': 'later' is not a number"), std::string::npos) << bad.err;
  EXPECT_EQ(run("stream " + (dir_ / "bad.clf").string() + " -q --no-pictures -o " + (dir_ / "y").string()).code, 0);

  // Ctrl-C while waiting for a late stamp (a minute away) stops the replay:
  // sent once the first observation was grouped, it ends the run with 130.
  writeFile(dir_ / "slow.clf", stampedLog({"0", "60"}));
  EXPECT_EQ(runInterruptedAtLine({"stream", (dir_ / "slow.clf").string(), "--realtime", "-o", (dir_ / "s").string()},
                                 "observation 0:"),
            130);
  EXPECT_FALSE(fs::exists(dir_ / "s"));
}

TEST_F(Cli, LocateFindsEachObservationsPlaceAndRefusesWhatItCannotUse) {
  const std::string input = kData + "/office_2d/office.clf";
  const fs::path run1 = dir_ / "run1", located = dir_ / "located.json";
  ASSERT_EQ(run("partition " + input + " -q --no-pictures -o " + run1.string()).code, 0);
  const Result r = run("locate " + run1.string() + " " + input + " -o " + located.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("77 observations: 77 in a place"), std::string::npos) << r.err;
  // The run's own poses lie in their own groups' places.
  const nlohmann::json partition = readJson(run1 / "partition.json");
  std::map<int, int> place_of;
  for (std::size_t g = 0; g < partition.at("groups").size(); ++g)
    for (int i : partition.at("groups")[g]) place_of[i] = partition.at("place_ids")[g];
  const nlohmann::json locations = readJson(located).at("locations");
  ASSERT_EQ(locations.size(), 77u);
  for (const auto& l : locations) {
    const int i = l.at("observation");
    EXPECT_EQ(l.at("place"), place_of.at(i)) << l.dump();
    EXPECT_EQ(l.at("distance_m"), 0.0);
    EXPECT_NE(l.at("source").get<std::string>().find("office.clf:"), std::string::npos);
    EXPECT_TRUE(l.at("stamp").is_number());
  }
  // Nothing the user gave is overwritten without asking, and no folder of places means usage.
  const std::string before = readFile(located);
  const Result again = run("locate " + run1.string() + " " + input + " -o " + located.string());
  EXPECT_EQ(again.code, 2);
  EXPECT_NE(again.err.find("exists; --force replaces it"), std::string::npos) << again.err;
  EXPECT_EQ(readFile(located), before);
  EXPECT_EQ(run("locate " + run1.string() + " " + input + " --force -q -o " + located.string()).code, 0);
  const Result no_places = run("locate " + dir_.string() + " " + input + " -o " + (dir_ / "x.json").string());
  EXPECT_EQ(no_places.code, 2);
  EXPECT_NE(no_places.err.find("holds no obsgroup places"), std::string::npos) << no_places.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.json"));
  // An input that fails to read is exit 3, as for partition.
  std::ofstream(dir_ / "bad.clf") << "FLASER 3 1.0 1.0\n";
  const Result bad = run("locate " + run1.string() + " " + (dir_ / "bad.clf").string() + " -o " + (dir_ / "y.json").string());
  EXPECT_EQ(bad.code, 3) << bad.err;
  EXPECT_FALSE(fs::exists(dir_ / "y.json"));
  // A damaged label map names its file.
  std::ofstream(run1 / "places.png") << "not a png";
  const Result damaged = run("locate " + run1.string() + " " + input + " -o " + (dir_ / "z.json").string());
  EXPECT_EQ(damaged.code, 3);
  EXPECT_NE(damaged.err.find("places.png"), std::string::npos) << damaged.err;
}

TEST_F(Cli, DriftedOdometryIsCorrectedBeforeGroupingAndLocating) {
  // sena_odometry's poses are a robot's raw odometry: partition groups at
  // the scan-matched poses, and locate corrects the same log the same way,
  // so each observation lies in its own group's place; at the raw poses it
  // does not, unless tracked against the map.
  const std::string input = kData + "/real/sena_odometry/sena_odometry.clf";
  const fs::path run1 = dir_ / "run1";
  const Result grouped = run("partition " + input + " --no-pictures -o " + run1.string());
  ASSERT_EQ(grouped.code, 0) << grouped.err;
  EXPECT_NE(grouped.err.find("poses corrected by scan matching"), std::string::npos) << grouped.err;
  const nlohmann::json partition = readJson(run1 / "partition.json");
  const nlohmann::json& correction = partition.at("statistics").at("odometry_correction");
  EXPECT_TRUE(correction.at("applied").get<bool>());
  EXPECT_LT(correction.at("corrected_map_cells").get<double>(), 0.5 * correction.at("input_map_cells").get<double>());
  EXPECT_LT(correction.at("corrected_blocked_share").get<double>(),
            0.8 * correction.at("input_blocked_share").get<double>());
  // Its odometry over-counts turns: the matched steps say so, and the summary tells the user.
  EXPECT_LT(correction.at("odometry_bias").at("turn_scale").get<double>(), -0.1);
  EXPECT_NE(grouped.err.find("odometry calibration the matched steps found"), std::string::npos) << grouped.err;
  EXPECT_EQ(partition.at("parameters").at("correct_odometry"), "auto");
  std::map<int, int> place_of;
  for (std::size_t g = 0; g < partition.at("groups").size(); ++g)
    for (int i : partition.at("groups")[g]) place_of[i] = partition.at("place_ids")[g];
  const auto ownPlaces = [&](const std::string& options) {
    const fs::path located = dir_ / "located.json";
    const Result r = run("locate " + run1.string() + " " + input + " -q --force " + options + " -o " + located.string());
    EXPECT_EQ(r.code, 0) << r.err;
    const nlohmann::json locations = readJson(located).at("locations");
    int own = 0;
    for (const auto& l : locations) own += l.at("place") == place_of.at(l.at("observation").get<int>());
    return own;
  };
  // At the same corrected poses every observation is in its own place;
  // tracked against the local maps, a scan on a boundary may align across it.
  EXPECT_EQ(ownPlaces("--no-track"), 224);
  EXPECT_GE(ownPlaces(""), 222);
  EXPECT_LT(ownPlaces("--correct-odometry off --no-track"), 200);
  // Tracked against the map, the raw odometry follows it too.
  EXPECT_GT(ownPlaces("--correct-odometry off"), 210);
  // Exact poses are not touched: the shipped office's groups with the correction off are the same.
  const fs::path exact_on = dir_ / "exact_on", exact_off = dir_ / "exact_off";
  ASSERT_EQ(run("partition " + kData + "/office_2d/office.clf -q --no-pictures -o " + exact_on.string()).code, 0);
  ASSERT_EQ(run("partition " + kData + "/office_2d/office.clf -q --no-pictures --correct-odometry off -o " +
                exact_off.string()).code, 0);
  EXPECT_EQ(readJson(exact_on / "partition.json").at("groups"), readJson(exact_off / "partition.json").at("groups"));
  EXPECT_FALSE(readJson(exact_on / "partition.json").at("statistics").at("odometry_correction").at("applied").get<bool>());
  // --paper groups at the poses given, and says so when asked for both.
  const Result both = run("partition " + input + " --paper --correct-odometry auto -o " + (dir_ / "p").string());
  EXPECT_EQ(both.code, 2);
  EXPECT_NE(both.err.find("--paper groups at the input poses"), std::string::npos) << both.err;
}

TEST_F(Cli, LocateAlignsAnOffsetRunToItsPlacesLocalMaps) {
  // Run 1 at the true poses; run 2 the same depth frames with every pose 0.29 m off.
  const fs::path run1 = dir_ / "run1";
  ASSERT_EQ(run("partition " + kData + "/office_3d/pcd --poses " + kData + "/office_3d/poses.txt -q --no-pictures -o " +
                run1.string()).code, 0);
  std::ifstream in(kData + "/office_3d/poses.txt");
  std::ofstream off(dir_ / "poses_off.txt");
  std::vector<Eigen::Vector2d> truth;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t, x, y, z, qx, qy, qz, qw;
    fields >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
    truth.emplace_back(x, y);
    off << std::setprecision(12) << t << " " << x + 0.25 << " " << y - 0.15 << " " << z << " " << qx << " " << qy << " "
        << qz << " " << qw << "\n";
  }
  off.close();
  const fs::path located = dir_ / "located.json";
  const Result r = run("locate " + run1.string() + " " + kData + "/office_3d/pcd --poses " +
                       (dir_ / "poses_off.txt").string() + " --align -o " + located.string());
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<double> errors;
  const nlohmann::json locations = readJson(located);
  for (const auto& l : locations.at("locations")) {
    ASSERT_TRUE(l.contains("converged")) << l.dump();
    if (!l.at("converged").get<bool>()) continue;
    EXPECT_TRUE(l.at("fitness_m2").is_number());
    const auto& pose = l.at("aligned_pose");
    const Eigen::Vector2d at(pose.at("x").get<double>(), pose.at("y").get<double>());
    errors.push_back((at - truth.at(l.at("observation").get<std::size_t>())).norm());
  }
  ASSERT_GE(errors.size(), 0.9 * truth.size()) << r.err;
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.1) << "median error of the aligned poses";  // 0.29 m before
}

// examples/pcl_grouping, "the few lines a PCL user needs", groups as the
// command does with its defaults (the same GroupingParameters).
TEST_F(Cli, ThePclExampleGivesTheCommandsGroups) {
  const std::string pcd = kData + "/office_3d/pcd";
  ASSERT_EQ(run("partition " + pcd + " -q --no-pictures -o " + (dir_ / "out").string()).code, 0);
  const nlohmann::json partition = readJson(dir_ / "out" / "partition.json");
  // The example takes the files in the order given: give them in name order, as the command reads them.
  std::vector<std::string> sorted;
  for (const auto& entry : fs::directory_iterator(pcd)) sorted.push_back(entry.path().string());
  std::sort(sorted.begin(), sorted.end());
  std::string files;
  for (const auto& f : sorted) files += " " + f;
  const fs::path out = dir_ / "example.txt";
  ASSERT_EQ(std::system((std::string(PCL_GROUPING_EXE) + files + " > " + out.string()).c_str()), 0);
  std::istringstream lines(readFile(out));
  std::vector<std::vector<int>> groups;
  for (std::string line; std::getline(lines, line);) {
    const std::size_t colon = line.rfind(':');
    ASSERT_NE(colon, std::string::npos) << line;
    std::istringstream members(line.substr(colon + 1));
    groups.emplace_back();
    for (int i; members >> i;) groups.back().push_back(i);
  }
  EXPECT_EQ(nlohmann::json(groups), partition.at("groups"));
  EXPECT_GT(groups.size(), 1u);
}
