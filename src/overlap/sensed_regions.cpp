#include "obsgroup/overlap/sensed_regions.h"

#include "cell_tiles.h"
#include "region_cells.h"

#include "obsgroup/common/freed_memory.h"
#include "obsgroup/common/parallel_for.h"
#include "obsgroup/common/invalid_observation.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <unordered_map>


namespace obsgroup {

namespace {

using namespace region_cells;

/// Observations per chunk of the loops that add to shared counters: long
/// runs of consecutive observations, so that the threads count cells far
/// apart along the route rather than the same cache lines, but at least
/// eight chunks a thread to share the work.
int countingChunk(int n, int threads) { return std::max(16, std::min(256, n / (8 * std::max(1, threads)))); }

/// The plane cells occupied in the evidence of all observations: at least
/// params.min_observations observations have a point in the cell, and at
/// least as many have a point in it as have a beam through it. A wall seen
/// once, by a sparse sequence, stands; a drifted copy of a wall across a door,
/// which the beams of everyone passing the door cross, does not. The evidence
/// is tallied per cell as it is found, never held as lists.
std::vector<std::uint64_t> occupiedCells(const WorldPoints& world, const std::vector<Eigen::Vector3d>& origins,
                                         const RegionParameters& params, const CellGrid& grid, bool planar,
                                         int threads) {
  const int n = world.size();
  // An observation's evidence lies in the cells of its points (in the band)
  // and, for the beams clipped to the range, in the box within range of its
  // sensor: those tiles are added first, in observation order. Not the box
  // of all its points: one far return would add every tile between.
  CellTiles tiles(true);
  {
    std::vector<std::vector<std::uint64_t>> tiles_of(n);
    parallelFor(n, threads, 16, [&](std::size_t i) {
      const PointSpan points = pointsOf(world, int(i));
      if (points.empty()) return;
      auto& touched = tiles_of[i];
      const auto [lo, hi] = boxAround<2>(grid.inCells<2>(origins[i]), params.max_range / grid.size);
      for (std::int64_t x = (lo[0] + kBias2) >> 6; x <= (hi[0] + kBias2) >> 6; ++x)
        for (std::int64_t y = (lo[1] + kBias2) >> 6; y <= (hi[1] + kBias2) >> 6; ++y)
          touched.push_back(std::uint64_t(x) << 32 | std::uint64_t(y));
      for (const Eigen::Vector3f* p = points.begin; p != points.end; ++p)
        if (inBand(*p, origins[i], params, planar)) {
          const std::uint64_t tile = tiles.tileOf(keyOf<2>(cellOf<2>(grid.inCells<2>(p->cast<double>()))));
          if (touched.back() != tile) touched.push_back(tile);
        }
      std::sort(touched.begin(), touched.end());
      touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    });
    for (auto& touched : tiles_of) {
      for (std::uint64_t tile : touched) tiles.add(tile);
      std::vector<std::uint64_t>().swap(touched);
    }
  }
  SlotCounters hits(tiles.slots()), misses(tiles.slots());
  struct Scratch {
    EvidenceScratch evidence;
    CellTiles::Lookup lookup;
  };
  parallelForWithScratch(
      n, threads, countingChunk(n, threads), [&tiles] { return Scratch{{}, CellTiles::Lookup(tiles)}; },
      [&](std::size_t i, Scratch& s) {
        occupancyEvidence(
            pointsOf(world, int(i)), origins[i], params, grid, planar, s.evidence,
            [&](std::uint64_t key) { hits.increment(s.lookup.existingSlot(key)); },
            [&](std::uint64_t key) { misses.increment(s.lookup.existingSlot(key)); });
      });
  std::vector<std::uint64_t> occupied;
  for (std::size_t slot = 0; slot < tiles.slots(); ++slot)
    if (hits.get(slot) > 0 && occupiedBy(hits.get(slot), misses.get(slot), params))
      occupied.push_back(tiles.keyOfSlot(slot));
  return occupied;
}

/// True when every point and every sensor lies within a quarter cell of one
/// height: 2D data (scans whose poses carry a few mm of z included).
bool isPlanar(const WorldPoints& world, const std::vector<Eigen::Vector3d>& origins, double cell_size) {
  if (origins.empty()) return true;
  const double z0 = origins[0].z(), tolerance = 0.25 * cell_size;
  for (int i = 0; i < world.size(); ++i)
    if (!observationPlanar(pointsOf(world, i), origins[i], z0, tolerance)) return false;
  return true;
}

/// Refuses, naming the first observation, data whose cell indices would not
/// fit a key: a corrupt pose far from the others, never a wrapped index.
void checkReach(const WorldPoints& world, const std::vector<Eigen::Vector3d>& origins, const RegionParameters& params,
                bool volumetric) {
  for (int i = 0; i < world.size(); ++i)
    if (!withinReach(origins[i], world.boxes[i], params, volumetric)) throw InvalidObservation(i, reachMessage(params));
}

}  // namespace

bool isPlanarData(const WorldPoints& world, const std::vector<Eigen::Vector3d>& sensor_origins, double cell_size) {
  return isPlanar(world, sensor_origins, cell_size);
}

Eigen::Vector3d ObservationRegions::cellCentre(std::uint64_t key) const {
  Eigen::Vector3d cell;
  if (planar) {
    cell << double(std::int64_t(key >> 32) - kBias2), double(std::int64_t(key & 0xffffffffu) - kBias2), phase[2] - 0.5;
  } else {
    const std::uint64_t mask = (std::uint64_t(1) << 21) - 1;
    cell << double(std::int64_t(key >> 42) - kBias3), double(std::int64_t((key >> 21) & mask) - kBias3),
        double(std::int64_t(key & mask) - kBias3);
  }
  return (cell + Eigen::Vector3d::Constant(0.5) - phase) * cell_size;
}

bool ObservationRegions::planeBounds(Eigen::Vector3d& lowest, Eigen::Vector3d& highest) const {
  if (empty()) return false;
  // A cell's x and y coordinates are fields of its key; the centre grows with
  // each. A run varies only the lowest field (y of a plane cell, z of a voxel).
  const int x_shift = planar ? 32 : 42, y_shift = planar ? 0 : 21;
  const std::uint64_t y_mask = planar ? 0xffffffffu : (std::uint64_t(1) << 21) - 1;
  std::uint64_t x_lo = ~std::uint64_t(0), x_hi = 0, y_lo = ~std::uint64_t(0), y_hi = 0;
  for (std::size_t r = 0; r < run_start_.size(); ++r) {
    const std::uint64_t first = run_start_[r], last = first + run_length_[r] - 1;
    x_lo = std::min(x_lo, first >> x_shift), x_hi = std::max(x_hi, first >> x_shift);
    y_lo = std::min(y_lo, (first >> y_shift) & y_mask), y_hi = std::max(y_hi, (last >> y_shift) & y_mask);
  }
  const std::uint64_t first = firstKey();
  const std::uint64_t z = planar ? 0 : first & ((std::uint64_t(1) << 21) - 1);
  lowest = cellCentre(x_lo << x_shift | y_lo << y_shift | z);
  highest = cellCentre(x_hi << x_shift | y_hi << y_shift | z);
  return true;
}

void ObservationRegions::appendRuns(const std::uint64_t* starts, const std::uint16_t* lengths, std::size_t runs) {
  std::size_t cells = 0;
  for (std::size_t r = 0; r < runs; ++r) {
    const bool fits = lengths[r] > 0 && starts[r] <= ~std::uint64_t(0) - (lengths[r] - 1);
    // Canonical runs: a gap before the next, unless the last one was full.
    const std::uint64_t last_before = r == 0 ? 0 : starts[r - 1] + (lengths[r - 1] - 1);
    const bool after =
        r == 0 || (starts[r] > last_before && (starts[r] != last_before + 1 || lengths[r - 1] == 0xffff));
    if (!fits || !after)
      throw std::invalid_argument("ObservationRegions: the cells of observation " + std::to_string(size()) +
                                  " must be ascending and distinct");
    cells += lengths[r];
  }
  run_start_.insert(run_start_.end(), starts, starts + runs);
  run_length_.insert(run_length_.end(), lengths, lengths + runs);
  run_offsets_.push_back(run_start_.size());
  cell_offsets_.push_back(cell_offsets_.back() + cells);
}

namespace {

/// Runs of consecutive keys, as ObservationRegions keeps them: one region.
struct RunList {
  std::vector<std::uint64_t> start;
  std::vector<std::uint16_t> length;
  std::size_t cells = 0;

  /// From keys ascending and distinct; false when they are not.
  bool assign(const std::uint64_t* begin, const std::uint64_t* end) {
    start.clear();
    length.clear();
    cells = std::size_t(end - begin);
    for (const std::uint64_t* key = begin; key != end; ++key) {
      if (key != begin && *key <= key[-1]) return false;
      if (!length.empty() && *key == start.back() + length.back() && length.back() < 0xffff) {
        ++length.back();
      } else {
        start.push_back(*key);
        length.push_back(1);
      }
    }
    start.shrink_to_fit();
    length.shrink_to_fit();
    return true;
  }
  template <typename F>
  void forEachRun(F&& f) const {
    for (std::size_t r = 0; r < start.size(); ++r) f(start[r], std::size_t(length[r]));
  }
  std::size_t bytes() const { return start.capacity() * sizeof(std::uint64_t) + length.capacity() * sizeof(std::uint16_t); }
};

}  // namespace

void ObservationRegions::append(const std::uint64_t* begin, const std::uint64_t* end) {
  RunList runs;
  if (!runs.assign(begin, end))
    throw std::invalid_argument("ObservationRegions: the cells of observation " + std::to_string(size()) +
                                " must be ascending and distinct");
  appendRuns(runs.start.data(), runs.length.data(), runs.start.size());
}

std::size_t ObservationRegions::bytes() const {
  return run_start_.capacity() * sizeof(std::uint64_t) + run_length_.capacity() * sizeof(std::uint16_t) +
         (run_offsets_.capacity() + cell_offsets_.capacity()) * sizeof(std::size_t);
}

std::vector<std::uint64_t> ObservationRegions::cellsOf(int i) const {
  std::vector<std::uint64_t> keys;
  keys.reserve(count(i));
  forEachCell(i, [&keys](std::uint64_t key) { keys.push_back(key); });
  return keys;
}

std::uint64_t ObservationRegions::firstKey() const { return run_start_.empty() ? 0 : run_start_.front(); }

bool ObservationRegions::operator==(const ObservationRegions& other) const {
  return planar == other.planar && cell_size == other.cell_size && phase == other.phase &&
         run_start_ == other.run_start_ && run_length_ == other.run_length_ && run_offsets_ == other.run_offsets_ &&
         occupied == other.occupied;
}

namespace {

/// Each observation's region as its own runs of keys, and whether they are
/// plane cells. Encoded as each region is found, so that the lists of keys
/// (8 bytes a cell) are never all held at once.
struct RegionLists {
  std::vector<RunList> cells;
  std::vector<std::uint64_t> occupied;  // visibility: plane cell keys, ascending
  bool planar = true;
  double cell_size = 1.0;
  Eigen::Vector3d phase = Eigen::Vector3d::Constant(0.5);
};

RegionLists regionLists(SensedSpaceModel model, const WorldPoints& world,
                        const std::vector<Eigen::Vector3d>& sensor_origins, const RegionParameters& params, int threads,
                        const InterruptFlag* interrupt) {
  if (model == SensedSpaceModel::Points)
    throw std::invalid_argument("computeRegions: the points model has no regions (use SensedSpaceOverlap)");
  checkRegionParameters(params);
  const int n = world.size();
  if (static_cast<int>(sensor_origins.size()) != n)
    throw std::invalid_argument("computeRegions: one sensor origin per observation expected");
  for (const auto& o : sensor_origins)
    if (!o.allFinite()) throw std::invalid_argument("computeRegions: a sensor origin is not finite");
  threads = threadCount(threads);

  RegionLists regions;
  regions.planar = isPlanar(world, sensor_origins, params.cell_size);
  const CellGrid cells(params.cell_size);
  regions.cell_size = params.cell_size;
  for (int a = 0; a < 3; ++a) regions.phase[a] = cells.phase[a];
  const bool volumetric = model == SensedSpaceModel::FreeSpace && !regions.planar;
  checkReach(world, sensor_origins, params, volumetric);
  std::vector<std::uint64_t>& occupied = regions.occupied;
  if (model == SensedSpaceModel::Visibility) occupied = occupiedCells(world, sensor_origins, params, cells, regions.planar, threads);
  std::sort(occupied.begin(), occupied.end());
  const OccupancyGrid grid(occupied);
  std::vector<RunList>& per_observation = regions.cells;
  per_observation.resize(n);
  struct Scratch {
    RegionMarker<2> marker2, own_surfaces;
    RegionMarker<3> marker3;
    OccupancyGrid::Reader reader;
    ViewWidths widths;
    std::vector<std::uint64_t> keys;
  };
  parallelForWithScratch(
      n, threads, 8, [&] { return Scratch{{}, {}, {}, OccupancyGrid::Reader(grid), {}, {}}; },
      [&](std::size_t i, Scratch& s) {
        if (interruptRequested(interrupt)) return;
        s.keys.clear();
        if (model == SensedSpaceModel::Visibility)
          visibilityOf(pointsOf(world, static_cast<int>(i)), sensor_origins[i], params, cells, regions.planar, s.reader,
                       s.own_surfaces, s.marker2, s.widths, s.keys);
        else if (volumetric)
          freeSpaceOf<3>(pointsOf(world, static_cast<int>(i)), sensor_origins[i], params, cells, s.marker3, s.keys);
        else
          freeSpaceOf<2>(pointsOf(world, static_cast<int>(i)), sensor_origins[i], params, cells, s.marker2, s.keys);
        // The markers give each key once, ascending.
        if (!per_observation[i].assign(s.keys.data(), s.keys.data() + s.keys.size()))
          throw std::logic_error("computeRegions: a region's cells came out of order");
      });
  throwIfInterrupted(interrupt);
  regions.planar = !volumetric;
  return regions;
}

/// A run's piece within one segment of 64 consecutive keys (a stretch of a
/// column of plane cells, of a stack of voxels): which observation holds it
/// and its first and last key's offsets in the segment.
struct SegmentPiece {
  std::uint32_t observation;
  std::uint8_t first, last;
};

constexpr int kSegmentBits = 6;

/// f(segment, first offset, last offset) for each piece of a run.
template <typename F>
void forEachPiece(std::uint64_t start, std::size_t length, F&& f) {
  const std::uint64_t last_key = start + (length - 1);
  for (std::uint64_t segment = start >> kSegmentBits; segment <= last_key >> kSegmentBits; ++segment) {
    const std::uint64_t base = segment << kSegmentBits;
    const std::uint64_t lo = std::max(start, base), hi = std::min(last_key, base + ((1u << kSegmentBits) - 1));
    f(segment, std::uint8_t(lo - base), std::uint8_t(hi - base));
  }
}

/// Which observations hold each segment, piece by piece: segment s (the
/// s-th of `segments`, ascending) is held by pieces[start[s], start[s+1]).
/// Indexing runs instead of cells keeps a few bytes per run where a cell
/// index would keep four per cell (docs/performance.md).
struct SharedSegments {
  std::vector<std::uint64_t> segments;
  std::vector<std::size_t> start;
  std::vector<SegmentPiece> pieces;

  std::size_t indexOf(std::uint64_t segment) const {
    return std::size_t(std::lower_bound(segments.begin(), segments.end(), segment) - segments.begin());
  }
};

/// Builds the index from for_each_run(i, f) (f called with each run of
/// observation i's region, ascending) without sorting the pieces: they are
/// counted per segment, and each observation's written into its segments.
template <typename ForEachRun>
SharedSegments indexSegments(int n, ForEachRun&& for_each_run, int threads, const InterruptFlag* interrupt) {
  SharedSegments index;
  {
    std::vector<std::vector<std::uint64_t>> segments_of(n);
    parallelFor(n, threads, 64, [&](std::size_t i) {
      auto& mine = segments_of[i];
      for_each_run(int(i), [&](std::uint64_t start, std::size_t length) {
        forEachPiece(start, length, [&](std::uint64_t segment, std::uint8_t, std::uint8_t) {
          if (mine.empty() || mine.back() != segment) mine.push_back(segment);
        });
      });
    });
    std::size_t total = 0;
    for (const auto& mine : segments_of) total += mine.size();
    index.segments.reserve(total);
    for (auto& mine : segments_of) {
      index.segments.insert(index.segments.end(), mine.begin(), mine.end());
      std::vector<std::uint64_t>().swap(mine);
    }
  }
  std::sort(index.segments.begin(), index.segments.end());
  index.segments.erase(std::unique(index.segments.begin(), index.segments.end()), index.segments.end());
  index.segments.shrink_to_fit();
  throwIfInterrupted(interrupt);
  SlotCounters pieces_of(index.segments.size());
  parallelFor(n, threads, countingChunk(n, threads), [&](std::size_t i) {
    for_each_run(int(i), [&](std::uint64_t start, std::size_t length) {
      forEachPiece(start, length, [&](std::uint64_t segment, std::uint8_t, std::uint8_t) {
        pieces_of.increment(index.indexOf(segment));
      });
    });
  });
  throwIfInterrupted(interrupt);
  index.start.resize(index.segments.size() + 1);
  index.start[0] = 0;
  for (std::size_t s = 0; s < index.segments.size(); ++s) {
    index.start[s + 1] = index.start[s] + pieces_of.get(s);
    pieces_of.set(s, 0);
  }
  index.pieces.resize(index.start.back());
  parallelFor(n, threads, countingChunk(n, threads), [&](std::size_t i) {
    for_each_run(int(i), [&](std::uint64_t start, std::size_t length) {
      forEachPiece(start, length, [&](std::uint64_t segment, std::uint8_t first, std::uint8_t last) {
        const std::size_t s = index.indexOf(segment);
        index.pieces[index.start[s] + pieces_of.increment(s)] = {std::uint32_t(i), first, last};
      });
    });
  });
  throwIfInterrupted(interrupt);
  return index;
}

/// For each observation, the other observations holding its cells and how
/// many: the overlaps of its runs' pieces with theirs, integer sums, the same
/// whatever the order of a segment's pieces. point_tests counts, as for
/// points, each cell of i once per observation holding it (i included).
/// release(i) is called once observation i's runs are no longer needed, so
/// that lists can be freed as the rows are counted.
template <typename ForEachRun, typename Release>
MatchCounts countShared(int n, ForEachRun&& for_each_run, Release&& release, int threads,
                        const InterruptFlag* interrupt) {
  if (std::uint64_t(n) > std::numeric_limits<std::uint32_t>::max())
    throw std::length_error("region overlap: more than 2^32 - 1 observations");
  const SharedSegments index = indexSegments(n, for_each_run, threads, interrupt);
  MatchCounts out;
  out.rows.resize(n);
  std::uint64_t pairs = 0, tests = 0;
#pragma omp parallel num_threads(threads) reduction(+ : pairs, tests)
  {
    std::vector<std::uint32_t> shared(n, 0);
    std::vector<int> touched;
#pragma omp for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i) {
      if (interruptRequested(interrupt)) continue;
      for_each_run(i, [&](std::uint64_t start, std::size_t length) {
        forEachPiece(start, length, [&](std::uint64_t segment, std::uint8_t first, std::uint8_t last) {
          // The segment exists: indexSegments added it for this very piece.
          const std::size_t s = index.indexOf(segment);
          for (std::size_t k = index.start[s]; k < index.start[s + 1]; ++k) {
            const SegmentPiece& other = index.pieces[k];
            const int lo = std::max(first, other.first), hi = std::min(last, other.last);
            if (hi < lo) continue;
            const std::uint32_t cells = std::uint32_t(hi - lo + 1);
            tests += cells;
            if (shared[other.observation] == 0) touched.push_back(int(other.observation));
            shared[other.observation] += cells;
          }
        });
      });
      release(i);
      std::sort(touched.begin(), touched.end());
      auto& row = out.rows[i];
      for (int j : touched) {
        if (j != i) row.push_back({j, shared[j]});
        shared[j] = 0;
      }
      pairs += row.size();
      touched.clear();
    }
  }
  throwIfInterrupted(interrupt);
  out.pairs_evaluated = pairs;
  out.point_tests = tests;
  return out;
}

/// countShared over per-observation lists, freeing each once counted.
MatchCounts countShared(RegionLists& lists, int threads, const InterruptFlag* interrupt) {
  std::size_t bytes = 0;
  for (const auto& list : lists.cells) bytes += list.bytes();
  MatchCounts counts = countShared(
      int(lists.cells.size()), [&lists](int i, auto&& f) { lists.cells[std::size_t(i)].forEachRun(f); },
      [&lists](int i) { lists.cells[std::size_t(i)] = RunList(); }, threads, interrupt);
  returnFreedMemory(bytes);
  return counts;
}

}  // namespace

void checkRegionParameters(const RegionParameters& p) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(p.cell_size)) throw std::invalid_argument("region cell size must be finite and > 0");
  if (!positive(p.max_range)) throw std::invalid_argument("region range must be finite and > 0");
  // 2000 cells keeps a region's bitmap (4000^2 cells in 2D) within the dense marker.
  if (p.max_range / p.cell_size > 2000)
    throw std::invalid_argument("region range is more than 2000 cells: raise the cell size or lower the range");
  if (!(std::isfinite(p.clearance) && p.clearance >= 0)) throw std::invalid_argument("clearance must be finite and >= 0");
  if (p.min_observations < 1) throw std::invalid_argument("min_observations must be >= 1");
  if (!(std::isfinite(p.door_width) && p.door_width >= 0)) throw std::invalid_argument("door width must be finite and >= 0");
  if (!(std::isfinite(p.door_depth) && p.door_depth >= 0)) throw std::invalid_argument("door depth must be finite and >= 0");
  // An opening's width is counted in cells in a byte.
  if (p.door_width / p.cell_size >= 250)
    throw std::invalid_argument("door width is 250 cells or more: raise the cell size or lower the door width");
  if (!(std::isfinite(p.band_low) && std::isfinite(p.band_high) && p.band_low < p.band_high))
    throw std::invalid_argument("height band must be finite with low < high");
}

ObservationRegions computeRegions(SensedSpaceModel model, const WorldPoints& world,
                                  const std::vector<Eigen::Vector3d>& sensor_origins, const RegionParameters& params,
                                  int threads, const InterruptFlag* interrupt) {
  RegionLists lists = regionLists(model, world, sensor_origins, params, threads, interrupt);
  ObservationRegions regions;
  regions.planar = lists.planar;
  regions.cell_size = lists.cell_size;
  regions.phase = lists.phase;
  regions.occupied = std::move(lists.occupied);
  // The lists are handed back as they are copied, so that the regions are
  // not resident twice at the end.
  std::size_t freed = 0;
  for (auto& list : lists.cells) {
    regions.appendRuns(list.start.data(), list.length.data(), list.start.size());
    freed += list.bytes();
    list = RunList();
    if (freed >= kTrimBytes) {
      returnFreedMemory(freed);
      freed = 0;
    }
  }
  returnFreedMemory(freed);
  return regions;
}

OverlapResult computeRegionOverlap(SensedSpaceModel model, const WorldPoints& world,
                                   const std::vector<Eigen::Vector3d>& sensor_origins, const RegionParameters& params,
                                   int threads, const InterruptFlag* interrupt) {
  RegionLists lists = regionLists(model, world, sensor_origins, params, threadCount(threads), interrupt);
  std::vector<std::size_t> sizes(lists.cells.size());
  for (std::size_t i = 0; i < sizes.size(); ++i) sizes[i] = lists.cells[i].cells;
  OverlapResult result = assembleOverlap(countShared(lists, threadCount(threads), interrupt), sizes);
  result.occupied_cells = std::move(lists.occupied);
  returnFreedMemory(kTrimBytes);  // the rows of counts, a small list per observation
  return result;
}


MatchCounts countSharedCells(const ObservationRegions& regions, int threads, const InterruptFlag* interrupt) {
  // ObservationRegions::append refused keys out of order: each region's are ascending and distinct.
  return countShared(
      regions.size(), [&regions](int i, auto&& f) { regions.forEachRun(i, f); }, [](int) {}, threadCount(threads),
      interrupt);
}

OverlapResult regionOverlap(const ObservationRegions& regions, int threads, const InterruptFlag* interrupt) {
  std::vector<std::size_t> sizes(regions.size());
  for (int i = 0; i < regions.size(); ++i) sizes[i] = regions.count(i);
  OverlapResult result = assembleOverlap(countSharedCells(regions, threads, interrupt), sizes);
  result.occupied_cells = regions.occupied;
  returnFreedMemory(kTrimBytes);  // the rows of counts, a small list per observation
  return result;
}

std::function<bool(const Eigen::Vector2d&)> planeCellReader(const std::vector<std::uint64_t>& occupied,
                                                            double cell_size) {
  struct Bitmap {
    explicit Bitmap(const std::vector<std::uint64_t>& keys) : grid(keys), reader(grid) {}
    OccupancyGrid grid;
    OccupancyGrid::Reader reader;
  };
  auto bitmap = std::make_shared<Bitmap>(occupied);
  const CellGrid grid(cell_size);
  return [bitmap, grid](const Eigen::Vector2d& p) {
    return bitmap->reader.occupied(cellOf<2>(grid.inCells<2>(Eigen::Vector3d(p.x(), p.y(), 0.0))));
  };
}

}  // namespace obsgroup
