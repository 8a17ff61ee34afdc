// Latency of online grouping: insert + update() per observation, on the long
// building of bench/make_scaling_input (2D laser of 360 beams, or a depth
// camera of 160 x 120 points), generated in memory.
//
//   online_latency 2d|3d N [--sample K] [--update-every U] [--exact-every E] [--check C] [--threads T]
//                  [--open-floor-width M]
//
// Without --sample, every observation is inserted and timed (a full replay),
// and the batch ObservationGrouping::compute() on the same N is timed too.
// With --sample K, the first N - K observations are inserted and grouped
// once, untimed, and only the last K inserts are timed: the latency at size
// N without replaying N. --exact-every E makes updates local between exact
// ones (OnlineGrouping::setExactInterval); --check C then compares the
// groups after every C-th insert with a batch compute() (adjusted Rand
// index, untimed). Prints one markdown row: median, 99th percentile and
// worst latency, the overlaps and split-tree nodes recomputed per update,
// (full replay) the replay and batch times, and the lowest ARI seen. The
// final groups, after an exact update, must equal the batch's.

#include "floor_plan.h"
#include "scenarios.h"
#include "to_cloud.h"

#include <obsgroup/online_grouping.h>

#include <pcl/point_types.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace obsgroup;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kBuildingPerScan = 0.2;  // as make_scaling_input

std::vector<Observation<pcl::PointXYZ>> makeInput(const std::string& kind, int n) {
  std::vector<Observation<pcl::PointXYZ>> out(n);
  const bool depth = kind == "3d";
  const double length = std::max(16.0, n * kBuildingPerScan * (depth ? 2 : 1));
  const sim::FloorPlan plan = sim::longBuilding(length);
  const auto route = sim::longBuildingRoute(length, n);
  sim::LaserModel laser;
  laser.beams = 360;
  laser.field_of_view = 2 * 3.14159265358979323846 * 359.0 / 360.0;
  laser.max_range = 20.0;
  laser.range_noise = 0.01;
  sim::DepthCamera camera;
  camera.width = 160;
  camera.height = 120;
  camera.range_noise = 0.005;
#pragma omp parallel for schedule(dynamic, 16)
  for (int k = 0; k < n; ++k) {
    const sim::Pose2D& p = route[k];
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translate(Eigen::Vector3d(p.x, p.y, 0.0));
    pose.rotate(Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ()));
    if (depth) {
      auto cloud = sim::depthCloud<pcl::PointXYZ>(plan, p, camera, k);
      out[k] = {cloud, poseFromSensorOrigin(*cloud)};
    } else {
      out[k] = {sim::toCloud<pcl::PointXYZ>(sim::scanToPoints(plan.scan(p, laser, k), laser), 0.0f), pose};
    }
  }
  return out;
}

double seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[std::min(v.size() - 1, std::size_t(q * double(v.size() - 1) + 0.5))];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: online_latency 2d|3d N [--sample K] [--update-every U] [--threads T]"
                 " [--open-floor-width M]\n");
    return 2;
  }
  const std::string kind = argv[1];
  const int n = std::atoi(argv[2]);
  int sample = 0, every = 1, threads = 0, exact_every = 1, check = 0;
  double open_floor_width = GroupingParameters{}.open_floor_width;
  for (int a = 3; a + 1 < argc; a += 2) {
    const std::string option = argv[a];
    if (option == "--sample") sample = std::atoi(argv[a + 1]);
    else if (option == "--update-every") every = std::max(1, std::atoi(argv[a + 1]));
    else if (option == "--threads") threads = std::atoi(argv[a + 1]);
    else if (option == "--exact-every") exact_every = std::atoi(argv[a + 1]);
    else if (option == "--check") check = std::atoi(argv[a + 1]);
    else if (option == "--open-floor-width") open_floor_width = std::atof(argv[a + 1]);
  }
  if ((kind != "2d" && kind != "3d") || n < 2 || sample < 0 || sample >= n) {
    std::fprintf(stderr, "online_latency: bad arguments\n");
    return 2;
  }
  const auto input = makeInput(kind, n);

  OnlineGrouping<pcl::PointXYZ> online;
  GroupingParameters params;
  params.open_floor_width = open_floor_width;
  online.setParameters(params);
  online.setNumberOfThreads(threads);
  online.setExactInterval(exact_every);
  const int untimed = sample > 0 ? n - sample : 0;
  for (int k = 0; k < untimed; ++k) online.insert(input[k].cloud, input[k].pose);
  if (untimed > 0) online.update();
  std::vector<double> latency;
  std::size_t recomputed = 0, computed_nodes = 0, updates = 0;
  double checking_s = 0.0, lowest_ari = 1.0;
  const auto replay = Clock::now();
  for (int k = untimed; k < n; ++k) {
    const auto start = Clock::now();
    online.insert(input[k].cloud, input[k].pose);
    if ((k - untimed + 1) % every == 0 || k + 1 == n) {
      const GroupUpdate u = k + 1 == n ? online.updateExact() : online.update();
      recomputed += u.observations_recomputed;
      computed_nodes += u.split_nodes_computed;
      ++updates;
    }
    latency.push_back(seconds(start) * 1e3);
    if (check > 0 && (k + 1) % check == 0 && k + 1 < n) {
      const auto check_start = Clock::now();
      ObservationGrouping<pcl::PointXYZ> reference;
      reference.setParameters(params);
      reference.setNumberOfThreads(threads);
      for (int i = 0; i <= k; ++i) reference.addObservation(input[i].cloud, input[i].pose);
      lowest_ari = std::min(lowest_ari, sim::adjustedRandIndex(reference.compute().group_of,
                                                                 online.getPartition().group_of));
      checking_s += seconds(check_start);
    }
  }
  const double replay_s = seconds(replay) - checking_s;

  double batch_s = 0.0;
  ObservationGrouping<pcl::PointXYZ> batch;
  batch.setParameters(params);
  batch.setNumberOfThreads(threads);
  for (const auto& o : input) batch.addObservation(o.cloud, o.pose);
  const auto batch_start = Clock::now();
  const Partition expected = batch.compute();
  batch_s = seconds(batch_start);
  const bool equal = expected.groups == online.getPartition().groups;

  std::printf("| %s | %d | %s | %d | %d | %.1f | %.1f | %.1f | %.1f | %.1f | %s | %.2f | %s | %s |\n",
              kind == "2d" ? "2D laser" : "depth camera", n, sample > 0 ? ("last " + std::to_string(sample)).c_str() : "all",
              every, exact_every, percentile(latency, 0.5), percentile(latency, 0.99), percentile(latency, 1.0),
              double(recomputed) / double(updates), double(computed_nodes) / double(updates),
              sample > 0 ? "-" : (std::to_string(replay_s).substr(0, 6) + " s").c_str(), batch_s,
              check > 0 ? std::to_string(lowest_ari).substr(0, 5).c_str() : "-", equal ? "yes" : "NO");
  return equal ? 0 : 1;
}
