// The evidence behind docs/results.md: which local maps let a robot localize
// on its next visit? A simulated building is driven twice. Run 1 builds the
// maps from drifted poses, as a SLAM front end would give them; run 2 goes
// another way through the same rooms, and each of its scans is aligned by
// ICP against the local map the robot would pick. The maps are cut from
// run 1 in several ways (the whole map, chunks of consecutive scans,
// obsgroup's groups), each built with and without refinement, and measured
// for internal consistency, coverage of run 2 and localization.
//
//   evaluate_local_maps [--output FILE] [--buildings office,loop,rooms20]
//                       [--sensors laser360,laser180,depth] [--failures]
// prints the tables (by default office and loop with every sensor), or
// writes them into FILE between the lines "<!-- generated:begin -->" and
// "<!-- generated:end -->", keeping the rest. --failures also prints (to
// stderr) each run-2 scan whose localization failed, with its map's scans.

#include "floor_plan.h"
#include "generated_section.h"
#include "scenarios.h"
#include "to_cloud.h"

#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/observation_grouping.h>

#include <pcl/console/print.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/transformation_estimation_2D.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

using namespace obsgroup;
using obsgroup::examples::splitList;
using obsgroup::examples::writeGeneratedSection;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Maps = std::vector<LocalMap<pcl::PointXYZ>>;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDelta = 0.1;          // the paper's match distance, metres
constexpr int kChunk = 90;              // Cartographer's 2D submap size, scans
constexpr std::uint64_t kDriftSeed = 7;
constexpr std::uint64_t kGuessSeed = 11;
constexpr std::uint64_t kRunTwoSeeds = 100000;  // run 2's scan noise, apart from run 1's seeds 0, 1, ...
constexpr double kRobotRadius = 0.3;
constexpr double kGuessTranslation = 0.3, kGuessRotation = 5.0 * kPi / 180.0;  // std of the initial guess
constexpr double kFailTranslation = 0.3, kFailRotation = 5.0 * kPi / 180.0;
constexpr double kCoverageDistance = 0.2;

std::string format(const char* pattern, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* pattern, ...) {
  char text[512];
  va_list args;
  va_start(args, pattern);
  std::vsnprintf(text, sizeof text, pattern, args);
  va_end(args);
  return text;
}

// --- the two runs --------------------------------------------------------------

/// The scans of one route, each in its sensor frame, and their true poses.
struct Run {
  std::vector<Cloud::ConstPtr> clouds;
  std::vector<Eigen::Isometry3d> truth;
};

/// sim::depthCamera() at half its resolution (40 x 30 pixels, 1200 points
/// where the lasers give 361 and 720): refinement's cost grows with the
/// points, and the whole benchmark has to run in minutes.
sim::DepthCamera depthCamera() {
  sim::DepthCamera camera = sim::depthCamera();
  camera.width /= 2;
  camera.height /= 2;
  return camera;
}

Cloud::ConstPtr scanAt(const sim::FloorPlan& plan, const sim::Pose2D& pose, sim::Sensor sensor, std::uint64_t seed) {
  switch (sensor) {
    case sim::Sensor::Laser360: return sim::scanCloud<pcl::PointXYZ>(plan, pose, sim::laser360(), seed);
    case sim::Sensor::Laser180: return sim::scanCloud<pcl::PointXYZ>(plan, pose, sim::laser180(), seed);
    case sim::Sensor::Depth: return sim::depthCloud<pcl::PointXYZ>(plan, pose, depthCamera(), seed);
    case sim::Sensor::Lidar: return sim::lidarCloud<pcl::PointXYZ>(plan, pose, sim::lidar(), seed);
  }
  throw std::logic_error("unknown sensor");
}

/// A robot is a disc, not a point: a pose nearer a wall than its radius is a bug of the route.
void checkClearance(const sim::FloorPlan& plan, const std::vector<sim::Pose2D>& route, const std::string& name) {
  for (const sim::Pose2D& pose : route)
    if (plan.clearanceAt(pose.x, pose.y, kRobotRadius) < kRobotRadius)
      throw std::runtime_error(format("%s: the pose (%.2f, %.2f) is nearer a wall than %.1f m", name.c_str(), pose.x,
                                      pose.y, kRobotRadius));
}

Run simulate(const sim::FloorPlan& plan, const std::vector<sim::Pose2D>& route, sim::Sensor sensor,
             std::uint64_t first_seed) {
  // A depth camera stands over the floor; a laser scans in the plane z = 0.
  const double height = sensor == sim::Sensor::Depth ? depthCamera().height_above_floor : sim::sensorHeight(sensor);
  Run run;
  for (std::size_t k = 0; k < route.size(); ++k) {
    run.clouds.push_back(scanAt(plan, route[k], sensor, first_seed + k));
    run.truth.push_back(sim::toIsometry(route[k], height));
  }
  return run;
}

struct Dataset {
  std::string title;
  sim::Sensor sensor;
  Run first, second;
  std::vector<Observation<pcl::PointXYZ>> drifted;  // run 1 as the maps are built from it
  /// For each run-2 scan, the run-1 scan whose drifted position is nearest
  /// its prior: the robot picks that scan's local map.
  std::vector<int> nearest_in_map;
};

std::size_t nearestPosition(const std::vector<Eigen::Isometry3d>& poses, const Eigen::Vector3d& position) {
  std::size_t best = 0;
  for (std::size_t k = 1; k < poses.size(); ++k)
    if ((poses[k].translation() - position).squaredNorm() < (poses[best].translation() - position).squaredNorm())
      best = k;
  return best;
}

/// Where the robot believes a run-2 scan is, in run 1's drifted frame: its
/// true pose relative to the nearest run-1 pose, composed onto that pose's
/// drifted estimate. Right locally, and wrong by the map's drift there.
Eigen::Isometry3d priorInMap(const Eigen::Isometry3d& truth, const std::vector<Eigen::Isometry3d>& first_truth,
                             const std::vector<Eigen::Isometry3d>& drifted) {
  const std::size_t n = nearestPosition(first_truth, truth.translation());
  return drifted[n] * first_truth[n].inverse() * truth;
}

Dataset makeDataset(const sim::Building& building, sim::Sensor sensor) {
  checkClearance(building.plan, building.route, building.key + " run 1");
  checkClearance(building.plan, building.second_visit, building.key + " run 2");
  Dataset d;
  d.title = building.title;
  d.sensor = sensor;
  d.first = simulate(building.plan, building.route, sensor, 0);
  d.second = simulate(building.plan, building.second_visit, sensor, kRunTwoSeeds);
  const std::vector<Eigen::Isometry3d> drifted = sim::drift(d.first.truth, kDriftSeed);
  for (std::size_t k = 0; k < drifted.size(); ++k) d.drifted.push_back({d.first.clouds[k], drifted[k]});
  for (const Eigen::Isometry3d& truth : d.second.truth) {
    const Eigen::Isometry3d prior = priorInMap(truth, d.first.truth, drifted);
    d.nearest_in_map.push_back(static_cast<int>(nearestPosition(drifted, prior.translation())));
  }
  return d;
}

// --- the cuts --------------------------------------------------------------------

struct Cut {
  std::string name;
  Partition partition;
  /// Chooses each map's reference and the pairs refinement aligns: the W of
  /// the grouping the cut is compared with, as `obsgroup partition` uses its own.
  std::shared_ptr<const WeightMatrix> W;
};

Partition fromGroups(std::vector<std::vector<int>> groups, int n) {
  Partition p;
  p.groups = std::move(groups);
  p.group_of.assign(n, -1);
  for (std::size_t g = 0; g < p.groups.size(); ++g)
    for (int i : p.groups[g]) p.group_of[i] = static_cast<int>(g);
  return p;
}

/// Runs of `size` consecutive scans; the last one holds what is left.
Partition chunksOfSize(int n, int size) {
  std::vector<std::vector<int>> chunks((n + size - 1) / size);
  for (int i = 0; i < n; ++i) chunks[i / size].push_back(i);
  return fromGroups(chunks, n);
}

/// `count` runs of consecutive scans whose sizes differ by one at most.
Partition consecutiveChunks(int n, int count) {
  std::vector<std::vector<int>> chunks(count);
  for (int i = 0; i < n; ++i) chunks[static_cast<std::size_t>(i) * count / n].push_back(i);
  return fromGroups(chunks, n);
}

struct Grouped {
  Partition partition;
  WeightMatrix W;
};

Grouped group(const std::vector<Observation<pcl::PointXYZ>>& observations, bool paper) {
  ObservationGrouping<pcl::PointXYZ> grouping;
  grouping.setNumberOfThreads(1);  // the datasets are spread over the cores instead
  for (const auto& o : observations) grouping.addObservation(o.cloud, o.pose);
  if (paper) {
    grouping.usePaperMethod();
    grouping.setMatchDistance(kDelta);
  }
  Grouped out;
  out.partition = grouping.compute();
  out.W = grouping.getWeightMatrix();
  return out;
}

/// Every cut of run 1, each with the weights that choose its maps'
/// references and the pairs refinement aligns: an obsgroup cut and the
/// chunks as many as its maps share its grouping's W; the whole map and the
/// chunks of 90 take the default grouping's.
std::vector<Cut> makeCuts(const Dataset& d) {
  const int n = static_cast<int>(d.drifted.size());
  std::vector<Cut> cuts{{"whole map", consecutiveChunks(n, 1), nullptr},
                        {format("chunks of %d", kChunk), chunksOfSize(n, kChunk), nullptr}};
  for (bool paper : {false, true}) {
    Grouped grouped = group(d.drifted, paper);
    const int count = static_cast<int>(grouped.partition.groups.size());
    const auto W = std::make_shared<const WeightMatrix>(std::move(grouped.W));
    if (!paper) cuts[0].W = cuts[1].W = W;
    cuts.push_back({paper ? format("obsgroup, the paper's (δ %.1f m)", kDelta) : "obsgroup, defaults", grouped.partition, W});
    // As many maps as the groups: is it the grouping, or only the number of maps?
    cuts.push_back({format("chunks, as many (%d)", count), consecutiveChunks(n, count), W});
  }
  return cuts;
}

// --- measures ------------------------------------------------------------------

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * double(v.size() - 1) + 0.5))];
}

double rotationAngle(const Eigen::Isometry3d& error) { return Eigen::AngleAxisd(error.linear()).angle(); }

struct Spread {
  double t50 = 0, t90 = 0, r50 = 0, r90 = 0;  // metres, radians
};

Spread spreadOf(const std::vector<double>& translation, const std::vector<double>& rotation) {
  return {percentile(translation, 0.5), percentile(translation, 0.9), percentile(rotation, 0.5),
          percentile(rotation, 0.9)};
}

/// How far each member's pose in its map is from the truth relative to the
/// map's reference (the reference itself, exact by construction, left out).
Spread memberPoseErrors(const Maps& maps, const std::vector<Eigen::Isometry3d>& truth) {
  std::vector<double> translation, rotation;
  for (const auto& map : maps) {
    const Eigen::Isometry3d reference = truth[map.frame.reference];
    for (std::size_t m = 0; m < map.frame.members.size(); ++m) {
      const int i = map.frame.members[m];
      if (i == map.frame.reference) continue;
      const Eigen::Isometry3d error = (reference.inverse() * truth[i]).inverse() * map.frame.member_poses[m];
      translation.push_back(error.translation().norm());
      rotation.push_back(rotationAngle(error));
    }
  }
  return spreadOf(translation, rotation);
}

void appendMoved(const Cloud& cloud, const Eigen::Isometry3d& pose, Cloud& out) {
  for (const auto& p : cloud) {
    const Eigen::Vector3d q = pose * p.getVector3fMap().cast<double>();
    out.push_back(pcl::PointXYZ(float(q.x()), float(q.y()), float(q.z())));
  }
}

/// The share of run 2's points, at their true poses, that have a point of
/// the chosen map within kCoverageDistance, the map's members at their true
/// poses too: what the map holds of the place, apart from its distortion.
double coverage(const Dataset& d, const Partition& partition) {
  std::vector<std::vector<int>> scans_of_map(partition.groups.size());
  for (std::size_t s = 0; s < d.second.clouds.size(); ++s)
    scans_of_map[partition.group_of[d.nearest_in_map[s]]].push_back(static_cast<int>(s));
  std::size_t covered = 0, total = 0;
  pcl::Indices index;
  std::vector<float> distances;
  for (std::size_t g = 0; g < partition.groups.size(); ++g) {
    if (scans_of_map[g].empty()) continue;
    Cloud::Ptr map(new Cloud);
    for (int i : partition.groups[g]) appendMoved(*d.first.clouds[i], d.first.truth[i], *map);
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    tree.setInputCloud(map);
    for (int s : scans_of_map[g]) {
      Cloud scan;
      appendMoved(*d.second.clouds[s], d.second.truth[s], scan);
      for (const auto& p : scan) covered += tree.radiusSearch(p, kCoverageDistance, index, distances, 1) > 0;
      total += scan.size();
    }
  }
  return total ? double(covered) / double(total) : 0.0;
}

/// ICP as a robot would run it: coarse correspondences first, then tight.
/// The robot drives on a floor, so every sensor is aligned in x, y and
/// heading (in 3D correspondences for the depth camera).
class ScanMatcher {
 public:
  ScanMatcher() {
    icp_.setTransformationEstimation(std::make_shared<Estimation2D>());
    icp_.setMaximumIterations(30);
    icp_.setTransformationEpsilon(1e-8);  // steps below 0.1 mm: converged
  }
  void setMap(const Cloud::ConstPtr& map) { icp_.setInputTarget(map); }
  Eigen::Isometry3d align(const Cloud::ConstPtr& scan, const Eigen::Isometry3d& guess) {
    Eigen::Matrix4f estimate = guess.matrix().cast<float>();
    icp_.setInputSource(scan);
    for (double distance : {1.0, 0.3}) {
      icp_.setMaxCorrespondenceDistance(distance);
      icp_.align(aligned_, estimate);
      estimate = icp_.getFinalTransformation();
    }
    return Eigen::Isometry3d(estimate.cast<double>());
  }

 private:
  using Estimation2D = pcl::registration::TransformationEstimation2D<pcl::PointXYZ, pcl::PointXYZ>;
  pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp_;
  Cloud aligned_;
};

/// Initial guesses: the truth relative to the map's reference, off by
/// Gaussian noise in x, y and heading. Drawn per scan in a fixed order, so
/// every cut gets the same noise for the same scan.
std::vector<Eigen::Isometry3d> guessNoise(std::size_t count) {
  std::mt19937_64 rng(kGuessSeed);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Isometry3d> noise;
  for (std::size_t s = 0; s < count; ++s) {
    const double dx = kGuessTranslation * unit(rng), dy = kGuessTranslation * unit(rng);
    const double dyaw = kGuessRotation * unit(rng);
    noise.push_back(pose2D(dx, dy, dyaw));
  }
  return noise;
}

/// The points of a depth image or map that ICP aligns: the walls. Floor and
/// ceiling fix none of x, y and heading, and they are most of the image:
/// point-to-point ICP crawls along them. Heights in the camera frame (1 m
/// over the floor, the ceiling 2.6 m high), 0.2 m kept off each.
Cloud::ConstPtr wallPoints(const Cloud& cloud) {
  constexpr float kLowest = -0.8f, kHighest = 1.4f;
  Cloud::Ptr out(new Cloud);
  for (const auto& p : cloud)
    if (p.z > kLowest && p.z < kHighest) out->push_back(p);
  return out;
}

/// What ICP aligns: a laser scan as it is, a depth image's walls only.
Cloud::ConstPtr forMatching(const Cloud::ConstPtr& cloud, sim::Sensor sensor) {
  return sensor == sim::Sensor::Depth ? wallPoints(*cloud) : cloud;
}

struct Localization {
  Spread errors;
  double failures = 0;  // share of the scans
  std::vector<std::string> failed;  ///< one line per failed scan, for --failures
};

/// The observations of a map as runs of consecutive indices: "146-156, 182-188".
std::string runsOf(const std::vector<int>& members) {
  std::string text;
  for (std::size_t k = 0; k < members.size();) {
    std::size_t end = k;
    while (end + 1 < members.size() && members[end + 1] == members[end] + 1) ++end;
    text += (text.empty() ? "" : ", ") + std::to_string(members[k]) +
            (end > k ? "-" + std::to_string(members[end]) : "");
    k = end + 1;
  }
  return text;
}

/// Aligns every run-2 scan against the map the robot picks and measures the
/// result against the truth relative to that map's reference.
Localization localize(const Dataset& d, const Partition& partition, const Maps& maps) {
  const std::vector<Eigen::Isometry3d> noise = guessNoise(d.second.clouds.size());
  ScanMatcher matcher;
  std::vector<double> translation, rotation;
  std::vector<std::string> failed;  // one line per failure: their count is the failures
  for (std::size_t g = 0; g < maps.size(); ++g) {  // map by map: one search tree per map
    bool target_set = false;
    for (std::size_t s = 0; s < d.second.clouds.size(); ++s) {
      if (partition.group_of[d.nearest_in_map[s]] != static_cast<int>(g)) continue;
      if (!target_set) matcher.setMap(forMatching(maps[g].cloud, d.sensor)), target_set = true;
      const Eigen::Isometry3d truth = d.first.truth[maps[g].frame.reference].inverse() * d.second.truth[s];
      const Eigen::Isometry3d estimate =
          matcher.align(forMatching(d.second.clouds[s], d.sensor), truth * noise[s]);
      const Eigen::Isometry3d error = truth.inverse() * estimate;
      translation.push_back(error.translation().norm());
      rotation.push_back(rotationAngle(error));
      if (translation.back() > kFailTranslation || rotation.back() > kFailRotation) {
        const Eigen::Isometry3d& start = noise[s];  // the start's error: the guess is truth * noise
        failed.push_back(format("run-2 scan %zu: %.1f cm, %.2f deg off (start %.1f cm, %.2f deg off); map %zu, run-1 "
                                "scans %s, reference %d",
                                s, 100 * translation.back(), rotation.back() * 180.0 / kPi,
                                100 * start.translation().norm(), rotationAngle(start) * 180.0 / kPi, g,
                                runsOf(maps[g].frame.members).c_str(), maps[g].frame.reference));
      }
    }
  }
  return {spreadOf(translation, rotation), double(failed.size()) / double(translation.size()), failed};
}

// --- the report ----------------------------------------------------------------

/// One building seen by one sensor, cut every way.
struct Evaluation {
  Dataset data;
  std::vector<Cut> cuts;
  std::vector<double> coverage;  // by cut
};

struct Row {
  std::string cut;
  Refinement refinement = Refinement::None;
  std::size_t maps = 0;
  RefinementReport refined;  ///< summed over the maps
  Spread members;
  Localization localization;
};

Row measure(const Evaluation& e, const Cut& cut, Refinement refinement) {
  LocalMapBuilder<pcl::PointXYZ> builder;
  builder.setRefinement(refinement);
  builder.setVoxelLeafSize(0.05);
  builder.setNumberOfThreads(1);  // the tasks are spread over the cores instead
  const Maps maps = builder.build(e.data.drifted, cut.partition, *cut.W);
  Row row;
  row.cut = cut.name;
  row.refinement = refinement;
  row.maps = maps.size();
  for (const auto& map : maps) row.refined += map.refinement;
  row.members = memberPoseErrors(maps, e.data.first.truth);
  row.localization = localize(e.data, cut.partition, maps);
  return row;
}

/// Runs task(0) ... task(count - 1) on every core. Each task writes only its
/// own result, so the results do not depend on the number of threads.
template <typename Task>
void runInParallel(std::size_t count, const Task& task) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&] {
    for (std::size_t k; (k = next++) < count;) {
      try {
        task(k);
      } catch (...) {
        std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  std::vector<std::thread> threads(std::max(1u, std::thread::hardware_concurrency()) - 1);
  for (auto& thread : threads) thread = std::thread(work);
  work();
  for (auto& thread : threads) thread.join();
  if (failure) std::rethrow_exception(failure);
}

std::string refinementName(const Row& row) {
  if (row.refinement == Refinement::None) return "none";
  std::string name = row.refinement == Refinement::Lum ? "LUM" : "ICP";
  return name + format(" (%d of %d moved)", row.refined.moved, row.refined.members);
}

std::string tableLine(const Row& r, double coverage) {
  constexpr double cm = 100.0, deg = 180.0 / kPi;
  const Spread& m = r.members;
  const Spread& e = r.localization.errors;
  return format("| %s | %s | %zu | %.1f / %.1f | %.2f / %.2f | %.0f | %.1f / %.1f | %.2f / %.2f | %.0f |\n",
                r.cut.c_str(), refinementName(r).c_str(), r.maps, cm * m.t50, cm * m.t90, deg * m.r50, deg * m.r90,
                100 * coverage, cm * e.t50, cm * e.t90, deg * e.r50, deg * e.r90, 100 * r.localization.failures);
}

std::string label(const Row& r) { return r.cut + (r.refinement == Refinement::None ? "" : " + LUM"); }

/// Written by the program, not by hand: the numbers change with the refinement.
std::string summary(const std::vector<Row>& rows) {
  const auto best = [&rows](auto key) {
    return *std::min_element(rows.begin(), rows.end(), [&key](const Row& a, const Row& b) { return key(a) < key(b); });
  };
  const Row& median = best([](const Row& r) { return r.localization.errors.t50; });
  // Ties (several cuts with no failure) go to the lower median error.
  const Row& failures =
      best([](const Row& r) { return std::make_pair(r.localization.failures, r.localization.errors.t50); });
  return format("Lowest median error: %s (%.1f cm). Fewest failures: %s (%.0f %%).\n", label(median).c_str(),
                100 * median.localization.errors.t50, label(failures).c_str(), 100 * failures.localization.failures);
}

/// Over a building's sensors: the cut and refinement with the lowest mean
/// failure share, ties to the lower mean of the median errors.
std::string buildingSummary(const std::vector<std::vector<Row>>& tables) {
  std::size_t best = 0;
  std::vector<double> failures(tables.front().size()), medians(tables.front().size());
  for (std::size_t r = 0; r < failures.size(); ++r) {
    for (const auto& rows : tables) {
      failures[r] += rows[r].localization.failures / double(tables.size());
      medians[r] += rows[r].localization.errors.t50 / double(tables.size());
    }
    if (std::make_pair(failures[r], medians[r]) < std::make_pair(failures[best], medians[best])) best = r;
  }
  return format("**Over the %zu sensors**, the fewest failures on average: %s (%.0f %%, mean median error %.1f cm).\n\n",
                tables.size(), label(tables.front()[best]).c_str(), 100 * failures[best], 100 * medians[best]);
}

std::string table(const Evaluation& e, const std::vector<Row>& rows) {
  std::ostringstream out;
  out << "#### " << sim::describe(e.data.sensor) << "\n\n"
      << "| cut | refinement | maps | member pose error p50 / p90 (cm) | (deg) | coverage (%) "
         "| localization error median / p90 (cm) | (deg) | failures (%) |\n"
      << "|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t r = 0; r < rows.size(); ++r) out << tableLine(rows[r], e.coverage[r / 2]);
  out << "\n" << summary(rows) << "\n";
  return out.str();
}

/// How far run 2 is from run 1: the distance from each run-2 pose to the
/// nearest run-1 pose, and the difference of their headings.
std::string describeRuns(const Dataset& d) {
  double worst = 0;
  for (std::size_t k = 0; k < d.drifted.size(); ++k)
    worst = std::max(worst, (d.drifted[k].pose.translation() - d.first.truth[k].translation()).norm());
  std::vector<double> distance, heading;
  for (const Eigen::Isometry3d& pose : d.second.truth) {
    const Eigen::Isometry3d& nearest = d.first.truth[nearestPosition(d.first.truth, pose.translation())];
    distance.push_back((nearest.translation() - pose.translation()).norm());
    heading.push_back(rotationAngle(nearest.inverse() * pose) * 180.0 / kPi);
  }
  return format("Run 1: %zu scans, the drifted poses up to %.2f m from the truth. Run 2: %zu scans, "
                "%.2f m (median) to %.2f m (largest) from the nearest pose of run 1, facing %.0f° (median) "
                "away from it.\n\n",
                d.drifted.size(), worst, d.second.truth.size(), percentile(distance, 0.5),
                percentile(distance, 1.0), percentile(heading, 0.5));
}

constexpr Refinement kRefinements[] = {Refinement::None, Refinement::Lum};
constexpr std::size_t kRowsPerCut = std::size(kRefinements);

/// Every building with every sensor: datasets, cuts and coverage first, then
/// the rows (a map build and the localization of run 2 each), the slowest first.
std::string evaluateAll(const std::vector<std::string>& keys, const std::vector<sim::Sensor>& sensors,
                        bool print_failures) {
  std::vector<sim::Building> buildings;
  for (const std::string& key : keys) buildings.push_back(sim::makeBuilding(key));
  std::vector<Evaluation> evaluations(buildings.size() * sensors.size());
  runInParallel(evaluations.size(), [&](std::size_t k) {
    Evaluation& e = evaluations[k];
    e.data = makeDataset(buildings[k / sensors.size()], sensors[k % sensors.size()]);
    e.cuts = makeCuts(e.data);
    for (const Cut& cut : e.cuts) e.coverage.push_back(coverage(e.data, cut.partition));
  });
  struct Task {
    std::size_t evaluation, cut, refinement;
    double cost;  // LUM solves a dense system of the map's size: large maps first, so that no core waits at the end
  };
  std::vector<Task> tasks;
  for (std::size_t k = 0; k < evaluations.size(); ++k)
    for (std::size_t c = 0; c < evaluations[k].cuts.size(); ++c) {
      std::size_t largest = 0;
      for (const auto& g : evaluations[k].cuts[c].partition.groups) largest = std::max(largest, g.size());
      for (std::size_t r = 0; r < kRowsPerCut; ++r)
        tasks.push_back({k, c, r, kRefinements[r] == Refinement::None ? 0.0 : std::pow(double(largest), 3)});
    }
  std::stable_sort(tasks.begin(), tasks.end(), [](const Task& a, const Task& b) { return a.cost > b.cost; });
  std::vector<std::vector<Row>> rows(evaluations.size());
  for (std::size_t k = 0; k < evaluations.size(); ++k) rows[k].resize(evaluations[k].cuts.size() * kRowsPerCut);
  runInParallel(tasks.size(), [&](std::size_t t) {
    const Task& task = tasks[t];
    const Evaluation& e = evaluations[task.evaluation];
    rows[task.evaluation][task.cut * kRowsPerCut + task.refinement] =
        measure(e, e.cuts[task.cut], kRefinements[task.refinement]);
  });
  std::string report;
  for (std::size_t b = 0; b < buildings.size(); ++b) {
    report += "### " + buildings[b].title + "\n\n" + describeRuns(evaluations[b * sensors.size()].data);
    std::vector<std::vector<Row>> tables;
    for (std::size_t s = 0; s < sensors.size(); ++s) {
      const std::size_t k = b * sensors.size() + s;
      report += table(evaluations[k], rows[k]);
      tables.push_back(rows[k]);
      if (print_failures)
        for (const Row& row : rows[k])
          for (const std::string& line : row.localization.failed)
            std::cerr << buildings[b].title << ", " << sim::describe(sensors[s]) << ", " << label(row) << ": " << line
                      << "\n";
    }
    report += buildingSummary(tables);
  }
  return report;
}

}  // namespace

int main(int argc, char** argv) {
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // ICP failures are measured, not printed
  std::string output;
  std::vector<std::string> buildings{"office", "loop"};
  std::vector<std::string> sensor_names{"laser360", "laser180", "depth"};
  bool print_failures = false;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--failures") print_failures = true;
    else if (arg == "--output" && a + 1 < argc) output = argv[++a];
    else if (arg == "--buildings" && a + 1 < argc) buildings = splitList(argv[++a]);
    else if (arg == "--sensors" && a + 1 < argc) sensor_names = splitList(argv[++a]);
    else {
      std::cerr << "usage: " << argv[0]
                << " [--output FILE] [--buildings office,loop,rooms20] [--sensors laser360,laser180,depth]"
                   " [--failures]\n";
      return 2;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  std::string report;
  try {
    std::vector<sim::Sensor> sensors;
    for (const std::string& name : sensor_names) sensors.push_back(sim::sensorFromString(name));
    report = evaluateAll(buildings, sensors, print_failures);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cerr << format("evaluated in %.0f s\n", seconds);
  report += format("(evaluated in %.0f s on %u threads)\n\n", seconds, std::max(1u, std::thread::hardware_concurrency()));
  if (output.empty()) {
    std::cout << report;
    return 0;
  }
  return writeGeneratedSection(output, report);
}
