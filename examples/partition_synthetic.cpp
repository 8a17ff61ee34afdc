// Partitions a simulated office (a corridor and four rooms, 77 scans of a
// 180-degree laser, as in the paper's Fig. 5) and prints the groups, the room
// each scan was taken in, and the split tree with its normalized cuts.
//
//   partition_synthetic [--scans N] [--delta METRES] [--split mean|sign|best] [--diagonal W_II]

#include "floor_plan.h"
#include "to_cloud.h"

#include <obsgroup/observation_grouping.h>

#include <pcl/point_types.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <string>

namespace {

void usage(const char* argv0) {
  std::cerr << "usage: " << argv0 << " [--scans N] [--delta METRES] [--split mean|sign|best] [--diagonal W_II]\n";
}

}  // namespace

int main(int argc, char** argv) {
  int scans = 77;
  double delta = 0.1;
  std::string split = "mean";
  double diagonal = obsgroup::kDefaultDiagonalWeight;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (a + 1 >= argc) {
      usage(argv[0]);
      return 2;
    }
    try {
      if (arg == "--scans") scans = std::stoi(argv[++a]);
      else if (arg == "--delta") delta = std::stod(argv[++a]);
      else if (arg == "--split") split = argv[++a];
      else if (arg == "--diagonal") diagonal = std::stod(argv[++a]);
      else {
        usage(argv[0]);
        return 2;
      }
    } catch (const std::exception&) {
      std::cerr << "error: option " << arg << ": not a number: " << argv[a] << "\n";
      return 2;
    }
  }
  if (scans < 1) {
    std::cerr << "error: option --scans: must be at least 1\n";
    return 2;
  }
  if (!(delta > 0) || !(diagonal >= 0)) {
    std::cerr << "error: --delta must be > 0 and --diagonal >= 0\n";
    return 2;
  }

  const obsgroup::sim::FloorPlan plan = obsgroup::sim::office();
  obsgroup::sim::LaserModel laser;  // 180 degrees, 361 beams, 30 m
  laser.range_noise = 0.01;
  const auto route = obsgroup::sim::officeRoute(scans);

  obsgroup::ObservationGrouping<pcl::PointXYZ> grouping;
  for (std::size_t k = 0; k < route.size(); ++k) {
    const auto& pose = route[k];
    const auto points = obsgroup::sim::scanToPoints(plan.scan(pose, laser, k), laser);
    grouping.addObservation(obsgroup::sim::toCloud<pcl::PointXYZ>(points), obsgroup::pose2D(pose.x, pose.y, pose.yaw));
  }
  // The paper's method (the points model of Fig. 5), with the options given.
  obsgroup::GroupingParameters params = obsgroup::GroupingParameters::paper();
  params.match_distance = delta;
  params.diagonal_weight = diagonal;
  try {
    params.split = obsgroup::splitCriterionFromString(split);
    grouping.setParameters(params);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }

  const auto start = std::chrono::steady_clock::now();
  const obsgroup::Partition partition = grouping.compute();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::printf("%zu scans of a simulated office, delta %.3g m, split '%s', W_ii = %g: %zu groups in %.3f s\n\n",
              route.size(), delta, split.c_str(), diagonal, partition.groups.size(), seconds);
  for (std::size_t g = 0; g < partition.groups.size(); ++g) {
    std::map<std::string, int> rooms;
    for (int i : partition.groups[g]) {
      const int room = plan.roomAt(route[i].x, route[i].y);
      ++rooms[room >= 0 ? plan.roomNames()[room] : "outside"];
    }
    std::printf("group %zu (%zu scans):", g, partition.groups[g].size());
    for (int i : partition.groups[g]) std::printf(" %d", i);
    std::printf("\n   taken in:");
    for (const auto& [name, count] : rooms) std::printf(" %s x%d", name.c_str(), count);
    std::printf("\n");
  }

  std::printf("\nsplit tree (Ncut of eq. 1, accepted while < %.3g):\n", grouping.getNcutThreshold());
  for (std::size_t s = 0; s < partition.splits.size(); ++s) {
    const auto& node = partition.splits[s];
    std::printf("%*snode %zu: %zu scans, %s", 2 * node.depth, "", s, node.members.size(),
                obsgroup::toString(node.kind).c_str());
    if (node.attempted) std::printf(", Ncut %.4f", node.ncut);
    std::printf(" (%s)\n", obsgroup::toString(node.outcome).c_str());
  }
  return 0;
}
