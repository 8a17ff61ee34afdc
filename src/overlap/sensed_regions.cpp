#include "obsgroup/overlap/sensed_regions.h"

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

#if defined(__GLIBCXX__) && defined(_OPENMP)
#include <parallel/algorithm>
#endif

namespace obsgroup {

namespace {

// --- cells and keys ---------------------------------------------------------
//
// A cell is (ix, iy) in 2D or (ix, iy, iz) in 3D, ix = floor(x / cell_size)
// of the re-centred coordinates. Its key packs the biased indices so that
// keys ascend in lexicographic (x, y, z) order: 32 bits per axis in 2D, 21 in 3D.

constexpr std::int64_t kBias2 = std::int64_t(1) << 31;
constexpr std::int64_t kBias3 = std::int64_t(1) << 20;

template <int D>
using Cell = std::array<std::int64_t, D>;

template <int D>
std::uint64_t keyOf(const Cell<D>& c) {
  if constexpr (D == 2) return (std::uint64_t(c[0] + kBias2) << 32) | std::uint64_t(c[1] + kBias2);
  else return (std::uint64_t(c[0] + kBias3) << 42) | (std::uint64_t(c[1] + kBias3) << 21) | std::uint64_t(c[2] + kBias3);
}

template <int D>
void checkRepresentable(const Cell<D>& lo, const Cell<D>& hi) {
  const std::int64_t limit = (D == 2 ? kBias2 : kBias3) - 2;
  for (int a = 0; a < D; ++a)
    if (lo[a] < -limit || hi[a] > limit)
      throw std::invalid_argument("the map spans more cells than a region can index: raise the cell size");
}

/// The cells one observation's region covers, marked in a bitmap over its
/// bounding box (in cells) and read back in key order; a box too large for a
/// bitmap falls back to collecting and sorting the keys.
template <int D>
class RegionMarker {
 public:
  void reset(const Cell<D>& lo, const Cell<D>& hi) {
    lo_ = lo;
    std::uint64_t total = 1;
    for (int a = 0; a < D; ++a) {
      extent_[a] = hi[a] - lo[a] + 1;
      total *= std::uint64_t(extent_[a]);
    }
    dense_ = total <= (std::uint64_t(1) << 26);
    keys_.clear();
    removed_.clear();
    if (dense_) bits_.assign((total + 63) / 64, 0);
  }
  void mark(const Cell<D>& c) {
    if (!dense_) {
      keys_.push_back(keyOf<D>(c));
      return;
    }
    const std::uint64_t b = offset(c);
    bits_[b >> 6] |= std::uint64_t(1) << (b & 63);
  }
  /// Clears a cell of the box (dense bitmaps; the sparse fallback drops it
  /// when emitting). Cells outside the box are ignored.
  void unmark(const Cell<D>& c) {
    for (int a = 0; a < D; ++a)
      if (c[a] < lo_[a] || c[a] >= lo_[a] + extent_[a]) return;
    if (!dense_) {
      removed_.push_back(keyOf<D>(c));
      return;
    }
    const std::uint64_t b = offset(c);
    bits_[b >> 6] &= ~(std::uint64_t(1) << (b & 63));
  }
  /// Whether a cell is marked (cells outside the box are not).
  bool marked(const Cell<D>& c) const {
    for (int a = 0; a < D; ++a)
      if (c[a] < lo_[a] || c[a] >= lo_[a] + extent_[a]) return false;
    if (!dense_) return std::find(keys_.begin(), keys_.end(), keyOf<D>(c)) != keys_.end();
    const std::uint64_t b = offset(c);
    return bits_[b >> 6] >> (b & 63) & 1;
  }
  /// Appends the marked keys, ascending.
  void emit(std::vector<std::uint64_t>& out) {
    if (!dense_) {
      std::sort(keys_.begin(), keys_.end());
      keys_.erase(std::unique(keys_.begin(), keys_.end()), keys_.end());
      std::sort(removed_.begin(), removed_.end());
      std::set_difference(keys_.begin(), keys_.end(), removed_.begin(), removed_.end(), std::back_inserter(out));
      return;
    }
    for (std::size_t w = 0; w < bits_.size(); ++w)
      for (std::uint64_t word = bits_[w]; word; word &= word - 1) {
        std::uint64_t b = w * 64 + std::uint64_t(__builtin_ctzll(word));
        Cell<D> c;
        for (int a = D - 1; a >= 0; --a) {
          c[a] = lo_[a] + std::int64_t(b % std::uint64_t(extent_[a]));
          b /= std::uint64_t(extent_[a]);
        }
        out.push_back(keyOf<D>(c));
      }
  }

 private:
  std::uint64_t offset(const Cell<D>& c) const {
    std::uint64_t b = 0;
    for (int a = 0; a < D; ++a) b = b * std::uint64_t(extent_[a]) + std::uint64_t(c[a] - lo_[a]);
    return b;
  }
  Cell<D> lo_{};
  std::array<std::int64_t, D> extent_{};
  bool dense_ = true;
  std::vector<std::uint64_t> bits_;
  std::vector<std::uint64_t> keys_, removed_;
};

/// Visits the cells a segment from `from` to `to` (in cell units) crosses, in
/// order (Amanatides and Woo). `visit(cell, t)` gets the parameter t in [0, 1]
/// at which the segment enters the cell and returns false to stop.
template <int D, typename Visit>
void traverse(const std::array<double, D>& from, const std::array<double, D>& to, Visit&& visit) {
  Cell<D> cell, last;
  std::array<double, D> next, step_t;
  std::array<int, D> step;
  std::int64_t budget = 1;
  for (int a = 0; a < D; ++a) {
    cell[a] = std::int64_t(std::floor(from[a]));
    last[a] = std::int64_t(std::floor(to[a]));
    const double d = to[a] - from[a];
    step[a] = d > 0 ? 1 : -1;
    step_t[a] = d != 0 ? 1.0 / std::abs(d) : std::numeric_limits<double>::infinity();
    next[a] = d != 0 ? (double(cell[a] + (d > 0)) - from[a]) / d : std::numeric_limits<double>::infinity();
    budget += std::abs(last[a] - cell[a]);
  }
  double t = 0.0;
  // The budget (the cells between the end cells) bounds the walk whatever
  // the rounding of `next`.
  for (std::int64_t k = 0; k < budget; ++k) {
    if (!visit(cell, t) || cell == last) return;
    int axis = 0;
    for (int a = 1; a < D; ++a)
      if (next[a] < next[axis]) axis = a;
    if (next[axis] > 1.0) return;
    t = next[axis];
    cell[axis] += step[axis];
    next[axis] += step_t[axis];
  }
}

/// The cell grid, anchored on the first observation (the origin of the
/// re-centred frame) so that a map at UTM coordinates has the same cells as
/// the same map near 0. The first sensor sits at a cell's centre, not on its
/// corner: routes that keep one coordinate (a corridor's axis) then do not
/// run along cell edges, where rounding would pick the side.
struct CellGrid {
  explicit CellGrid(double cell_size) : size(cell_size) {}
  /// Re-centred coordinates in cells.
  template <int D>
  std::array<double, D> inCells(const Eigen::Vector3d& p) const {
    std::array<double, D> out;
    for (int a = 0; a < D; ++a) out[a] = p[a] / size + phase[a];
    return out;
  }
  double size;
  std::array<double, 3> phase{0.5, 0.5, 0.5};
};

template <int D>
Cell<D> cellOf(const std::array<double, D>& p) {
  Cell<D> c;
  for (int a = 0; a < D; ++a) c[a] = std::int64_t(std::floor(p[a]));
  return c;
}

/// The box of cells within `range` of `origin` (both in cell units), one
/// cell of margin for rounding.
template <int D>
std::pair<Cell<D>, Cell<D>> boxAround(const std::array<double, D>& origin, double range) {
  Cell<D> lo, hi;
  for (int a = 0; a < D; ++a) {
    lo[a] = std::int64_t(std::floor(origin[a] - range)) - 1;
    hi[a] = std::int64_t(std::floor(origin[a] + range)) + 1;
  }
  checkRepresentable<D>(lo, hi);
  return {lo, hi};
}

// --- free space --------------------------------------------------------------

/// The cells crossed by observation i's beams, from the sensor to each point
/// (or to max_range along it).
template <int D>
void freeSpaceOf(const WorldPoints& world, int i, const Eigen::Vector3d& origin, const RegionParameters& params,
                 const CellGrid& grid, RegionMarker<D>& marker, std::vector<std::uint64_t>& out) {
  if (world.count(i) == 0) return;
  const double range = params.max_range / grid.size;
  const auto o = grid.inCells<D>(origin);
  // The box of the beams: the origin and every (clipped) end point.
  std::vector<std::array<double, D>> ends;
  ends.reserve(world.count(i));
  Cell<D> lo = cellOf<D>(o), hi = lo;
  for (const Eigen::Vector3f* p = world.begin(i); p != world.end(i); ++p) {
    std::array<double, D> e = grid.inCells<D>(p->cast<double>());
    double length = 0;
    for (int a = 0; a < D; ++a) length += (e[a] - o[a]) * (e[a] - o[a]);
    length = std::sqrt(length);
    if (length > range)
      for (int a = 0; a < D; ++a) e[a] = o[a] + (e[a] - o[a]) * (range / length);
    const Cell<D> c = cellOf<D>(e);
    for (int a = 0; a < D; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
    ends.push_back(e);
  }
  checkRepresentable<D>(lo, hi);
  marker.reset(lo, hi);
  for (const auto& e : ends)
    traverse<D>(o, e, [&](const Cell<D>& c, double) {
      marker.mark(c);
      return true;
    });
  marker.emit(out);
}

// --- visibility --------------------------------------------------------------

/// The occupied cells of the plane, in tiles of 64 x 64 found by hash: any
/// extent, memory in proportion to the occupied area.
class OccupancyGrid {
 public:
  explicit OccupancyGrid(const std::vector<std::uint64_t>& occupied_keys) {
    for (std::uint64_t key : occupied_keys) {
      const std::uint64_t ux = key >> 32, uy = key & 0xffffffffu;
      const std::uint64_t tile = ((ux >> 6) << 32) | (uy >> 6);
      auto [it, added] = index_.emplace(tile, std::uint32_t(tiles_.size()));
      if (added) tiles_.emplace_back();
      tiles_[it->second][ux & 63] |= std::uint64_t(1) << (uy & 63);
    }
  }

  /// One ray caster per thread: it remembers the last tile it looked at.
  class Reader {
   public:
    explicit Reader(const OccupancyGrid& grid) : grid_(grid) {}
    bool occupied(const Cell<2>& c) {
      const std::uint64_t ux = std::uint64_t(c[0] + kBias2), uy = std::uint64_t(c[1] + kBias2);
      const std::uint64_t tile = ((ux >> 6) << 32) | (uy >> 6);
      if (tile != last_tile_) {
        const auto it = grid_.index_.find(tile);
        last_ = it == grid_.index_.end() ? nullptr : &grid_.tiles_[it->second];
        last_tile_ = tile;
      }
      return last_ && ((*last_)[ux & 63] >> (uy & 63) & 1);
    }

   private:
    const OccupancyGrid& grid_;
    std::uint64_t last_tile_ = std::numeric_limits<std::uint64_t>::max();
    const std::array<std::uint64_t, 64>* last_ = nullptr;
  };

 private:
  std::unordered_map<std::uint64_t, std::uint32_t> index_;
  std::vector<std::array<std::uint64_t, 64>> tiles_;
};

/// Whether point p of an observation whose sensor is at `origin` feeds the
/// occupancy grid: in 3D only the band about the sensor's height, so that
/// floor and ceiling do not close the view.
bool inBand(const Eigen::Vector3f& p, const Eigen::Vector3d& origin, const RegionParameters& params, bool planar) {
  if (planar) return true;
  const double height = double(p.z()) - origin.z();
  return height >= params.band_low && height <= params.band_high;
}

/// Sorts distinct-or-integer values in parallel: one order whatever the threads.
template <typename T>
void sortInParallel(std::vector<T>& values) {
#if defined(__GLIBCXX__) && defined(_OPENMP)
  __gnu_parallel::sort(values.begin(), values.end());
#else
  std::sort(values.begin(), values.end());
#endif
}

/// Concatenates per-observation key lists (freeing them) and sorts them.
std::vector<std::uint64_t> gatherSorted(std::vector<std::vector<std::uint64_t>>& per_observation) {
  std::size_t total = 0;
  for (const auto& keys : per_observation) total += keys.size();
  std::vector<std::uint64_t> all;
  all.reserve(total);
  for (auto& keys : per_observation) {
    all.insert(all.end(), keys.begin(), keys.end());
    std::vector<std::uint64_t>().swap(keys);
  }
  sortInParallel(all);
  return all;
}

/// The plane cells occupied in the evidence of all observations: at least
/// params.min_observations observations have a point in the cell, and at
/// least as many have a point in it as have a beam through it. A wall seen
/// once, by a sparse sequence, stands; a drifted copy of a wall across a door,
/// which the beams of everyone passing the door cross, does not.
std::vector<std::uint64_t> occupiedCells(const WorldPoints& world, const std::vector<Eigen::Vector3d>& origins,
                                         const RegionParameters& params, const CellGrid& grid, bool planar,
                                         int threads) {
  const int n = world.size();
  const double range = params.max_range / grid.size;
  std::vector<std::vector<std::uint64_t>> hit(n), crossed(n);
#pragma omp parallel num_threads(threads)
  {
    RegionMarker<2> marker;
    std::vector<Cell<2>> ends;
    std::vector<std::array<double, 2>> targets;
#pragma omp for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i) {
      if (world.count(i) == 0) continue;
      ends.clear();
      targets.clear();
      const auto o = grid.inCells<2>(origins[i]);
      Cell<2> lo = cellOf<2>(o), hi = lo;
      for (const Eigen::Vector3f* p = world.begin(i); p != world.end(i); ++p) {
        if (!inBand(*p, origins[i], params, planar)) continue;
        std::array<double, 2> e = grid.inCells<2>(p->cast<double>());
        ends.push_back(cellOf<2>(e));
        // The beam counts as seeing through the cells it crosses within range.
        const double length = std::hypot(e[0] - o[0], e[1] - o[1]);
        if (length > range)
          for (int a = 0; a < 2; ++a) e[a] = o[a] + (e[a] - o[a]) * (range / length);
        targets.push_back(e);
        const Cell<2> t = cellOf<2>(e);
        for (int a = 0; a < 2; ++a)
          lo[a] = std::min({lo[a], t[a], ends.back()[a]}), hi[a] = std::max({hi[a], t[a], ends.back()[a]});
      }
      marker.reset(lo, hi);
      for (const Cell<2>& c : ends) marker.mark(c);
      marker.emit(hit[i]);
      marker.reset(lo, hi);
      for (const auto& e : targets)
        traverse<2>(o, e, [&](const Cell<2>& c, double) {
          marker.mark(c);
          return true;
        });
      for (const Cell<2>& c : ends) marker.unmark(c);  // a surface it saw is not a cell it saw through
      marker.emit(crossed[i]);
    }
  }
  const std::vector<std::uint64_t> hits = gatherSorted(hit), misses = gatherSorted(crossed);
  std::vector<std::uint64_t> occupied;
  std::size_t m = 0;
  for (std::size_t a = 0; a < hits.size();) {
    std::size_t b = a;
    while (b < hits.size() && hits[b] == hits[a]) ++b;
    while (m < misses.size() && misses[m] < hits[a]) ++m;
    std::size_t e = m;
    while (e < misses.size() && misses[e] == hits[a]) ++e;
    if (b - a >= std::size_t(params.min_observations) && b - a >= e - m) occupied.push_back(hits[a]);
    a = b;
    m = e;
  }
  return occupied;
}

/// The cells visible from observation i's position: rays all around it at a
/// fixed set of world angles (so the heading plays no part), each stopped by
/// the first occupied cell it enters beyond the clearance, that cell included.
void visibilityOf(const WorldPoints& world, int i, const Eigen::Vector3d& origin, const RegionParameters& params,
                  const CellGrid& grid, bool planar, OccupancyGrid::Reader& occupancy, RegionMarker<2>& own,
                  RegionMarker<2>& marker, std::vector<std::uint64_t>& out) {
  if (world.count(i) == 0) return;  // an observation with no point sensed nothing
  const double range = params.max_range / grid.size, clear = params.clearance / params.max_range;
  const auto o = grid.inCells<2>(origin);
  const auto [lo, hi] = boxAround<2>(o, range);
  // The observation's own surfaces block its view even where too few others
  // saw them to make them occupied: its points agree with its own pose. A
  // ray's direction is covered when one of its points lies that way.
  // Adjacent rays at most one cell apart at full range.
  const double kTwoPi = 2.0 * 3.14159265358979323846;
  const int rays = std::max(64, int(std::ceil(kTwoPi * range)));
  std::vector<char> covered(rays, 0);
  own.reset(lo, hi);
  for (const Eigen::Vector3f* p = world.begin(i); p != world.end(i); ++p)
    if (inBand(*p, origin, params, planar)) {
      const auto e = grid.inCells<2>(p->cast<double>());
      const Cell<2> c = cellOf<2>(e);
      if (c[0] >= lo[0] && c[0] <= hi[0] && c[1] >= lo[1] && c[1] <= hi[1]) own.mark(c);
      double angle = std::atan2(e[1] - o[1], e[0] - o[0]);
      if (angle < 0) angle += kTwoPi;
      covered[std::min(rays - 1, int(std::lround(angle / kTwoPi * rays)) % rays)] = 1;
    }
  marker.reset(lo, hi);
  for (int r = 0; r < rays; ++r) {
    const double angle = kTwoPi * r / rays;
    const std::array<double, 2> end{o[0] + range * std::cos(angle), o[1] + range * std::sin(angle)};
    // Where the observation looked, its own beams say what it saw: only its
    // own surfaces stop the ray, so drifted copies of other observations'
    // walls do not cut its view. Elsewhere (behind a forward laser, beside
    // a camera) the occupancy of all observations stands in for its eyes.
    const bool own_view = covered[r];
    // Only the occupied cells a ray starts among are passed, and only
    // within the clearance: once it has crossed a free cell, the next
    // occupied cell is a wall seen from inside and stops it.
    bool crossed_free = false;
    traverse<2>(o, end, [&](const Cell<2>& c, double t) {
      marker.mark(c);
      if (!own.marked(c) && (own_view || !occupancy.occupied(c))) return crossed_free = true;
      return !crossed_free && t < clear;
    });
  }
  marker.emit(out);
}

void checkParameters(const RegionParameters& p) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(p.cell_size)) throw std::invalid_argument("region cell size must be finite and > 0");
  if (!positive(p.max_range)) throw std::invalid_argument("region range must be finite and > 0");
  // 2000 cells keeps a region's bitmap (4000^2 cells in 2D) within the dense marker.
  if (p.max_range / p.cell_size > 2000)
    throw std::invalid_argument("region range is more than 2000 cells: raise the cell size or lower the range");
  if (!(std::isfinite(p.clearance) && p.clearance >= 0)) throw std::invalid_argument("clearance must be finite and >= 0");
  if (p.min_observations < 1) throw std::invalid_argument("min_observations must be >= 1");
  if (!(std::isfinite(p.band_low) && std::isfinite(p.band_high) && p.band_low < p.band_high))
    throw std::invalid_argument("height band must be finite with low < high");
}

/// True when every point and every sensor lies within a quarter cell of one
/// height: 2D data (scans whose poses carry a few mm of z included).
bool isPlanar(const WorldPoints& world, const std::vector<Eigen::Vector3d>& origins, double cell_size) {
  if (origins.empty()) return true;
  const double z0 = origins[0].z(), tolerance = 0.25 * cell_size;
  for (const auto& o : origins)
    if (std::abs(o.z() - z0) > tolerance) return false;
  for (const auto& p : world.points)
    if (std::abs(double(p.z()) - z0) > tolerance) return false;
  return true;
}

/// Refuses, naming the first observation, data whose cell indices would not
/// fit a key: a corrupt pose far from the others, never a wrapped index.
void checkReach(const WorldPoints& world, const std::vector<Eigen::Vector3d>& origins, const RegionParameters& params,
                bool volumetric) {
  const double limit =
      double((volumetric ? kBias3 : kBias2) - 4) - std::ceil(params.max_range / params.cell_size);
  const auto within = [&](const Eigen::Vector3d& p) {
    const int axes = volumetric ? 3 : 2;
    for (int a = 0; a < axes; ++a)
      if (!(std::abs(p[a] / params.cell_size) < limit)) return false;
    return true;
  };
  for (int i = 0; i < world.size(); ++i) {
    const bool ok = within(origins[i]) && (world.boxes[i].isEmpty() || (within(world.boxes[i].min().cast<double>()) &&
                                                                        within(world.boxes[i].max().cast<double>())));
    if (!ok)
      throw InvalidObservation(i, "region grid: a point lies too far from the first observation for " +
                                      std::to_string(params.cell_size) + " m cells (raise --cell)");
  }
}

}  // namespace

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

namespace {

/// Each observation's region as its own list of keys (ascending), and
/// whether they are plane cells.
struct RegionLists {
  std::vector<std::vector<std::uint64_t>> cells;
  bool planar = true;
  double cell_size = 1.0;
  Eigen::Vector3d phase = Eigen::Vector3d::Constant(0.5);
};

RegionLists regionLists(SensedSpaceModel model, const WorldPoints& world,
                        const std::vector<Eigen::Vector3d>& sensor_origins, const RegionParameters& params, int threads,
                        const InterruptFlag* interrupt) {
  if (model == SensedSpaceModel::Points)
    throw std::invalid_argument("computeRegions: the points model has no regions (use SensedSpaceOverlap)");
  checkParameters(params);
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
  std::vector<std::uint64_t> occupied;
  if (model == SensedSpaceModel::Visibility) occupied = occupiedCells(world, sensor_origins, params, cells, regions.planar, threads);
  const OccupancyGrid grid(occupied);
  std::vector<std::vector<std::uint64_t>>& per_observation = regions.cells;
  per_observation.resize(n);
  struct Scratch {
    RegionMarker<2> marker2, own_surfaces;
    RegionMarker<3> marker3;
    OccupancyGrid::Reader reader;
  };
  parallelForWithScratch(
      n, threads, 8, [&] { return Scratch{{}, {}, {}, OccupancyGrid::Reader(grid)}; },
      [&](std::size_t i, Scratch& s) {
        if (interruptRequested(interrupt)) return;
        if (model == SensedSpaceModel::Visibility)
          visibilityOf(world, static_cast<int>(i), sensor_origins[i], params, cells, regions.planar, s.reader,
                       s.own_surfaces, s.marker2, per_observation[i]);
        else if (volumetric)
          freeSpaceOf<3>(world, static_cast<int>(i), sensor_origins[i], params, cells, s.marker3, per_observation[i]);
        else
          freeSpaceOf<2>(world, static_cast<int>(i), sensor_origins[i], params, cells, s.marker2, per_observation[i]);
      });
  throwIfInterrupted(interrupt);
  regions.planar = !volumetric;
  return regions;
}

/// Which observations hold each cell, and which cells each observation
/// holds: cell c is held by watchers[cell_start[c], cell_start[c+1]);
/// observation i's cells, ascending, are cells_of[offsets[i], offsets[i+1]).
struct SharedCells {
  std::vector<std::size_t> offsets, cell_start;
  std::vector<std::uint32_t> watchers, cells_of;
};

/// Consumes `lists`: each observation's keys are freed once entered, so the
/// regions are never held twice.
SharedCells indexSharedCells(std::vector<std::vector<std::uint64_t>>& lists, int threads,
                             const InterruptFlag* interrupt) {
  const int n = static_cast<int>(lists.size());
  // Group the (cell, observation) entries by cell: one sort of all of them.
  // Packed to 12 bytes: at 100,000 observations they are the largest array.
#pragma pack(push, 4)
  struct Entry {
    std::uint64_t key;
    std::uint32_t observation;
    bool operator<(const Entry& other) const {
      return key < other.key || (key == other.key && observation < other.observation);
    }
  };
#pragma pack(pop)
  SharedCells shared;
  shared.offsets = {0};
  for (const auto& list : lists) shared.offsets.push_back(shared.offsets.back() + list.size());
  std::vector<Entry> entries(shared.offsets.back());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 64)
  for (int i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < lists[i].size(); ++k) entries[shared.offsets[i] + k] = {lists[i][k], std::uint32_t(i)};
    std::vector<std::uint64_t>().swap(lists[i]);
  }
  throwIfInterrupted(interrupt);
  sortInParallel(entries);  // distinct entries
  throwIfInterrupted(interrupt);
  shared.watchers.resize(entries.size());
  shared.cells_of.resize(entries.size());
  std::vector<std::size_t> fill(shared.offsets.begin(), shared.offsets.end() - 1);
  for (std::size_t k = 0; k < entries.size(); ++k) {
    if (k == 0 || entries[k].key != entries[k - 1].key) shared.cell_start.push_back(k);
    shared.watchers[k] = entries[k].observation;
    shared.cells_of[fill[entries[k].observation]++] = std::uint32_t(shared.cell_start.size() - 1);
  }
  shared.cell_start.push_back(entries.size());
  return shared;
}

/// For each observation, the other observations holding its cells and how
/// many. Consumes `lists`.
MatchCounts countShared(std::vector<std::vector<std::uint64_t>>& lists, int threads, const InterruptFlag* interrupt) {
  const int n = static_cast<int>(lists.size());
  const SharedCells cells = indexSharedCells(lists, threads, interrupt);
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
      for (std::size_t k = cells.offsets[i]; k < cells.offsets[i + 1]; ++k) {
        const std::uint32_t c = cells.cells_of[k];
        for (std::size_t w = cells.cell_start[c]; w < cells.cell_start[c + 1]; ++w) {
          const std::uint32_t j = cells.watchers[w];
          if (shared[j]++ == 0) touched.push_back(int(j));
        }
        tests += cells.cell_start[c + 1] - cells.cell_start[c];
      }
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

}  // namespace

ObservationRegions computeRegions(SensedSpaceModel model, const WorldPoints& world,
                                  const std::vector<Eigen::Vector3d>& sensor_origins, const RegionParameters& params,
                                  int threads, const InterruptFlag* interrupt) {
  RegionLists lists = regionLists(model, world, sensor_origins, params, threads, interrupt);
  ObservationRegions regions;
  regions.planar = lists.planar;
  regions.cell_size = lists.cell_size;
  regions.phase = lists.phase;
  for (const auto& list : lists.cells) regions.offsets.push_back(regions.offsets.back() + list.size());
  regions.cells.reserve(regions.offsets.back());
  for (auto& list : lists.cells) {
    regions.cells.insert(regions.cells.end(), list.begin(), list.end());
    std::vector<std::uint64_t>().swap(list);
  }
  return regions;
}

OverlapResult computeRegionOverlap(SensedSpaceModel model, const WorldPoints& world,
                                   const std::vector<Eigen::Vector3d>& sensor_origins, const RegionParameters& params,
                                   int threads, const InterruptFlag* interrupt) {
  RegionLists lists = regionLists(model, world, sensor_origins, params, threadCount(threads), interrupt);
  std::vector<std::size_t> sizes(lists.cells.size());
  for (std::size_t i = 0; i < sizes.size(); ++i) sizes[i] = lists.cells[i].size();
  return assembleOverlap(countShared(lists.cells, threadCount(threads), interrupt), sizes);
}


MatchCounts countSharedCells(const ObservationRegions& regions, int threads, const InterruptFlag* interrupt) {
  const int n = regions.size();
  threads = threadCount(threads);
  if (regions.offsets.empty() || regions.offsets.front() != 0 || regions.offsets.back() != regions.cells.size() ||
      !std::is_sorted(regions.offsets.begin(), regions.offsets.end()))
    throw std::invalid_argument("countSharedCells: offsets must run from 0 to the number of cells, ascending");
  for (int i = 0; i < n; ++i)
    for (std::size_t k = regions.offsets[i] + 1; k < regions.offsets[i + 1]; ++k)
      if (regions.cells[k] <= regions.cells[k - 1])
        throw std::invalid_argument("countSharedCells: the cells of observation " + std::to_string(i) +
                                    " must be ascending and distinct");
  std::vector<std::vector<std::uint64_t>> lists(n);
  for (int i = 0; i < n; ++i)
    lists[i].assign(regions.cells.begin() + regions.offsets[i], regions.cells.begin() + regions.offsets[i + 1]);
  return countShared(lists, threads, interrupt);
}

OverlapResult regionOverlap(const ObservationRegions& regions, int threads, const InterruptFlag* interrupt) {
  std::vector<std::size_t> sizes(regions.size());
  for (int i = 0; i < regions.size(); ++i) sizes[i] = regions.count(i);
  return assembleOverlap(countSharedCells(regions, threads, interrupt), sizes);
}

}  // namespace obsgroup
