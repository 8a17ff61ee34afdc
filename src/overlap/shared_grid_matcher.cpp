#include "obsgroup/overlap/shared_grid_matcher.h"

#include "obsgroup/invalid_observation.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace obsgroup {
namespace {

struct CellKey {
  std::int32_t x, y, z;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
  bool operator<(const CellKey& o) const {
    return x != o.x ? x < o.x : (y != o.y ? y < o.y : z < o.z);
  }
};

/// A run of consecutive grid points of one observation inside one cell.
struct Run {
  std::int32_t observation;
  std::uint32_t begin, end;  // into Grid::points
};

/// What the grid knows of one cell.
struct CellRuns {
  std::uint32_t begin = 0, end = 0;  ///< the cell's runs, [begin, end) into the run array
  std::uint32_t ordinal = 0;         ///< the cell's number, in key order
};

/// Open-addressing hash table from a cell to its runs. Built once, read-only
/// afterwards, so all threads share it without locks.
class CellTable {
 public:
  void reserve(std::size_t cells) {
    std::size_t capacity = 16;
    while (capacity < 2 * cells) capacity <<= 1;
    mask_ = capacity - 1;
    slots_.assign(capacity, Slot{});
  }
  void insert(const CellKey& key, const CellRuns& runs) {
    std::size_t s = hash(key) & mask_;
    while (slots_[s].runs.end != 0) s = (s + 1) & mask_;
    slots_[s] = Slot{key, runs};
  }
  /// The cell's runs; begin == end if the cell is empty.
  CellRuns find(const CellKey& key) const {
    for (std::size_t s = hash(key) & mask_;; s = (s + 1) & mask_) {
      const Slot& slot = slots_[s];
      if (slot.runs.end == 0) return {};
      if (slot.key == key) return slot.runs;
    }
  }

 private:
  struct Slot {
    CellKey key{0, 0, 0};
    CellRuns runs;  // runs.end == 0 marks a free slot
  };
  static std::size_t hash(const CellKey& k) {
    std::uint64_t h = std::uint64_t(std::uint32_t(k.x)) * 0x9E3779B97F4A7C15ull;
    h ^= std::uint64_t(std::uint32_t(k.y)) * 0xC2B2AE3D27D4EB4Full;
    h ^= std::uint64_t(std::uint32_t(k.z)) * 0x165667B19E3779F9ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
};

class Grid {
 public:
  Grid(const WorldPoints& world, double delta) : world_(world) {
    // Cells a hair larger than delta: two points within delta then differ by
    // at most one in every cell index, whatever the rounding of x / cell.
    inv_cell_ = 1.0 / (delta * (1.0 + 1e-6));
    build();
  }

  CellKey cellOf(const Eigen::Vector3f& p) const {
    const auto index = [this](float v) {
      const double c = std::floor(double(v) * inv_cell_);
      if (!(std::abs(c) < double(1 << 30)))
        throw std::invalid_argument("shared grid: a point lies too far from the map centre for the grid "
                                    "(coordinate " + std::to_string(v) + " m); use a larger delta or the "
                                    "PCL search back-end");
      return static_cast<std::int32_t>(c);
    };
    return {index(p.x()), index(p.y()), index(p.z())};
  }

  bool flat() const { return flat_; }
  const CellTable& table() const { return table_; }
  /// Distinct observations with points in the neighbourhood of a cell (by ordinal).
  std::uint32_t observationsNear(std::uint32_t ordinal) const { return observations_near_[ordinal]; }
  /// Calls f(runs) for each non-empty cell of the 3x3 (flat) or 3x3x3 neighbourhood of c.
  template <typename F>
  void forEachNeighbour(const CellKey& c, F&& f) const {
    const int dz_max = flat_ ? 0 : 1;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -dz_max; dz <= dz_max; ++dz) {
          const CellRuns runs = table_.find({c.x + dx, c.y + dy, c.z + dz});
          if (runs.begin != runs.end) f(runs);
        }
  }
  const std::vector<Run>& runs() const { return runs_; }
  const std::vector<Eigen::Vector3f>& points() const { return points_; }

 private:
  void build() {
    const std::size_t total = world_.points.size();
    if (total >= std::numeric_limits<std::uint32_t>::max())
      throw std::invalid_argument("shared grid: more than 4 billion points");
    struct Entry {
      CellKey key;
      std::int32_t observation;
      std::uint32_t index;
    };
    std::vector<Entry> entries(total);
    for (int i = 0; i < world_.size(); ++i) {
      try {
        for (std::size_t k = world_.offsets[i]; k < world_.offsets[i + 1]; ++k)
          entries[k] = Entry{cellOf(world_.points[k]), i, static_cast<std::uint32_t>(k)};
      } catch (const std::invalid_argument& e) {
        throw InvalidObservation(i, e.what());
      }
    }
    // Sorting by (cell, observation, index) groups each cell's points into one
    // run per observation, in a deterministic order.
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
      if (!(a.key == b.key)) return a.key < b.key;
      return a.observation != b.observation ? a.observation < b.observation : a.index < b.index;
    });
    points_.resize(total);
    flat_ = true;
    std::size_t cells = 0;
    for (std::size_t k = 0; k < total; ++k) {
      points_[k] = world_.points[entries[k].index];
      flat_ = flat_ && entries[k].key.z == entries[0].key.z;
      if (k == 0 || !(entries[k].key == entries[k - 1].key)) ++cells;
    }
    table_.reserve(cells);
    std::vector<CellKey> keys;
    keys.reserve(cells);
    std::uint32_t cell_first_run = 0;
    const auto close_cell = [&](const CellKey& key) {
      table_.insert(key, {cell_first_run, static_cast<std::uint32_t>(runs_.size()),
                          static_cast<std::uint32_t>(keys.size())});
      keys.push_back(key);
    };
    for (std::size_t k = 0; k < total; ++k) {
      const bool new_cell = k == 0 || !(entries[k].key == entries[k - 1].key);
      if (new_cell && k > 0) close_cell(entries[k - 1].key);
      if (new_cell) cell_first_run = static_cast<std::uint32_t>(runs_.size());
      if (new_cell || entries[k].observation != entries[k - 1].observation)
        runs_.push_back(Run{entries[k].observation, static_cast<std::uint32_t>(k), 0});
      runs_.back().end = static_cast<std::uint32_t>(k + 1);
    }
    if (total > 0) close_cell(entries[total - 1].key);
    countObservationsNear(keys);
  }

  /// For each cell, the distinct observations in its neighbourhood: every
  /// point of the cell is tested once against each of them but its own, so
  /// the work statistic costs nothing in the per-point loop.
  void countObservationsNear(const std::vector<CellKey>& keys) {
    observations_near_.assign(keys.size(), 0);
#pragma omp parallel
    {
      std::vector<std::uint32_t> stamp(world_.size(), 0);
#pragma omp for schedule(dynamic, 256)
      for (std::size_t c = 0; c < keys.size(); ++c) {
        std::uint32_t distinct = 0;
        const std::uint32_t mark = static_cast<std::uint32_t>(c + 1);
        forEachNeighbour(keys[c], [&](const CellRuns& runs) {
          for (std::uint32_t r = runs.begin; r < runs.end; ++r) {
            std::uint32_t& s = stamp[runs_[r].observation];
            if (s != mark) {
              s = mark;
              ++distinct;
            }
          }
        });
        observations_near_[c] = distinct;
      }
    }
  }

  const WorldPoints& world_;
  double inv_cell_ = 0.0;
  bool flat_ = true;
  CellTable table_;
  std::vector<Run> runs_;
  std::vector<Eigen::Vector3f> points_;
  std::vector<std::uint32_t> observations_near_;
};

/// Per-thread scratch for one row of counts: dense by observation, reset only
/// where touched, so a row costs O(matches), not O(N).
struct RowScratch {
  explicit RowScratch(int n) : seen(n, 0), tested(n, -1), count(n, 0) {}
  std::vector<std::uint32_t> seen;  // point stamp of the last match with j
  std::vector<int> tested;          // last row i that compared points with j
  std::vector<std::uint32_t> count;
  std::vector<int> touched;
  std::uint32_t stamp = 0;
  std::uint64_t pairs = 0, tests = 0;

  void nextPoint() {
    if (++stamp == 0) {  // wrapped: forget old stamps
      std::fill(seen.begin(), seen.end(), 0);
      stamp = 1;
    }
  }
};

void countRow(const Grid& grid, const WorldPoints& world, int i, const MatchDistance& within, RowScratch& s,
              std::vector<MatchCount>& row) {
  // Visit i's points cell by cell, so each neighbourhood is looked up once per cell.
  const std::size_t m = world.count(i);
  std::vector<std::pair<CellKey, std::uint32_t>> cells(m);
  for (std::size_t k = 0; k < m; ++k) cells[k] = {grid.cellOf(world.begin(i)[k]), static_cast<std::uint32_t>(k)};
  std::sort(cells.begin(), cells.end(), [](const auto& a, const auto& b) {
    return a.first == b.first ? a.second < b.second : a.first < b.first;
  });
  std::array<CellRuns, 27> neighbourhood;
  for (std::size_t first = 0; first < m;) {
    const CellKey c = cells[first].first;
    int used = 0;
    grid.forEachNeighbour(c, [&](const CellRuns& runs) { neighbourhood[used++] = runs; });
    std::size_t last = first;
    while (last < m && cells[last].first == c) ++last;
    // Each point is tested once against every other observation near its cell.
    s.tests += std::uint64_t(grid.observationsNear(grid.table().find(c).ordinal) - 1) * (last - first);
    for (std::size_t k = first; k < last; ++k) {
      const Eigen::Vector3f& p = world.begin(i)[cells[k].second];
      s.nextPoint();
      for (int h = 0; h < used; ++h) {
        for (std::uint32_t r = neighbourhood[h].begin; r < neighbourhood[h].end; ++r) {
          const Run& run = grid.runs()[r];
          const int j = run.observation;
          if (j == i || s.seen[j] == s.stamp) continue;  // each j counted once per point
          if (s.tested[j] != i) {
            s.tested[j] = i;
            ++s.pairs;
          }
          for (std::uint32_t q = run.begin; q < run.end; ++q) {
            if (within(p, grid.points()[q])) {
              s.seen[j] = s.stamp;
              if (s.count[j]++ == 0) s.touched.push_back(j);
              break;
            }
          }
        }
      }
    }
    first = last;
  }
  std::sort(s.touched.begin(), s.touched.end());
  row.reserve(s.touched.size());
  for (int j : s.touched) {
    row.push_back({j, s.count[j]});
    s.count[j] = 0;
  }
  s.touched.clear();
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
  const Grid grid(world, delta);
  const MatchDistance within(delta);
  const int nthreads = threads > 0 ? threads : omp_get_max_threads();
  std::uint64_t pairs = 0, tests = 0;
  std::atomic<std::size_t> done{0};
  // Every point's cell was computed (and range-checked) when the grid was
  // built, so nothing below can throw inside the parallel region.
#pragma omp parallel num_threads(nthreads) reduction(+ : pairs, tests)
  {
    RowScratch scratch(n);
#pragma omp for schedule(dynamic, 8)
    for (int i = 0; i < n; ++i) {
      if (interruptRequested(interrupt)) continue;  // no throwing inside the parallel region
      countRow(grid, world, i, within, scratch, out.rows[i]);
      const std::size_t now = ++done;
      if (progress && omp_get_thread_num() == 0) progress(now, n);
    }
    pairs += scratch.pairs;
    tests += scratch.tests;
  }
  throwIfInterrupted(interrupt);
  if (progress) progress(n, n);
  out.pairs_evaluated = pairs;
  out.point_tests = tests;
  return out;
}

}  // namespace obsgroup
