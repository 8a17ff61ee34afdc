#include "obsgroup/places/place_map.h"

#include "obsgroup/common/parallel_for.h"
#include "obsgroup/partition/open_floor.h"
#include "../overlap/region_cells.h"

#include <Eigen/Eigenvalues>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <list>
#include <map>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace obsgroup {

Eigen::Vector2i FloorGrid::cellOf(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d cell = ((p - origin) / resolution).array().floor();
  const double limit = double(std::numeric_limits<int>::max() / 2);
  return cell.cwiseMax(-limit).cwiseMin(limit).cast<int>();
}

Eigen::Vector2d FloorGrid::cellCentre(int i, int j) const {
  return origin + resolution * Eigen::Vector2d(i + 0.5, j + 0.5);
}

namespace {

constexpr int kNone = -1;

/// The grid over the region cells (plus a border of one cell), in the
/// re-centred frame of the regions, and the world frame. Every position is
/// put in a cell by one expression, from `base`, so a point on a cell edge
/// falls in the same cell whoever asks.
struct GridFrame {
  FloorGrid grid;
  Eigen::Vector2d base = Eigen::Vector2d::Zero();  // a region cell's corner, re-centred
  Eigen::Vector2i first = Eigen::Vector2i::Zero();  // the grid's cell (0, 0), in cells from `base`
  int cellX(double x) const { return cellFrom(x, base.x()) - first.x(); }
  int cellY(double y) const { return cellFrom(y, base.y()) - first.y(); }
  /// The grid index of (x, y), or nothing outside the grid.
  std::optional<std::size_t> indexOf(double x, double y) const {
    const int i = cellX(x), j = cellY(y);
    if (!grid.contains(i, j)) return std::nullopt;
    return grid.index(i, j);
  }

 private:
  int cellFrom(double v, double b) const {
    const double cell = std::floor((v - b) / grid.resolution);
    return int(std::max(-1.0e9, std::min(1.0e9, cell)));  // far points stay outside, no overflow
  }
};

/// The grid over the regions' cells and a border of one cell: the floor
/// lies in the regions, and an obstacle beyond them (a far return) says
/// nothing of any place. `caller` names the function in the message of a
/// grid too large.
GridFrame makeGrid(const ObservationRegions& regions, const Eigen::Vector3d& world_origin, const std::string& caller) {
  const double cs = regions.cell_size;
  GridFrame f;
  f.grid.resolution = cs;
  if (regions.empty()) return f;
  // Cell edges where the regions' are: a corner half a cell below a region cell's centre.
  const Eigen::Vector3d first = regions.cellCentre(regions.firstKey());
  f.base = Eigen::Vector2d(first.x() - cs / 2, first.y() - cs / 2);
  // The extreme cells by their keys: cellX and cellY grow with a cell's coordinates.
  Eigen::Vector3d lowest, highest;
  regions.planeBounds(lowest, highest);
  const Eigen::Vector2i lo(f.cellX(lowest.x()), f.cellY(lowest.y()));  // `first` is still (0, 0)
  const Eigen::Vector2i hi(f.cellX(highest.x()), f.cellY(highest.y()));
  const Eigen::Vector2d size = (hi - lo).cast<double>() + Eigen::Vector2d::Constant(3);
  if (size.x() * size.y() > 4.0e8)
    throw std::invalid_argument(caller + ": the floor grid would have more than 400 million cells of " +
                                std::to_string(cs) + " m");
  f.first = lo - Eigen::Vector2i::Ones();
  f.grid.width = int(size.x());
  f.grid.height = int(size.y());
  f.grid.origin = Eigen::Vector2d(world_origin.x(), world_origin.y()) + f.base + cs * f.first.cast<double>();
  return f;
}

/// The most bytes of per-thread tables over the grid a thread may take:
/// beyond it the work runs on fewer threads (one at the least).
constexpr std::size_t kMaxCopiedBytes = std::size_t(1) << 28;

/// What the beams say of a cell, as bits: one crossed it, a point lies in
/// it, a point within the obstacle band lies in it.
enum CellSeen : std::uint8_t { kCrossed = 1, kPoint = 2, kPointInBand = 4 };

/// One beam's walk through the grid's cells (Amanatides & Woo), from the
/// sensor's cell up to, not into, the cell of its point.
struct BeamWalk {
  int x, y, step_x, step_y, steps;
  double next_x, next_y, delta_x, delta_y;

  /// `s` and `e`: the sensor and the point in cells of the grid.
  BeamWalk(double sx, double sy, double ex, double ey, const FloorGrid& g) {
    x = int(std::floor(sx)), y = int(std::floor(sy));
    const int end_x = int(std::floor(ex)), end_y = int(std::floor(ey));
    const double dx = ex - sx, dy = ey - sy;
    step_x = dx > 0 ? 1 : -1, step_y = dy > 0 ? 1 : -1;
    const double inf = std::numeric_limits<double>::infinity();
    delta_x = dx != 0 ? std::abs(1 / dx) : inf, delta_y = dy != 0 ? std::abs(1 / dy) : inf;
    next_x = dx != 0 ? (dx > 0 ? std::floor(sx) + 1 - sx : sx - std::floor(sx)) * delta_x : inf;
    next_y = dy != 0 ? (dy > 0 ? std::floor(sy) + 1 - sy : sy - std::floor(sy)) * delta_y : inf;
    // Beyond the grid a ray marks nothing: stop where it leaves for good.
    steps = std::min(std::abs(end_x - x) + std::abs(end_y - y), 2 * (g.width + g.height) + 4);
  }
  /// Marks the current cell crossed and moves to the next.
  void step(const FloorGrid& g, std::uint8_t* seen) {
    if (g.contains(x, y)) seen[g.index(x, y)] |= kCrossed;
    if (next_x < next_y) {
      next_x += delta_x;
      x += step_x;
    } else {
      next_y += delta_y;
      y += step_y;
    }
    --steps;
  }
};

/// Marks in `seen` the cells a beam of an observation crosses on its way
/// from the sensor to a point (seen from above; the point's own cell
/// excluded), and the cells its points lie in. Two beams are walked at
/// once: each step of a walk waits on the one before it, and two walks in
/// turn overlap in the processor. Each beam's cells are its own walk's, so
/// the bits are the same as one beam after another.
void markBeams(const GridFrame& f, region_cells::PointSpan points, const Eigen::Vector3d& sensor,
               const PlaceOptions& options, std::vector<std::uint8_t>& seen) {
  const FloorGrid& g = f.grid;
  // Positions in cells of the grid, as GridFrame::cellX/cellY put them.
  const Eigen::Vector2d corner = f.base + g.resolution * f.first.cast<double>();
  const double sx = (sensor.x() - corner.x()) / g.resolution;
  const double sy = (sensor.y() - corner.y()) / g.resolution;
  std::uint8_t* cells = seen.data();
  const auto beamTo = [&](const Eigen::Vector3f& p) {
    if (const auto k = f.indexOf(p.x(), p.y())) {
      const double height = double(p.z()) - sensor.z();
      cells[*k] |= std::uint8_t(kPoint | (height >= options.band_low && height <= options.band_high ? kPointInBand : 0));
    }
    return BeamWalk(sx, sy, (double(p.x()) - corner.x()) / g.resolution, (double(p.y()) - corner.y()) / g.resolution,
                    g);
  };
  const std::ptrdiff_t count = points.end - points.begin;
  std::ptrdiff_t k = 0;
  for (; k + 1 < count; k += 2) {
    BeamWalk a = beamTo(points.begin[k]), b = beamTo(points.begin[k + 1]);
    while (a.steps > 0 && b.steps > 0) {
      a.step(g, cells);
      b.step(g, cells);
    }
    while (a.steps > 0) a.step(g, cells);
    while (b.steps > 0) b.step(g, cells);
  }
  if (k < count)
    for (BeamWalk a = beamTo(points.begin[k]); a.steps > 0;) a.step(g, cells);
}

/// What every observation's beams say of each cell (CellSeen bits), in one
/// pass over the observations, each asked for its points once: every
/// thread marks its own grid, OR-ed together (the same cells for any thread
/// count). A grid too large to copy per thread is marked on one. `planar`
/// is whether the sensors and points all lie at the first sensor's height
/// (isPlanarData). Rethrows what points_of throws.
std::vector<std::uint8_t> seenCells(const GridFrame& f, const PlacePointSource& points_of,
                                    const std::vector<Eigen::Vector3d>& sensors, double cell_size,
                                    const PlaceOptions& options, bool& planar, int threads_asked,
                                    const InterruptFlag* interrupt) {
  const std::size_t cells = std::size_t(f.grid.width) * std::size_t(f.grid.height);
  const int n = int(sensors.size());
  const int threads = std::max(1, std::min({threadCount(threads_asked), n, int(kMaxCopiedBytes / std::max<std::size_t>(cells, 1))}));
  std::list<std::vector<std::uint8_t>> seen;  // one per thread; a list, so that each stays where it was made
  std::mutex seen_mutex;
  struct Scratch {
    std::vector<std::uint8_t>* seen;
    std::vector<Eigen::Vector3f> points;
  };
  std::vector<char> flat(std::size_t(n), 1);
  const double z0 = n > 0 ? sensors[0].z() : 0.0;
  parallelForWithScratch(
      std::size_t(n), threads, 16,
      [&] {
        std::lock_guard<std::mutex> lock(seen_mutex);
        seen.emplace_back(cells, std::uint8_t(0));
        return Scratch{&seen.back(), {}};
      },
      [&](std::size_t i, Scratch& s) {
        throwIfInterrupted(interrupt);
        const auto [begin, end] = points_of(int(i), s.points);
        const region_cells::PointSpan span{begin, end};
        flat[i] = region_cells::observationPlanar(span, sensors[i], z0, 0.25 * cell_size);
        markBeams(f, span, sensors[i], options, *s.seen);
      });
  planar = std::all_of(flat.begin(), flat.end(), [](char c) { return c != 0; });
  if (seen.empty()) return std::vector<std::uint8_t>(cells, 0);
  for (auto other = std::next(seen.begin()); other != seen.end(); ++other)
    for (std::size_t k = 0; k < cells; ++k) seen.front()[k] |= (*other)[k];
  return std::move(seen.front());
}

/// The grid cell of a region cell's key (3D voxels fall on the cell below
/// them), from the key's integer coordinates: the grid's cell edges are the
/// regions' (makeGrid), so a cell's offset from the first region cell is its
/// offset in the grid. No index per region cell is stored.
class FloorCellOfKey {
 public:
  FloorCellOfKey(const ObservationRegions& regions, const GridFrame& f)
      : x_shift_(regions.planar ? 32 : 42), y_shift_(regions.planar ? 0 : 21),
        y_mask_(regions.planar ? 0xffffffffu : (std::uint64_t(1) << 21) - 1), grid_(f.grid) {
    const std::uint64_t first = regions.firstKey();
    x0_ = std::int64_t(first >> x_shift_) + f.first.x();
    y0_ = std::int64_t((first >> y_shift_) & y_mask_) + f.first.y();
  }
  std::size_t operator()(std::uint64_t key) const {
    return grid_.index(int(std::int64_t(key >> x_shift_) - x0_), int(std::int64_t((key >> y_shift_) & y_mask_) - y0_));
  }

 private:
  int x_shift_, y_shift_;
  std::uint64_t y_mask_;
  const FloorGrid& grid_;
  std::int64_t x0_ = 0, y0_ = 0;
};

/// Per floor cell, the group the largest share of whose observations hold
/// it (ties: the lower group), or kNone. Each thread takes its share of the
/// groups, each group counting its observations per cell once (a 3D
/// region's voxels above one cell count once), so no sort of all the cells
/// is needed; the threads' owners are then merged by the same exact rule,
/// which does not depend on the order the groups were taken in, so the
/// owners are the same for any thread count.
std::vector<int> ownerOfCells(const ObservationRegions& regions, const FloorCellOfKey& cell_of,
                              const std::vector<std::vector<int>>& groups, const std::vector<Occupancy>& occupancy) {
  const std::size_t cells = occupancy.size();
  // Plane cells of one region are distinct; voxels stacked above a cell are not.
  const bool stacked = !regions.planar;
  // Group g's share count / size beats group h's: compared exactly, ties to the lower group.
  const auto beats = [&](std::uint64_t count, int g, std::uint64_t best_count, int h) {
    if (h == kNone) return true;
    const std::uint64_t a = count * groups[std::size_t(h)].size(), b = best_count * groups[std::size_t(g)].size();
    return a > b || (a == b && g < h);
  };
  struct Owners {
    std::vector<int> owner;
    std::vector<std::uint32_t> best_count, count, seen_by, touched;
    std::uint32_t stamp = 0;  // which observation last counted a cell (its position + 1)
  };
  const std::size_t bytes_per_thread = std::max<std::size_t>(1, cells * (stacked ? 16 : 12));
  const int threads = std::max(1, std::min({omp_get_max_threads(), int(groups.size()),
                                            int(kMaxCopiedBytes / bytes_per_thread)}));
  std::list<Owners> per_thread;  // a list, so that each stays where it was made
  std::mutex per_thread_mutex;
  parallelForWithScratch(
      groups.size(), threads, 1,
      [&] {
        std::lock_guard<std::mutex> lock(per_thread_mutex);
        Owners& o = per_thread.emplace_back();
        o.owner.assign(cells, kNone);
        o.best_count.assign(cells, 0);
        o.count.assign(cells, 0);
        if (stacked) o.seen_by.assign(cells, 0);
        return &o;
      },
      [&](std::size_t g, Owners* o) {
        o->touched.clear();
        for (int i : groups[g]) {
          ++o->stamp;
          regions.forEachCell(i, [&](std::uint64_t key) {
            const std::size_t c = cell_of(key);
            if (stacked) {
              if (o->seen_by[c] == o->stamp) return;  // another voxel of this observation above the cell
              o->seen_by[c] = o->stamp;
            }
            if (o->count[c]++ == 0) o->touched.push_back(std::uint32_t(c));
          });
        }
        for (std::uint32_t c : o->touched) {
          if (occupancy[c] == Occupancy::Free && beats(o->count[c], int(g), o->best_count[c], o->owner[c])) {
            o->owner[c] = int(g);
            o->best_count[c] = o->count[c];
          }
          o->count[c] = 0;
        }
      });
  if (per_thread.empty()) return std::vector<int>(cells, kNone);
  Owners& merged = per_thread.front();
  for (auto other = std::next(per_thread.begin()); other != per_thread.end(); ++other)
    for (std::size_t c = 0; c < cells; ++c)
      if (other->owner[c] != kNone &&
          beats(other->best_count[c], other->owner[c], merged.best_count[c], merged.owner[c])) {
        merged.owner[c] = other->owner[c];
        merged.best_count[c] = other->best_count[c];
      }
  return std::move(merged.owner);
}

/// The free cell an observation stands in goes to its own group (to the
/// group of most observations standing in it; ties: the lower group): the
/// place a scan was taken in holds its pose, even where the floor around a
/// doorway or a corridor's cut is held by more of the next group's views.
void keepPoseCells(const GridFrame& f, const std::vector<Occupancy>& occupancy,
                   const std::vector<std::vector<int>>& groups, const std::vector<Eigen::Vector3d>& sensor_origins,
                   std::vector<int>& label) {
  std::vector<std::pair<std::size_t, int>> standing;  // (cell, group)
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (int i : groups[g])
      if (const auto k = f.indexOf(sensor_origins[std::size_t(i)].x(), sensor_origins[std::size_t(i)].y());
          k && occupancy[*k] == Occupancy::Free)
        standing.emplace_back(*k, int(g));
  std::sort(standing.begin(), standing.end());
  for (std::size_t a = 0; a < standing.size();) {
    std::size_t best_count = 0;
    int best = kNone;
    std::size_t b = a;
    while (b < standing.size() && standing[b].first == standing[a].first) {
      std::size_t e = b;
      while (e < standing.size() && standing[e] == standing[b]) ++e;
      if (e - b > best_count) best_count = e - b, best = standing[b].second;
      b = e;
    }
    label[standing[a].first] = best;
    a = b;
  }
}

/// Numbers the 4-connected components of the cells for which in(cell) holds,
/// each of one label, into `component` (-1 elsewhere), calling
/// visit(component, cell) on each cell as the fill reaches it; returns their
/// count.
template <typename In, typename Visit>
int componentsOf(const FloorGrid& g, const std::vector<int>& label, In&& in, std::vector<int>& component,
                 Visit&& visit) {
  component.assign(label.size(), -1);
  int count = 0;
  std::vector<std::size_t> stack;
  for (std::size_t start = 0; start < label.size(); ++start) {
    if (component[start] >= 0 || !in(start)) continue;
    component[start] = count;
    stack.assign(1, start);
    while (!stack.empty()) {
      const std::size_t c = stack.back();
      stack.pop_back();
      visit(count, c);
      const int i = int(c % std::size_t(g.width)), j = int(c / std::size_t(g.width));
      const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
      for (int n = 0; n < 4; ++n) {
        if (!g.contains(i + di[n], j + dj[n])) continue;
        const std::size_t d = g.index(i + di[n], j + dj[n]);
        if (component[d] < 0 && label[d] == label[start] && in(d)) {
          component[d] = count;
          stack.push_back(d);
        }
      }
    }
    ++count;
  }
  return count;
}

template <typename In>
int componentsOf(const FloorGrid& g, const std::vector<int>& label, In&& in, std::vector<int>& component) {
  return componentsOf(g, label, in, component, [](int, std::size_t) {});
}

/// Drops the floor a place holds only beyond a neck of two cells or less
/// that none of its observations stood beyond: the fans its scans saw
/// through a door at a slant, into rooms they did not enter (the visibility
/// model stops a ray in the first wide cell past a door, but measures a door
/// across the ray, so a ray crossing one at more than 45 degrees from its
/// normal does not see it narrow). A place's *core* is its cells whose four
/// neighbours are its own; the core's pieces within one cell of a cell where
/// one of its observations stands are kept, with the cells next to them;
/// the cells next to its other core pieces go, and then each piece of what
/// is left that touches neither. A place none of whose core pieces is near
/// its poses (a corridor two cells wide) keeps its floor. Five bytes a cell
/// (a flag byte and one component number), fewer than the owners took.
void dropFloorBeyondNecks(const GridFrame& f, const std::vector<std::vector<int>>& groups,
                          const std::vector<Eigen::Vector3d>& sensor_origins, std::vector<int>& label) {
  enum : std::uint8_t { kCore = 1, kSeed = 2, kNearKept = 4, kGone = 8 };
  const FloorGrid& g = f.grid;
  const std::size_t cells = label.size();
  const int di[5] = {0, 1, -1, 0, 0}, dj[5] = {0, 0, 0, 1, -1};  // the cell and its four neighbours
  const auto around = [&](std::size_t c, auto&& visit) {
    const int i = int(c % std::size_t(g.width)), j = int(c / std::size_t(g.width));
    for (int n = 0; n < 5; ++n)
      if (g.contains(i + di[n], j + dj[n])) visit(g.index(i + di[n], j + dj[n]));
  };
  std::vector<std::uint8_t> flags(cells, 0);
  for (std::size_t c = 0; c < cells; ++c) {
    if (label[c] == kNone) continue;
    const int i = int(c % std::size_t(g.width)), j = int(c / std::size_t(g.width));
    bool inner = true;
    for (int n = 1; n < 5 && inner; ++n)
      inner = g.contains(i + di[n], j + dj[n]) && label[g.index(i + di[n], j + dj[n])] == label[c];
    if (inner) flags[c] |= kCore;
  }
  std::vector<int> piece;
  const int core_pieces = componentsOf(g, label, [&](std::size_t c) { return flags[c] & kCore; }, piece);
  // The poses' cells, and the core pieces next to them, per place.
  std::vector<char> kept_piece(std::size_t(core_pieces), 0), place_kept(groups.size(), 0);
  for (std::size_t k = 0; k < groups.size(); ++k)
    for (int i : groups[k]) {
      const auto c = f.indexOf(sensor_origins[std::size_t(i)].x(), sensor_origins[std::size_t(i)].y());
      if (!c) continue;
      if (label[*c] == int(k)) flags[*c] |= kSeed;
      around(*c, [&](std::size_t d) {
        if ((flags[d] & kCore) && label[d] == int(k)) kept_piece[std::size_t(piece[d])] = place_kept[k] = 1;
      });
    }
  // Near a kept core piece: kept; else near another core piece of the place: gone.
  for (std::size_t c = 0; c < cells; ++c)
    if ((flags[c] & kCore) && kept_piece[std::size_t(piece[c])])
      around(c, [&](std::size_t d) {
        if (label[d] == label[c]) flags[d] |= kNearKept;
      });
  for (std::size_t c = 0; c < cells; ++c)
    if ((flags[c] & kCore) && !kept_piece[std::size_t(piece[c])] && place_kept[std::size_t(label[c])])
      around(c, [&](std::size_t d) {
        if (label[d] == label[c] && !(flags[d] & kNearKept)) flags[d] |= kGone;
      });
  const auto left = [&](std::size_t c) { return label[c] != kNone && !(flags[c] & kGone); };
  const int pieces = componentsOf(g, label, left, piece);
  std::vector<char> keep_piece(std::size_t(pieces), 0);
  for (std::size_t c = 0; c < cells; ++c)
    if (left(c) && (flags[c] & (kNearKept | kSeed))) keep_piece[std::size_t(piece[c])] = 1;
  for (std::size_t c = 0; c < cells; ++c)
    if (label[c] != kNone && place_kept[std::size_t(label[c])] && !(left(c) && keep_piece[std::size_t(piece[c])]))
      label[c] = kNone;
}

/// Keeps a cell only when some 2x2 block of its label holds it (a morphological
/// opening by a 2x2 square): one-cell-wide spokes and lines go.
std::vector<int> openedLabels(const FloorGrid& g, const std::vector<int>& label) {
  std::vector<int> out(label.size(), kNone);
  for (int j = 0; j + 1 < g.height; ++j)
    for (int i = 0; i + 1 < g.width; ++i) {
      const int l = label[g.index(i, j)];
      if (l == kNone || label[g.index(i + 1, j)] != l || label[g.index(i, j + 1)] != l ||
          label[g.index(i + 1, j + 1)] != l)
        continue;
      out[g.index(i, j)] = out[g.index(i + 1, j)] = out[g.index(i, j + 1)] = out[g.index(i + 1, j + 1)] = l;
    }
  return out;
}

/// 4-connected pieces of each label: piece id per cell (-1: none) and the
/// cells of each piece.
struct Pieces {
  std::vector<int> piece_of;
  std::vector<std::vector<std::size_t>> cells;
  std::vector<int> label;
};

Pieces piecesOf(const FloorGrid& g, const std::vector<int>& label) {
  Pieces p;
  componentsOf(
      g, label, [&](std::size_t c) { return label[c] != kNone; }, p.piece_of,
      [&](int piece, std::size_t c) {
        if (std::size_t(piece) == p.cells.size()) {
          p.cells.emplace_back();
          p.label.push_back(label[c]);
        }
        p.cells[std::size_t(piece)].push_back(c);
      });
  return p;
}

/// Drops the pieces smaller than `min_cells`, except each label's largest.
void dropSpecks(std::vector<int>& label, const Pieces& pieces, std::size_t min_cells) {
  std::map<int, std::size_t> largest;  // label -> its largest piece
  for (std::size_t k = 0; k < pieces.cells.size(); ++k) {
    const auto it = largest.find(pieces.label[k]);
    if (it == largest.end() || pieces.cells[k].size() > pieces.cells[it->second].size()) largest[pieces.label[k]] = k;
  }
  for (std::size_t k = 0; k < pieces.cells.size(); ++k)
    if (pieces.cells[k].size() < min_cells && largest[pieces.label[k]] != k)
      for (std::size_t c : pieces.cells[k]) label[c] = kNone;
}

using Vertex = std::pair<int, int>;  // grid corner (i, j): the lower-left corner of cell (i, j)

/// Splits a ring that passes a corner twice into rings that do not: a
/// ring only touching itself is not simple.
void splitAtRepeatedCorners(std::vector<Vertex> ring, std::vector<std::vector<Vertex>>& out) {
  std::map<Vertex, std::size_t> seen;
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const auto [it, inserted] = seen.emplace(ring[k], k);
    if (inserted) continue;
    // ring[it->second .. k) is a loop of its own; the rest goes on without it.
    std::vector<Vertex> loop(ring.begin() + std::ptrdiff_t(it->second), ring.begin() + std::ptrdiff_t(k));
    ring.erase(ring.begin() + std::ptrdiff_t(it->second), ring.begin() + std::ptrdiff_t(k));
    splitAtRepeatedCorners(std::move(loop), out);
    splitAtRepeatedCorners(std::move(ring), out);
    return;
  }
  out.push_back(std::move(ring));
}

/// The rings around the cells of one label, interior on the left (outer
/// rings counter-clockwise, holes clockwise), in grid corners. At a corner
/// where two of its cells touch only diagonally the ring turns left, so each
/// 4-connected piece gets its own rings and no ring passes a corner twice.
std::vector<std::vector<Vertex>> traceRings(const FloorGrid& g, const std::vector<int>& label,
                                            const std::vector<std::size_t>& cells) {
  const int l = label[cells.front()];
  const auto is = [&](int i, int j) { return g.contains(i, j) && label[g.index(i, j)] == l; };
  // Directed edges by their start corner; direction 0 +x, 1 +y, 2 -x, 3 -y.
  std::map<Vertex, std::vector<int>> out;
  for (std::size_t c : cells) {
    const int i = int(c % std::size_t(g.width)), j = int(c / std::size_t(g.width));
    if (!is(i, j - 1)) out[{i, j}].push_back(0);
    if (!is(i + 1, j)) out[{i + 1, j}].push_back(1);
    if (!is(i, j + 1)) out[{i + 1, j + 1}].push_back(2);
    if (!is(i - 1, j)) out[{i, j + 1}].push_back(3);
  }
  const int dx[4] = {1, 0, -1, 0}, dy[4] = {0, 1, 0, -1};
  std::vector<std::vector<Vertex>> rings;
  for (auto& [first, dirs] : out) {
    while (!dirs.empty()) {
      std::vector<Vertex> ring;
      Vertex v = first;
      int dir = dirs.back();
      dirs.pop_back();
      ring.push_back(v);
      while (true) {
        v = {v.first + dx[dir], v.second + dy[dir]};
        if (v == first) {
          // Close unless `first` holds another edge this ring must take first
          // (it cannot: corners are left by one edge per visit).
          break;
        }
        ring.push_back(v);
        auto& next = out.at(v);
        // Prefer a left turn, then straight, then right.
        int chosen = -1;
        for (int turn : {1, 0, 3}) {
          const int d = (dir + turn) % 4;
          const auto it = std::find(next.begin(), next.end(), d);
          if (it != next.end()) {
            chosen = d;
            next.erase(it);
            break;
          }
        }
        if (chosen < 0) throw std::logic_error("buildPlaceMap: an outline does not close");
        dir = chosen;
      }
      splitAtRepeatedCorners(std::move(ring), rings);
    }
  }
  return rings;
}

/// Drops the corners where a ring goes straight on.
std::vector<Vertex> withoutStraightCorners(const std::vector<Vertex>& ring) {
  std::vector<Vertex> out;
  const std::size_t n = ring.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Vertex& a = ring[(k + n - 1) % n];
    const Vertex& b = ring[k];
    const Vertex& c = ring[(k + 1) % n];
    const long cross = long(b.first - a.first) * (c.second - b.second) - long(b.second - a.second) * (c.first - b.first);
    if (cross != 0) out.push_back(b);
  }
  return out;
}

/// The doors between places. Where two places touch, their contact (the
/// cell edges between them) is cut into clusters of edges at most two cells
/// apart: the cells of a door are often held partly by each side, so one
/// opening makes several short chains. A cluster is a door when it spans at
/// most options.max_door_width along its main direction; its segment is
/// that span, through the cluster's mean.
std::vector<Door> findDoors(const FloorGrid& g, const std::vector<int>& label, const std::vector<int>& place_ids,
                            const PlaceOptions& options) {
  // Edge midpoints (in half cells) between two labels, by label pair.
  std::map<std::pair<int, int>, std::vector<Eigen::Vector2i>> contacts;
  for (int j = 0; j < g.height; ++j)
    for (int i = 0; i < g.width; ++i) {
      const int a = label[g.index(i, j)];
      if (a == kNone) continue;
      if (i + 1 < g.width) {
        const int b = label[g.index(i + 1, j)];
        if (b != kNone && b != a) contacts[{std::min(a, b), std::max(a, b)}].push_back({2 * (i + 1), 2 * j + 1});
      }
      if (j + 1 < g.height) {
        const int b = label[g.index(i, j + 1)];
        if (b != kNone && b != a) contacts[{std::min(a, b), std::max(a, b)}].push_back({2 * i + 1, 2 * (j + 1)});
      }
    }
  std::vector<Door> doors;
  for (const auto& [pair, mids] : contacts) {
    std::vector<int> parent(mids.size());
    std::iota(parent.begin(), parent.end(), 0);
    const auto root = [&parent](int e) {
      while (parent[e] != e) e = parent[e] = parent[parent[e]];
      return e;
    };
    // Edges whose midpoints lie within two cells (four half cells) join.
    std::map<std::pair<int, int>, std::vector<int>> bucket;  // 4x4 half-cell buckets
    for (int e = 0; e < int(mids.size()); ++e) bucket[{mids[e].x() >> 2, mids[e].y() >> 2}].push_back(e);
    for (int e = 0; e < int(mids.size()); ++e) {
      const int bx = mids[e].x() >> 2, by = mids[e].y() >> 2;
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy) {
          const auto it = bucket.find({bx + dx, by + dy});
          if (it == bucket.end()) continue;
          for (int f : it->second)
            if (f < e && (mids[e] - mids[f]).cwiseAbs().maxCoeff() <= 4) parent[root(e)] = root(f);
        }
    }
    std::map<int, std::vector<int>> clusters;
    for (int e = 0; e < int(mids.size()); ++e) clusters[root(e)].push_back(e);
    for (const auto& [r, cluster] : clusters) {
      // The edges' end corners, in metres, and their main direction.
      std::vector<Eigen::Vector2d> corners;
      for (int e : cluster) {
        const Eigen::Vector2i m = mids[e];
        const Eigen::Vector2d half = m.x() % 2 == 0 ? Eigen::Vector2d(0, 1) : Eigen::Vector2d(1, 0);
        const Eigen::Vector2d centre = m.cast<double>();
        corners.push_back(g.origin + g.resolution / 2 * (centre - half));
        corners.push_back(g.origin + g.resolution / 2 * (centre + half));
      }
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      for (const auto& c : corners) mean += c;
      mean /= double(corners.size());
      Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
      for (const auto& c : corners) scatter += (c - mean) * (c - mean).transpose();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
      const Eigen::Vector2d axis = eigen.eigenvectors().col(1);
      // The bar across the opening: the corners' extent along that direction, through their mean.
      double lo = 0, hi = 0;
      for (const auto& c : corners) {
        lo = std::min(lo, (c - mean).dot(axis));
        hi = std::max(hi, (c - mean).dot(axis));
      }
      const double width = hi - lo;
      if (width > options.max_door_width) continue;
      Door d;
      d.place_a = place_ids[pair.first];
      d.place_b = place_ids[pair.second];
      if (d.place_a > d.place_b) std::swap(d.place_a, d.place_b);
      d.end_a = mean + lo * axis;
      d.end_b = mean + hi * axis;
      d.midpoint = (d.end_a + d.end_b) / 2;
      d.width_m = (d.end_b - d.end_a).norm();
      doors.push_back(d);
    }
  }
  std::sort(doors.begin(), doors.end(), [](const Door& x, const Door& y) {
    return std::tie(x.place_a, x.place_b, x.midpoint.x(), x.midpoint.y()) <
           std::tie(y.place_a, y.place_b, y.midpoint.x(), y.midpoint.y());
  });
  return doors;
}

}  // namespace

double twiceSignedArea(const std::vector<Eigen::Vector2d>& ring) {
  double twice = 0;
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const Eigen::Vector2d& a = ring[k];
    const Eigen::Vector2d& b = ring[(k + 1) % ring.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return twice;
}

namespace {

/// Even-odd point in ring.
bool inside(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& p) {
  bool in = false;
  for (std::size_t k = 0, l = ring.size() - 1; k < ring.size(); l = k++) {
    const Eigen::Vector2d& a = ring[k];
    const Eigen::Vector2d& b = ring[l];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      in = !in;
  }
  return in;
}

/// Each label's cell farthest from any cell of another label (or none, or
/// the grid's edge), by a two-pass chamfer distance (3 along an edge, 4
/// across a corner); ties go to the first cell in row order.
std::vector<std::size_t> deepestCells(const FloorGrid& g, const std::vector<int>& label, std::size_t labels) {
  constexpr int kFar = std::numeric_limits<int>::max() / 2;
  std::vector<int> distance(label.size(), kFar);
  const auto at = [&](int i, int j) { return g.contains(i, j) ? distance[g.index(i, j)] : 0; };
  const auto same = [&](int i, int j, int l) { return g.contains(i, j) && label[g.index(i, j)] == l; };
  for (int j = 0; j < g.height; ++j)
    for (int i = 0; i < g.width; ++i) {
      const int l = label[g.index(i, j)];
      int& d = distance[g.index(i, j)];
      if (l == kNone) { d = 0; continue; }
      d = std::min(d, same(i - 1, j, l) ? at(i - 1, j) + 3 : 3);
      d = std::min(d, same(i, j - 1, l) ? at(i, j - 1) + 3 : 3);
      d = std::min(d, same(i - 1, j - 1, l) ? at(i - 1, j - 1) + 4 : 4);
      d = std::min(d, same(i + 1, j - 1, l) ? at(i + 1, j - 1) + 4 : 4);
    }
  for (int j = g.height - 1; j >= 0; --j)
    for (int i = g.width - 1; i >= 0; --i) {
      const int l = label[g.index(i, j)];
      if (l == kNone) continue;
      int& d = distance[g.index(i, j)];
      d = std::min(d, same(i + 1, j, l) ? at(i + 1, j) + 3 : 3);
      d = std::min(d, same(i, j + 1, l) ? at(i, j + 1) + 3 : 3);
      d = std::min(d, same(i + 1, j + 1, l) ? at(i + 1, j + 1) + 4 : 4);
      d = std::min(d, same(i - 1, j + 1, l) ? at(i - 1, j + 1) + 4 : 4);
    }
  std::vector<std::size_t> deepest(labels, 0);
  std::vector<int> best(labels, -1);
  for (std::size_t k = 0; k < label.size(); ++k)
    if (const int l = label[k]; l != kNone && distance[k] > best[std::size_t(l)]) {
      best[std::size_t(l)] = distance[k];
      deepest[std::size_t(l)] = k;
    }
  return deepest;
}


}  // namespace

std::vector<std::vector<std::size_t>> polygonsOf(const std::vector<std::vector<Eigen::Vector2d>>& rings) {
  std::vector<std::vector<std::size_t>> polygons;
  std::vector<std::size_t> polygon_of_outer(rings.size(), 0);
  for (std::size_t r = 0; r < rings.size(); ++r)
    if (rings[r].size() >= 3 && twiceSignedArea(rings[r]) > 0) {
      polygon_of_outer[r] = polygons.size();
      polygons.push_back({r});
    }
  for (std::size_t h = 0; h < rings.size(); ++h) {
    if (rings[h].size() < 3 || twiceSignedArea(rings[h]) >= 0) continue;
    // A point just inside the floor beside the hole's first edge (on its left).
    const Eigen::Vector2d a = rings[h][0], b = rings[h][1];
    const Eigen::Vector2d along = (b - a).normalized();
    const Eigen::Vector2d probe = (a + b) / 2 + 1e-6 * (b - a).norm() * Eigen::Vector2d(-along.y(), along.x());
    std::size_t best = rings.size();
    double best_area = std::numeric_limits<double>::infinity();
    for (std::size_t r = 0; r < rings.size(); ++r) {
      if (rings[r].size() < 3) continue;
      const double area = twiceSignedArea(rings[r]);
      if (area > 0 && area < best_area && inside(rings[r], probe)) best = r, best_area = area;
    }
    if (best < rings.size()) polygons[polygon_of_outer[best]].push_back(h);
  }
  return polygons;
}

Location PlaceMap::locate(const Eigen::Vector2d& position, double tolerance) const {
  Location out;
  if (grid.width == 0 || !position.allFinite()) return out;
  const Eigen::Vector2i c = grid.cellOf(position);
  if (grid.contains(c.x(), c.y()) && labels[grid.index(c.x(), c.y())] >= 0) {
    out.place = labels[grid.index(c.x(), c.y())];
    return out;
  }
  if (!(tolerance > 0)) return out;
  // The cells within the tolerance, clipped to the grid (in double: a huge
  // tolerance or a far position overflows no int).
  const double reach = std::ceil(tolerance / grid.resolution) + 1;
  const Eigen::Vector2d at = ((position - grid.origin) / grid.resolution).array().floor();
  const int i0 = int(std::max(0.0, at.x() - reach)), i1 = int(std::min(double(grid.width - 1), at.x() + reach));
  const int j0 = int(std::max(0.0, at.y() - reach)), j1 = int(std::min(double(grid.height - 1), at.y() + reach));
  double best = std::numeric_limits<double>::infinity();
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      const int l = labels[grid.index(i, j)];
      if (l < 0) continue;
      const double d = (grid.cellCentre(i, j) - position).norm();
      if (d <= tolerance && (d < best || (d == best && l < *out.place))) {
        best = d;
        out.place = l;
      }
    }
  if (out.place) out.distance_m = best;
  return out;
}

PlaceMap buildPlaceMap(const ObservationRegions& regions, const WorldPoints& world,
                       const std::vector<Eigen::Vector3d>& sensor_origins,
                       const std::vector<std::vector<int>>& groups, const std::vector<int>& place_ids,
                       const PlaceOptions& options) {
  if (world.size() != regions.size())
    throw std::invalid_argument("buildPlaceMap: regions and points of " + std::to_string(regions.size()) + " and " +
                                std::to_string(world.size()) + " observations");
  const PlacePointSource points_of = [&world](int i, std::vector<Eigen::Vector3f>&) {
    return std::make_pair(world.begin(i), world.end(i));
  };
  return buildPlaceMap(regions, world.origin, points_of, sensor_origins, groups, place_ids, options);
}

namespace {

/// Throws std::invalid_argument, as buildPlaceMap documents, unless every
/// observation is in exactly one group and the options are in range.
void checkPlaceInputs(int n, const std::vector<Eigen::Vector3d>& sensor_origins,
                      const std::vector<std::vector<int>>& groups, const std::vector<int>& place_ids,
                      const PlaceOptions& options) {
  if (int(sensor_origins.size()) != n)
    throw std::invalid_argument("buildPlaceMap: regions and sensor origins of " + std::to_string(n) + " and " +
                                std::to_string(sensor_origins.size()) + " observations");
  if (place_ids.size() != groups.size())
    throw std::invalid_argument("buildPlaceMap: one place id per group expected");
  std::vector<char> grouped(std::size_t(n), 0);
  for (const auto& group : groups)
    for (int i : group) {
      if (i < 0 || i >= n || grouped[std::size_t(i)])
        throw std::invalid_argument("buildPlaceMap: observation " + std::to_string(i) +
                                    " is out of range or in two groups");
      grouped[std::size_t(i)] = 1;
    }
  if (std::find(grouped.begin(), grouped.end(), 0) != grouped.end())
    throw std::invalid_argument("buildPlaceMap: every observation must be in a group");
  if (!(std::isfinite(options.max_door_width) && options.max_door_width >= 0) ||
      !(std::isfinite(options.min_piece_area) && options.min_piece_area >= 0) ||
      !(std::isfinite(options.band_low) && std::isfinite(options.band_high) && options.band_low < options.band_high))
    throw std::invalid_argument("buildPlaceMap: the door width and piece area must be finite and >= 0, the band "
                                "finite with low < high");
}

PlaceMap placesFrom(const ObservationRegions& regions, const GridFrame& f, std::vector<Occupancy> occupancy,
                    const std::vector<Eigen::Vector3d>& sensor_origins, const std::vector<std::vector<int>>& groups,
                    const std::vector<int>& place_ids, const PlaceOptions& options);

}  // namespace

FloorEvidence observeFloor(const ObservationRegions& regions, const Eigen::Vector3d& world_origin,
                           const PlacePointSource& points_of, const std::vector<Eigen::Vector3d>& sensor_origins,
                           const PlaceOptions& options, int threads, const InterruptFlag* interrupt) {
  if (int(sensor_origins.size()) != regions.size())
    throw std::invalid_argument("observeFloor: regions and sensor origins of " + std::to_string(regions.size()) +
                                " and " + std::to_string(sensor_origins.size()) + " observations");
  if (!(std::isfinite(options.band_low) && std::isfinite(options.band_high) && options.band_low < options.band_high))
    throw std::invalid_argument("observeFloor: the band must be finite with low < high");
  const GridFrame f = makeGrid(regions, world_origin, "observeFloor");
  FloorEvidence floor;
  floor.grid = f.grid;
  floor.band_low = options.band_low;
  floor.band_high = options.band_high;
  bool planar = true;
  const std::vector<std::uint8_t> seen =
      seenCells(f, points_of, sensor_origins, regions.cell_size, options, planar, threads, interrupt);
  // Floor is what a beam crossed and a region holds: a region model may
  // reach where no beam went (visibility all around a forward sensor).
  const FloorCellOfKey cell_of(regions, f);
  const std::size_t cells = seen.size();
  floor.occupancy.assign(cells, Occupancy::Unknown);
  for (int i = 0; i < regions.size(); ++i)
    regions.forEachCell(i, [&](std::uint64_t key) {
      if (const std::size_t k = cell_of(key); seen[k] & kCrossed) floor.occupancy[k] = Occupancy::Free;
    });
  // Planar data is all obstacle; in 3D, the points within the band above the floor.
  const std::uint8_t obstacle = planar ? kPoint : kPointInBand;
  for (std::size_t k = 0; k < cells; ++k)
    if (seen[k] & obstacle) floor.occupancy[k] = Occupancy::Occupied;
  return floor;
}

PlaceMap buildPlaceMap(const ObservationRegions& regions, const Eigen::Vector3d& world_origin,
                       const PlacePointSource& points_of, const std::vector<Eigen::Vector3d>& sensor_origins,
                       const std::vector<std::vector<int>>& groups, const std::vector<int>& place_ids,
                       const PlaceOptions& options) {
  checkPlaceInputs(regions.size(), sensor_origins, groups, place_ids, options);  // before the pass over the beams
  const FloorEvidence floor = observeFloor(regions, world_origin, points_of, sensor_origins, options);
  return buildPlaceMap(regions, floor, sensor_origins, groups, place_ids, options);
}

PlaceMap buildPlaceMap(const ObservationRegions& regions, const FloorEvidence& floor,
                       const std::vector<Eigen::Vector3d>& sensor_origins,
                       const std::vector<std::vector<int>>& groups, const std::vector<int>& place_ids,
                       const PlaceOptions& options) {
  checkPlaceInputs(regions.size(), sensor_origins, groups, place_ids, options);
  // The grid's cells are the regions' wherever the world origin lies: only
  // its origin in the world frame comes from the evidence.
  GridFrame f = makeGrid(regions, Eigen::Vector3d::Zero(), "buildPlaceMap");
  const std::size_t cells = std::size_t(f.grid.width) * std::size_t(f.grid.height);
  if (floor.grid.width != f.grid.width || floor.grid.height != f.grid.height ||
      floor.grid.resolution != f.grid.resolution || floor.occupancy.size() != cells)
    throw std::invalid_argument("buildPlaceMap: the floor evidence is of another grid than these regions'");
  if (floor.band_low != options.band_low || floor.band_high != options.band_high)
    throw std::invalid_argument("buildPlaceMap: the floor evidence was marked with another band");
  f.grid.origin = floor.grid.origin;
  return placesFrom(regions, f, floor.occupancy, sensor_origins, groups, place_ids, options);
}

namespace {

PlaceMap placesFrom(const ObservationRegions& regions, const GridFrame& f, std::vector<Occupancy> occupancy,
                    const std::vector<Eigen::Vector3d>& sensor_origins, const std::vector<std::vector<int>>& groups,
                    const std::vector<int>& place_ids, const PlaceOptions& options) {
  PlaceMap map;
  const FloorGrid& g = f.grid;
  map.grid = g;
  const std::size_t cells = std::size_t(g.width) * std::size_t(g.height);
  const FloorCellOfKey cell_of(regions, f);
  map.occupancy = std::move(occupancy);

  std::vector<int> label = cells ? openedLabels(g, ownerOfCells(regions, cell_of, groups, map.occupancy)) : std::vector<int>{};
  const double cell_area = g.resolution * g.resolution;
  dropSpecks(label, piecesOf(g, label), std::size_t(std::ceil(options.min_piece_area / cell_area)));
  if (cells) keepPoseCells(f, map.occupancy, groups, sensor_origins, label);
  if (cells) dropFloorBeyondNecks(f, groups, sensor_origins, label);
  const Pieces pieces = piecesOf(g, label);

  map.places.resize(groups.size());
  std::vector<std::size_t> cell_count(groups.size(), 0);
  std::vector<Eigen::Vector2d> centre_sum(groups.size(), Eigen::Vector2d::Zero());
  std::vector<std::pair<int, int>> touches;  // (place, neighbour), both ways; a matrix would be quadratic in places
  for (int j = 0; j < g.height; ++j)
    for (int i = 0; i < g.width; ++i) {
      const int l = label[g.index(i, j)];
      if (l == kNone) continue;
      ++cell_count[l];
      centre_sum[l] += g.cellCentre(i, j);
      if (i + 1 < g.width) {
        const int r = label[g.index(i + 1, j)];
        if (r != kNone && r != l) touches.insert(touches.end(), {{l, r}, {r, l}});
      }
      if (j + 1 < g.height) {
        const int u = label[g.index(i, j + 1)];
        if (u != kNone && u != l) touches.insert(touches.end(), {{l, u}, {u, l}});
      }
    }
  std::sort(touches.begin(), touches.end());
  touches.erase(std::unique(touches.begin(), touches.end()), touches.end());
  const std::vector<std::size_t> deepest = deepestCells(g, label, groups.size());
  for (std::size_t k = 0; k < groups.size(); ++k) {
    Place& place = map.places[k];
    place.id = place_ids[k];
    if (cell_count[k] > 0) place.label_point = g.cellCentre(int(deepest[k] % g.width), int(deepest[k] / g.width));
    place.members = groups[k];
    place.area_m2 = double(cell_count[k]) * cell_area;
    if (cell_count[k] > 0) place.centroid = centre_sum[k] / double(cell_count[k]);
    const auto first = std::lower_bound(touches.begin(), touches.end(), std::make_pair(int(k), 0));
    for (auto t = first; t != touches.end() && t->first == int(k); ++t) place.neighbours.push_back(place_ids[t->second]);
    std::sort(place.neighbours.begin(), place.neighbours.end());
  }
  // Each piece's rings on any thread, then added to their places in piece
  // order: the same outlines for any thread count.
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> rings_of(pieces.cells.size());
  parallelFor(pieces.cells.size(), 0, 16, [&](std::size_t p) {
    for (const auto& ring : traceRings(g, label, pieces.cells[p])) {
      std::vector<Eigen::Vector2d> points;
      for (const Vertex& v : withoutStraightCorners(ring))
        points.push_back(g.origin + g.resolution * Eigen::Vector2d(v.first, v.second));
      rings_of[p].push_back(std::move(points));
    }
  });
  for (std::size_t p = 0; p < pieces.cells.size(); ++p) {
    Place& place = map.places[pieces.label[p]];
    for (auto& points : rings_of[p]) {
      for (const Eigen::Vector2d& point : points) place.bbox.extend(point);
      place.outline.push_back(std::move(points));
    }
  }
  map.doors = findDoors(g, label, place_ids, options);
  map.labels.assign(cells, -1);
  for (std::size_t c = 0; c < cells; ++c)
    if (label[c] != kNone) map.labels[c] = place_ids[label[c]];
  return map;
}

}  // namespace

namespace {

/// Whether the grid cell holding `q` (in cells from the grid's origin) is free.
bool freeCell(const PlaceMap& map, const Eigen::Vector2d& q) {
  const double i = std::floor(q.x()), j = std::floor(q.y());
  if (!(i >= 0 && j >= 0 && i < map.grid.width && j < map.grid.height)) return false;  // also NaN
  return map.occupancy[map.grid.index(int(i), int(j))] == Occupancy::Free;
}

/// The free run from `q` along `direction` (unit), in half-cell steps up to
/// `cap`, all in cells: it ends at the first cell that is not free
/// (occupied, unknown, or off the grid).
double freeRunOn(const PlaceMap& map, const Eigen::Vector2d& q, const Eigen::Vector2d& direction, double cap) {
  for (double s = 0.0; s < cap; s += 0.5)
    if (!freeCell(map, q + s * direction)) return s;
  return cap;
}

/// Free space along a chord is measured up to this on each side, metres.
constexpr double kPassageCap = 6.0;

bool isPassage(const PlaceMap& map, const Door& contact) {
  // In cells from the grid's origin, the ends on a grid of 1/16 cell: the
  // same lines wherever the map lies (at UTM coordinates the world frame's
  // last bits would move a line lying on a cell edge into the next cell).
  const double res = map.grid.resolution;
  const auto local = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector2d(((p - map.grid.origin) / res * 16.0).array().round() / 16.0);
  };
  const Eigen::Vector2d a = local(contact.end_a), b = local(contact.end_b);
  if (!((b - a).norm() > 0.0)) return false;
  const Eigen::Vector2d d = (b - a).normalized(), normal(-d.y(), d.x()), middle = (a + b) / 2;
  const double cap = kPassageCap / res;
  const auto chord = [&](const Eigen::Vector2d& q) { return res * (freeRunOn(map, q, d, cap) + freeRunOn(map, q, -d, cap)); };
  const double opening = chord(middle);
  if (opening < kMinPassageWidth || contact.width_m < 0.75 * opening) return false;
  // One side is enough: a corridor cut where it meets another, or turns, is
  // narrow on its own side alone (docs/method.md, "Passages").
  for (const double side : {1.0, -1.0}) {
    std::vector<double> widths;
    for (int k = 0; k <= 6; ++k) {
      const Eigen::Vector2d q = middle + side * (0.4 + 0.2 * k) / res * normal;
      if (freeCell(map, q)) widths.push_back(chord(q));
    }
    if (widths.empty()) continue;  // a wall right behind the contact: no side to judge
    // The lower median: a door along a corridor beside one line does not widen it.
    std::nth_element(widths.begin(), widths.begin() + (widths.size() - 1) / 2, widths.end());
    if (widths[(widths.size() - 1) / 2] < kDoorWidening * opening) return true;
  }
  return false;
}

}  // namespace

std::vector<Door> passagesOf(const PlaceMap& map) {
  std::vector<Door> passages;
  for (const Door& contact : map.doors)
    if (isPassage(map, contact)) passages.push_back(contact);
  return passages;
}

std::vector<Door> joinThroughPassages(Partition& partition, std::vector<int>& place_ids, const PlaceMap& map) {
  if (place_ids.size() != partition.groups.size())
    throw std::invalid_argument("joinThroughPassages: one place id per group expected");
  std::unordered_map<int, int> group_of_place;
  for (std::size_t g = 0; g < place_ids.size(); ++g) group_of_place.emplace(place_ids[g], int(g));
  std::vector<Door> joined;
  std::vector<std::pair<int, int>> pairs;
  std::vector<int> set_of(place_ids.size());
  std::iota(set_of.begin(), set_of.end(), 0);
  const auto root = [&set_of](int g) {
    while (set_of[std::size_t(g)] != g) g = set_of[std::size_t(g)] = set_of[std::size_t(set_of[std::size_t(g)])];
    return g;
  };
  for (const Door& passage : passagesOf(map)) {
    const auto a = group_of_place.find(passage.place_a), b = group_of_place.find(passage.place_b);
    if (a == group_of_place.end() || b == group_of_place.end()) continue;
    const int ra = root(a->second), rb = root(b->second);
    if (ra == rb) continue;
    set_of[std::size_t(std::max(ra, rb))] = std::min(ra, rb);
    pairs.emplace_back(a->second, b->second);
    joined.push_back(passage);
  }
  if (pairs.empty()) return joined;
  const std::vector<int> first_of = joinGroups(partition, pairs);
  std::vector<int> ids;
  for (int g : first_of) ids.push_back(place_ids[std::size_t(g)]);
  place_ids = std::move(ids);
  return joined;
}

}  // namespace obsgroup
