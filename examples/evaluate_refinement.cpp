// The evidence behind docs/refinement.md: does refining a local map make it
// right, and never worse? Simulated buildings give the true poses. Each
// dataset is grouped by obsgroup's defaults and every group built as a
// local map three ways (Refinement::None, Icp, Lum):
//   exact poses    how far refinement moves members that were already right
//                  (their pose in the map frame against the input);
//   drifted poses  the members' relative-pose error in their map frame
//                  against the truth, before and after refinement;
//   joined or not  the drifted members' error split into those a chain of
//                  alignments joins to their map's reference and the others.
//
//   evaluate_refinement [--output FILE] [--buildings office,loop] [--sensors laser360,laser180,depth]
//                       [--min-constraint-ratio R] [--point-neighbours N] [--min-gain G] [--by-visit]
//                       [--worst]
// prints the tables, or writes them into FILE between the lines
// "<!-- generated:begin -->" and "<!-- generated:end -->", keeping the rest.
// --min-constraint-ratio overrides RefinementParameters::min_constraint_ratio
// (0: every direction of every pair is trusted), to measure what the guard
// against unconstrained directions does; --point-neighbours overrides
// RefinementParameters::point_neighbours (0: Lum pairs by W alone), and
// --min-gain RefinementParameters::min_gain (-1: every solved pose within
// the bounds is kept), to measure what the acceptance test holds back.
// --by-visit also prints (to stderr) the drifted members' error split into
// the reference's own visit of the place and other visits (a loop's return);
// --worst prints the drifted members above their row's 90th percentile, each
// with its error in the world's axes and its true position.

#include "floor_plan.h"
#include "generated_section.h"
#include "scenarios.h"
#include "to_cloud.h"

#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/observation_grouping.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

using namespace obsgroup;
using obsgroup::examples::splitList;
using obsgroup::examples::writeGeneratedSection;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::uint64_t kDriftSeed = 7;

struct Dataset {
  std::string title;
  std::vector<Cloud::ConstPtr> clouds;
  std::vector<Eigen::Isometry3d> truth, drifted;
};

Dataset makeDataset(const std::string& key, sim::Sensor sensor) {
  const sim::Building building = sim::makeBuilding(key);
  Dataset d;
  d.title = building.title + ", " + sim::describe(sensor);
  const double height = sim::sensorHeight(sensor);
  for (std::size_t k = 0; k < building.route.size(); ++k) {
    const sim::Pose2D& pose = building.route[k];
    switch (sensor) {
      case sim::Sensor::Laser360: d.clouds.push_back(sim::scanCloud<pcl::PointXYZ>(building.plan, pose, sim::laser360(), k)); break;
      case sim::Sensor::Laser180: d.clouds.push_back(sim::scanCloud<pcl::PointXYZ>(building.plan, pose, sim::laser180(), k)); break;
      case sim::Sensor::Depth: d.clouds.push_back(sim::depthCloud<pcl::PointXYZ>(building.plan, pose, sim::depthCamera(), k)); break;
      case sim::Sensor::Lidar: d.clouds.push_back(sim::lidarCloud<pcl::PointXYZ>(building.plan, pose, sim::lidar(), k)); break;
    }
    d.truth.push_back(sim::toIsometry(pose, height));
  }
  d.drifted = sim::drift(d.truth, kDriftSeed);
  return d;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * double(v.size() - 1) + 0.5))];
}

/// Translation (m) and rotation (rad) of a pose error.
std::pair<double, double> size(const Eigen::Isometry3d& error) {
  return {error.translation().norm(), Eigen::AngleAxisd(error.linear()).angle()};
}

struct Errors {
  RefinementReport report;
  std::vector<double> translation, rotation;
  int moved = 0, members = 0, warnings = 0, off_plane = 0;
  double seconds = 0;
};

/// Every non-reference member's pose in its map frame against `expected`
/// (the input pose for exact data, the truth for drifted data).
Errors measure(const std::vector<LocalMap<pcl::PointXYZ>>& maps, const std::vector<Eigen::Isometry3d>& expected,
               const std::vector<Eigen::Isometry3d>& input, bool planar) {
  Errors e;
  for (const auto& map : maps) {
    const LocalMapFrame& f = map.frame;
    e.moved += map.refinement.moved;
    e.report += map.refinement;
    e.warnings += !map.refinement.warning().empty();
    for (std::size_t k = 0; k < f.members.size(); ++k) {
      const int i = f.members[k];
      if (i == f.reference) continue;
      ++e.members;
      const Eigen::Isometry3d want = expected[f.reference].inverse() * expected[i];
      const auto [t, r] = size(want.inverse() * f.member_poses[k]);
      e.translation.push_back(t);
      e.rotation.push_back(r);
      if (planar) {
        const Eigen::Isometry3d in_map = input[f.reference].inverse() * input[i];
        const Eigen::Isometry3d& m = f.member_poses[k];
        // Up to rounding: a map anchored at another member than its first
        // reference (refinement.h) is re-expressed in that member's frame.
        const auto differs = [](double a, double b) { return std::abs(a - b) > 1e-12; };
        if (differs(m.translation().z(), in_map.translation().z()) || differs(m.linear()(2, 2), in_map.linear()(2, 2)) ||
            differs(m.linear()(0, 2), in_map.linear()(0, 2)) || differs(m.linear()(1, 2), in_map.linear()(1, 2)))
          ++e.off_plane;
      }
    }
  }
  return e;
}

std::string cell(const Errors& e) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "%.2f / %.2f | %.2f / %.2f", 100 * percentile(e.translation, 0.5),
                100 * percentile(e.translation, 0.9), percentile(e.rotation, 0.5) * 180 / kPi,
                percentile(e.rotation, 0.9) * 180 / kPi);
  return buffer;
}

/// Whether member `i` belongs to the same visit of its place as the
/// reference: no gap of more than 3 in the sequence between the two among
/// the map's members.
bool sameVisit(const LocalMapFrame& f, int i) {
  const int lo = std::min(i, f.reference), hi = std::max(i, f.reference);
  int previous = -1;
  for (int j : f.members) {
    if (j < lo || j > hi) continue;
    if (previous >= 0 && j - previous > 3) return false;
    previous = j;
  }
  return true;
}

/// Calls visit(map, k, want) for every non-reference member k of every
/// map, `want` being its true pose in the map frame.
template <typename Visit>
void forEachMember(const std::vector<LocalMap<pcl::PointXYZ>>& maps, const Dataset& d, const Visit& visit) {
  for (const auto& map : maps) {
    const LocalMapFrame& f = map.frame;
    for (std::size_t k = 0; k < f.members.size(); ++k)
      if (f.members[k] != f.reference)
        visit(map, k, Eigen::Isometry3d(d.truth[f.reference].inverse() * d.truth[f.members[k]]));
  }
}

bool isUnlinked(const LocalMap<pcl::PointXYZ>& map, int i) {
  const auto& unlinked = map.refinement.unlinked;
  return std::find(unlinked.begin(), unlinked.end(), i) != unlinked.end();
}

/// The drifted members' error before (input) and after refinement, split
/// into the reference's own visit and other visits (a loop's return).
std::string byVisit(const std::vector<LocalMap<pcl::PointXYZ>>& maps, const Dataset& d,
                    const std::vector<Eigen::Isometry3d>& input, const std::string& label) {
  std::vector<double> before[2], after[2];
  forEachMember(maps, d, [&](const LocalMap<pcl::PointXYZ>& map, std::size_t k, const Eigen::Isometry3d& want) {
    const LocalMapFrame& f = map.frame;
    const int i = f.members[k], s = sameVisit(f, i) ? 0 : 1;
    before[s].push_back(size(want.inverse() * input[f.reference].inverse() * input[i]).first);
    after[s].push_back(size(want.inverse() * f.member_poses[k]).first);
  });
  std::ostringstream out;
  char buffer[200];
  for (int s = 0; s < 2; ++s) {
    std::snprintf(buffer, sizeof buffer, "%s, %s: %zu members, error median / p90 %.1f / %.1f cm before, %.1f / %.1f after\n",
                  label.c_str(), s == 0 ? "reference's visit" : "other visits", before[s].size(),
                  100 * percentile(before[s], 0.5), 100 * percentile(before[s], 0.9), 100 * percentile(after[s], 0.5),
                  100 * percentile(after[s], 0.9));
    out << buffer;
  }
  return out.str();
}

/// The drifted members whose refined error is above the 90th percentile of
/// their row, each with its error in the world's axes (the truth's x, y and
/// heading): which way the maps are still off, and where.
std::string worstMembers(const std::vector<LocalMap<pcl::PointXYZ>>& maps, const Dataset& d,
                         const std::vector<double>& errors, const std::string& label) {
  const double p90 = percentile(errors, 0.9);
  std::ostringstream out;
  forEachMember(maps, d, [&](const LocalMap<pcl::PointXYZ>& map, std::size_t k, const Eigen::Isometry3d& want) {
    const LocalMapFrame& f = map.frame;
    const int i = f.members[k];
    const auto [t, r] = size(want.inverse() * f.member_poses[k]);
    if (t <= p90) return;
    const Eigen::Vector3d e = d.truth[f.reference].linear() * (f.member_poses[k].translation() - want.translation());
    char buffer[240];
    std::snprintf(buffer, sizeof buffer,
                  "%s: member %d (at %.1f, %.1f) of the map of %d, %s: %.1f cm off (x %+.1f, y %+.1f cm), %.2f deg\n",
                  label.c_str(), i, d.truth[i].translation().x(), d.truth[i].translation().y(), f.reference,
                  isUnlinked(map, i) ? "not joined" : "joined", 100 * t, 100 * e.x(), 100 * e.y(), r * 180 / kPi);
    out << buffer;
  });
  return out.str();
}

/// The drifted members' error (m) before (input) and after refinement,
/// split into the members the alignments join to their map's reference
/// ([0]) and the others ([1], RefinementReport::unlinked).
struct LinkedSplit {
  std::vector<double> before[2], after[2];
};

LinkedSplit splitByLink(const std::vector<LocalMap<pcl::PointXYZ>>& maps, const Dataset& d,
                        const std::vector<Eigen::Isometry3d>& input) {
  LinkedSplit split;
  forEachMember(maps, d, [&](const LocalMap<pcl::PointXYZ>& map, std::size_t k, const Eigen::Isometry3d& want) {
    const LocalMapFrame& f = map.frame;
    const int i = f.members[k], s = isUnlinked(map, i) ? 1 : 0;
    split.before[s].push_back(size(want.inverse() * input[f.reference].inverse() * input[i]).first);
    split.after[s].push_back(size(want.inverse() * f.member_poses[k]).first);
  });
  return split;
}

/// One row of the linked/unlinked table.
std::string linkedRow(const std::string& title, Refinement refinement, const LinkedSplit& split, int exact_unlinked,
                      int exact_members) {
  std::ostringstream row;
  row << "| " << title << " | " << toString(refinement);
  char buffer[160];
  for (int s = 0; s < 2; ++s) {
    const auto& b = split.before[s];
    const auto& a = split.after[s];
    if (b.empty()) {
      row << " | 0 | –";
      continue;
    }
    std::snprintf(buffer, sizeof buffer, " | %zu | %.2f → %.2f", b.size(), 100 * percentile(b, 0.9),
                  100 * percentile(a, 0.9));
    row << buffer;
  }
  row << " | " << exact_unlinked << " of " << exact_members << " |\n";
  return row.str();
}

/// Per dataset title: members RefinementReport::unlinked names when the
/// input poses are exact, and all members, for Refinement::Lum.
std::map<std::string, std::pair<int, int>> g_exact_unlinked;

std::string evaluate(const std::string& key, sim::Sensor sensor, bool drifted, const RefinementParameters& parameters,
                     bool by_visit, bool worst, std::ostringstream& linked_rows) {
  const Dataset d = makeDataset(key, sensor);
  const std::vector<Eigen::Isometry3d>& input = drifted ? d.drifted : d.truth;
  std::vector<Observation<pcl::PointXYZ>> observations;
  for (std::size_t k = 0; k < d.clouds.size(); ++k) observations.push_back({d.clouds[k], input[k]});
  ObservationGrouping<pcl::PointXYZ> grouping;
  for (const auto& o : observations) grouping.addObservation(o.cloud, o.pose);
  const Partition partition = grouping.compute();
  const bool planar = true;  // every simulated pose lies in the floor plane, the depth camera's too
  std::ostringstream out;
  for (Refinement refinement : {Refinement::None, Refinement::Icp, Refinement::Lum}) {
    LocalMapBuilder<pcl::PointXYZ> builder;
    builder.setRefinement(refinement);
    builder.setRefinementParameters(parameters);
    const auto start = std::chrono::steady_clock::now();
    const auto maps = builder.build(observations, partition, grouping.getWeightMatrix());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const Errors e = measure(maps, drifted ? d.truth : input, input, planar);
    if (by_visit && drifted) std::cerr << byVisit(maps, d, input, d.title + " " + toString(refinement));
    if (worst && drifted) std::cerr << worstMembers(maps, d, e.translation, d.title + " " + toString(refinement));
    if (!drifted && refinement == Refinement::Lum)
      g_exact_unlinked[d.title] = {static_cast<int>(e.report.unlinked.size()), e.members};
    if (drifted && refinement != Refinement::None) {
      const auto exact = g_exact_unlinked[d.title];
      linked_rows << linkedRow(d.title, refinement, splitByLink(maps, d, input), exact.first, exact.second);
    }
    char tail[200];
    std::snprintf(tail, sizeof tail, " | %d of %d | %d | %s | %.1f |", e.moved, e.members, e.warnings,
                  planar ? (e.off_plane == 0 ? "yes" : "**no**") : "–", seconds);
    out << "| " << d.title << " | " << partition.groups.size() << " | " << toString(refinement) << " | " << cell(e)
        << tail << "\n";
    const RefinementReport& t = e.report;
    std::cerr << d.title << (drifted ? " (drifted)" : " (exact)") << " " << toString(refinement) << ": " << cell(e)
              << tail << " pairs " << t.pairs << " refused " << t.pairs_refused << " partial " << t.pairs_partial
              << "; kept: not better " << t.kept_not_better << ", beyond bound " << t.kept_beyond_bound
              << ", unaligned " << t.kept_unaligned << "\n";
  }
  return out.str();
}

const char* kHeader =
    "| dataset | maps | refinement | error median / p90 (cm) | rotation median / p90 (deg) | members moved | maps "
    "with a warning | z, roll, pitch unchanged | time (s) |\n|---|---|---|---|---|---|---|---|---|\n";

const char* kLinkedHeader =
    "| dataset | refinement | joined members | their error p90, input → refined (cm) | members not joined | "
    "their error p90, input → refined (cm) | members not joined with exact poses (lum) |\n"
    "|---|---|---|---|---|---|---|\n";

}  // namespace

int main(int argc, char** argv) {
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  std::string output;
  std::vector<std::string> buildings{"office", "loop"};
  std::vector<sim::Sensor> sensors{sim::Sensor::Laser360, sim::Sensor::Laser180, sim::Sensor::Depth};
  RefinementParameters parameters;
  bool by_visit = false, worst = false;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    const bool value = a + 1 < argc;
    if (arg == "--by-visit") by_visit = true;
    else if (arg == "--worst") worst = true;
    else if (arg == "--output" && value) output = argv[++a];
    else if (arg == "--buildings" && value) buildings = splitList(argv[++a]);
    else if (arg == "--min-constraint-ratio" && value) parameters.min_constraint_ratio = std::atof(argv[++a]);
    else if (arg == "--min-gain" && value) parameters.min_gain = std::atof(argv[++a]);
    else if (arg == "--point-neighbours" && value) parameters.point_neighbours = std::atoi(argv[++a]);
    else if (arg == "--sensors" && value) {
      sensors.clear();
      try {
        for (const auto& name : splitList(argv[++a])) sensors.push_back(sim::sensorFromString(name));
      } catch (const std::exception& e) {
        std::cerr << "error: " << e.what() << "\n";
        return 2;
      }
    } else {
      std::cerr << "usage: evaluate_refinement [--output FILE] [--buildings office,loop] [--sensors laser360,...] "
                   "[--min-constraint-ratio R] [--point-neighbours N] [--min-gain G] [--by-visit] [--worst]\n";
      return 2;
    }
  }
  std::ostringstream page, linked_rows;
  for (bool drifted : {false, true}) {
    page << (drifted ? "### Drifted input poses: members' error in their map frame against the truth\n\n"
                     : "### Exact input poses: how far refinement moves each member in its map frame\n\n")
         << kHeader;
    for (const auto& key : buildings)
      for (sim::Sensor sensor : sensors) page << evaluate(key, sensor, drifted, parameters, by_visit, worst, linked_rows);
    page << "\n";
  }
  page << "### Drifted input poses: members the alignments join to their map's reference, and the others\n\n"
       << kLinkedHeader << linked_rows.str() << "\n";
  if (output.empty()) {
    std::cout << page.str();
    return 0;
  }
  return writeGeneratedSection(output, page.str());
}
