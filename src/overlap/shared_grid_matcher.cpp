#include "obsgroup/overlap/shared_grid_matcher.h"

#include "obsgroup/common/parallel_for.h"
#include "obsgroup/common/invalid_observation.h"

#include <omp.h>

#include <algorithm>
#include <thread>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace obsgroup {
namespace {

struct CellKey {
  std::int32_t x, y, z;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
  bool operator<(const CellKey& o) const { return x != o.x ? x < o.x : (y != o.y ? y < o.y : z < o.z); }
  bool operator<=(const CellKey& o) const { return !(o < *this); }
};

/// A run of consecutive grid points of one observation inside one cell.
struct Run {
  std::int32_t observation;
  std::uint32_t begin, end;  // into Grid::points
};

/// One observation's points in one cell, as pass 2 reads them: the cell, and
/// where the points sit among the cell's points.
struct OwnRun {
  std::uint32_t cell;
  std::uint32_t first;  ///< index of the run's first point among the cell's points
  std::uint32_t count;
};

/// [begin, end) of some array.
struct Span {
  std::uint32_t begin = 0, end = 0;
};

/// One world point and its cell, the unit the grid sorts.
struct Entry {
  CellKey key;
  std::uint32_t index;  // into WorldPoints::points, which is in observation order
};

/// Stable LSD radix sort by cell key (x, then y, then z), 11 bits per pass
/// and only as many passes as the extent of the map needs; entries that share
/// a cell keep their input order. Each pass splits the entries into one slice
/// per thread, and slice t's entries of a digit land after those of slices
/// before t: the order is the same for any thread count.
void sortByCell(std::vector<Entry>& entries, int threads) {
  constexpr std::uint32_t kDigits = 2048;
  const std::size_t n = entries.size();
  if (n == 0) return;
  std::vector<Entry> buffer(n);
  const auto coordinate = [](const Entry& e, int axis) { return axis == 0 ? e.key.x : axis == 1 ? e.key.y : e.key.z; };
  const int slices = static_cast<int>(std::max<std::size_t>(1, std::min<std::size_t>(threads, n / 65536 + 1)));
  std::vector<std::size_t> bounds(slices + 1);
  for (int t = 0; t <= slices; ++t) bounds[t] = n * std::size_t(t) / std::size_t(slices);
  std::vector<std::size_t> start(std::size_t(slices) * kDigits);
  for (int axis = 2; axis >= 0; --axis) {  // least significant key first
    std::int32_t lo = std::numeric_limits<std::int32_t>::max(), hi = std::numeric_limits<std::int32_t>::min();
#pragma omp parallel for num_threads(slices) reduction(min : lo) reduction(max : hi)
    for (std::size_t k = 0; k < n; ++k) {
      lo = std::min(lo, coordinate(entries[k], axis));
      hi = std::max(hi, coordinate(entries[k], axis));
    }
    const std::uint32_t extent = std::uint32_t(std::int64_t(hi) - lo);
    for (int shift = 0; shift < 32 && (extent >> shift) != 0; shift += 11) {
      const auto digit = [&](const Entry& e) {
        return (std::uint32_t(std::int64_t(coordinate(e, axis)) - lo) >> shift) & (kDigits - 1);
      };
      std::fill(start.begin(), start.end(), 0);
#pragma omp parallel for num_threads(slices) schedule(static, 1)
      for (int t = 0; t < slices; ++t)
        for (std::size_t k = bounds[t]; k < bounds[t + 1]; ++k) ++start[std::size_t(t) * kDigits + digit(entries[k])];
      std::size_t at = 0;
      for (std::uint32_t d = 0; d < kDigits; ++d)
        for (int t = 0; t < slices; ++t) {
          const std::size_t count = start[std::size_t(t) * kDigits + d];
          start[std::size_t(t) * kDigits + d] = at;
          at += count;
        }
#pragma omp parallel for num_threads(slices) schedule(static, 1)
      for (int t = 0; t < slices; ++t)
        for (std::size_t k = bounds[t]; k < bounds[t + 1]; ++k)
          buffer[start[std::size_t(t) * kDigits + digit(entries[k])]++] = entries[k];
      entries.swap(buffer);
    }
  }
}

/// The cell of a point: cells a hair larger than delta, so that two points
/// within delta differ by at most one in every cell index, whatever the
/// rounding of x / cell.
class CellIndexer {
 public:
  explicit CellIndexer(double delta) : inv_cell_(1.0 / (delta * (1.0 + 1e-6))) {}
  CellKey operator()(const Eigen::Vector3f& p) const {
    return {index(p.x()), index(p.y()), index(p.z())};
  }

 private:
  std::int32_t index(float v) const {
    const double c = std::floor(double(v) * inv_cell_);
    if (!(std::abs(c) < double(1 << 30)))
      throw std::invalid_argument("shared grid: a point lies too far from the map centre for the grid "
                                  "(coordinate " + std::to_string(v) + " m); use a larger delta or the "
                                  "PCL search back-end");
    return static_cast<std::int32_t>(c);
  }
  double inv_cell_;
};

/// Every world point in (cell, observation) order, with its cell and its
/// observation. A point too far out for the grid is an InvalidObservation
/// naming the lowest such observation, whatever the thread count.
struct SortedPoints {
  std::vector<Entry> entries;  ///< cell and world index of each sorted point
  std::vector<Eigen::Vector3f> points;
  std::vector<std::int32_t> observation;
};

SortedPoints sortPointsByCell(const WorldPoints& world, const CellIndexer& cell_of, int threads) {
  const std::size_t total = world.points.size();
  if (total >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("shared grid: more than 4 billion points");
  SortedPoints sorted;
  sorted.entries.resize(total);
  const int n = world.size();
  parallelFor(n, threads, 64, [&](std::size_t i) {
    try {
      for (std::size_t k = world.offsets[i]; k < world.offsets[i + 1]; ++k)
        sorted.entries[k] = Entry{cell_of(world.points[k]), static_cast<std::uint32_t>(k)};
    } catch (const std::invalid_argument& e) {
      throw InvalidObservation(static_cast<int>(i), e.what());
    }
  });
  sortByCell(sorted.entries, threads);
  // The gathers are random reads, done in parallel.
  std::vector<std::int32_t> observation_of(total);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 64)
  for (int i = 0; i < n; ++i)
    std::fill(observation_of.begin() + world.offsets[i], observation_of.begin() + world.offsets[i + 1], i);
  sorted.points.resize(total);
  sorted.observation.resize(total);
#pragma omp parallel for num_threads(threads) schedule(static, 65536)
  for (std::size_t k = 0; k < total; ++k) {
    sorted.points[k] = world.points[sorted.entries[k].index];
    sorted.observation[k] = observation_of[sorted.entries[k].index];
  }
  return sorted;
}

/// The sorted points cut into cells and runs (one observation's points in
/// one cell), and the key of each cell.
struct CellRuns {
  std::vector<CellKey> keys;
  std::vector<Span> cell_runs;  ///< each cell's runs
  std::vector<Run> runs;
};

/// Each thread takes a slice of the points and first counts the cells and
/// runs that start in it, so the layout is the same for any thread count.
CellRuns cutRuns(const std::vector<Entry>& entries, const std::vector<std::int32_t>& observation, int threads) {
  const std::size_t total = entries.size();
  const auto new_cell = [&](std::size_t k) { return k == 0 || !(entries[k].key == entries[k - 1].key); };
  const auto new_run = [&](std::size_t k) { return new_cell(k) || observation[k] != observation[k - 1]; };
  const int slices = threads;
  std::vector<std::size_t> cells_before(slices + 1, 0), runs_before(slices + 1, 0);
  const auto bound = [&](int t) { return total * std::size_t(t) / std::size_t(slices); };
#pragma omp parallel for num_threads(slices) schedule(static, 1)
  for (int t = 0; t < slices; ++t) {
    std::size_t cells = 0, runs = 0;  // local: the slices' counters share a cache line
    for (std::size_t k = bound(t); k < bound(t + 1); ++k) {
      cells += new_cell(k);
      runs += new_run(k);
    }
    cells_before[t + 1] = cells;
    runs_before[t + 1] = runs;
  }
  for (int t = 0; t < slices; ++t) {
    cells_before[t + 1] += cells_before[t];
    runs_before[t + 1] += runs_before[t];
  }
  const std::size_t cells = cells_before[slices], runs = runs_before[slices];
  CellRuns out;
  out.keys.resize(cells);
  out.cell_runs.resize(cells);
  out.runs.resize(runs);
#pragma omp parallel num_threads(slices)
  {
#pragma omp for schedule(static, 1)
    for (int t = 0; t < slices; ++t) {
      std::size_t c = cells_before[t], r = runs_before[t];
      for (std::size_t k = bound(t); k < bound(t + 1); ++k) {
        if (new_cell(k)) {
          out.keys[c] = entries[k].key;
          out.cell_runs[c++].begin = static_cast<std::uint32_t>(r);
        }
        if (new_run(k)) out.runs[r++] = Run{observation[k], static_cast<std::uint32_t>(k), 0};
      }
    }
    // Each run ends where the next begins, each cell's runs where the next cell's do.
#pragma omp for schedule(static)
    for (std::size_t r = 0; r < runs; ++r)
      out.runs[r].end = r + 1 < runs ? out.runs[r + 1].begin : static_cast<std::uint32_t>(total);
#pragma omp for schedule(static)
    for (std::size_t c = 0; c < cells; ++c)
      out.cell_runs[c].end = c + 1 < cells ? out.cell_runs[c + 1].begin : static_cast<std::uint32_t>(runs);
  }
  return out;
}

/// Every world point sorted by (cell, observation), cut into runs, plus for
/// each cell the runs of its neighbourhood. Cells sorted by key make the
/// neighbourhood a few contiguous slices of the run array: in a column of
/// cells that differ only in the last coordinate (z, or y for flat data), the
/// cells -1, 0, +1 follow each other in key order, so the 3x3 (flat) or 3x3x3
/// neighbourhood is 3 or 9 slices, found without a hash table.
class Grid {
 public:
  Grid(const WorldPoints& world, double delta, int threads) : world_(world), threads_(threads) {
    SortedPoints sorted = sortPointsByCell(world, CellIndexer(delta), threads);
    const auto& entries = sorted.entries;
    flat_ = std::all_of(entries.begin(), entries.end(), [&](const Entry& e) { return e.key.z == entries[0].key.z; });
    columns_ = flat_ ? 3 : 9;
    CellRuns cut = cutRuns(sorted.entries, sorted.observation, threads);
    points_ = std::move(sorted.points);
    sorted = {};  // the entries and observations are in the runs now
    runs_ = std::move(cut.runs);
    cell_runs_ = std::move(cut.cell_runs);
    planar_ = std::all_of(points_.begin(), points_.end(), [&](const Eigen::Vector3f& p) { return p.z() == points_[0].z(); });
    indexRunsByObservation();
    buildNeighbourhoods(cut.keys);
    countObservationsNear();
  }

  std::size_t cells() const { return cell_runs_.size(); }
  int columns() const { return columns_; }
  /// Every point has the same z (2D scans): distances need no z.
  bool planar() const { return planar_; }
  /// The run slices of a cell's neighbourhood (columns() of them).
  const Span* neighbourhood(std::size_t cell) const { return &neighbourhood_[cell * columns_]; }
  /// Distinct observations with points in the neighbourhood of a cell.
  std::uint32_t observationsNear(std::size_t cell) const { return observations_near_[cell]; }
  Span runsOfCell(std::size_t cell) const { return cell_runs_[cell]; }
  std::uint32_t pointsOfCell(std::size_t cell) const {
    return runs_[cell_runs_[cell].end - 1].end - runs_[cell_runs_[cell].begin].begin;
  }
  const std::vector<Run>& runs() const { return runs_; }
  /// Observation i's runs, in cell order: [ownRuns(i), ownRuns(i + 1)).
  const OwnRun* ownRuns(int i) const { return observation_runs_.data() + observation_run_offsets_[i]; }
  const std::vector<Eigen::Vector3f>& points() const { return points_; }
  int observations() const { return world_.size(); }

 private:
  /// Each observation's runs in cell order: a counting sort of the runs.
  /// Each thread counts the runs of each observation in its slice of the
  /// cells; slice t's runs of an observation go after those of slices before
  /// t, so the result is that of one sequential pass.
  void indexRunsByObservation() {
    const int n = world_.size();
    const std::size_t cells = cell_runs_.size();
    const int slices = threads_;
    const auto bound = [&](int t) { return cells * std::size_t(t) / std::size_t(slices); };
    std::vector<std::vector<std::uint32_t>> next(slices, std::vector<std::uint32_t>(n, 0));
#pragma omp parallel for num_threads(slices) schedule(static, 1)
    for (int t = 0; t < slices; ++t)
      for (std::size_t c = bound(t); c < bound(t + 1); ++c)
        for (std::uint32_t r = cell_runs_[c].begin; r < cell_runs_[c].end; ++r) ++next[t][runs_[r].observation];
    observation_run_offsets_.assign(n + 1, 0);
    std::uint32_t at = 0;
    for (int i = 0; i < n; ++i) {
      observation_run_offsets_[i] = at;
      for (int t = 0; t < slices; ++t) {
        const std::uint32_t count = next[t][i];
        next[t][i] = at;
        at += count;
      }
    }
    observation_run_offsets_[n] = at;
    observation_runs_.resize(runs_.size());
#pragma omp parallel for num_threads(slices) schedule(static, 1)
    for (int t = 0; t < slices; ++t)
      for (std::size_t c = bound(t); c < bound(t + 1); ++c) {
        const std::uint32_t first = runs_[cell_runs_[c].begin].begin;
        for (std::uint32_t r = cell_runs_[c].begin; r < cell_runs_[c].end; ++r)
          observation_runs_[next[t][runs_[r].observation]++] = {static_cast<std::uint32_t>(c), runs_[r].begin - first,
                                                                 runs_[r].end - runs_[r].begin};
      }
  }

  /// One merge-like sweep over the sorted cells per column offset: as the
  /// cell advances in key order, the column's first and last cells only move
  /// forward.
  void buildNeighbourhoods(const std::vector<CellKey>& keys) {
    const std::size_t cells = keys.size();
    neighbourhood_.assign(cells * columns_, Span{});
#pragma omp parallel for num_threads(threads_) schedule(static, 1)
    for (int column = 0; column < columns_; ++column) {
      const int dx = column % 3 - 1;
      const int dy = column / 3 - 1;
      std::size_t lo = 0, hi = 0;
      for (std::size_t c = 0; c < cells; ++c) {
        const CellKey& k = keys[c];
        const CellKey first = flat_ ? CellKey{k.x + dx, k.y - 1, k.z} : CellKey{k.x + dx, k.y + dy, k.z - 1};
        const CellKey last = flat_ ? CellKey{k.x + dx, k.y + 1, k.z} : CellKey{k.x + dx, k.y + dy, k.z + 1};
        while (lo < cells && keys[lo] < first) ++lo;
        hi = std::max(hi, lo);
        while (hi < cells && keys[hi] <= last) ++hi;
        if (lo < hi) neighbourhood_[c * columns_ + column] = {cell_runs_[lo].begin, cell_runs_[hi - 1].end};
      }
    }
  }

  void countObservationsNear() {
    observations_near_.assign(cells(), 0);
#pragma omp parallel num_threads(threads_)
    {
      std::vector<std::uint32_t> stamp(world_.size(), 0);
#pragma omp for schedule(dynamic, 1024)
      for (std::size_t c = 0; c < cells(); ++c) {
        std::uint32_t distinct = 0;
        const std::uint32_t mark = static_cast<std::uint32_t>(c + 1);
        const Span* slices = neighbourhood(c);
        for (int h = 0; h < columns_; ++h)
          for (std::uint32_t r = slices[h].begin; r < slices[h].end; ++r) {
            std::uint32_t& s = stamp[runs_[r].observation];
            distinct += s != mark;
            s = mark;
          }
        observations_near_[c] = distinct;
      }
    }
  }

  const WorldPoints& world_;
  int threads_;
  bool flat_ = true, planar_ = true;
  int columns_ = 3;
  std::vector<Eigen::Vector3f> points_;
  std::vector<Run> runs_;
  std::vector<Span> cell_runs_;
  std::vector<std::uint32_t> observation_run_offsets_;
  std::vector<OwnRun> observation_runs_;
  std::vector<Span> neighbourhood_;
  std::vector<std::uint32_t> observations_near_;
};

/// The outcome of matching every point against its cell's neighbourhood: for
/// each cell c the distinct observations near it, J_c, and for each point of
/// c the subset of J_c it matched (eq. 16), as a bit set of ceil(|J_c| / 64)
/// words. Its own observation is never in its set.
struct CellMatches {
  std::vector<std::uint64_t> near_offsets;  ///< per cell, into near
  std::vector<std::int32_t> near;           ///< J_c, cell after cell
  std::vector<std::uint64_t> mask_offsets;  ///< per cell, into masks
  std::vector<std::uint64_t> masks;         ///< per point of the cell, in grid order
  std::uint64_t point_tests = 0;

  std::size_t words(std::size_t cell) const { return (near_offsets[cell + 1] - near_offsets[cell] + 63) / 64; }
};

/// Squared float distance from p to point q of the neighbourhood's arrays;
/// planar data (every z the same) skips z.
template <bool Planar>
inline float squaredDistance(const Eigen::Vector3f& p, const float* x, const float* y, const float* z, std::uint32_t q) {
  const float dx = p.x() - x[q], dy = p.y() - y[q];
  const float d = dx * dx + dy * dy;
  if (Planar) return d;
  const float dz = p.z() - z[q];
  return d + dz * dz;
}

/// The float test of MatchDistance, written so that the compiler vectorises
/// it; `border` tells whether some distance fell in the band where only the
/// double test may decide.
template <bool Planar>
std::uint8_t floatMatches(const Eigen::Vector3f& p, float inside, float outside, const float* __restrict x,
                          const float* __restrict y, const float* __restrict z, std::uint8_t* __restrict hit,
                          std::uint32_t begin, std::uint32_t end) {
  std::uint8_t border = 0;
  for (std::uint32_t q = begin; q < end; ++q) {
    const float d = squaredDistance<Planar>(p, x, y, z, q);
    hit[q] = d < inside;
    border |= (d >= inside) & (d <= outside);
  }
  return border;
}

/// The float test of MatchDistance when the neighbourhood has at most 64
/// groups: the OR of the group bits of the points within delta of p, in one
/// loop that the compiler vectorises; `border` as for floatMatches. The bits
/// are kept as two 32-bit halves, the width of the float comparisons, so no
/// lane is widened.
template <bool Planar>
std::uint64_t floatMatchBits(const Eigen::Vector3f& p, float inside, float outside, const float* __restrict x,
                             const float* __restrict y, const float* __restrict z,
                             const std::uint32_t* __restrict low_bit, const std::uint32_t* __restrict high_bit,
                             std::uint32_t begin, std::uint32_t end, std::uint8_t& border) {
  std::uint32_t low = 0, high = 0, band = 0;
  for (std::uint32_t q = begin; q < end; ++q) {
    const float d = squaredDistance<Planar>(p, x, y, z, q);
    const std::uint32_t hit = std::uint32_t(0) - std::uint32_t(d < inside);
    low |= low_bit[q] & hit;
    high |= high_bit[q] & hit;
    band |= std::uint32_t(d >= inside) & std::uint32_t(d <= outside);
  }
  border |= band != 0;
  return std::uint64_t(high) << 32 | low;
}

/// keep[n]: a word whose first n bytes in memory are 0xff and the rest 0,
/// whatever the endianness.
struct ByteMasks {
  std::uint64_t keep[9];
  ByteMasks() {
    for (int n = 0; n <= 8; ++n) {
      std::uint8_t bytes[8] = {};
      std::memset(bytes, 0xff, n);
      std::memcpy(&keep[n], bytes, 8);
    }
  }
};
const ByteMasks kByteMasks;

/// Whether any of hit[begin, end) is set; hit is readable 8 bytes past end.
inline bool anyHit(const std::uint8_t* hit, std::uint32_t begin, std::uint32_t end) {
  std::uint64_t any = 0, word;
  for (; begin + 8 <= end; begin += 8) {
    std::memcpy(&word, hit + begin, 8);
    any |= word;
  }
  std::memcpy(&word, hit + begin, 8);
  return (any | (word & kByteMasks.keep[end - begin])) != 0;
}

/// Per-thread scratch of the cell pass: the neighbourhood's points grouped by
/// observation (group g holds the points of J_c[g]), in float arrays.
struct NeighbourhoodScratch {
  explicit NeighbourhoodScratch(int n) : mark(n, 0), group(n, 0) {}
  std::vector<std::uint32_t> mark, group;  // stamp of the last cell that saw j, and j's group there
  std::vector<std::uint32_t> group_begin, cursor;
  std::vector<float> x, y, z;
  /// The bit of the point's group, 1 << g when the groups fit in one word,
  /// as its low and high halves.
  std::vector<std::uint32_t> low_bit, high_bit;
  std::vector<std::uint8_t> hit;
};

/// Fills J_c and the group layout of one cell's neighbourhood.
std::uint32_t groupNeighbourhood(const Grid& grid, std::size_t c, std::int32_t* near, NeighbourhoodScratch& s) {
  const std::vector<Run>& runs = grid.runs();
  const Span* slices = grid.neighbourhood(c);
  const std::uint32_t stamp = static_cast<std::uint32_t>(c + 1);
  std::uint32_t groups = 0;
  s.group_begin.assign(grid.observationsNear(c) + 1, 0);
  for (int h = 0; h < grid.columns(); ++h)
    for (std::uint32_t r = slices[h].begin; r < slices[h].end; ++r) {
      const int j = runs[r].observation;
      if (s.mark[j] != stamp) {
        s.mark[j] = stamp;
        s.group[j] = groups;
        near[groups++] = j;
      }
      s.group_begin[s.group[j] + 1] += runs[r].end - runs[r].begin;
    }
  for (std::uint32_t g = 0; g < groups; ++g) s.group_begin[g + 1] += s.group_begin[g];
  const std::uint32_t total = s.group_begin[groups];
  s.x.resize(total);
  s.y.resize(total);
  s.z.resize(total);
  s.low_bit.resize(total);
  s.high_bit.resize(total);
  if (groups > 64) s.hit.assign(total + 8, 0);  // only the multi-word path reads hit bytes
  s.cursor.assign(s.group_begin.begin(), s.group_begin.end() - 1);
  const Eigen::Vector3f* points = grid.points().data();
  for (int h = 0; h < grid.columns(); ++h)
    for (std::uint32_t r = slices[h].begin; r < slices[h].end; ++r) {
      const std::uint32_t g = s.group[runs[r].observation];
      std::uint32_t& at = s.cursor[g];
      for (std::uint32_t q = runs[r].begin; q < runs[r].end; ++q, ++at) {
        s.x[at] = points[q].x();
        s.y[at] = points[q].y();
        s.z[at] = points[q].z();
        s.low_bit[at] = g < 32 ? std::uint32_t(1) << g : 0;
        s.high_bit[at] = g >= 32 && g < 64 ? std::uint32_t(1) << (g - 32) : 0;
      }
    }
  return groups;
}

/// Calls test(begin, end) on the ranges of the neighbourhood's points to
/// test: all of them, or all but the point's own observation
/// [own_begin, own_end) when that is large.
template <typename Test>
void testOthers(std::uint32_t own_begin, std::uint32_t own_end, std::uint32_t total, const Test& test) {
  if (own_end - own_begin <= 16) {  // one loop is cheaper than skipping a few points
    test(0, total);
  } else {  // dense clouds: most of the neighbourhood is the point's own observation
    test(0, own_begin);
    test(own_end, total);
  }
}

/// Sets, in `mask`, the groups of the neighbourhood that have a point within
/// delta of p, its own group `self` excepted.
template <bool Planar>
void matchPoint(const Eigen::Vector3f& p, std::uint32_t self, std::uint32_t groups, const MatchDistance& within,
                float inside, float outside, NeighbourhoodScratch& s, std::uint64_t* mask) {
  const std::uint32_t total = s.group_begin[groups];
  const std::uint32_t own_begin = s.group_begin[self], own_end = s.group_begin[self + 1];
  std::uint8_t* hit = s.hit.data();
  const float *x = s.x.data(), *y = s.y.data(), *z = s.z.data();
  std::uint8_t border = 0;
  if (groups <= 64) {  // the usual case: the group bits are ORed as the distances are tested
    const std::uint32_t *low = s.low_bit.data(), *high = s.high_bit.data();
    std::uint64_t word = 0;
    testOthers(own_begin, own_end, total, [&](std::uint32_t begin, std::uint32_t end) {
      word |= floatMatchBits<Planar>(p, inside, outside, x, y, z, low, high, begin, end, border);
    });
    if (border) {  // rare: a distance within 1e-4 of delta, decided in double
      word = 0;
      for (std::uint32_t q = 0; q < total; ++q)
        if (within(p, Eigen::Vector3f(x[q], y[q], z[q]))) word |= std::uint64_t(high[q]) << 32 | low[q];
    }
    mask[0] = word & ~(std::uint64_t(1) << self);
    return;
  }
  testOthers(own_begin, own_end, total, [&](std::uint32_t begin, std::uint32_t end) {
    border |= floatMatches<Planar>(p, inside, outside, x, y, z, hit, begin, end);
  });
  if (border) {  // rare: a distance within 1e-4 of delta, decided in double
    for (std::uint32_t q = 0; q < total; ++q) hit[q] = within(p, Eigen::Vector3f(x[q], y[q], z[q]));
  }
  // Branch-free: whether a group matched is as good as a coin flip.
  std::uint64_t word = 0;
  for (std::uint32_t g = 0; g < groups; ++g) {
    word |= std::uint64_t(anyHit(hit, s.group_begin[g], s.group_begin[g + 1])) << (g & 63);
    if ((g & 63) == 63) {
      mask[g >> 6] = word;
      word = 0;
    }
  }
  if (groups & 63) mask[groups >> 6] = word;
  mask[self >> 6] &= ~(std::uint64_t(1) << (self & 63));
}

/// Pass 1, cell by cell: each cell's neighbourhood is grouped by observation
/// once and shared by all the points of the cell, whatever their observation.
CellMatches matchCells(const Grid& grid, double delta, int threads, const ProgressCallback& progress,
                       std::size_t progress_total, const InterruptFlag* interrupt) {
  const std::size_t cells = grid.cells();
  CellMatches out;
  out.near_offsets.assign(cells + 1, 0);
  out.mask_offsets.assign(cells + 1, 0);
  for (std::size_t c = 0; c < cells; ++c) {
    const std::uint64_t near = grid.observationsNear(c), points = grid.pointsOfCell(c);
    out.near_offsets[c + 1] = out.near_offsets[c] + near;
    out.mask_offsets[c + 1] = out.mask_offsets[c] + points * ((near + 63) / 64);
    out.point_tests += (near - 1) * points;  // each point against every observation near it but its own
  }
  out.near.resize(out.near_offsets[cells]);
  out.masks.assign(out.mask_offsets[cells], 0);
  const MatchDistance within(delta);
  const float inside = float(delta * delta * (1.0 - 1e-4)), outside = float(delta * delta * (1.0 + 1e-4));
  const std::vector<Run>& runs = grid.runs();
  std::atomic<std::size_t> done{0};
  // The progress callback is the user's code: parallelFor hands its
  // exception, as the interruption's, to the caller. It is called on the
  // calling thread (a small loop runs there, maybe inside a caller's team).
  const std::thread::id caller = std::this_thread::get_id();
  parallelForWithScratch(
      cells, threads, 256, [&grid] { return NeighbourhoodScratch(grid.observations()); },
      [&](std::size_t c, NeighbourhoodScratch& scratch) {
        if (c % 256 == 0) {
          throwIfInterrupted(interrupt);
          const std::size_t now = done += 256;
          if (progress && std::this_thread::get_id() == caller) progress(std::min(now, cells), progress_total);
        }
        const std::uint32_t groups = groupNeighbourhood(grid, c, out.near.data() + out.near_offsets[c], scratch);
        const std::size_t words = out.words(c);
        std::uint64_t* mask = out.masks.data() + out.mask_offsets[c];
        const Span own = grid.runsOfCell(c);
        for (std::uint32_t r = own.begin; r < own.end; ++r) {
          const std::uint32_t self = scratch.group[runs[r].observation];
          for (std::uint32_t k = runs[r].begin; k < runs[r].end; ++k, mask += words)
            if (grid.planar())
              matchPoint<true>(grid.points()[k], self, groups, within, inside, outside, scratch, mask);
            else
              matchPoint<false>(grid.points()[k], self, groups, within, inside, outside, scratch, mask);
        }
      });
  return out;
}

/// Per-thread scratch for one row of counts: dense by observation, reset only
/// where touched, so a row costs O(matches), not O(N).
struct RowScratch {
  explicit RowScratch(int n) : tested(n, -1), count(n, 0), touched(n) {}
  std::vector<int> tested;  // last row i that compared points with j
  std::vector<std::uint32_t> count;
  std::vector<int> touched;
  std::uint64_t pairs = 0;
};

/// Pass 2, observation by observation: adds up the bit sets of i's points.
void countRow(const Grid& grid, const CellMatches& matches, int i, RowScratch& s, std::vector<MatchCount>& row) {
  int* tested = s.tested.data();
  std::uint32_t* count = s.count.data();
  int* touched = s.touched.data();
  std::size_t touched_size = 0;
  tested[i] = i;  // never a pair of itself
  for (const OwnRun *own = grid.ownRuns(i), *end = grid.ownRuns(i + 1); own != end; ++own) {
    if (own + 2 < end) {  // the cells of a row are scattered: fetch ahead
      __builtin_prefetch(&matches.near_offsets[own[2].cell]);
      __builtin_prefetch(&matches.mask_offsets[own[2].cell]);
    }
    const std::uint32_t cell = own->cell;
    const std::int32_t* near = matches.near.data() + matches.near_offsets[cell];
    const std::size_t near_size = matches.near_offsets[cell + 1] - matches.near_offsets[cell];
    for (std::size_t g = 0; g < near_size; ++g) {  // every j near the cell had points compared with i's
      s.pairs += tested[near[g]] != i;
      tested[near[g]] = i;
    }
    const std::size_t words = matches.words(cell);
    const std::uint64_t* mask = matches.masks.data() + matches.mask_offsets[cell] + std::size_t(own->first) * words;
    for (std::uint32_t p = 0; p < own->count; ++p)
      for (std::size_t w = 0; w < words; ++w, ++mask)
        for (std::uint64_t bits = *mask; bits != 0; bits &= bits - 1) {
          const int j = near[w * 64 + static_cast<std::size_t>(__builtin_ctzll(bits))];
          touched[touched_size] = j;
          touched_size += count[j]++ == 0;
        }
  }
  std::sort(touched, touched + touched_size);
  row.reserve(touched_size);
  for (std::size_t t = 0; t < touched_size; ++t) {
    row.push_back({touched[t], count[touched[t]]});
    count[touched[t]] = 0;
  }
}

}  // namespace

MatchCounts countMatchesSharedGrid(const WorldPoints& world, double delta, int threads,
                                   const ProgressCallback& progress, const InterruptFlag* interrupt) {
  if (!(delta > 0.0) || !std::isfinite(delta))
    throw std::invalid_argument("shared grid: the match distance delta must be finite and > 0");
  const int n = world.size();
  MatchCounts out;
  out.rows.resize(n);
  if (n == 0) return out;
  const int nthreads = threads > 0 ? threads : omp_get_max_threads();
  // Every point's cell is computed (and range-checked) when the grid is
  // built, so nothing below can throw inside a parallel region.
  const Grid grid(world, delta, nthreads);
  // Progress is reported in observations, as by the other back-end: the
  // cells done and then the observations added up, scaled to n.
  const std::size_t progress_total = grid.cells() + std::size_t(n);
  const ProgressCallback in_observations = [&progress, progress_total, n](std::size_t done, std::size_t) {
    progress(std::size_t(n) * std::min(done, progress_total) / progress_total, std::size_t(n));
  };
  const ProgressCallback report = progress ? in_observations : ProgressCallback{};
  const CellMatches matches = matchCells(grid, delta, nthreads, report, progress_total, interrupt);
  throwIfInterrupted(interrupt);
  std::vector<std::uint64_t> row_pairs(n, 0);
  std::atomic<std::size_t> done{0};
  const std::thread::id caller = std::this_thread::get_id();
  parallelForWithScratch(
      std::size_t(n), nthreads, 16, [n] { return RowScratch(n); },
      [&](std::size_t i, RowScratch& scratch) {
        throwIfInterrupted(interrupt);
        const std::uint64_t before = scratch.pairs;
        countRow(grid, matches, int(i), scratch, out.rows[i]);
        row_pairs[i] = scratch.pairs - before;
        const std::size_t now = ++done;
        if (report && std::this_thread::get_id() == caller) report(grid.cells() + now, progress_total);
      });
  std::uint64_t pairs = 0;
  for (const std::uint64_t p : row_pairs) pairs += p;
  if (progress) progress(n, n);
  out.pairs_evaluated = pairs;
  out.point_tests = matches.point_tests;
  return out;
}

}  // namespace obsgroup
