#pragma once
// The cell machinery of the region models (sensed_regions.h), shared by the
// batch computation (sensed_regions.cpp) and the incremental one
// (incremental_overlap.cpp), so that both compute each observation's region
// with the same code and get the same cells. Internal: not installed.

#include "obsgroup/overlap/sensed_regions.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <unordered_map>
#include <utility>
#include <vector>

namespace obsgroup {
namespace region_cells {

/// One observation's points in the re-centred frame.
struct PointSpan {
  const Eigen::Vector3f* begin = nullptr;
  const Eigen::Vector3f* end = nullptr;
  bool empty() const { return begin == end; }
  std::size_t size() const { return std::size_t(end - begin); }
};

inline PointSpan pointsOf(const WorldPoints& world, int i) { return {world.begin(i), world.end(i)}; }

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
    forEachMarked([&out](std::uint64_t key) { out.push_back(key); });
  }
  /// Calls visit(key) for each marked cell, keys ascending.
  template <typename Visit>
  void forEachMarked(Visit&& visit) {
    if (!dense_) {
      std::sort(keys_.begin(), keys_.end());
      keys_.erase(std::unique(keys_.begin(), keys_.end()), keys_.end());
      std::sort(removed_.begin(), removed_.end());
      auto removed = removed_.begin();
      for (std::uint64_t key : keys_) {
        while (removed != removed_.end() && *removed < key) ++removed;
        if (removed == removed_.end() || *removed != key) visit(key);
      }
      return;
    }
    if constexpr (D == 2) {
      // Bits ascend, so the row (x) is found by moving on from the last
      // one's rather than by a division per cell.
      const std::uint64_t row_length = std::uint64_t(extent_[1]);
      std::uint64_t row = 0, row_start = 0;
      for (std::size_t w = 0; w < bits_.size(); ++w)
        for (std::uint64_t word = bits_[w]; word; word &= word - 1) {
          const std::uint64_t b = w * 64 + std::uint64_t(__builtin_ctzll(word));
          while (b - row_start >= row_length) ++row, row_start += row_length;
          visit(keyOf<2>(Cell<2>{lo_[0] + std::int64_t(row), lo_[1] + std::int64_t(b - row_start)}));
        }
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
        visit(keyOf<D>(c));
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

/// One segment's walk through the plane's cells (Amanatides and Woo), held
/// as a state so that walks can advance in turn (traversePair): the plane's
/// walk is the inner loop of every view and of the occupancy evidence, and
/// each step waits on the one before it. Adding 0.0 to the axis not taken
/// leaves it to the bit. (The compiler turns the selects into branches; a
/// form without branches, the step masked by bits, took the evidence of
/// 360-beam scans from 0.059 to 0.077 ms a scan in a micro-benchmark.)
class PlaneWalk {
 public:
  PlaneWalk(const std::array<double, 2>& from, const std::array<double, 2>& to) {
    x_ = std::int64_t(std::floor(from[0])), y_ = std::int64_t(std::floor(from[1]));
    last_x_ = std::int64_t(std::floor(to[0])), last_y_ = std::int64_t(std::floor(to[1]));
    const double dx = to[0] - from[0], dy = to[1] - from[1];
    step_x_ = dx > 0 ? 1 : -1, step_y_ = dy > 0 ? 1 : -1;
    step_tx_ = dx != 0 ? 1.0 / std::abs(dx) : std::numeric_limits<double>::infinity();
    step_ty_ = dy != 0 ? 1.0 / std::abs(dy) : std::numeric_limits<double>::infinity();
    next_x_ = dx != 0 ? (double(x_ + (dx > 0)) - from[0]) / dx : std::numeric_limits<double>::infinity();
    next_y_ = dy != 0 ? (double(y_ + (dy > 0)) - from[1]) / dy : std::numeric_limits<double>::infinity();
    // The budget (the cells between the end cells) bounds the walk whatever
    // the rounding of `next`.
    remaining_ = 1 + std::abs(last_x_ - x_) + std::abs(last_y_ - y_);
  }

  /// Visits the current cell (visit(cell, t) returns false to stop) and
  /// steps to the next; false once the walk has ended.
  template <typename Visit>
  bool advance(Visit& visit) {
    if (remaining_-- <= 0) return false;
    if (!visit(Cell<2>{x_, y_}, t_) || (x_ == last_x_ && y_ == last_y_)) return false;
    const bool along_y = next_y_ < next_x_;
    const double reached = along_y ? next_y_ : next_x_;
    if (reached > 1.0) return false;
    t_ = reached;
    x_ += along_y ? 0 : step_x_;
    y_ += along_y ? step_y_ : 0;
    next_x_ += along_y ? 0.0 : step_tx_;
    next_y_ += along_y ? step_ty_ : 0.0;
    return true;
  }

 private:
  std::int64_t x_, y_, last_x_, last_y_, step_x_, step_y_, remaining_;
  double next_x_, next_y_, step_tx_, step_ty_, t_ = 0.0;
};

/// Visits the cells a segment from `from` to `to` (in cell units) crosses, in
/// order (Amanatides and Woo). `visit(cell, t)` gets the parameter t in [0, 1]
/// at which the segment enters the cell and returns false to stop.
template <int D, typename Visit>
void traverse(const std::array<double, D>& from, const std::array<double, D>& to, Visit&& visit) {
  if constexpr (D == 2) {
    PlaneWalk walk(from, to);
    while (walk.advance(visit)) {
    }
    return;
  }
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

/// traverse<2> of two segments at once, their steps taken in turn so that
/// the two chains of dependent steps overlap: each segment's cells are
/// visited in its own order by its own visitor, the two sequences
/// interleaved. On the occupancy evidence of 360-beam scans the pair walks
/// took about a quarter less time than one ray after another.
template <typename VisitA, typename VisitB>
void traversePair(const std::array<double, 2>& from, const std::array<double, 2>& to_a, VisitA&& visit_a,
                  const std::array<double, 2>& to_b, VisitB&& visit_b) {
  PlaneWalk a(from, to_a), b(from, to_b);
  bool on_a = true, on_b = true;
  while (on_a && on_b) {
    on_a = a.advance(visit_a);
    on_b = b.advance(visit_b);
  }
  while (on_a) on_a = a.advance(visit_a);
  while (on_b) on_b = b.advance(visit_b);
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
void freeSpaceOf(PointSpan points, const Eigen::Vector3d& origin, const RegionParameters& params,
                 const CellGrid& grid, RegionMarker<D>& marker, std::vector<std::uint64_t>& out) {
  if (points.empty()) return;
  const double range = params.max_range / grid.size;
  const auto o = grid.inCells<D>(origin);
  // The box of the beams: the origin and every (clipped) end point.
  std::vector<std::array<double, D>> ends;
  ends.reserve(points.size());
  Cell<D> lo = cellOf<D>(o), hi = lo;
  for (const Eigen::Vector3f* p = points.begin; p != points.end; ++p) {
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
  OccupancyGrid() = default;
  explicit OccupancyGrid(const std::vector<std::uint64_t>& occupied_keys) {
    for (std::uint64_t key : occupied_keys) set(key, true);
  }
  /// Marks a plane cell (keyOf<2>) occupied or free. Readers must not run meanwhile.
  void set(std::uint64_t key, bool occupied) {
    const std::uint64_t ux = key >> 32, uy = key & 0xffffffffu;
    const std::uint64_t tile = ((ux >> 6) << 32) | (uy >> 6);
    auto [it, added] = index_.emplace(tile, std::uint32_t(tiles_.size()));
    if (added) tiles_.emplace_back(std::array<std::uint64_t, 64>{});
    auto& word = tiles_[it->second][ux & 63];
    const std::uint64_t bit = std::uint64_t(1) << (uy & 63);
    word = occupied ? (word | bit) : (word & ~bit);
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
inline bool inBand(const Eigen::Vector3f& p, const Eigen::Vector3d& origin, const RegionParameters& params, bool planar) {
  if (planar) return true;
  const double height = double(p.z()) - origin.z();
  return height >= params.band_low && height <= params.band_high;
}

/// How wide the free space is around each cell of one view's box, across
/// four axes (along x, along y and the two diagonals): the length of the run
/// of free cells through the cell, between two blocked cells. A run that
/// reaches the box's edge is open (wide). The visibility model's doors
/// (RegionParameters::door_width) are the short stretches of a ray where the
/// width across it is below a door's.
class OpeningWidths {
 public:
  static constexpr int kAxes = 4;
  /// A run that is not closed at both ends, or longer than any door
  /// (checkRegionParameters keeps door_width under 250 cells).
  static constexpr std::uint8_t kOpen = 0xff;

  /// Fills the table for the box [lo, hi]; blocked(cell) says whether a cell stops the view.
  template <typename Blocked>
  void compute(const Cell<2>& lo, const Cell<2>& hi, Blocked&& blocked) {
    lo_ = lo;
    nx_ = int(hi[0] - lo[0] + 1), ny_ = int(hi[1] - lo[1] + 1);
    const std::size_t cells = std::size_t(nx_) * std::size_t(ny_);
    blocked_.resize(cells);
    blocked_by_row_.resize(cells);
    for (int x = 0; x < nx_; ++x)
      for (int y = 0; y < ny_; ++y)
        blocked_by_row_[rowIndex(x, y)] = blocked_[index(x, y)] = blocked(Cell<2>{lo[0] + x, lo[1] + y});
    // Free cells from the run's start (forward) and to its end (backward),
    // kOpen when the run reaches the box's edge on that side.
    for (int k = 0; k < kAxes; ++k) {
      forward_[k].resize(cells);
      backward_[k].resize(cells);
      sweep(k, forward_[k], -1);
      sweep(k, backward_[k], +1);
    }
  }

  /// The free run through cell c along axis k, in cells (c included), or
  /// kOpen when it is not closed at both ends.
  std::uint32_t run(const Cell<2>& c, int k) const {
    const int x = int(c[0] - lo_[0]), y = int(c[1] - lo_[1]);
    if (x < 0 || y < 0 || x >= nx_ || y >= ny_) return kOpen;
    const std::size_t i = k == kAlongY ? rowIndex(x, y) : index(x, y);
    const std::uint8_t ahead = forward_[k][i], behind = backward_[k][i];
    if (ahead == kOpen || behind == kOpen) return kOpen;
    return std::uint32_t(ahead) + behind - 1;
  }

  /// The step of axis k, in cells.
  static std::array<int, 2> axis(int k) {
    static constexpr int steps[kAxes][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    return {steps[k][0], steps[k][1]};
  }

 private:
  /// Axis k = kAlongY is kept row by row (rowIndex), the others column by
  /// column (index): each sweep then runs along contiguous memory.
  static constexpr int kAlongY = 1;
  std::size_t index(int x, int y) const { return std::size_t(x) * std::size_t(ny_) + std::size_t(y); }
  std::size_t rowIndex(int x, int y) const { return std::size_t(y) * std::size_t(nx_) + std::size_t(x); }
  /// One pass along axis k: each free cell counts one more than its
  /// neighbour behind it (sign -1: back along the axis; +1: ahead), kOpen
  /// past the box's edge; a blocked cell is 0. The count saturates at kOpen:
  /// runs of kOpen - 1 cells and more are wider than any door.
  void sweep(int k, std::vector<std::uint8_t>& runs, int sign) {
    const auto a = axis(k);
    const int dx = sign * a[0], dy = sign * a[1];
    if (dx == 0) {
      // Along a column: rows in the order the neighbour is visited first,
      // every column at once (independent, where one column's rows are
      // not), in the row-by-row layout.
      for (int yi = 0; yi < ny_; ++yi) {
        const int y = dy > 0 ? ny_ - 1 - yi : yi;
        const char* blocked = blocked_by_row_.data() + rowIndex(0, y);
        std::uint8_t* out = runs.data() + rowIndex(0, y);
        if (y + dy < 0 || y + dy >= ny_) {
          for (int x = 0; x < nx_; ++x) out[x] = blocked[x] ? 0 : kOpen;
        } else {
          stepColumn(blocked, runs.data() + rowIndex(0, y + dy), out, nx_);
        }
      }
      return;
    }
    // Columns (x) in the order the neighbour is visited first.
    for (int xi = 0; xi < nx_; ++xi) {
      const int x = dx > 0 ? nx_ - 1 - xi : xi;
      const int px = x + dx;
      const bool column_open = px < 0 || px >= nx_;
      const char* blocked = blocked_.data() + index(x, 0);
      std::uint8_t* out = runs.data() + index(x, 0);
      // The neighbour lies in the previous column, done: rows in any order.
      if (column_open) {
        for (int y = 0; y < ny_; ++y) out[y] = blocked[y] ? 0 : kOpen;
        continue;
      }
      const std::uint8_t* before = runs.data() + index(px, 0);
      const int y_lo = std::max(0, -dy), y_hi = std::min(ny_, ny_ - dy);  // rows whose neighbour is in the box
      for (int y = 0; y < y_lo; ++y) out[y] = blocked[y] ? 0 : kOpen;
      stepColumn(blocked + y_lo, before + y_lo + dy, out + y_lo, y_hi - y_lo);
      for (int y = std::max(y_lo, y_hi); y < ny_; ++y) out[y] = blocked[y] ? 0 : kOpen;
    }
  }

  /// out[y] = 0 where blocked, else one more than before[y] (saturating at
  /// kOpen), for n cells. The lines are distinct (restrict) and the body
  /// has no branch, so that the compiler vectorises it: the sweeps are the
  /// largest part of a view's cost.
  static void stepColumn(const char* __restrict blocked, const std::uint8_t* __restrict before,
                         std::uint8_t* __restrict out, int n) {
    for (int y = 0; y < n; ++y) {
      const std::uint8_t v = before[y];
      const std::uint8_t stepped = std::uint8_t(v + std::uint8_t(v != kOpen));
      out[y] = std::uint8_t(stepped & std::uint8_t(blocked[y] == 0 ? 0xff : 0));
    }
  }

  Cell<2> lo_{};
  int nx_ = 0, ny_ = 0;
  std::vector<char> blocked_, blocked_by_row_;
  std::array<std::vector<std::uint8_t>, kAxes> forward_, backward_;
};

/// Follows one ray of the visibility model through free cells and says when
/// it has come through a door: a stretch no longer than door_depth where the
/// free space across the ray is narrower than door_width, entered from and
/// left into wider space. A long narrow stretch is a passage, not a door. A
/// ray that starts in a narrow spot (a pose in a doorway) goes on into the
/// wide space it meets, unless told that this is the far side
/// (startInDoorway).
class DoorCrossing {
 public:
  /// For a ray of unit direction (cos, sin of its angle).
  DoorCrossing(const RegionParameters& params, double cell_size, const std::array<double, 2>& direction)
      : depth_(params.door_depth / cell_size) {
    const double width = params.door_width / cell_size;  // in cells
    const double dx = direction[0], dy = direction[1];
    for (int k = 0; k < OpeningWidths::kAxes; ++k) {
      const auto a = OpeningWidths::axis(k);
      const double length = std::hypot(double(a[0]), double(a[1]));
      // Across the ray: the axes at least 45 degrees from its direction.
      if (std::abs(a[0] * dx + a[1] * dy) / length <= std::sqrt(0.5) + 1e-9) {
        // A run of r cells is narrower than a door when r * length < width:
        // true below the first r for which it is false (at most width + 1,
        // under 252 cells), found with the same products, so that the walk
        // compares integers and decides exactly as the products would.
        std::uint32_t narrow_below = 0;
        while (double(narrow_below) * length < width) ++narrow_below;
        across_[count_++] = {k, narrow_below};
      }
    }
  }
  /// The ray starts in a doorway and leaves it on the far side from the
  /// pose: the first wide cell is beyond the door.
  void startInDoorway() { state_ = State::kInDoor, narrow_cells_ = 0; }
  /// Whether the free space across the ray is narrower than a door at c.
  bool narrowAt(const Cell<2>& c, const OpeningWidths& widths) const {
    for (int j = 0; j < count_; ++j) {
      const std::uint32_t run = widths.run(c, across_[j].axis);
      if (run != OpeningWidths::kOpen && run < across_[j].narrow_below) return true;
    }
    return false;
  }

  /// Called with each free cell the ray enters, in order; true once the ray
  /// has come through a door into wide space (that cell is its last).
  bool throughDoor(const Cell<2>& c, const OpeningWidths& widths) {
    if (!narrowAt(c, widths)) {
      const bool through = state_ == State::kInDoor;
      state_ = State::kWide;
      return through;
    }
    if (state_ == State::kWide) state_ = State::kInDoor, narrow_cells_ = 0;
    if (state_ == State::kInDoor && ++narrow_cells_ > depth_) state_ = State::kNarrow;
    return false;
  }

 private:
  enum class State { kNarrow, kWide, kInDoor };
  struct Across {
    int axis;
    std::uint32_t narrow_below;  ///< runs of fewer cells are narrower than a door along this axis
  };
  double depth_;
  std::array<Across, OpeningWidths::kAxes> across_{};
  int count_ = 0;
  State state_ = State::kNarrow;
  int narrow_cells_ = 0;
};

/// The opening widths of one view, and scratch for its rays: by its own
/// surfaces (for the rays it saw along, as its own surfaces alone stop them)
/// and by its own and the shared occupied cells (for the others).
struct ViewWidths {
  OpeningWidths own, shared;
  std::vector<int> to_wide;  ///< per ray: narrow cells before its first wide one (-1: none)
  /// Per ray, its unit direction (cos, sin of its angle), for `rays` rays.
  std::vector<std::array<double, 2>> directions;
  int rays = 0;
  /// Per ray, its DoorCrossing before the walk, for `rays` rays and the
  /// door width and depth and cell size of `doors_for`: the same for every
  /// view of a run, made once per thread.
  std::vector<DoorCrossing> doors;
  std::array<double, 3> doors_for{};
  /// Whether the last view read the shared occupancy: false when every ray
  /// had a point of the observation's own that way, and the view then
  /// depends on its own points alone (online grouping need not recompute it
  /// when others flip cells).
  bool read_occupancy = false;
  /// The cells whose shared occupancy the last view depended on, as a box
  /// (read_lo > read_hi on an axis: none): every cell its rays that read the
  /// shared occupancy entered, grown by the reach of a door-width run
  /// (OpeningWidths::run at a cell is narrower than a door or not by the
  /// cells within that many steps of it). A cell flipped outside it cannot
  /// change the view.
  Cell<2> read_lo{}, read_hi{};
};

/// The cells visible from observation i's position: rays all around it at a
/// fixed set of world angles (so the heading plays no part), each stopped by
/// the first occupied cell it enters beyond the clearance, that cell included.
inline void visibilityOf(PointSpan points, const Eigen::Vector3d& origin, const RegionParameters& params,
                         const CellGrid& grid, bool planar, OccupancyGrid::Reader& occupancy, RegionMarker<2>& own,
                         RegionMarker<2>& marker, ViewWidths& widths, std::vector<std::uint64_t>& out) {
  widths.read_occupancy = false;
  widths.read_lo = {1, 1}, widths.read_hi = {0, 0};
  if (points.empty()) return;  // an observation with no point sensed nothing
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
  for (const Eigen::Vector3f* p = points.begin; p != points.end; ++p)
    if (inBand(*p, origin, params, planar)) {
      const auto e = grid.inCells<2>(p->cast<double>());
      const Cell<2> c = cellOf<2>(e);
      if (c[0] >= lo[0] && c[0] <= hi[0] && c[1] >= lo[1] && c[1] <= hi[1]) own.mark(c);
      double angle = std::atan2(e[1] - o[1], e[0] - o[0]);
      if (angle < 0) angle += kTwoPi;
      covered[std::min(rays - 1, int(std::lround(angle / kTwoPi * rays)) % rays)] = 1;
    }
  // An uncovered ray reads the shared occupancy: on its walk, and through
  // the shared widths table when doors are on.
  widths.read_occupancy = std::find(covered.begin(), covered.end(), 0) != covered.end();
  const bool doors = params.door_width > 0;
  if (doors) {
    // Each table only when a ray reads it: a 360-degree scan covers every
    // ray, and never needs the shared one.
    const bool any_own = std::find(covered.begin(), covered.end(), 1) != covered.end();
    const bool any_shared = std::find(covered.begin(), covered.end(), 0) != covered.end();
    if (any_shared)
      widths.shared.compute(lo, hi, [&](const Cell<2>& c) { return own.marked(c) || occupancy.occupied(c); });
    if (any_own) widths.own.compute(lo, hi, [&](const Cell<2>& c) { return own.marked(c); });
  }
  // Walks ray r through the cells it sees, calling free_cell(cell) on each
  // free one (false stops it) and seen(cell) on every cell.
  if (widths.rays != rays) {  // the same for every view of a run: computed once per thread
    widths.directions.resize(rays);
    for (int r = 0; r < rays; ++r) {
      const double angle = kTwoPi * r / rays;
      widths.directions[r] = {std::cos(angle), std::sin(angle)};
    }
    widths.rays = rays;
  }
  const std::array<double, 3> doors_for{params.door_width, params.door_depth, grid.size};
  if (widths.doors.size() != std::size_t(rays) || widths.doors_for != doors_for) {
    widths.doors.clear();
    for (int r = 0; r < rays; ++r) widths.doors.emplace_back(params, grid.size, widths.directions[r]);
    widths.doors_for = doors_for;
  }
  const auto& directions = widths.directions;
  const auto ray_end = [&](int r) {
    return std::array<double, 2>{o[0] + range * directions[r][0], o[1] + range * directions[r][1]};
  };
  struct ReadBox {
    Cell<2> lo{std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::max()};
    Cell<2> hi{std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::min()};
    void add(const Cell<2>& c) {
      lo = {std::min(lo[0], c[0]), std::min(lo[1], c[1])};
      hi = {std::max(hi[0], c[0]), std::max(hi[1], c[1])};
    }
  } read_box;
  // The visitor of ray r's walk through the cells it sees: free_cell(cell,
  // widths) on each free one (false stops it), seen(cell) on every cell.
  const auto ray_visitor = [&](int r, auto& free_cell, auto& seen) {
    // Where the observation looked, its own beams say what it saw: only its
    // own surfaces stop the ray, so drifted copies of other observations'
    // walls do not cut its view. Elsewhere (behind a forward laser, beside
    // a camera) the occupancy of all observations stands in for its eyes.
    const bool own_view = covered[r] != 0;
    const OpeningWidths* ray_widths = own_view ? &widths.own : &widths.shared;
    // Only the occupied cells a ray starts among are passed, and only
    // within the clearance: once it has crossed a free cell, the next
    // occupied cell is a wall seen from inside and stops it.
    return [&free_cell, &seen, &own, &occupancy, clear, own_view, ray_widths, &reads = read_box, crossed_free = false](
               const Cell<2>& c, double t) mutable {
      seen(c);
      if (!own_view) reads.add(c);
      if (!own.marked(c) && (own_view || !occupancy.occupied(c))) {
        crossed_free = true;
        return bool(free_cell(c, *ray_widths));
      }
      return !crossed_free && t < clear;
    };
  };
  // Walks every ray: walk_two(r, q) for two at a time (traversePair), their
  // cells marked in any order; walk_one(r) for an odd last one.
  const auto walk_rays = [&](auto&& walk_one, auto&& walk_two) {
    int r = 0;
    for (; r + 1 < rays; r += 2) walk_two(r, r + 1);
    if (r < rays) walk_one(r);
  };
  const auto ignore = [](const Cell<2>&) {};
  // A pose in a doorway (its rays start narrow) stands on the side whose
  // wide space is nearer: each ray's narrow cells before its first wide one,
  // -1 when it never reaches wide space.
  std::vector<int>& to_wide = widths.to_wide;
  if (doors) {
    to_wide.assign(rays, -1);
    const auto probe = [&](int r, int& narrow) {
      return [&widths, &to_wide, &narrow, r](const Cell<2>& c, const OpeningWidths& w) {
        if (widths.doors[r].narrowAt(c, w)) {
          ++narrow;
          return true;
        }
        to_wide[r] = narrow;
        return false;
      };
    };
    walk_rays(
        [&](int r) {
          int narrow = 0;
          auto free_cell = probe(r, narrow);
          traverse<2>(o, ray_end(r), ray_visitor(r, free_cell, ignore));
        },
        [&](int r, int q) {
          int narrow_r = 0, narrow_q = 0;
          auto free_r = probe(r, narrow_r);
          auto free_q = probe(q, narrow_q);
          traversePair(o, ray_end(r), ray_visitor(r, free_r, ignore), ray_end(q), ray_visitor(q, free_q, ignore));
        });
  }
  marker.reset(lo, hi);
  // A ray that comes through a door stops in the first wide cell beyond
  // it: the view is of the place the observation stands in. From a
  // doorway, the far side is beyond the door.
  const auto door_of = [&](int r) {
    DoorCrossing door = widths.doors[r];
    if (doors) {
      const int opposite = to_wide[(r + rays / 2) % rays];
      // More than one cell nearer: a pose in the middle of the doorway sees both sides.
      if (to_wide[r] > 0 && opposite >= 0 && opposite + 1 < to_wide[r]) door.startInDoorway();
    }
    return door;
  };
  const auto stop_at_door = [doors](DoorCrossing& door) {
    return [&door, doors](const Cell<2>& c, const OpeningWidths& w) { return !doors || !door.throughDoor(c, w); };
  };
  auto mark = [&marker](const Cell<2>& c) { marker.mark(c); };
  walk_rays(
      [&](int r) {
        DoorCrossing door = door_of(r);
        auto free_cell = stop_at_door(door);
        traverse<2>(o, ray_end(r), ray_visitor(r, free_cell, mark));
      },
      [&](int r, int q) {
        DoorCrossing door_r = door_of(r), door_q = door_of(q);
        auto free_r = stop_at_door(door_r);
        auto free_q = stop_at_door(door_q);
        traversePair(o, ray_end(r), ray_visitor(r, free_r, mark), ray_end(q), ray_visitor(q, free_q, mark));
      });
  marker.emit(out);
  if (read_box.lo[0] <= read_box.hi[0]) {
    // A run is narrower than a door by the cells within door_width / cell
    // (+ 1 for rounding) steps of the cell it is read at, diagonal steps
    // included (DoorCrossing's narrow_below).
    const std::int64_t reach = doors ? std::int64_t(std::ceil(params.door_width / grid.size)) + 1 : 0;
    // Runs end at the view's box (OpeningWidths::kOpen beyond it).
    widths.read_lo = {std::max(lo[0], read_box.lo[0] - reach), std::max(lo[1], read_box.lo[1] - reach)};
    widths.read_hi = {std::min(hi[0], read_box.hi[0] + reach), std::min(hi[1], read_box.hi[1] + reach)};
  }
}

/// Scratch of occupancyEvidence, reused across observations.
struct EvidenceScratch {
  RegionMarker<2> marker;
  std::vector<Cell<2>> ends;
  std::vector<std::array<double, 2>> targets;
};

/// One observation's evidence for the occupancy grid: the plane cells its
/// points (in the band) lie in, and the cells its beams cross within range
/// without ending there, both ascending.
/// Each key is passed once, in ascending order: hit(key), then crossed(key).
template <typename OnHit, typename OnCrossed>
void occupancyEvidence(PointSpan points, const Eigen::Vector3d& origin, const RegionParameters& params,
                       const CellGrid& grid, bool planar, EvidenceScratch& s, OnHit&& hit, OnCrossed&& crossed) {
  if (points.empty()) return;
  const double range = params.max_range / grid.size;
  s.ends.clear();
  s.targets.clear();
  const auto o = grid.inCells<2>(origin);
  Cell<2> lo = cellOf<2>(o), hi = lo;
  for (const Eigen::Vector3f* p = points.begin; p != points.end; ++p) {
    if (!inBand(*p, origin, params, planar)) continue;
    std::array<double, 2> e = grid.inCells<2>(p->cast<double>());
    s.ends.push_back(cellOf<2>(e));
    // The beam counts as seeing through the cells it crosses within range.
    // Most points lie within range: std::hypot (slow, and the clipping's
    // length as before) only where the squares leave a doubt.
    const double dx = e[0] - o[0], dy = e[1] - o[1];
    if (dx * dx + dy * dy > range * range * (1.0 - 1e-9)) {
      const double length = std::hypot(dx, dy);
      if (length > range)
        for (int a = 0; a < 2; ++a) e[a] = o[a] + (e[a] - o[a]) * (range / length);
    }
    s.targets.push_back(e);
    const Cell<2> t = cellOf<2>(e);
    for (int a = 0; a < 2; ++a)
      lo[a] = std::min({lo[a], t[a], s.ends.back()[a]}), hi[a] = std::max({hi[a], t[a], s.ends.back()[a]});
  }
  s.marker.reset(lo, hi);
  for (const Cell<2>& c : s.ends) s.marker.mark(c);
  s.marker.forEachMarked(hit);
  s.marker.reset(lo, hi);
  const auto mark = [&](const Cell<2>& c, double) {
    s.marker.mark(c);
    return true;
  };
  std::size_t k = 0;
  for (; k + 1 < s.targets.size(); k += 2) traversePair(o, s.targets[k], mark, s.targets[k + 1], mark);
  if (k < s.targets.size()) traverse<2>(o, s.targets[k], mark);
  for (const Cell<2>& c : s.ends) s.marker.unmark(c);  // a surface it saw is not a cell it saw through
  s.marker.forEachMarked(crossed);
}

/// occupancyEvidence as two lists of keys, ascending.
inline void occupancyEvidence(PointSpan points, const Eigen::Vector3d& origin, const RegionParameters& params,
                              const CellGrid& grid, bool planar, EvidenceScratch& s, std::vector<std::uint64_t>& hit,
                              std::vector<std::uint64_t>& crossed) {
  occupancyEvidence(
      points, origin, params, grid, planar, s, [&hit](std::uint64_t key) { hit.push_back(key); },
      [&crossed](std::uint64_t key) { crossed.push_back(key); });
}

/// Whether a cell with this evidence is occupied (RegionParameters::min_observations).
inline bool occupiedBy(std::size_t hits, std::size_t misses, const RegionParameters& params) {
  return hits >= std::size_t(params.min_observations) && hits >= misses;
}

/// True when the sensor and every point lie within `tolerance` of height z0
/// (one observation of planar, 2D data).
inline bool observationPlanar(PointSpan points, const Eigen::Vector3d& origin, double z0, double tolerance) {
  if (std::abs(origin.z() - z0) > tolerance) return false;
  for (const Eigen::Vector3f* p = points.begin; p != points.end; ++p)
    if (std::abs(double(p->z()) - z0) > tolerance) return false;
  return true;
}

/// Whether an observation's cell indices fit a key (2D or 3D): its sensor
/// and its points' box within the key's range, less the region's reach.
inline bool withinReach(const Eigen::Vector3d& origin, const Eigen::AlignedBox3f& box, const RegionParameters& params,
                        bool volumetric) {
  const double limit = double((volumetric ? kBias3 : kBias2) - 4) - std::ceil(params.max_range / params.cell_size);
  const auto within = [&](const Eigen::Vector3d& p) {
    const int axes = volumetric ? 3 : 2;
    for (int a = 0; a < axes; ++a)
      if (!(std::abs(p[a] / params.cell_size) < limit)) return false;
    return true;
  };
  return within(origin) &&
         (box.isEmpty() || (within(box.min().cast<double>()) && within(box.max().cast<double>())));
}

/// The message of an observation outside withinReach.
inline std::string reachMessage(const RegionParameters& params) {
  return "region grid: a point lies too far from the first observation for " + std::to_string(params.cell_size) +
         " m cells (raise --cell)";
}

}  // namespace region_cells
}  // namespace obsgroup
