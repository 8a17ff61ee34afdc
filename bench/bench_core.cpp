// Google Benchmark micro-benchmarks of the core: one SSO pair, the whole
// overlap stage, graph build, one eigen solve (dense and Spectra), a full
// recursive partition, and the places' pass over every beam. Speed targets are
// checked here, never in unit tests.
//
//   bench_core --benchmark_filter=Fiedler
#include "floor_plan.h"
#include "to_cloud.h"

#include <obsgroup/observation_grouping.h>
#include <obsgroup/places/place_map.h>

#include <benchmark/benchmark.h>

#include <random>

using namespace obsgroup;

namespace {

/// A route-like graph: each node linked to its next `reach` nodes.
WeightMatrix routeGraph(int n, int reach) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> weight(0.2, 1.0);
  std::vector<WeightedPair> pairs;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j <= std::min(n - 1, i + reach); ++j) pairs.push_back({i, j, weight(rng) / (j - i)});
  return buildWeightMatrix(n, pairs);
}

std::vector<Observation<pcl::PointXYZ>> officeScans(int count) {
  const auto plan = sim::office();
  sim::LaserModel laser;
  std::vector<Observation<pcl::PointXYZ>> obs;
  const auto route = sim::officeRoute(count);
  for (std::size_t k = 0; k < route.size(); ++k)
    obs.push_back({sim::toCloud<pcl::PointXYZ>(sim::scanToPoints(plan.scan(route[k], laser, k), laser)),
                   pose2D(route[k].x, route[k].y, route[k].yaw)});
  return obs;
}

void BM_FiedlerDense(benchmark::State& state) {
  const WeightMatrix W = routeGraph(static_cast<int>(state.range(0)), 10);
  for (auto _ : state) benchmark::DoNotOptimize(fiedlerVector(W, {EigenSolver::Dense}).eigenvalue);
}
BENCHMARK(BM_FiedlerDense)->Arg(50)->Arg(100)->Arg(200)->Arg(400)->Arg(1000)->Unit(benchmark::kMillisecond);

void BM_FiedlerSparse(benchmark::State& state) {
  const WeightMatrix W = routeGraph(static_cast<int>(state.range(0)), 10);
  for (auto _ : state) benchmark::DoNotOptimize(fiedlerVector(W, {EigenSolver::Sparse}).eigenvalue);
}
BENCHMARK(BM_FiedlerSparse)
    ->Arg(50)->Arg(100)->Arg(200)->Arg(400)->Arg(1000)->Arg(10000)->Arg(100000)
    ->Unit(benchmark::kMillisecond);

void BM_SsoPair(benchmark::State& state) {
  const auto obs = officeScans(77);
  const std::vector<Observation<pcl::PointXYZ>> pair{obs[10], obs[11]};
  SensedSpaceOverlap<pcl::PointXYZ> sso;
  sso.setNeighbourSearch(state.range(0) ? NeighbourSearch::PclSearch : NeighbourSearch::SharedGrid);
  sso.setNumberOfThreads(1);
  for (auto _ : state) benchmark::DoNotOptimize(sso.compute(pair).pairs.size());
  state.SetLabel(state.range(0) ? "pcl-kdtree" : "shared-grid");
}
BENCHMARK(BM_SsoPair)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_OverlapStage(benchmark::State& state) {
  const auto obs = officeScans(static_cast<int>(state.range(0)));
  SensedSpaceOverlap<pcl::PointXYZ> sso;
  OverlapResult r;
  for (auto _ : state) r = sso.compute(obs);
  state.counters["point_tests/s"] =
      benchmark::Counter(static_cast<double>(r.point_tests), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_OverlapStage)->Arg(77)->Arg(500)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_GraphBuild(benchmark::State& state) {
  const WeightMatrix W = routeGraph(static_cast<int>(state.range(0)), 20);
  std::vector<WeightedPair> pairs;
  for (int k = 0; k < W.outerSize(); ++k)
    for (WeightMatrix::InnerIterator it(W, k); it; ++it)
      if (it.row() < k) pairs.push_back({static_cast<int>(it.row()), k, it.value()});
  for (auto _ : state) benchmark::DoNotOptimize(buildWeightMatrix(static_cast<int>(W.rows()), pairs).nonZeros());
}
BENCHMARK(BM_GraphBuild)->Arg(10000)->Unit(benchmark::kMillisecond);

void BM_RecursivePartition(benchmark::State& state) {
  const WeightMatrix W = routeGraph(static_cast<int>(state.range(0)), 10);
  for (auto _ : state) benchmark::DoNotOptimize(recursivePartition(W).groups.size());
}
BENCHMARK(BM_RecursivePartition)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);

/// observeFloor on one thread: every beam of the simulated office walked
/// through the places' grid (30 m laser, 720 beams a scan).
void BM_ObserveFloor(benchmark::State& state) {
  const auto obs = officeScans(static_cast<int>(state.range(0)));
  SensedSpaceOverlap<pcl::PointXYZ> sso;
  sso.setSensedSpaceModel(SensedSpaceModel::Visibility);
  const WorldPoints world = sso.toWorld(obs);
  const ObservationRegions regions = sso.computeRegions(obs, world);
  std::vector<Eigen::Vector3d> sensors;
  for (const auto& o : obs) sensors.push_back(o.pose.translation() - world.origin);
  const PlacePointSource points_of = [&world](int i, std::vector<Eigen::Vector3f>&) {
    return std::make_pair(world.begin(i), world.begin(i) + world.count(i));
  };
  for (auto _ : state)
    benchmark::DoNotOptimize(observeFloor(regions, world.origin, points_of, sensors, {}, 1).occupancy.size());
}
BENCHMARK(BM_ObserveFloor)->Arg(500)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
