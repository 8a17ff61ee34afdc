// The evidence behind docs/results.md: do obsgroup's local maps localize
// better than the alternatives? Simulated buildings give ground truth; the
// map is built from a drifted copy of the poses (odometry-like error), then
// cut three ways and each way measured:
//   whole      the whole drifted map as one;
//   chunks     fixed-size consecutive chunks (90 scans, as Cartographer's 2D submaps);
//   obsgroup   obsgroup's groups: its defaults (the visibility model), and the
//              paper's method (delta 0.1 and 0.2 m, the paper's threshold and split).
// Metrics: internal consistency (how far apart in the map are point pairs
// that are the same place in truth), localization of held-out scans by ICP
// against the map holding the nearest pose, and agreement with the true rooms.
//
//   evaluate_local_maps [--output FILE]
// prints the tables, or writes them into FILE between the lines
// "<!-- generated:begin -->" and "<!-- generated:end -->", keeping the rest.

#include "floor_plan.h"
#include "scenarios.h"
#include "to_cloud.h"

#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/observation_grouping.h>

#include <pcl/console/print.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/transformation_estimation_2D.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <random>
#include <sstream>

using namespace obsgroup;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDelta = 0.1;
constexpr int kChunk = 90;

struct Scenario {
  std::string name;
  sim::FloorPlan plan;
  std::vector<sim::Pose2D> route;
};

struct Dataset {
  std::vector<Observation<pcl::PointXYZ>> drifted;  // what the map is built from
  std::vector<Eigen::Isometry3d> truth;
  std::vector<int> room;                            // true place of each scan
  std::vector<Cloud::Ptr> held_out;                 // scans not in any map
  std::vector<Eigen::Isometry3d> held_out_truth;
};

Dataset makeDataset(const Scenario& s) {
  sim::LaserModel laser;  // 180 degrees, 361 beams, 30 m
  laser.range_noise = 0.01;
  Dataset d;
  for (std::size_t k = 0; k < s.route.size(); ++k) d.truth.push_back(sim::toIsometry(s.route[k]));
  const auto drifted = sim::drift(d.truth, 7);
  for (std::size_t k = 0; k < s.route.size(); ++k) {
    d.drifted.push_back({sim::toCloud<pcl::PointXYZ>(sim::scanToPoints(s.plan.scan(s.route[k], laser, k), laser)),
                         drifted[k]});
    d.room.push_back(s.plan.roomAt(s.route[k].x, s.route[k].y));
  }
  // Held-out scans halfway between consecutive poses, every second step.
  for (std::size_t k = 0; k + 1 < s.route.size(); k += 2) {
    const sim::Pose2D& a = s.route[k];
    const sim::Pose2D& b = s.route[k + 1];
    const sim::Pose2D mid{(a.x + b.x) / 2, (a.y + b.y) / 2, std::atan2(std::sin(a.yaw) + std::sin(b.yaw), std::cos(a.yaw) + std::cos(b.yaw))};
    d.held_out.push_back(sim::toCloud<pcl::PointXYZ>(sim::scanToPoints(s.plan.scan(mid, laser, 100000 + k), laser)));
    d.held_out_truth.push_back(sim::toIsometry(mid));
  }
  return d;
}

struct Cut {
  std::string name;
  Partition partition;
};

Partition fromGroups(std::vector<std::vector<int>> groups, int n) {
  Partition p;
  p.groups = std::move(groups);
  p.group_of.assign(n, -1);
  for (std::size_t g = 0; g < p.groups.size(); ++g)
    for (int i : p.groups[g]) p.group_of[i] = static_cast<int>(g);
  return p;
}

Cloud::Ptr moved(const Cloud& cloud, const Eigen::Isometry3d& pose) {
  Cloud::Ptr out(new Cloud);
  for (const auto& p : cloud) {
    const Eigen::Vector3d q = pose * Eigen::Vector3d(p.x, p.y, p.z);
    out->push_back(pcl::PointXYZ(float(q.x()), float(q.y()), float(q.z())));
  }
  return out;
}

struct Row {
  std::string name;
  std::size_t maps = 0;
  double mean_distance = 0, disagreeing = 0;
  double t_median = 0, t_p90 = 0, r_median = 0, r_p90 = 0;
  double ari = 0;
  int rooms_whole = 0, rooms = 0;
};

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5))];
}

/// Point pairs that are the same place in truth (within delta), measured in the map.
void consistency(const Dataset& d, const Partition& p, const WeightMatrix& W_truth, Row& row) {
  double sum = 0;
  std::size_t count = 0, far = 0;
  for (int j = 0; j < W_truth.outerSize(); ++j) {
    Cloud::Ptr truth_j = moved(*d.drifted[j].cloud, d.truth[j]);
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    bool built = false;
    for (WeightMatrix::InnerIterator it(W_truth, j); it; ++it) {
      const int i = static_cast<int>(it.row());
      if (i == j || p.group_of[i] != p.group_of[j]) continue;
      if (!built) tree.setInputCloud(truth_j), built = true;
      const Eigen::Isometry3d relative = d.drifted[i].pose.inverse() * d.drifted[j].pose;  // as the map has it
      pcl::Indices index(1);
      std::vector<float> sq(1);
      for (const auto& local : *d.drifted[i].cloud) {
        const Eigen::Vector3d world = d.truth[i] * Eigen::Vector3d(local.x, local.y, local.z);
        const pcl::PointXYZ q(float(world.x()), float(world.y()), float(world.z()));
        if (tree.nearestKSearch(q, 1, index, sq) < 1 || sq[0] > kDelta * kDelta) continue;
        const auto& other = (*d.drifted[j].cloud)[index[0]];
        const double gap = (Eigen::Vector3d(local.x, local.y, local.z) -
                            relative * Eigen::Vector3d(other.x, other.y, other.z)).norm();
        sum += gap;
        far += gap > 3 * kDelta;
        ++count;
      }
    }
  }
  row.mean_distance = count ? sum / count : 0.0;
  row.disagreeing = count ? double(far) / count : 0.0;
}

/// ICP of each held-out scan against the map holding the nearest pose, from
/// the true relative pose plus noise (0.3 m, 5 degrees).
void localization(const Dataset& d, const std::vector<LocalMap<pcl::PointXYZ>>& maps, const Partition& p, Row& row) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> unit(0.0, 1.0);
  pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
  icp.setTransformationEstimation(pcl::registration::TransformationEstimation2D<pcl::PointXYZ, pcl::PointXYZ>::Ptr(
      new pcl::registration::TransformationEstimation2D<pcl::PointXYZ, pcl::PointXYZ>));
  icp.setMaxCorrespondenceDistance(1.0);
  icp.setMaximumIterations(60);
  icp.setTransformationEpsilon(1e-10);
  std::vector<double> t_err, r_err;
  Cloud aligned;
  for (std::size_t h = 0; h < d.held_out.size(); ++h) {
    std::size_t nearest = 0;
    for (std::size_t k = 1; k < d.truth.size(); ++k)
      if ((d.truth[k].translation() - d.held_out_truth[h].translation()).norm() <
          (d.truth[nearest].translation() - d.held_out_truth[h].translation()).norm())
        nearest = k;
    const auto& map = maps[p.group_of[nearest]];
    const Eigen::Isometry3d truth = d.truth[map.frame.reference].inverse() * d.held_out_truth[h];
    const double angle = 5.0 * kPi / 180.0 * unit(rng);
    const double dx = 0.3 * unit(rng), dy = 0.3 * unit(rng);
    const Eigen::Isometry3d guess = truth * pose2D(dx, dy, angle);
    icp.setInputTarget(map.cloud);
    icp.setInputSource(d.held_out[h]);
    icp.align(aligned, guess.matrix().cast<float>());
    Eigen::Isometry3d estimate(icp.getFinalTransformation().cast<double>());
    t_err.push_back((estimate.translation() - truth.translation()).norm());
    r_err.push_back(std::abs(std::atan2((truth.linear().transpose() * estimate.linear())(1, 0),
                                        (truth.linear().transpose() * estimate.linear())(0, 0))));
  }
  row.t_median = percentile(t_err, 0.5);
  row.t_p90 = percentile(t_err, 0.9);
  row.r_median = percentile(r_err, 0.5) * 180 / kPi;
  row.r_p90 = percentile(r_err, 0.9) * 180 / kPi;
}

void rooms(const Dataset& d, const Partition& p, Row& row) {
  row.ari = sim::adjustedRandIndex(d.room, p.group_of);
  std::map<int, std::set<int>> groups_of_room;
  for (std::size_t i = 0; i < d.room.size(); ++i) groups_of_room[d.room[i]].insert(p.group_of[i]);
  row.rooms = static_cast<int>(groups_of_room.size());
  row.rooms_whole = 0;
  for (const auto& [room, groups] : groups_of_room) row.rooms_whole += groups.size() == 1;
}

WeightMatrix overlapOf(const std::vector<Observation<pcl::PointXYZ>>& obs) {
  SensedSpaceOverlap<pcl::PointXYZ> sso;
  sso.setMatchDistance(kDelta);
  return buildWeightMatrix(static_cast<int>(obs.size()), sso.compute(obs).pairs);
}

std::string evaluate(const Scenario& s) {
  const auto start = std::chrono::steady_clock::now();
  const Dataset d = makeDataset(s);
  const int n = static_cast<int>(d.drifted.size());
  std::vector<Observation<pcl::PointXYZ>> true_obs = d.drifted;
  for (int i = 0; i < n; ++i) true_obs[i].pose = d.truth[i];
  const WeightMatrix W_truth = overlapOf(true_obs);

  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  const auto chunked = [&all, n](int size) {
    std::vector<std::vector<int>> chunks;
    for (int i = 0; i < n; i += size) chunks.emplace_back(all.begin() + i, all.begin() + std::min(n, i + size));
    return fromGroups(chunks, n);
  };
  std::vector<std::pair<std::string, Partition>> cuts{{"whole map", fromGroups({all}, n)},
                                                      {"chunks of " + std::to_string(kChunk), chunked(kChunk)}};
  WeightMatrix W;  // the paper's at delta 0.1: chooses each map's reference, for every cut alike
  // delta 0: obsgroup's defaults (the visibility model); else the paper's method at that delta.
  for (double delta : {0.0, kDelta, 0.2}) {
    ObservationGrouping<pcl::PointXYZ> grouping;
    for (const auto& o : d.drifted) grouping.addObservation(o.cloud, o.pose);
    if (delta > 0) {
      grouping.usePaperMethod();
      grouping.setMatchDistance(delta);
    }
    const Partition groups = grouping.compute();
    if (delta == kDelta) W = grouping.getWeightMatrix();
    char name[80];
    if (delta > 0) std::snprintf(name, sizeof name, "obsgroup, the paper's, δ %.1f m", delta);
    else std::snprintf(name, sizeof name, "obsgroup, defaults (visibility)");
    cuts.emplace_back(name, groups);
    // Chunks as small as these groups on average: is it the grouping, or only the size?
    const int size = std::max(1, static_cast<int>(std::lround(double(n) / groups.groups.size())));
    cuts.emplace_back("chunks of " + std::to_string(size) + " (the same mean size)", chunked(size));
  }

  std::ostringstream out;
  out << "### " << s.name << "\n\n" << n << " scans, " << d.held_out.size() << " held out; ";
  double worst = 0;
  for (int i = 0; i < n; ++i) worst = std::max(worst, (d.drifted[i].pose.translation() - d.truth[i].translation()).norm());
  char text[400];
  std::snprintf(text, sizeof text, "largest drift of a pose from the truth %.2f m.\n\n", worst);
  out << text;
  out << "| cut | maps | matched-point gap, mean (cm) | pairs > 3δ (%) | loc. error median / p90 (cm) "
         "| rotation median / p90 (deg) | ARI vs rooms | places whole |\n"
      << "|---|---|---|---|---|---|---|---|\n";
  for (const auto& [name, partition] : cuts) {
    for (Refinement refine : {Refinement::None, Refinement::Icp}) {
      if (refine == Refinement::Icp && name != cuts[2].first) continue;
      Row row;
      row.name = name + (refine == Refinement::Icp ? " + ICP refinement" : "");
      LocalMapBuilder<pcl::PointXYZ> builder;
      builder.setRefinement(refine);
      builder.setVoxelLeafSize(0.05);
      const auto maps = builder.build(d.drifted, partition, W);
      row.maps = maps.size();
      if (refine == Refinement::None) consistency(d, partition, W_truth, row);
      localization(d, maps, partition, row);
      rooms(d, partition, row);
      if (refine == Refinement::None)
        std::snprintf(text, sizeof text, "| %s | %zu | %.2f | %.2f | %.1f / %.1f | %.2f / %.2f | %.2f | %d of %d |\n",
                      row.name.c_str(), row.maps, 100 * row.mean_distance, 100 * row.disagreeing, 100 * row.t_median,
                      100 * row.t_p90, row.r_median, row.r_p90, row.ari, row.rooms_whole, row.rooms);
      else
        std::snprintf(text, sizeof text, "| %s | %zu | (as above) | (as above) | %.1f / %.1f | %.2f / %.2f | %.2f | %d of %d |\n",
                      row.name.c_str(), row.maps, 100 * row.t_median, 100 * row.t_p90, row.r_median, row.r_p90,
                      row.ari, row.rooms_whole, row.rooms);
      out << text;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::snprintf(text, sizeof text, "\n(evaluated in %.1f s)\n\n", seconds);
  out << text;
  return out.str();
}

}  // namespace

int main(int argc, char** argv) {
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // ICP failures are measured, not printed
  std::string output;
  for (int a = 1; a < argc; ++a) {
    if (std::string(argv[a]) == "--output" && a + 1 < argc) output = argv[++a];
    else {
      std::cerr << "usage: " << argv[0] << " [--output FILE]\n";
      return 2;
    }
  }
  const std::vector<Scenario> scenarios{
      {"Office: a corridor and four rooms", sim::office(), sim::officeRoute(150)},
      {"Building with a loop: a corridor ring around six rooms", sim::loopBuilding(), sim::loopBuildingRoute(300)},
  };
  std::string report;
  for (const auto& s : scenarios) report += evaluate(s);
  if (output.empty()) {
    std::cout << report;
    return 0;
  }
  std::ifstream in(output);
  std::stringstream existing;
  existing << in.rdbuf();
  const std::string text = existing.str();
  const std::string begin = "<!-- generated:begin -->\n", end = "<!-- generated:end -->";
  const std::size_t b = text.find(begin), e = text.find(end);
  if (b == std::string::npos || e == std::string::npos || e < b) {
    std::cerr << "error: " << output << ": no '<!-- generated:begin -->' ... '<!-- generated:end -->' section\n";
    return 3;
  }
  std::ofstream(output) << text.substr(0, b + begin.size()) << report << text.substr(e);
  std::cout << "updated " << output << "\n";
  return 0;
}
