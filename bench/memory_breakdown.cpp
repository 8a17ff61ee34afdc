// Where the bytes of a grouping go: reads an input as `obsgroup partition`
// does (the same options), groups it keeping its world points and regions
// (the command keeps the regions and makes the points again), and prints the size of each structure per
// observation, then the process's peak resident memory.
//   memory_breakdown INPUT [partition options...]
// docs/performance.md ("Memory") is made from its output.
#include "command_line.h"
#include "partition_command.h"

#include <obsgroup/observation_grouping.h>

#include <sys/resource.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace {

struct Row {
  std::string structure;
  double bytes = 0;
  std::string when;
};

template <typename T>
double capacityBytes(const std::vector<T>& v) {
  return double(v.capacity()) * double(sizeof(T));
}

double sparseBytes(const obsgroup::WeightMatrix& W) {
  return double(W.nonZeros()) * (sizeof(double) + sizeof(int)) + double(W.outerSize() + 1) * sizeof(int);
}

template <typename PointT>
std::vector<Row> breakdown(const obsgroup::cli::PartitionArgs& args,
                           const std::vector<obsgroup::Observation<PointT>>& observations) {
  obsgroup::ObservationGrouping<PointT> grouping;
  grouping.setParameters(args.method);
  grouping.setKeepWorldPoints(true);
  grouping.setKeepRegions(true);
  for (const auto& o : observations) grouping.addObservation(o.cloud, o.pose);
  const obsgroup::Partition partition = grouping.compute();

  std::vector<Row> rows;
  double cloud_bytes = 0;
  for (const auto& o : observations) cloud_bytes += double(o.cloud->points.capacity()) * sizeof(PointT);
  rows.push_back({"clouds (" + std::to_string(sizeof(PointT)) + " B a point)", cloud_bytes, "whole run"});
  const obsgroup::WorldPoints& world = grouping.getWorldPoints();
  rows.push_back({"world points (12 B a point)", capacityBytes(world.points) + capacityBytes(world.offsets) +
                                                     capacityBytes(world.boxes),
                  "overlap; made again for the pictures (the places make each observation's in turn)"});
  const obsgroup::ObservationRegions& regions = grouping.getRegions();
  rows.push_back({"regions (10 B a run of cells)", double(regions.bytes()), "overlap, places"});
  // countSharedCells' index: a piece per run and 64-key segment it crosses (8 bytes), and each
  // segment's key and start (16 bytes).
  std::size_t pieces = 0;
  std::vector<std::uint64_t> segments;
  for (int i = 0; i < regions.size(); ++i)
    regions.forEachRun(i, [&](std::uint64_t start, std::size_t length) {
      for (std::uint64_t s = start >> 6; s <= (start + length - 1) >> 6; ++s, ++pieces) segments.push_back(s);
    });
  std::sort(segments.begin(), segments.end());
  const double distinct = double(std::unique(segments.begin(), segments.end()) - segments.begin());
  rows.push_back({"shared-segment index (8 B a run piece, 16 B a segment)", 8.0 * double(pieces) + 16.0 * distinct,
                  "overlap"});
  const obsgroup::OverlapResult& overlap = grouping.getOverlap();
  rows.push_back({"Pi and the pairs of Psi", double(overlap.match_ratio.nonZeros()) * (sizeof(double) + sizeof(int)) +
                                                 capacityBytes(overlap.pairs),
                  "overlap, until W stands"});
  rows.push_back({"W", sparseBytes(grouping.getWeightMatrix()), "from the graph on"});
  double partition_bytes = capacityBytes(partition.group_of);
  for (const auto& g : partition.groups) partition_bytes += capacityBytes(g);
  rows.push_back({"groups", partition_bytes, "from the partition on"});
  std::printf("observations %zu, points %zu, region cells %zu (%.0f a region) in %zu runs (%.0f a region), edges %zu\n",
              observations.size(), world.points.size(), regions.totalCells(),
              double(regions.totalCells()) / double(observations.size()), regions.runCount(),
              double(regions.runCount()) / double(observations.size()), overlap.pairs.size());
  return rows;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<const char*> words{"obsgroup", "partition"};
  for (int k = 1; k < argc; ++k) words.push_back(argv[k]);
  // Nothing is written: the output folder is only there to satisfy the parser.
  for (const char* w : {"--no-pictures", "--output", "memory-breakdown-unused"}) words.push_back(w);
  const auto parsed = obsgroup::cli::parseCommandLine(int(words.size()), words.data());
  if (!parsed.args) {
    std::fprintf(stderr, "usage: memory_breakdown INPUT [partition options]\n%s\n", parsed.error.c_str());
    return 2;
  }
  std::vector<Row> rows;
  try {
    obsgroup::cli::AnyInput input = obsgroup::cli::readInput(*parsed.args);
    std::visit([&](auto& in) { rows = breakdown(*parsed.args, in.observations); }, input);
    const std::size_t n = std::visit([](auto& in) { return in.observations.size(); }, input);
    std::printf("| structure | MiB | bytes per observation | alive |\n|---|---|---|---|\n");
    for (const Row& r : rows)
      std::printf("| %s | %.0f | %.0f | %s |\n", r.structure.c_str(), r.bytes / (1 << 20), r.bytes / double(n),
                  r.when.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "memory_breakdown: %s\n", e.what());
    return 3;
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::printf("peak resident memory: %.0f MiB\n", double(usage.ru_maxrss) / 1024.0);
  return 0;
}
