// The evidence behind docs/grouping.md: which sensed-space model groups the
// observations of a building into its rooms? Simulated buildings give the
// true place of every pose; each dataset is a building scanned along its
// route by one sensor, the grouping seeing either the true poses or a
// drifted copy of them (the scans are always taken at the true poses).
// Measured per dataset and configuration: the number of groups, their mean
// size, the adjusted Rand index against the true places (rooms and corridor
// stretches) and how many rooms land whole in one group.
//
//   evaluate_grouping [--output FILE] [parameters]
//       the six configurations of the page (models points, free-space and
//       visibility, each split by mean and by best Ncut) on every dataset;
//       prints the tables, or writes them into FILE between the lines
//       "<!-- generated:begin -->" and "<!-- generated:end -->", keeping the rest.
//   evaluate_grouping --model M [--split S] [parameters] [selection]
//       one configuration: a line per dataset and a summary line, for sweeps.
//
//   evaluate_grouping --log LOG --labels LABELS.json [--log ... --labels ...] [parameters]
//       real CARMEN logs with a room label per scan ({"names", "kinds",
//       "labels"}: a region per scan, "room" or "corridor"): a line per log
//       (groups, ARI, rooms found and pure) and a summary line.
//
//   evaluate_grouping --write-logs FOLDER [selection]
//       writes the selected laser datasets as CARMEN logs (ROBOTLASER1, the
//       poses the grouping sees), the depth camera's and the lidar's as
//       folders of PCD files with their poses.txt, and the labels of each
//       building in the same JSON, to run `obsgroup partition` on them and
//       look at its pictures.
//
// Run with --help for the parameters and the selection of datasets.

#include "floor_plan.h"
#include "generated_section.h"
#include "scenarios.h"
#include "to_cloud.h"

#include <obsgroup/maps/odometry_correction.h>
#include <obsgroup/observation_grouping.h>

#include <pcl/io/pcd_io.h>
#ifdef OBSGROUP_EVALUATE_LABELLED_LOGS
#include <obsgroup/io/carmen_reader.h>

#include <nlohmann/json.hpp>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using namespace obsgroup;
using obsgroup::examples::splitList;
using obsgroup::examples::writeGeneratedSection;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

namespace {

/// The drift of the "drift" datasets; one seed for every building and sensor,
/// so that a building's drifted route is the same whatever scans it.
constexpr std::uint64_t kDriftSeed = 7;
/// Corridors are cut into places of about this length (see sim::placesAlong).
constexpr double kStretchLength = 8.0;
/// A pose nearer a wall than this is reported (a robot is wider).
constexpr double kCrampedClearance = 0.25;

/// printf into a std::string (the tables' numbers).
std::string format(const char* pattern, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* pattern, ...) {
  char buffer[1024];
  va_list args;
  va_start(args, pattern);
  std::vsnprintf(buffer, sizeof buffer, pattern, args);
  va_end(args);
  return buffer;
}

/// Exact poses, odometry-like random drift (sim::drift), or biased odometry
/// (sim::biasedDrift: each step 2% long and turned 1 degree per metre).
enum class PoseSource { Exact, Drift, Bias };

std::string toString(PoseSource poses) {
  return poses == PoseSource::Exact ? "exact" : poses == PoseSource::Drift ? "drift" : "bias";
}

PoseSource poseSourceFromString(const std::string& name) {
  if (name == "exact") return PoseSource::Exact;
  if (name == "drift") return PoseSource::Drift;
  if (name == "bias") return PoseSource::Bias;
  throw std::invalid_argument("unknown poses '" + name + "' (exact, drift or bias)");
}

/// One building scanned by one sensor, seen through exact or drifted poses.
struct Dataset {
  std::string building, title;
  sim::Sensor sensor = sim::Sensor::Laser360;
  PoseSource poses = PoseSource::Exact;
  std::vector<Observation<pcl::PointXYZ>> observations;
  /// The same scans at the poses the command groups at: corrected by scan
  /// matching when that draws a more consistent map (OdometryCorrection::Auto).
  std::vector<Observation<pcl::PointXYZ>> corrected;
  double corrected_rms = 0.0;  ///< of `corrected`, from the true poses, metres
  bool correction_applied = false;
  sim::Places places;
  int rooms = 0;            ///< true rooms (not corridor stretches) with at least one pose
  double drift_rms = 0.0;   ///< of the poses the grouping sees, from the true poses, metres
  double mean_points = 0.0;
  /// Poses of the route closer than kCrampedClearance to a wall, or inside
  /// furniture: their scans see little but that wall or box.
  int cramped_poses = 0;

  std::string name() const { return building + " " + sim::toString(sensor) + " " + toString(poses); }
  std::string heading() const {
    return title + "; " + sim::describe(sensor) + ", " +
           (poses == PoseSource::Exact ? "exact poses" : poses == PoseSource::Drift ? "drifted poses" : "biased odometry");
  }
};

/// Generates the selected datasets. A building's scans are made once per
/// sensor and shared (the clouds are reference counted) by its exact and
/// drifted datasets, which differ only in the poses.
std::vector<Dataset> makeDatasets(const std::vector<std::string>& buildings, const std::vector<sim::Sensor>& sensors,
                                  const std::vector<PoseSource>& pose_sources,
                                  const sim::DepthCamera& depth_camera = sim::depthCamera()) {
  std::vector<Dataset> datasets;
  for (const std::string& key : buildings) {
    const sim::Building building = sim::makeBuilding(key);
    const sim::Places places = sim::placesAlong(building.plan, building.route, kStretchLength);
    std::set<int> rooms_visited;
    for (int place : places.of_pose)
      if (places.is_room[place]) rooms_visited.insert(place);
    int cramped = 0;
    for (const sim::Pose2D& pose : building.route)
      cramped += building.plan.clearanceAt(pose.x, pose.y, kCrampedClearance) < kCrampedClearance;
    for (sim::Sensor sensor : sensors) {
      // The sensor frame's height: a depth camera stands over the floor, a
      // laser scans in the plane z = 0.
      const double height = sim::sensorHeight(sensor);
      std::vector<Cloud::ConstPtr> clouds;
      std::vector<Eigen::Isometry3d> truth;
      std::size_t points = 0;
      for (std::size_t k = 0; k < building.route.size(); ++k) {
        const sim::Pose2D& pose = building.route[k];
        Cloud::ConstPtr cloud;
        switch (sensor) {
          case sim::Sensor::Laser360:
            cloud = sim::scanCloud<pcl::PointXYZ>(building.plan, pose, sim::laser360(), k);
            break;
          case sim::Sensor::Laser180:
            cloud = sim::scanCloud<pcl::PointXYZ>(building.plan, pose, sim::laser180(), k);
            break;
          case sim::Sensor::Depth:
            cloud = sim::depthCloud<pcl::PointXYZ>(building.plan, pose, depth_camera, k);
            break;
          case sim::Sensor::Lidar:
            cloud = sim::lidarCloud<pcl::PointXYZ>(building.plan, pose, sim::lidar(), k);
            break;
        }
        points += cloud->size();
        clouds.push_back(cloud);
        truth.push_back(sim::toIsometry(pose, height));
      }
      const std::vector<Eigen::Isometry3d> drifted = sim::drift(truth, kDriftSeed);
      const std::vector<Eigen::Isometry3d> biased = sim::biasedDrift(truth);
      for (PoseSource source : pose_sources) {
        Dataset d;
        d.building = key;
        d.title = building.title;
        d.sensor = sensor;
        d.poses = source;
        d.places = places;
        d.rooms = static_cast<int>(rooms_visited.size());
        d.cramped_poses = cramped;
        d.mean_points = clouds.empty() ? 0.0 : double(points) / double(clouds.size());
        const std::vector<Eigen::Isometry3d>& seen =
            source == PoseSource::Exact ? truth : source == PoseSource::Drift ? drifted : biased;
        d.drift_rms = sim::rmsPositionError(seen, truth);
        for (std::size_t k = 0; k < clouds.size(); ++k) d.observations.push_back({clouds[k], seen[k]});
        d.corrected = d.observations;
        d.correction_applied = correctOdometry(d.corrected, OdometryCorrection::Auto).applied;
        std::vector<Eigen::Isometry3d> corrected_poses;
        for (const auto& o : d.corrected) corrected_poses.push_back(o.pose);
        d.corrected_rms = sim::rmsPositionError(corrected_poses, truth);
        datasets.push_back(std::move(d));
      }
    }
  }
  return datasets;
}

/// Everything ObservationGrouping is given besides the observations.
struct Configuration {
  SensedSpaceModel model = SensedSpaceModel::Points;
  SplitCriterion split = SplitCriterion::Mean;
  double match_distance = 0.1;  ///< delta of the points model: the paper's
  RegionParameters region;      ///< of the free-space and visibility models
  int min_group_size = 1;
  double ncut_threshold = GroupingParameters{}.ncut_threshold;
  int boundary_passes = GroupingParameters{}.boundary_passes;
  /// GroupingParameters::mutual_neighbours (a count, swept as a number).
  double mutual_neighbours = GroupingParameters{}.mutual_neighbours;
  double mutual_neighbours_share = GroupingParameters{}.mutual_neighbours_share;
  /// GroupingParameters::open_floor_width (the visibility model's alone).
  double open_floor_width = GroupingParameters{}.open_floor_width;
  /// Groups whose places meet through a passage are joined, as `obsgroup
  /// partition` does (--join-passages; the visibility model's alone).
  bool join_passages = true;
  int threads = 0;  ///< 0: all cores
  /// Off: grouped at the poses given; Auto: at the poses the command groups
  /// at (each dataset's `corrected`).
  OdometryCorrection correct_odometry = OdometryCorrection::Auto;
  /// Voxel leaf of each observation (0: every point); the command reduces
  /// dense frames at io::kDefaultFrameVoxel with the same pcl::VoxelGrid in
  /// the sensor frame as they are read.
  double voxel_leaf = 0.0;

  /// The page's row label: the model (with δ for points) and the split; the
  /// region parameters are common to all rows and stated once.
  std::string label() const {
    const std::string delta = model == SensedSpaceModel::Points ? format(" δ %g m", match_distance) : std::string();
    const auto same_method = [this](const GroupingParameters& p) {
      return model == p.model && split == p.split && ncut_threshold == p.ncut_threshold &&
             boundary_passes == p.boundary_passes && mutual_neighbours == p.mutual_neighbours &&
             mutual_neighbours_share == p.mutual_neighbours_share &&
             (model != SensedSpaceModel::Visibility || open_floor_width == p.open_floor_width);
    };
    const bool paper = same_method(GroupingParameters::paper());
    const bool library_default = same_method(GroupingParameters{}) && join_passages;
    return toString(model) + delta + ", split " + toString(split) + format(", Ncut < %g", ncut_threshold) +
           (boundary_passes > 0 ? format(", %d boundary passes", boundary_passes) : std::string()) +
           (mutual_neighbours > 0 || mutual_neighbours_share > 0
                ? format(", mutual neighbours %g / %g of the median", mutual_neighbours, mutual_neighbours_share)
                : std::string()) +
           (model == SensedSpaceModel::Visibility && open_floor_width > 0
                ? format(", open floor %g m", open_floor_width)
                : std::string()) +
           (model == SensedSpaceModel::Visibility && !join_passages ? ", passages not joined" : "") +
           (correct_odometry == OdometryCorrection::Off && !paper ? ", poses as given" : "") +
           (paper ? " (the paper)" : "") +
           (library_default && correct_odometry != OdometryCorrection::Off ? " (**the default**)" : "");
  }

  /// Every parameter, for the summary line of a sweep.
  std::string parameters() const {
    return format("model=%s split=%s delta=%g cell=%g range=%g clearance=%g min-observations=%d band=%g..%g "
                  "door-width=%g door-depth=%g min-group-size=%d ncut-threshold=%g boundary-passes=%d "
                  "mutual-neighbours=%g mutual-neighbours-share=%g open-floor-width=%g join-passages=%s "
                  "correct-odometry=%s",
                  toString(model).c_str(), toString(split).c_str(), match_distance, region.cell_size,
                  region.max_range, region.clearance, region.min_observations, region.band_low, region.band_high,
                  region.door_width, region.door_depth, min_group_size, ncut_threshold, boundary_passes,
                  mutual_neighbours, mutual_neighbours_share, open_floor_width, join_passages ? "on" : "off",
                  toString(correct_odometry).c_str());
  }
};

struct Result {
  int groups = 0;
  double mean_group_size = 0.0;
  double ari = 0.0;
  int rooms_whole = 0, rooms = 0;
  int rooms_found = 0, rooms_pure = 0;  ///< sim::scoreRooms: the measure of real logs with room labels
  double seconds = 0.0;  ///< ObservationGrouping::compute() and the passage joins, wall time
  std::size_t warnings = 0;
  std::string error;  ///< what compute() threw; the numbers are then meaningless
};

/// Groups `observations` with configuration `c`; throws what compute() throws.
Partition group(const std::vector<Observation<pcl::PointXYZ>>& observations, const Configuration& c,
                std::size_t* warnings = nullptr) {
  ObservationGrouping<pcl::PointXYZ> grouping;
  for (const auto& o : observations) grouping.addObservation(o.cloud, o.pose);
  GroupingParameters params;
  params.model = c.model;
  // Each model is given only what it uses: the rest would be refused.
  if (c.model == SensedSpaceModel::Points) {
    params.match_distance = c.match_distance;
  } else if (c.model == SensedSpaceModel::FreeSpace) {
    params.regions.cell_size = c.region.cell_size;  // the rest is the visibility model's
    params.regions.max_range = c.region.max_range;
  } else {
    params.regions = c.region;
    params.open_floor_width = c.open_floor_width;
  }
  params.split = c.split;
  params.min_group_size = c.min_group_size;
  params.ncut_threshold = c.ncut_threshold;
  params.boundary_passes = c.boundary_passes;
  params.mutual_neighbours = int(std::lround(c.mutual_neighbours));
  params.mutual_neighbours_share = c.mutual_neighbours_share;
  params.threads = c.threads;
  params.voxel_leaf = c.voxel_leaf;
  params.join_passages = c.join_passages;
  grouping.setParameters(params);
  Partition p = grouping.compute();
  if (warnings) *warnings = grouping.getWarnings().size();
  joinGroupsThroughPassages(observations, params, p);  // as the command does after the grouping
  return p;
}

/// The observations configuration `c` groups: at the poses given, or at the
/// command's (corrected when that is more consistent).
template <typename D>
const std::vector<Observation<pcl::PointXYZ>>& posed(const D& d, const Configuration& c) {
  return c.correct_odometry == OdometryCorrection::Off ? d.observations : d.corrected;
}

Result evaluate(const Dataset& d, const Configuration& c) {
  Result r;
  r.rooms = d.rooms;
  Partition p;
  const auto start = std::chrono::steady_clock::now();
  try {
    p = group(posed(d, c), c, &r.warnings);
  } catch (const std::exception& e) {
    r.error = e.what();
    return r;
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.groups = static_cast<int>(p.groups.size());
  r.mean_group_size = r.groups ? double(d.observations.size()) / r.groups : 0.0;
  r.ari = sim::adjustedRandIndex(d.places.of_pose, p.group_of);
  std::map<int, std::set<int>> groups_of_room;
  for (std::size_t i = 0; i < d.places.of_pose.size(); ++i)
    if (d.places.is_room[d.places.of_pose[i]]) groups_of_room[d.places.of_pose[i]].insert(p.group_of[i]);
  for (const auto& [room, groups] : groups_of_room) r.rooms_whole += groups.size() == 1;
  const sim::RoomScores scores = sim::scoreRooms(d.places.of_pose, d.places.is_room, p.group_of);
  r.rooms_found = scores.found;
  r.rooms_pure = scores.pure;
  return r;
}

/// Results of one configuration over the datasets.
struct Summary {
  double mean_ari = 0.0;
  int rooms_whole = 0, rooms = 0, rooms_found = 0, rooms_pure = 0;
  double worst_ari = 1.0;
  std::string worst;  ///< the dataset of the worst ARI
  double seconds = 0.0;
  int datasets = 0;  ///< evaluated without error
  int errors = 0;
};

Summary summarize(const std::vector<Dataset>& datasets, const std::vector<Result>& results,
                  const std::function<bool(const Dataset&)>& include = nullptr) {
  Summary s;
  for (std::size_t k = 0; k < datasets.size(); ++k) {
    if (include && !include(datasets[k])) continue;
    const Result& r = results[k];
    s.seconds += r.seconds;
    if (!r.error.empty()) {
      ++s.errors;
      continue;
    }
    ++s.datasets;
    s.mean_ari += r.ari;
    s.rooms_whole += r.rooms_whole;
    s.rooms_found += r.rooms_found;
    s.rooms_pure += r.rooms_pure;
    s.rooms += r.rooms;
    if (r.ari < s.worst_ari || s.worst.empty()) s.worst_ari = r.ari, s.worst = datasets[k].name();
  }
  if (s.datasets) s.mean_ari /= s.datasets;
  return s;
}

/// An exception's text fit for one table cell or one line.
std::string errorText(const std::string& error) {
  std::string text = error.substr(0, 120);
  std::replace(text.begin(), text.end(), '|', '/');
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

/// The single-configuration mode: one line per dataset, then the summary.
int evaluateOneConfiguration(const std::vector<Dataset>& datasets, const Configuration& c) {
  std::vector<Result> results;
  for (const Dataset& d : datasets) {
    const Result r = evaluate(d, c);
    if (!r.error.empty())
      std::cout << format("%-24s error: %s\n", d.name().c_str(), errorText(r.error).c_str());
    else
      std::cout << format("%-24s %4zu scans  drift %4.2f m%s  groups %4d (size %5.1f)  ARI %6.3f  rooms whole %2d/%-2d"
                          "  found %2d  pure %2d  %6.2f s%s\n",
                          d.name().c_str(), d.observations.size(), d.drift_rms,
                          c.correct_odometry != OdometryCorrection::Off && d.correction_applied
                              ? format(" (scan-matched: %.2f m)", d.corrected_rms).c_str()
                              : "",
                          r.groups, r.mean_group_size, r.ari,
                          r.rooms_whole, r.rooms, r.rooms_found, r.rooms_pure, r.seconds,
                          r.warnings ? format("  (%zu warnings)", r.warnings).c_str() : "");
    std::cout.flush();
    results.push_back(r);
  }
  const Summary s = summarize(datasets, results);
  const std::string worst = s.datasets ? format("%.3f (%s)", s.worst_ari, s.worst.c_str()) : std::string("–");
  std::cout << format("summary %s: mean ARI %.3f  rooms whole %d/%d  found %d  pure %d  worst ARI %s  %.1f s%s\n",
                      c.parameters().c_str(), s.mean_ari, s.rooms_whole, s.rooms, s.rooms_found, s.rooms_pure,
                      worst.c_str(), s.seconds,
                      s.errors ? format("  %d ERRORS", s.errors).c_str() : "");
  return s.errors ? 1 : 0;
}

/// A cloud dataset as `obsgroup partition` reads it: FOLDER/pcd/%06d.pcd
/// (binary, the sensor's frame) and FOLDER/poses.txt (TUM, the poses the
/// grouping sees).
void writeCloudSequence(const std::string& folder, const Dataset& d) {
  std::filesystem::create_directories(folder + "/pcd");
  std::ofstream poses(folder + "/poses.txt");
  poses << "# timestamp tx ty tz qx qy qz qw (" << d.title << "; " << sim::describe(d.sensor) << ", "
        << toString(d.poses) << " poses; obsgroup's scan simulator, examples/evaluate_grouping.cpp)\n";
  for (std::size_t k = 0; k < d.observations.size(); ++k) {
    const Observation<pcl::PointXYZ>& o = d.observations[k];
    if (pcl::io::savePCDFileBinary(folder + "/pcd/" + format("%06zu.pcd", k), *o.cloud) != 0)
      throw std::runtime_error("cannot write into " + folder + "/pcd");
    const Eigen::Quaterniond q(o.pose.linear());
    const Eigen::Vector3d t = o.pose.translation();
    poses << format("%.1f %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", 0.5 * double(k), t.x(), t.y(), t.z(), q.x(), q.y(),
                    q.z(), q.w());
  }
  if (!poses) throw std::runtime_error("cannot write " + folder + "/poses.txt");
  std::cout << "wrote " << folder << "\n";
}

/// Writes the datasets of `buildings` and their places as labels (the
/// format of --labels): FOLDER/BUILDING_labels.json, the lasers' as CARMEN
/// logs FOLDER/BUILDING_SENSOR_POSES.clf, the depth camera's and the lidar's
/// as folders FOLDER/BUILDING_SENSOR_POSES/ (writeCloudSequence).
int writeLogs(const std::string& folder, const std::vector<std::string>& buildings,
              const std::vector<sim::Sensor>& sensors, const std::vector<PoseSource>& pose_sources,
              const sim::DepthCamera& depth_camera) {
  for (const std::string& key : buildings) {
    const sim::Building building = sim::makeBuilding(key);
    const sim::Places places = sim::placesAlong(building.plan, building.route, kStretchLength);
    {
      std::ofstream labels(folder + "/" + key + "_labels.json");
      labels << "{\"names\": [";
      for (std::size_t p = 0; p < places.names.size(); ++p) labels << (p ? ", " : "") << '"' << places.names[p] << '"';
      labels << "],\n \"kinds\": [";
      for (std::size_t p = 0; p < places.is_room.size(); ++p)
        labels << (p ? ", " : "") << (places.is_room[p] ? "\"room\"" : "\"corridor\"");
      labels << "],\n \"labels\": [";
      for (std::size_t i = 0; i < places.of_pose.size(); ++i) labels << (i ? ", " : "") << places.of_pose[i];
      labels << "]}\n";
      if (!labels) throw std::runtime_error("cannot write into " + folder);
    }
    std::vector<Eigen::Isometry3d> truth;
    for (const sim::Pose2D& pose : building.route) truth.push_back(sim::toIsometry(pose));
    const std::vector<Eigen::Isometry3d> drifted = sim::drift(truth, kDriftSeed);
    const std::vector<Eigen::Isometry3d> biased = sim::biasedDrift(truth);
    for (sim::Sensor sensor : sensors) {
      if (sensor == sim::Sensor::Depth || sensor == sim::Sensor::Lidar) {  // clouds, not a CARMEN log
        for (const Dataset& d : makeDatasets({key}, {sensor}, pose_sources, depth_camera))
          writeCloudSequence(folder + "/" + key + "_" + sim::toString(sensor) + "_" + toString(d.poses), d);
        continue;
      }
      const sim::LaserModel laser = sensor == sim::Sensor::Laser360 ? sim::laser360() : sim::laser180();
      const double step = laser.full_turn ? laser.field_of_view / laser.beams : laser.field_of_view / (laser.beams - 1);
      for (PoseSource source : pose_sources) {
        const std::string path = folder + "/" + key + "_" + sim::toString(sensor) + "_" + toString(source) + ".clf";
        std::ofstream out(path);
        out << "# " << building.title << "; " << sim::describe(sensor) << ", " << toString(source)
            << " poses (obsgroup's scan simulator, examples/evaluate_grouping.cpp)\n";
        for (std::size_t k = 0; k < building.route.size(); ++k) {
          const auto ranges = building.plan.scan(building.route[k], laser, k);  // the seed of makeDatasets
          const Eigen::Isometry3d& pose =
              source == PoseSource::Exact ? truth[k] : source == PoseSource::Drift ? drifted[k] : biased[k];
          const double yaw = std::atan2(pose.linear()(1, 0), pose.linear()(0, 0));
          out << format("ROBOTLASER1 0 %.9f %.9f %.9f %.3f 0.01 0 %zu", laser.beamAngle(0, ranges.size()),
                        laser.field_of_view, step, laser.max_range, ranges.size());
          for (double r : ranges) out << format(" %.3f", r);
          const double x = pose.translation().x(), y = pose.translation().y();
          out << format(" 0 %.6f %.6f %.6f %.6f %.6f %.6f 0 0 0 0 0 %.3f sim %.3f\n", x, y, yaw, x, y, yaw,
                        1000.0 + 0.5 * double(k), 0.5 * double(k));
        }
        if (!out) throw std::runtime_error("cannot write " + path);
        std::cout << "wrote " << path << "\n";
      }
    }
  }
  return 0;
}

/// A real log with a room label per scan.
struct LabelledLog {
  std::string log, labels;
};

/// A labelled log read: its scans as the command reads them, its labels.
struct LabelledDataset {
  std::string name;
  std::vector<Observation<pcl::PointXYZ>> observations;
  std::vector<Observation<pcl::PointXYZ>> corrected;  ///< as the command groups them (Auto)
  std::vector<int> place_of;
  std::vector<bool> is_room;
};

#ifdef OBSGROUP_EVALUATE_LABELLED_LOGS
LabelledDataset readLabelledLog(const LabelledLog& l) {
  LabelledDataset d;
  d.name = l.log;
  const io::CarmenLog log = io::readCarmenLog(l.log);  // the command's default laser messages
  for (const io::LaserScan& scan : log.scans) d.observations.push_back({io::scanToCloud(scan), scan.laser_pose});
  d.corrected = d.observations;
  correctOdometry(d.corrected, OdometryCorrection::Auto);
  const nlohmann::json labels = nlohmann::json::parse(std::ifstream(l.labels));
  d.place_of = labels.at("labels").get<std::vector<int>>();
  if (d.place_of.size() != d.observations.size())
    throw std::invalid_argument(l.labels + ": " + std::to_string(d.place_of.size()) + " labels for " +
                                std::to_string(d.observations.size()) + " scans of " + l.log);
  for (const std::string& kind : labels.at("kinds").get<std::vector<std::string>>()) d.is_room.push_back(kind == "room");
  return d;
}
#else
LabelledDataset readLabelledLog(const LabelledLog&) {
  throw std::invalid_argument("built without the readers or nlohmann-json: no --log");
}
#endif

/// Groups each labelled log and scores the groups against its labels: a
/// line per log and a summary line, or (with `output`) a table into the
/// page's "labelled" section, each log named by its file name alone.
int evaluateLabelledLogs(const std::vector<LabelledDataset>& logs, const Configuration& c,
                         const std::string& output = "") {
  int rooms = 0, found = 0, pure = 0, errors = 0;
  std::ostringstream table;
  table << "| log | scans | groups | ARI vs labels | rooms found | rooms pure |\n|---|---|---|---|---|---|\n";
  for (const LabelledDataset& d : logs) {
    try {
      const auto start = std::chrono::steady_clock::now();
      const Partition p = group(posed(d, c), c);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const sim::RoomScores scores = sim::scoreRooms(d.place_of, d.is_room, p.group_of);
      rooms += scores.rooms;
      found += scores.found;
      pure += scores.pure;
      std::cout << format("%-40s %5zu scans  groups %4zu  ARI %6.3f  rooms found %2d/%-2d  pure %2d/%-2d  %6.2f s\n",
                          d.name.c_str(), d.observations.size(), p.groups.size(),
                          sim::adjustedRandIndex(d.place_of, p.group_of), scores.found, scores.rooms, scores.pure,
                          scores.rooms, seconds);
      const std::string name = d.name.substr(d.name.find_last_of('/') + 1);
      table << format("| %s | %zu | %zu | %.3f | %d of %d | %d of %d |\n", name.c_str(), d.observations.size(),
                      p.groups.size(), sim::adjustedRandIndex(d.place_of, p.group_of), scores.found, scores.rooms,
                      scores.pure, scores.rooms);
    } catch (const std::exception& e) {
      ++errors;
      std::cout << format("%-40s error: %s\n", d.name.c_str(), e.what());
    }
  }
  std::cout << format("summary %s: rooms found %d/%d  pure %d/%d%s\n", c.parameters().c_str(), found, rooms, pure,
                      rooms, errors ? format("  %d ERRORS", errors).c_str() : "");
  if (errors) return 1;
  if (output.empty()) return 0;
  table << format("| all | | | | %d of %d | %d of %d |\n\nParameters: %s.\n", found, rooms, pure, rooms,
                  c.parameters().c_str());
  return writeGeneratedSection(output, table.str(), "labelled");
}

/// Rooms found and pure over simulated and labelled datasets.
struct SweepPoint {
  sim::RoomScores simulated, labelled;
};

SweepPoint sweepPoint(const std::vector<Dataset>& datasets, const std::vector<LabelledDataset>& logs,
                      const Configuration& c) {
  SweepPoint point;
  const auto add = [](sim::RoomScores& total, const sim::RoomScores& s) {
    total.rooms += s.rooms;
    total.found += s.found;
    total.pure += s.pure;
    total.whole += s.whole;
  };
  for (const Dataset& d : datasets)
    add(point.simulated, sim::scoreRooms(d.places.of_pose, d.places.is_room, group(posed(d, c), c).group_of));
  for (const LabelledDataset& d : logs)
    add(point.labelled, sim::scoreRooms(d.place_of, d.is_room, group(posed(d, c), c).group_of));
  return point;
}

/// The plateau of the defaults: each parameter of `base` at 75% and 125% of
/// its value, rooms found and pure on the simulated datasets and on the
/// labelled logs, and the change of rooms found from the defaults.
std::string sweepTable(const std::vector<Dataset>& datasets, const std::vector<LabelledDataset>& logs,
                       const Configuration& base) {
  struct Parameter {
    const char* name;
    std::function<double&(Configuration&)> value;
  };
  const std::vector<Parameter> parameters{
      {"Ncut threshold", [](Configuration& c) -> double& { return c.ncut_threshold; }},
      {"cell (m)", [](Configuration& c) -> double& { return c.region.cell_size; }},
      {"range (m)", [](Configuration& c) -> double& { return c.region.max_range; }},
      {"clearance (m)", [](Configuration& c) -> double& { return c.region.clearance; }},
      {"door width (m)", [](Configuration& c) -> double& { return c.region.door_width; }},
      {"door depth (m)", [](Configuration& c) -> double& { return c.region.door_depth; }},
      {"mutual neighbours", [](Configuration& c) -> double& { return c.mutual_neighbours; }},
      {"mutual neighbours' share of the median", [](Configuration& c) -> double& { return c.mutual_neighbours_share; }},
      {"open floor width (m)", [](Configuration& c) -> double& { return c.open_floor_width; }},
  };
  const SweepPoint reference = sweepPoint(datasets, logs, base);
  const auto change = [](int value, int of) {
    return of ? format("%+.1f%%", 100.0 * double(value - of) / double(of)) : std::string("–");
  };
  const auto row = [&](const std::string& name, const std::string& value, const SweepPoint& p) {
    return "| " + name + " | " + value + " | " +
           format("%d / %d of %d", p.simulated.found, p.simulated.pure, p.simulated.rooms) + " | " +
           change(p.simulated.found, reference.simulated.found) + " | " +
           (p.labelled.rooms ? format("%d / %d of %d", p.labelled.found, p.labelled.pure, p.labelled.rooms) +
                                   " | " + change(p.labelled.found, reference.labelled.found)
                             : std::string("– | –")) +
           " |\n";
  };
  std::ostringstream out;
  out << "| parameter | value | simulated: rooms found / pure | change of found | labelled logs: rooms found / pure "
         "| change of found |\n|---|---|---|---|---|---|\n";
  out << row("(the defaults)", "–", reference);
  for (const Parameter& parameter : parameters)
    for (double factor : {0.75, 1.25}) {
      Configuration c = base;
      double& value = parameter.value(c);
      value *= factor;
      if (&value == &c.mutual_neighbours) value = std::round(value);  // a count
      std::cerr << parameter.name << " " << value << "\n";
      out << row(parameter.name, format("%g", value), sweepPoint(datasets, logs, c));
    }
  return out.str();
}

/// The page's generated section: the datasets, a summary per configuration
/// and a table per dataset.
std::string page(const std::vector<Dataset>& datasets, const std::vector<Configuration>& configurations,
                 double generation_seconds) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::vector<Result>> results(configurations.size());
  for (std::size_t k = 0; k < datasets.size(); ++k) {
    std::cerr << datasets[k].name() << ":";
    for (std::size_t c = 0; c < configurations.size(); ++c) {
      results[c].push_back(evaluate(datasets[k], configurations[c]));
      std::cerr << format(" %.3f", results[c].back().ari);
    }
    std::cerr << "\n";
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::ostringstream out;
  const Configuration& common = configurations.front();
  out << "Parameters of every row: δ " << common.match_distance << " m (points); cell " << common.region.cell_size
      << " m, range " << common.region.max_range << " m, clearance " << common.region.clearance
      << " m, min observations " << common.region.min_observations << ", band " << common.region.band_low << " to "
      << common.region.band_high << " m, door width " << common.region.door_width << " m, door depth "
      << common.region.door_depth << " m (free space, visibility); minimum group size " << common.min_group_size
      << "; everything else the library's default.\n\n";

  out << "### Summary over the " << datasets.size() << " datasets\n\n"
      << "| configuration | mean ARI | exact / drifted poses | 360° laser / 180° laser / depth camera "
         "| rooms whole | rooms found | rooms pure | worst ARI (dataset) | time (s) |\n"
      << "|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t c = 0; c < configurations.size(); ++c) {
    const Summary all = summarize(datasets, results[c]);
    const auto ari_where = [&](const std::function<bool(const Dataset&)>& include) {
      const Summary s = summarize(datasets, results[c], include);
      return s.datasets ? format("%.2f", s.mean_ari) : std::string("–");
    };
    const auto of_poses = [](PoseSource p) { return [p](const Dataset& d) { return d.poses == p; }; };
    const auto of_sensor = [](sim::Sensor s) { return [s](const Dataset& d) { return d.sensor == s; }; };
    out << "| " << configurations[c].label() << " | " << format("%.3f", all.mean_ari) << " | "
        << ari_where(of_poses(PoseSource::Exact)) << " / " << ari_where(of_poses(PoseSource::Drift)) << " | "
        << ari_where(of_sensor(sim::Sensor::Laser360)) << " / " << ari_where(of_sensor(sim::Sensor::Laser180))
        << " / " << ari_where(of_sensor(sim::Sensor::Depth)) << " | " << all.rooms_whole << " of " << all.rooms
        << " | " << all.rooms_found << " | " << all.rooms_pure << " | " << format("%.2f", all.worst_ari) << " (" << all.worst << ") | " << format("%.1f", all.seconds)
        << (all.errors ? format(" (%d failed)", all.errors) : std::string()) << " |\n";
  }

  // One row per building and sensor: its exact and drifted datasets share the scans.
  out << "\n### Datasets\n\n"
      << "| building, sensor | scans | points per scan | places (rooms + corridor stretches) "
      << "| drift RMS of the drifted poses (m) | ... after the command's scan matching (m) | poses < "
      << kCrampedClearance << " m from a wall or in furniture |\n"
      << "|---|---|---|---|---|---|---|\n";
  std::set<std::pair<std::string, sim::Sensor>> listed;
  for (const Dataset& d : datasets) {
    if (!listed.insert({d.building, d.sensor}).second) continue;
    std::string drift = "–", corrected = "–";
    for (const Dataset& other : datasets)
      if (other.building == d.building && other.sensor == d.sensor && other.poses == PoseSource::Drift) {
        drift = format("%.2f", other.drift_rms);
        corrected = other.correction_applied ? format("%.2f", other.corrected_rms) : "not corrected";
      }
    const int places = static_cast<int>(d.places.names.size());
    out << "| " << d.building << ", " << sim::describe(d.sensor) << " | " << d.observations.size() << " | "
        << format("%.0f", d.mean_points) << " | " << places << " (" << d.rooms << " + " << places - d.rooms << ") | "
        << drift << " | " << corrected << " | " << d.cramped_poses << " |\n";
  }

  for (std::size_t k = 0; k < datasets.size(); ++k) {
    const Dataset& d = datasets[k];
    out << "\n#### " << d.heading() << "\n\n"
        << "| configuration | groups | mean group size | ARI vs places | rooms whole | rooms found | rooms pure "
           "| time (s) |\n"
        << "|---|---|---|---|---|---|---|---|\n";
    for (std::size_t c = 0; c < configurations.size(); ++c) {
      const Result& r = results[c][k];
      if (!r.error.empty())
        out << "| " << configurations[c].label() << " | failed: " << errorText(r.error) << " | | | | | | |\n";
      else
        out << "| " << configurations[c].label() << " | " << r.groups << " | " << format("%.1f", r.mean_group_size)
            << " | " << format("%.3f", r.ari) << " | " << r.rooms_whole << " of " << r.rooms << " | "
            << r.rooms_found << " | " << r.rooms_pure << " | " << format("%.2f", r.seconds) << " |\n";
    }
  }
  out << format("\n(datasets generated in %.1f s, evaluated in %.1f s", generation_seconds, seconds)
      << (common.threads ? format(", %d threads", common.threads) : std::string(", all cores")) << ")\n";
  return out.str();
}

/// The whole of `text` as a number; a trailing "abc" is an error, not ignored.
double parseNumber(const std::string& flag, const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::logic_error&) {  // std::invalid_argument, std::out_of_range
    used = 0;
  }
  if (used == 0 || used != text.size()) throw std::invalid_argument("bad number for " + flag + ": '" + text + "'");
  return value;
}

int parseInteger(const std::string& flag, const std::string& text) {
  const double value = parseNumber(flag, text);
  if (!(std::abs(value) < 1e9) || value != static_cast<int>(value))
    throw std::invalid_argument("bad integer for " + flag + ": '" + text + "'");
  return static_cast<int>(value);
}

const char* kUsage =
    "usage: evaluate_grouping [--output FILE] [parameters] [selection]\n"
    "       evaluate_grouping --model M [--split S] [parameters] [selection]\n"
    "Without --model: the page's sixteen configurations (points, free-space, visibility; split mean and best; Ncut threshold 1 and the default's; the default without boundary refinement; the default without joins across open floor; the default with every overlap, no mutual neighbours; the default at the poses given, without the scan matching).\n"
    "With --model or --split: that one configuration (unset: the library's default), a line per dataset and a summary line.\n"
    "parameters (defaults: the library's):\n"
    "  --model points|free-space|visibility   --split mean|sign|best\n"
    "  --delta M (points)  --cell M  --range M  --clearance M  --min-observations N\n"
    "  --band-low M  --band-high M  --door-width M  --door-depth M  --min-group-size N  --ncut-threshold X  --boundary-passes N\n"
    "  --mutual-neighbours N  --mutual-neighbours-share X  --open-floor-width M  --join-passages on|off (visibility)\n"
    "  --threads N (0: all cores)  --voxel M (each observation's voxel leaf, as the command's --voxel)\n"
    "  --correct-odometry auto|off (auto: at the poses the command groups at, scan-matched when more consistent)\n"
    "  --depth-size WxH (the depth camera's pixels; default 80x60, the field of view kept)\n"
    "selection (defaults: all):\n"
    "  --datasets office,loop,rooms20,smallrooms,hall  --sensors laser360,laser180,depth[,lidar]  --poses exact,drift[,bias]\n"
    "real logs instead of the simulated buildings (each --log with its --labels, in order):\n"
    "  --log LOG --labels LABELS.json\n"
    "the selected datasets with their labels, for obsgroup partition and --log (lasers: CARMEN logs;\n"
    "depth camera, lidar: folders of PCD files and poses.txt):\n"
    "  --write-logs FOLDER\n"
    "each default at 75% and 125% (rooms found and pure; with --output, the page's 'sweep' section):\n"
    "  --sweep defaults [--log LOG --labels LABELS.json ...] [selection]\n";

}  // namespace

int main(int argc, char** argv) {
  Configuration configuration;
  std::optional<SensedSpaceModel> model;
  std::optional<SplitCriterion> split;
  std::string output;
  std::vector<std::string> buildings = sim::buildingKeys();
  std::vector<sim::Sensor> sensors{sim::Sensor::Laser360, sim::Sensor::Laser180, sim::Sensor::Depth};
  std::vector<PoseSource> pose_sources{PoseSource::Exact, PoseSource::Drift};
  std::vector<std::string> logs, label_files;
  std::string write_logs;
  sim::DepthCamera depth_camera = sim::depthCamera();
  bool sweep = false;
  try {
    RegionParameters& region = configuration.region;
    using Setter = std::function<void(const std::string& flag, const std::string& value)>;
    const auto number = [](double& target) -> Setter {
      return [&target](const std::string& flag, const std::string& v) { target = parseNumber(flag, v); };
    };
    const auto integer = [](int& target) -> Setter {
      return [&target](const std::string& flag, const std::string& v) { target = parseInteger(flag, v); };
    };
    const std::map<std::string, Setter> options{
        {"--output", [&](const std::string&, const std::string& v) { output = v; }},
        {"--model", [&](const std::string&, const std::string& v) { model = sensedSpaceModelFromString(v); }},
        {"--split", [&](const std::string&, const std::string& v) { split = splitCriterionFromString(v); }},
        {"--delta", number(configuration.match_distance)},
        {"--cell", number(region.cell_size)},
        {"--range", number(region.max_range)},
        {"--clearance", number(region.clearance)},
        {"--min-observations", integer(region.min_observations)},
        {"--band-low", number(region.band_low)},
        {"--band-high", number(region.band_high)},
        {"--door-width", number(region.door_width)},
        {"--door-depth", number(region.door_depth)},
        {"--min-group-size", integer(configuration.min_group_size)},
        {"--ncut-threshold", number(configuration.ncut_threshold)},
        {"--boundary-passes", integer(configuration.boundary_passes)},
        {"--mutual-neighbours", number(configuration.mutual_neighbours)},
        {"--mutual-neighbours-share", number(configuration.mutual_neighbours_share)},
        {"--open-floor-width", number(configuration.open_floor_width)},
        {"--join-passages",
         [&](const std::string& flag, const std::string& v) {
           if (v != "on" && v != "off") throw std::invalid_argument(flag + " takes on or off, not '" + v + "'");
           configuration.join_passages = v == "on";
         }},
        {"--threads", integer(configuration.threads)},
        {"--voxel", number(configuration.voxel_leaf)},
        {"--correct-odometry",
         [&](const std::string&, const std::string& v) {
           configuration.correct_odometry = odometryCorrectionFromString(v);
           if (configuration.correct_odometry == OdometryCorrection::On)
             throw std::invalid_argument("--correct-odometry takes auto or off");
         }},
        {"--depth-size",
         [&](const std::string& flag, const std::string& v) {
           const auto x = v.find('x');
           if (x == std::string::npos) throw std::invalid_argument(flag + " takes WIDTHxHEIGHT");
           depth_camera.width = parseInteger(flag, v.substr(0, x));
           depth_camera.height = parseInteger(flag, v.substr(x + 1));
         }},
        {"--write-logs", [&](const std::string&, const std::string& v) { write_logs = v; }},
        {"--sweep",
         [&](const std::string& flag, const std::string& v) {
           if (v != "defaults") throw std::invalid_argument(flag + " takes 'defaults'");
           sweep = true;
         }},
        {"--log", [&](const std::string&, const std::string& v) { logs.push_back(v); }},
        {"--labels", [&](const std::string&, const std::string& v) { label_files.push_back(v); }},
        {"--datasets",
         [&](const std::string&, const std::string& v) {
           buildings = splitList(v);
           for (const auto& key : buildings) sim::makeBuilding(key);  // reject unknown keys before any work
         }},
        {"--sensors",
         [&](const std::string&, const std::string& v) {
           sensors.clear();
           for (const auto& name : splitList(v)) sensors.push_back(sim::sensorFromString(name));
         }},
        {"--poses",
         [&](const std::string&, const std::string& v) {
           pose_sources.clear();
           for (const auto& name : splitList(v)) pose_sources.push_back(poseSourceFromString(name));
         }},
    };
    for (int a = 1; a < argc; ++a) {
      const std::string flag = argv[a];
      if (flag == "--help" || flag == "-h") {
        std::cout << kUsage;
        return 0;
      }
      const auto it = options.find(flag);
      if (it == options.end() || a + 1 >= argc) throw std::invalid_argument("unknown option or missing value: " + flag);
      it->second(flag, argv[++a]);
    }
    if ((model || split) && !output.empty() && !sweep && logs.empty())
      throw std::invalid_argument("--output writes the page; it takes no --model or --split");
    if (buildings.empty() || sensors.empty() || pose_sources.empty()) throw std::invalid_argument("nothing selected");
    if (logs.size() != label_files.size()) throw std::invalid_argument("each --log needs its --labels");
#ifndef OBSGROUP_EVALUATE_LABELLED_LOGS
    if (!logs.empty()) throw std::invalid_argument("built without the readers or nlohmann-json: no --log");
#endif
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n" << kUsage;
    return 2;
  }
  if (!write_logs.empty()) {
    try {
      return writeLogs(write_logs, buildings, sensors, pose_sources, depth_camera);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 1;
    }
  }
  std::vector<LabelledDataset> labelled;
  try {
    for (std::size_t k = 0; k < logs.size(); ++k) labelled.push_back(readLabelledLog({logs[k], label_files[k]}));
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  if (!labelled.empty() && !sweep) {
    const GroupingParameters defaults;
    configuration.model = model.value_or(defaults.model);
    configuration.split = split.value_or(defaults.split);
    return evaluateLabelledLogs(labelled, configuration, output);
  }

  const auto start = std::chrono::steady_clock::now();
  const std::vector<Dataset> datasets = makeDatasets(buildings, sensors, pose_sources, depth_camera);
  const double generation_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  if (sweep) {
    const GroupingParameters defaults;
    configuration.model = model.value_or(defaults.model);
    configuration.split = split.value_or(defaults.split);
    const std::string table = "Each default at 75% and 125% of its value, everything else at the defaults; " +
                              format("%zu simulated datasets, %zu labelled logs.\n\n", datasets.size(),
                                     labelled.size()) +
                              sweepTable(datasets, labelled, configuration);
    if (output.empty()) {
      std::cout << table;
      return 0;
    }
    return writeGeneratedSection(output, table, "sweep");
  }
  if (model || split) {
    const GroupingParameters defaults;
    configuration.model = model.value_or(defaults.model);
    configuration.split = split.value_or(defaults.split);
    std::cout << format("# %zu datasets generated in %.1f s\n", datasets.size(), generation_seconds);
    return evaluateOneConfiguration(datasets, configuration);
  }

  std::vector<Configuration> configurations;
  // Every model with each split, at the paper's threshold and the default's.
  for (SensedSpaceModel m : {SensedSpaceModel::Points, SensedSpaceModel::FreeSpace, SensedSpaceModel::Visibility})
    for (double threshold : {GroupingParameters::paper().ncut_threshold, GroupingParameters{}.ncut_threshold})
      for (SplitCriterion s : {SplitCriterion::Mean, SplitCriterion::BestNcut}) {
        Configuration c = configuration;
        c.model = m;
        c.split = s;
        c.ncut_threshold = threshold;
        // The paper's row is the paper's method: no boundary refinement, every overlap.
        if (m == SensedSpaceModel::Points && s == SplitCriterion::Mean && threshold == 1.0) {
          c.correct_odometry = OdometryCorrection::Off;
          c.boundary_passes = 0;
          c.mutual_neighbours = 0;
          c.mutual_neighbours_share = 0;
        }
        configurations.push_back(c);
      }
  // The default without the boundary refinement, to show what it changes.
  Configuration unrefined = configuration;
  const GroupingParameters defaults;
  unrefined.model = defaults.model;
  unrefined.split = defaults.split;
  unrefined.ncut_threshold = defaults.ncut_threshold;
  unrefined.boundary_passes = 0;
  configurations.push_back(unrefined);
  // The default without joins across open floor: what they change.
  Configuration unjoined = unrefined;
  unjoined.boundary_passes = defaults.boundary_passes;
  unjoined.open_floor_width = 0;
  configurations.push_back(unjoined);
  // The default without joins through passages: what they change.
  Configuration no_passages = unrefined;
  no_passages.boundary_passes = defaults.boundary_passes;
  no_passages.join_passages = false;
  configurations.push_back(no_passages);
  // The default on W itself, every overlap kept: what the mutual neighbours change.
  Configuration every_overlap = unrefined;
  every_overlap.boundary_passes = defaults.boundary_passes;
  every_overlap.mutual_neighbours = 0;
  every_overlap.mutual_neighbours_share = 0;
  configurations.push_back(every_overlap);
  // The default at the poses given: what the scan matching changes.
  Configuration as_given = every_overlap;
  as_given.mutual_neighbours = defaults.mutual_neighbours;
  as_given.mutual_neighbours_share = defaults.mutual_neighbours_share;
  as_given.correct_odometry = OdometryCorrection::Off;
  configurations.push_back(as_given);
  const std::string report = page(datasets, configurations, generation_seconds);
  if (output.empty()) {
    std::cout << report;
    return 0;
  }
  return writeGeneratedSection(output, report);
}
