#include "obsgroup/overlap/incremental_overlap.h"

#include "obsgroup/common/parallel_for.h"
#include "obsgroup/overlap/world_points.h"
#include "region_cells.h"

#include <algorithm>
#include <limits>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

namespace obsgroup {

using namespace region_cells;

namespace {

/// One pair of observations as seen from row i: j, the count of i's points
/// (or cells) matched in j, and the count of j's matched in i (the same for
/// regions: the cells they share).
struct PairCounts {
  int j = 0;
  std::uint32_t ij = 0, ji = 0;
};

struct Slot {
  bool present = false;
  bool dirty = false;  // its points or origin changed (or it left) since the last update
  std::vector<Eigen::Vector3f> points;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::AlignedBox3f box;  // of the points; empty without points
  bool planar = true;       // within a quarter cell of z = 0 (the first observation's height)
  // As last computed (they may lag `points` until update()):
  std::vector<std::uint64_t> region, hit, crossed;
  bool reads_occupancy = true;  // visibility: its region read the shared occupancy grid
  region_cells::Cell<2> read_lo{}, read_hi{};  // where (ViewWidths::read_lo, read_hi)
  std::vector<PairCounts> row;  // ascending j
};

/// Points of `a` with a point of `b` within delta (the numerator of eq. 17),
/// with the predicate every back-end uses (MatchDistance).
class PointMatcher {
 public:
  PointMatcher(const std::vector<Eigen::Vector3f>& b, double delta) : points_(b), within_(delta), cell_(delta) {
    for (std::size_t k = 0; k < b.size(); ++k) cells_[key(cellOf(b[k]))].push_back(std::uint32_t(k));
  }
  std::uint32_t countMatched(const std::vector<Eigen::Vector3f>& a) const {
    std::uint32_t count = 0;
    for (const Eigen::Vector3f& p : a) count += matched(p);
    return count;
  }

 private:
  using Index = Eigen::Array3i;
  Index cellOf(const Eigen::Vector3f& p) const { return (p.cast<double>().array() / cell_).floor().cast<int>(); }
  static std::uint64_t key(const Index& c) {
    return (std::uint64_t(std::uint32_t(c[0]) & 0x1fffff) << 42) | (std::uint64_t(std::uint32_t(c[1]) & 0x1fffff) << 21) |
           std::uint64_t(std::uint32_t(c[2]) & 0x1fffff);
  }
  bool matched(const Eigen::Vector3f& p) const {
    const Index c = cellOf(p);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(c + Index(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (std::uint32_t k : it->second)
            if (within_(p, points_[k])) return true;
        }
    return false;
  }
  const std::vector<Eigen::Vector3f>& points_;
  MatchDistance within_;
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

Eigen::AlignedBox3f boxOf(const std::vector<Eigen::Vector3f>& points) {
  Eigen::AlignedBox3f box;  // empty
  for (const auto& p : points) box.extend(p);
  return box;
}

std::vector<std::uint64_t> difference(const std::vector<std::uint64_t>& a, const std::vector<std::uint64_t>& b) {
  std::vector<std::uint64_t> out;
  std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

}  // namespace

struct IncrementalOverlap::State {
  SensedSpaceModel model;
  double delta;
  RegionParameters params;
  CellGrid grid;
  std::vector<Slot> slots;
  bool stale = true;          // everything must be recomputed
  bool planar_used = true;    // the planarity the regions were computed with
  struct Evidence {
    std::uint32_t hits = 0, misses = 0;
  };
  std::unordered_map<std::uint64_t, Evidence> evidence;           // visibility: per plane cell
  OccupancyGrid occupancy;                                         // visibility
  std::unordered_map<std::uint64_t, std::vector<int>> watchers;    // region models: slots holding each cell
  std::vector<char> changed;                                       // rows changed since the last update
  std::vector<char> sources;                                       // slots whose own points or region changed
  // The last W built (weightMatrix): its slots, diagonal and entry count,
  // and the rows changed since, so that the next one copies the others.
  std::vector<int> matrix_slots;
  double matrix_diagonal = std::numeric_limits<double>::quiet_NaN();
  Eigen::Index matrix_entries = -1;
  std::vector<char> changed_since_matrix;
  std::size_t recomputed = 0;

  State(SensedSpaceModel m, double d, const RegionParameters& p) : model(m), delta(d), params(p), grid(p.cell_size) {}

  bool present(int slot) const { return slot >= 0 && slot < int(slots.size()) && slots[slot].present; }
  bool planarNow() const {
    for (const Slot& s : slots)
      if (s.present && !s.planar) return false;
    return true;
  }
  void markChanged(int slot) {
    if (slot >= int(changed.size())) changed.resize(slots.size(), 0);
    changed[slot] = 1;
    if (slot >= int(changed_since_matrix.size())) changed_since_matrix.resize(slots.size(), 1);
    changed_since_matrix[slot] = 1;
  }
  /// Every pair that changes has a source at one end: a slot given new
  /// points, or whose region now holds other cells.
  void markSource(int slot) {
    if (slot >= int(sources.size())) sources.resize(slots.size(), 0);
    sources[slot] = 1;
  }

  // --- pair counts, kept symmetric in the rows of both slots ---

  PairCounts* find(int i, int j) {
    auto& row = slots[i].row;
    auto it = std::lower_bound(row.begin(), row.end(), j, [](const PairCounts& p, int v) { return p.j < v; });
    return it != row.end() && it->j == j ? &*it : nullptr;
  }
  void put(int i, int j, std::uint32_t ij, std::uint32_t ji) {
    auto& row = slots[i].row;
    auto it = std::lower_bound(row.begin(), row.end(), j, [](const PairCounts& p, int v) { return p.j < v; });
    const bool found = it != row.end() && it->j == j;
    if (ij == 0 && ji == 0) {
      if (found) row.erase(it);
    } else if (found) {
      it->ij = ij, it->ji = ji;
    } else {
      row.insert(it, {j, ij, ji});
    }
  }
  void setPair(int i, int j, std::uint32_t ij, std::uint32_t ji) {
    const PairCounts* old = find(i, j);
    if (old && old->ij == ij && old->ji == ji) return;
    if (!old && ij == 0 && ji == 0) return;
    put(i, j, ij, ji);
    put(j, i, ji, ij);
    markChanged(i);
    markChanged(j);
  }
  /// Adds `step` to the cells slots i and j share.
  void addShared(int i, int j, int step) {
    const PairCounts* old = find(i, j);
    const std::uint32_t now = std::uint32_t(std::int64_t(old ? old->ij : 0) + step);
    setPair(i, j, now, now);
  }
  void clearRow(int i) {
    for (const PairCounts& p : slots[i].row) {
      put(p.j, i, 0, 0);
      markChanged(p.j);
    }
    if (!slots[i].row.empty()) markChanged(i);
    slots[i].row.clear();
  }
  /// A slot whose M (points or cells) changed changes the weight of every pair it is in.
  void markPartners(int i) {
    markChanged(i);
    for (const PairCounts& p : slots[i].row) markChanged(p.j);
  }

  void resetAll() {
    evidence.clear();
    occupancy = OccupancyGrid();
    watchers.clear();
    for (int i = 0; i < int(slots.size()); ++i) {
      Slot& s = slots[i];
      s.region.clear(), s.hit.clear(), s.crossed.clear(), s.row.clear();
      s.dirty = s.present;
      markChanged(i);
      markSource(i);
    }
    stale = false;
  }

  std::vector<int> dirtySlots() const {
    std::vector<int> out;
    for (int i = 0; i < int(slots.size()); ++i)
      if (slots[i].dirty) out.push_back(i);
    return out;
  }

  void updatePoints(const std::vector<int>& dirty, int threads) {
    for (int d : dirty) {
      clearRow(d);
      markChanged(d);
      markSource(d);
    }
    // The pairs of each changed observation, each pair once.
    std::vector<std::pair<int, int>> pairs;
    std::vector<char> is_dirty(slots.size(), 0);
    for (int d : dirty) is_dirty[d] = 1;
    const float grow = float(delta) * (1.0f + 1e-4f) + 1e-6f;
    for (int d : dirty) {
      if (!slots[d].present || slots[d].box.isEmpty()) continue;
      Eigen::AlignedBox3f near_d = slots[d].box;
      near_d.min().array() -= grow;
      near_d.max().array() += grow;
      for (int j = 0; j < int(slots.size()); ++j)
        if (j != d && slots[j].present && !slots[j].box.isEmpty() && !(is_dirty[j] && j < d) &&
            near_d.intersects(slots[j].box))
          pairs.emplace_back(d, j);
    }
    std::vector<PairCounts> counts(pairs.size());
    parallelFor(pairs.size(), threads, 4, [&](std::size_t k) {
      const auto [i, j] = pairs[k];
      counts[k] = {j, PointMatcher(slots[j].points, delta).countMatched(slots[i].points),
                   PointMatcher(slots[i].points, delta).countMatched(slots[j].points)};
    });
    for (std::size_t k = 0; k < pairs.size(); ++k) setPair(pairs[k].first, pairs[k].second, counts[k].ij, counts[k].ji);
    recomputed = dirty.size();
  }

  /// Visibility: replaces the occupancy evidence of the changed slots and
  /// returns the plane cells whose occupancy flipped.
  std::vector<std::uint64_t> updateEvidence(const std::vector<int>& dirty, int threads) {
    std::unordered_map<std::uint64_t, bool> before;
    const auto touch = [&](std::uint64_t key) -> Evidence& {
      Evidence& e = evidence[key];
      before.emplace(key, occupiedBy(e.hits, e.misses, params));
      return e;
    };
    for (int d : dirty) {
      for (std::uint64_t key : slots[d].hit) --touch(key).hits;
      for (std::uint64_t key : slots[d].crossed) --touch(key).misses;
      slots[d].hit.clear();
      slots[d].crossed.clear();
    }
    parallelForWithScratch(
        dirty.size(), threads, 4, [] { return EvidenceScratch{}; },
        [&](std::size_t k, EvidenceScratch& scratch) {
          Slot& s = slots[dirty[k]];
          if (!s.present) return;
          occupancyEvidence({s.points.data(), s.points.data() + s.points.size()}, s.origin, params, grid,
                            planar_used, scratch, s.hit, s.crossed);
        });
    for (int d : dirty) {
      for (std::uint64_t key : slots[d].hit) ++touch(key).hits;
      for (std::uint64_t key : slots[d].crossed) ++touch(key).misses;
    }
    std::vector<std::uint64_t> flipped;
    for (const auto& [key, was] : before) {
      const auto it = evidence.find(key);
      const bool now = occupiedBy(it->second.hits, it->second.misses, params);
      if (now != was) flipped.push_back(key);
      if (it->second.hits == 0 && it->second.misses == 0) evidence.erase(it);
    }
    std::sort(flipped.begin(), flipped.end());
    for (std::uint64_t key : flipped) occupancy.set(key, !static_cast<bool>(before[key]));
    return flipped;
  }

  /// The present slots whose view depended on a flipped cell's occupancy
  /// (the box of ViewWidths::read_lo, read_hi holds it), among those whose
  /// last view read the shared occupancy at all.
  std::vector<int> viewsReaching(const std::vector<std::uint64_t>& flipped) const {
    std::vector<int> out;
    if (flipped.empty()) return out;
    for (int i = 0; i < int(slots.size()); ++i) {
      const Slot& s = slots[i];
      // A view that read none of the shared occupancy cannot change with it.
      if (!s.present || s.points.empty() || !s.reads_occupancy) continue;
      const auto& lo = s.read_lo;
      const auto& hi = s.read_hi;
      if (lo[0] > hi[0] || lo[1] > hi[1]) continue;
      const std::uint64_t first = keyOf<2>(lo), last = keyOf<2>(hi);
      // Keys ascend with x first: only flipped keys between the box's
      // corners can lie in it.
      for (auto it = std::lower_bound(flipped.begin(), flipped.end(), first); it != flipped.end() && *it <= last;
           ++it) {
        const std::int64_t y = std::int64_t(*it & 0xffffffffu) - (std::int64_t(1) << 31);
        if (y >= lo[1] && y <= hi[1]) {
          out.push_back(i);
          break;
        }
      }
    }
    return out;
  }

  void computeRegion(Slot& s, RegionMarker<2>& own, RegionMarker<2>& marker2, RegionMarker<3>& marker3,
                     OccupancyGrid::Reader& reader, ViewWidths& widths) const {
    s.region.clear();
    if (!s.present) return;
    const PointSpan points{s.points.data(), s.points.data() + s.points.size()};
    if (model == SensedSpaceModel::Visibility) {
      visibilityOf(points, s.origin, params, grid, planar_used, reader, own, marker2, widths, s.region);
      s.reads_occupancy = widths.read_occupancy;
      s.read_lo = widths.read_lo, s.read_hi = widths.read_hi;
    } else if (!planar_used) {
      freeSpaceOf<3>(points, s.origin, params, grid, marker3, s.region);
    } else {
      freeSpaceOf<2>(points, s.origin, params, grid, marker2, s.region);
    }
  }

  /// Changes of the cells slot i shares with each other slot, summed over
  /// its cells before they are applied: one update of a pair's counts instead
  /// of one per cell.
  struct SharedDelta {
    std::vector<int> delta;  // by slot
    std::vector<int> touched;
    void add(int w, int step) {
      if (w >= int(delta.size())) delta.resize(w + 1, 0);
      if (delta[w] == 0) touched.push_back(w);
      delta[w] += step;
    }
  };

  void removeCell(int i, std::uint64_t key, SharedDelta& shared) {
    auto it = watchers.find(key);
    auto& list = it->second;
    list.erase(std::find(list.begin(), list.end(), i));
    for (int w : list) shared.add(w, -1);
    if (list.empty()) watchers.erase(it);
  }
  void addCell(int i, std::uint64_t key, SharedDelta& shared) {
    auto& list = watchers[key];
    for (int w : list) shared.add(w, +1);
    list.push_back(i);
  }
  void applyShared(int i, SharedDelta& shared) {
    std::sort(shared.touched.begin(), shared.touched.end());
    for (int w : shared.touched) {
      if (shared.delta[w] != 0) addShared(i, w, shared.delta[w]);
      shared.delta[w] = 0;
    }
    shared.touched.clear();
  }

  void updateRegions(std::vector<int> dirty, int threads) {
    std::vector<int> affected = dirty;
    if (model == SensedSpaceModel::Visibility) {
      const std::vector<int> reached = viewsReaching(updateEvidence(dirty, threads));
      std::vector<int> merged;
      std::set_union(dirty.begin(), dirty.end(), reached.begin(), reached.end(), std::back_inserter(merged));
      affected = std::move(merged);
    }
    std::vector<std::vector<std::uint64_t>> old(affected.size());
    for (std::size_t k = 0; k < affected.size(); ++k) old[k] = std::move(slots[affected[k]].region);
    struct Scratch {
      RegionMarker<2> own, marker2;
      RegionMarker<3> marker3;
      OccupancyGrid::Reader reader;
      ViewWidths widths;
    };
    parallelForWithScratch(
        affected.size(), threads, 2, [&] { return Scratch{{}, {}, {}, OccupancyGrid::Reader(occupancy), {}}; },
        [&](std::size_t k, Scratch& s) { computeRegion(slots[affected[k]], s.own, s.marker2, s.marker3, s.reader, s.widths); });
    SharedDelta shared;
    for (std::size_t k = 0; k < affected.size(); ++k) {
      const int i = affected[k];
      const std::vector<std::uint64_t>& now = slots[i].region;
      if (now != old[k] || slots[i].dirty) markSource(i);
      if (now.size() != old[k].size()) markPartners(i);
      for (std::uint64_t key : difference(old[k], now)) removeCell(i, key, shared);
      for (std::uint64_t key : difference(now, old[k])) addCell(i, key, shared);
      applyShared(i, shared);
      if (now.size() != old[k].size()) markPartners(i);
    }
    recomputed = affected.size();
  }
};

IncrementalOverlap::IncrementalOverlap(SensedSpaceModel model, double delta, const RegionParameters& params)
    : state_(std::make_unique<State>(model, delta, params)) {
  if (model == SensedSpaceModel::Points) {
    if (!(delta > 0.0) || !std::isfinite(delta))
      throw std::invalid_argument("match distance delta must be finite and > 0");
  } else {
    checkRegionParameters(params);
  }
}
IncrementalOverlap::~IncrementalOverlap() = default;
IncrementalOverlap::IncrementalOverlap(IncrementalOverlap&&) noexcept = default;
IncrementalOverlap& IncrementalOverlap::operator=(IncrementalOverlap&&) noexcept = default;

void IncrementalOverlap::check(int slot, const std::vector<Eigen::Vector3f>& points,
                               const Eigen::Vector3d& sensor_origin) const {
  const State& s = *state_;
  if (slot < 0) throw std::invalid_argument("negative slot");
  if (!sensor_origin.allFinite()) throw std::invalid_argument("sensor position is not finite");
  if (s.model == SensedSpaceModel::Points) return;
  // The grid's reach depends on whether the data stays planar with it.
  bool planar = observationPlanar({points.data(), points.data() + points.size()}, sensor_origin, 0.0,
                                  0.25 * s.params.cell_size);
  for (int i = 0; i < int(s.slots.size()); ++i)
    if (i != slot && s.slots[i].present) planar = planar && s.slots[i].planar;
  const bool volumetric = s.model == SensedSpaceModel::FreeSpace && !planar;
  if (!withinReach(sensor_origin, boxOf(points), s.params, volumetric))
    throw std::invalid_argument(reachMessage(s.params));
  if (volumetric && s.planar_used)  // the others are then indexed in 3D too
    for (int i = 0; i < int(s.slots.size()); ++i)
      if (i != slot && s.slots[i].present && !withinReach(s.slots[i].origin, s.slots[i].box, s.params, true))
        throw std::invalid_argument("with this observation the data is 3D, and observation " + std::to_string(i) +
                                    " lies too far for 3D cells of " + std::to_string(s.params.cell_size) + " m");
}

void IncrementalOverlap::set(int slot, std::vector<Eigen::Vector3f> points, const Eigen::Vector3d& sensor_origin) {
  State& s = *state_;
  if (slot >= int(s.slots.size())) s.slots.resize(slot + 1);
  Slot& o = s.slots[slot];
  o.present = true;
  o.dirty = true;
  o.box = boxOf(points);
  o.planar = observationPlanar({points.data(), points.data() + points.size()}, sensor_origin, 0.0,
                               0.25 * s.params.cell_size);
  o.points = std::move(points);
  o.origin = sensor_origin;
}

void IncrementalOverlap::erase(int slot) {
  State& s = *state_;
  if (!s.present(slot)) return;
  Slot& o = s.slots[slot];
  o.present = false;
  o.dirty = true;
  o.points.clear();
  o.box = Eigen::AlignedBox3f();
}

void IncrementalOverlap::invalidate() { state_->stale = true; }

std::vector<int> IncrementalOverlap::update(int threads, const InterruptFlag* interrupt) {
  State& s = *state_;
  throwIfInterrupted(interrupt);
  threads = threadCount(threads);
  s.changed.assign(s.slots.size(), 0);
  s.sources.assign(s.slots.size(), 0);
  if (s.model != SensedSpaceModel::Points) {
    const bool planar = s.planarNow();
    if (planar != s.planar_used) s.stale = true;
    s.planar_used = planar;
  }
  if (s.stale) s.resetAll();
  const std::vector<int> dirty = s.dirtySlots();
  if (s.model == SensedSpaceModel::Points) {
    s.updatePoints(dirty, threads);
  } else {
    s.updateRegions(dirty, threads);
  }
  for (int d : dirty) s.slots[d].dirty = false;
  std::vector<int> out;
  for (int i = 0; i < int(s.changed.size()); ++i)
    if (s.changed[i] && s.present(i)) out.push_back(i);
  return out;
}

std::vector<int> IncrementalOverlap::sourcesOfLastUpdate() const {
  const State& s = *state_;
  std::vector<int> out;
  for (int i = 0; i < int(s.sources.size()); ++i)
    if (s.sources[i] && s.present(i)) out.push_back(i);
  return out;
}

std::vector<int> IncrementalOverlap::slots() const {
  std::vector<int> out;
  for (int i = 0; i < int(state_->slots.size()); ++i)
    if (state_->slots[i].present) out.push_back(i);
  return out;
}

std::size_t IncrementalOverlap::pointCount(int slot) const {
  return state_->present(slot) ? state_->slots[slot].points.size() : 0;
}
std::size_t IncrementalOverlap::regionCells(int slot) const {
  return state_->present(slot) ? state_->slots[slot].region.size() : 0;
}
std::function<bool(const Eigen::Vector2d&)> IncrementalOverlap::planeCellReader() const {
  if (state_->model != SensedSpaceModel::Visibility) return [](const Eigen::Vector2d&) { return false; };
  auto reader = std::make_shared<OccupancyGrid::Reader>(state_->occupancy);
  const CellGrid grid = state_->grid;
  return [reader, grid](const Eigen::Vector2d& p) {
    return reader->occupied(cellOf<2>(grid.inCells<2>(Eigen::Vector3d(p.x(), p.y(), 0.0))));
  };
}

std::size_t IncrementalOverlap::recomputedLastUpdate() const { return state_->recomputed; }

WeightMatrix IncrementalOverlap::weightMatrix(double diagonal) const { return weightMatrix(diagonal, nullptr); }

WeightMatrix IncrementalOverlap::weightMatrix(double diagonal, const WeightMatrix* previous) const {
  WeightMatrix W;
  weightMatrix(diagonal, previous, W);
  W.data().squeeze();  // returned: no room kept for growth
  return W;
}

void IncrementalOverlap::weightMatrix(double diagonal, const WeightMatrix* previous, WeightMatrix& W) const {
  if (previous == &W) throw std::invalid_argument("weightMatrix: the output cannot be the previous matrix");
  State& s = *state_;
  if (!std::isfinite(diagonal) || diagonal < 0.0)
    throw std::invalid_argument("buildWeightMatrix: diagonal weight must be finite and >= 0");
  const std::vector<int> present = slots();
  std::vector<int> position(s.slots.size(), -1);
  for (std::size_t k = 0; k < present.size(); ++k) position[present[k]] = int(k);
  const bool points = s.model == SensedSpaceModel::Points;
  const auto size = [&](int i) { return double(points ? s.slots[i].points.size() : s.slots[i].region.size()); };
  const Eigen::Index n = Eigen::Index(present.size());
  // The previous matrix's column of a row unchanged since is this one's
  // when every slot it held keeps its position (observations appended, as a
  // robot adds them): the row's pairs, and the sizes of both ends of each,
  // are as they were, or the row would have been marked changed.
  const Eigen::Index kept = Eigen::Index(s.matrix_slots.size());
  const bool copy = previous && diagonal == s.matrix_diagonal && previous->rows() == kept &&
                    previous->cols() == kept && previous->isCompressed() && previous->nonZeros() == s.matrix_entries &&
                    kept <= n &&
                    std::equal(s.matrix_slots.begin(), s.matrix_slots.end(), present.begin());
  s.changed_since_matrix.resize(s.slots.size(), 1);
  const auto copied = [&](Eigen::Index k) { return copy && k < kept && !s.changed_since_matrix[present[k]]; };
  // Written straight into the compressed arrays, sized up front, a kept
  // column copied as one block: entry by entry, the copy of the unchanged
  // columns was about a twentieth of an online update at 10,000 scans.
  std::size_t entries = 0;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (copied(k)) {
      entries += std::size_t(previous->outerIndexPtr()[k + 1] - previous->outerIndexPtr()[k]);
      continue;
    }
    const auto& row = s.slots[present[k]].row;
    entries += row.size() + (diagonal != 0.0 ? 1 : 0);
  }
  W.resize(n, n);  // compressed; its storage kept, with a tenth to spare as rows are added
  W.data().resize(Eigen::Index(entries), 0.1);
  int* outer = W.outerIndexPtr();
  int* inner = W.innerIndexPtr();
  double* value = W.valuePtr();
  std::size_t at = 0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const int i = present[k];
    outer[k] = int(at);
    if (copied(k)) {
      const int begin = previous->outerIndexPtr()[k], end = previous->outerIndexPtr()[k + 1];
      std::copy(previous->innerIndexPtr() + begin, previous->innerIndexPtr() + end, inner + at);
      std::copy(previous->valuePtr() + begin, previous->valuePtr() + end, value + at);
      at += std::size_t(end - begin);
      continue;
    }
    const auto put = [&](Eigen::Index row, double v) {
      inner[at] = int(row);
      value[at] = v;
      ++at;
    };
    bool diagonal_done = diagonal == 0.0;
    for (const PairCounts& p : s.slots[i].row) {
      if (!diagonal_done && p.j > i) {
        put(k, diagonal);
        diagonal_done = true;
      }
      // Psi, eq. (18), with Pi of eq. (17) as SensedSpaceOverlap computes it.
      const double pi_ij = p.ij ? double(p.ij) / size(i) : 0.0;
      const double pi_ji = p.ji ? double(p.ji) / size(p.j) : 0.0;
      put(position[p.j], i < p.j ? 0.5 * (pi_ij + pi_ji) : 0.5 * (pi_ji + pi_ij));
    }
    if (!diagonal_done) put(k, diagonal);
  }
  outer[n] = int(at);
  s.matrix_slots = present;
  s.matrix_diagonal = diagonal;
  s.matrix_entries = W.nonZeros();
  std::fill(s.changed_since_matrix.begin(), s.changed_since_matrix.end(), 0);
}

}  // namespace obsgroup
