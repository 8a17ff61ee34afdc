#include "obsgroup/partition/open_floor.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

namespace obsgroup {

namespace {

/// Eight lines through a point, 22.5 degrees apart: a door or a corridor is
/// narrow across it whatever its heading, within about 8 degrees.
constexpr int kLines = 8;

/// How far the free space runs from `p` along `direction` (unit), in steps
/// of `step` metres, up to `cap`.
double freeRun(const Eigen::Vector2d& p, const Eigen::Vector2d& direction, double step, double cap,
               const OccupiedAt& occupied) {
  double s = 0.0;
  while (s < cap) {
    if (occupied(p + s * direction)) return s;
    s += step;
  }
  return cap;
}

struct UnionFind {
  explicit UnionFind(int n) : parent(std::size_t(n)) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[std::size_t(i)] != i) i = parent[std::size_t(i)] = parent[std::size_t(parent[std::size_t(i)])];
    return i;
  }
  /// The larger root joins the smaller; false when already one.
  bool join(int a, int b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    parent[std::size_t(std::max(a, b))] = std::min(a, b);
    return true;
  }
  std::vector<int> parent;
};

/// The chords through the points of the segment, as narrowestChord walks
/// them, stopped as soon as one is narrower than `stop_below` (when above 0;
/// a chord below it is then returned): a step through a door or a corridor
/// is settled by its first narrow line, whose far side need not be walked
/// beyond what would reach `stop_below`.
double walkChords(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double cell, double cap, double stop_below,
                  const OccupiedAt& occupied) {
  const int intervals = std::max(1, int(std::ceil((b - a).norm() / cell)));
  double narrowest = 2.0 * cap;
  for (int s = 0; s <= intervals; ++s) {
    const Eigen::Vector2d p = a + (double(s) / double(intervals)) * (b - a);
    for (int line = 0; line < kLines; ++line) {
      const double angle = 3.14159265358979323846 * double(line) / double(kLines);
      const Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
      const double ahead = freeRun(p, direction, 0.5 * cell, cap, occupied);
      const double behind_cap = stop_below > 0.0 ? std::min(cap, std::max(stop_below - ahead, 0.0) + cell) : cap;
      narrowest = std::min(narrowest, ahead + freeRun(p, -direction, 0.5 * cell, behind_cap, occupied));
      if (narrowest == 0.0 || narrowest < stop_below) return narrowest;
    }
  }
  return narrowest;
}

/// Whether the occupied cell holding `q` belongs to a piece of occupied
/// cells (8-connected, cells of `cell` metres) that fits within
/// `extent_cells` cells along both axes. Walks the piece from `q` and stops
/// as soon as it outgrows that; only cells within that many of `q` can
/// belong to a piece that fits, so the walk's marks are a small square.
bool withinSmallPiece(const Eigen::Vector2d& q, double cell, int extent_cells, const OccupiedAt& occupied) {
  const int side = 2 * extent_cells + 1;
  std::vector<char> marked(std::size_t(side) * std::size_t(side), 0);
  const auto index = [&](int i, int j) { return std::size_t(i + extent_cells) * std::size_t(side) + std::size_t(j + extent_cells); };
  std::vector<std::pair<int, int>> stack{{0, 0}};
  marked[index(0, 0)] = 1;
  int lo_i = 0, hi_i = 0, lo_j = 0, hi_j = 0;
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    for (int di = -1; di <= 1; ++di)
      for (int dj = -1; dj <= 1; ++dj) {
        const int ni = i + di, nj = j + dj;
        if (std::abs(ni) > extent_cells || std::abs(nj) > extent_cells) {
          // Beyond the square: the piece fits only if this cell is free.
          if (occupied(q + cell * Eigen::Vector2d(ni, nj))) return false;
          continue;
        }
        if (marked[index(ni, nj)] || !occupied(q + cell * Eigen::Vector2d(ni, nj))) continue;
        marked[index(ni, nj)] = 1;
        lo_i = std::min(lo_i, ni), hi_i = std::max(hi_i, ni), lo_j = std::min(lo_j, nj), hi_j = std::max(hi_j, nj);
        if (hi_i - lo_i + 1 > extent_cells || hi_j - lo_j + 1 > extent_cells) return false;
        stack.emplace_back(ni, nj);
      }
  }
  return true;
}

/// The observations' positions by square cells of `range`: whether a point
/// lies within `range` of one looks at the nine cells around it.
class NearPositions {
 public:
  NearPositions(const std::vector<Eigen::Vector2d>& positions, double range) : range_(range) {
    for (const Eigen::Vector2d& p : positions)
      if (p.allFinite()) cells_[key(cellOf(p.x()), cellOf(p.y()))].push_back(p);
  }
  bool near(const Eigen::Vector2d& q) const {
    const std::int64_t cx = cellOf(q.x()), cy = cellOf(q.y());
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = cells_.find(key(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (const Eigen::Vector2d& p : it->second)
          if ((p - q).squaredNorm() <= range_ * range_) return true;
      }
    return false;
  }

 private:
  std::int64_t cellOf(double v) const { return std::int64_t(std::floor(v / range_)); }
  static std::uint64_t key(std::int64_t x, std::int64_t y) {
    return (std::uint64_t(std::uint32_t(x)) << 32) | std::uint64_t(std::uint32_t(y));
  }
  double range_;
  std::unordered_map<std::uint64_t, std::vector<Eigen::Vector2d>> cells_;
};

}  // namespace

std::vector<int> joinGroups(Partition& partition, const std::vector<std::pair<int, int>>& pairs) {
  const int count = int(partition.groups.size());
  UnionFind sets(count);
  for (const auto& [a, b] : pairs) {
    if (a < 0 || b < 0 || a >= count || b >= count)
      throw std::invalid_argument("joinGroups: the pair (" + std::to_string(a) + ", " + std::to_string(b) +
                                  ") names a group beyond the " + std::to_string(count) + " there are");
    sets.join(a, b);
  }
  // Each set's members, in the order of its first group (the groups are
  // ordered by their first observation, so the union is too).
  std::vector<std::vector<int>> merged;
  std::vector<int> first_of;
  std::vector<int> index_of_root(std::size_t(count), -1);
  for (int g = 0; g < count; ++g) {
    const int root = sets.find(g);
    if (index_of_root[std::size_t(root)] < 0) {
      index_of_root[std::size_t(root)] = int(merged.size());
      merged.emplace_back();
      first_of.push_back(g);
    }
    auto& members = merged[std::size_t(index_of_root[std::size_t(root)])];
    members.insert(members.end(), partition.groups[std::size_t(g)].begin(), partition.groups[std::size_t(g)].end());
  }
  if (int(merged.size()) == count) return first_of;
  for (auto& members : merged) std::sort(members.begin(), members.end());
  partition.groups = std::move(merged);
  for (int g = 0; g < int(partition.groups.size()); ++g)
    for (int i : partition.groups[std::size_t(g)]) partition.group_of[std::size_t(i)] = g;
  return first_of;
}

double narrowestChord(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double cell, double cap,
                      const OccupiedAt& occupied) {
  return walkChords(a, b, cell, cap, 0.0, occupied);
}

bool enclosedAlong(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double cell, double reach,
                   const OccupiedAt& occupied, const SeenAt& seen) {
  const int intervals = std::max(1, int(std::ceil((b - a).norm() / cell)));
  const double step = 0.5 * cell;
  for (int s = 0; s <= intervals; ++s) {
    const Eigen::Vector2d p = a + (double(s) / double(intervals)) * (b - a);
    int open = 0;
    for (int direction = 0; direction < 2 * kLines; ++direction) {
      const double angle = 3.14159265358979323846 * double(direction) / double(kLines);
      const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
      // The first occupied cell along the ray must be a wall the route came
      // near, not a structure far off that no view reached.
      double t = 0.0;
      while (t < reach && !occupied(p + t * d)) t += step;
      if (t >= reach) {
        if (++open > kMaxOpenDirections) return false;
      } else if (!seen(p + t * d)) {
        return false;
      }
    }
  }
  return true;
}

std::vector<OpenFloorJoin> joinAcrossOpenFloor(Partition& partition, const std::vector<Eigen::Vector2d>& positions,
                                               double width, double cell, const OccupiedAt& occupied,
                                               double view_range, double reach) {
  const int n = int(partition.group_of.size());
  if (int(positions.size()) != n)
    throw std::invalid_argument("joinAcrossOpenFloor: one position per observation expected (" +
                                std::to_string(positions.size()) + " for " + std::to_string(n) + ")");
  for (const double v : {width, cell, view_range, reach})
    if (!(std::isfinite(v) && v > 0.0))
      throw std::invalid_argument("joinAcrossOpenFloor: width, cell, view range and reach must be finite and positive");
  std::unique_ptr<NearPositions> near;  // made when a step first needs it
  const SeenAt seen = [&](const Eigen::Vector2d& q) {
    if (!near) near = std::make_unique<NearPositions>(positions, kSeenBeyondViews * view_range);
    return near->near(q);
  };
  // Free space flows round a pillar or a piece of furniture: such a piece
  // does not narrow a chord, a wall does (the enclosure still meets both).
  const int clutter_cells = int(std::floor(kClutterExtent / cell + 1e-9));
  const OccupiedAt walls = [&](const Eigen::Vector2d& q) {
    return occupied(q) && !(clutter_cells > 0 && withinSmallPiece(q, cell, clutter_cells, occupied));
  };
  // Per pair of groups the narrowest chord of its steps so far; a pair is
  // settled as soon as one step is narrower than `width`.
  std::map<std::pair<int, int>, double> narrowest;
  for (int k = 0; k + 1 < n; ++k) {
    const int a = partition.group_of[std::size_t(k)], b = partition.group_of[std::size_t(k + 1)];
    if (a == b) continue;
    const std::pair<int, int> pair(std::min(a, b), std::max(a, b));
    const auto it = narrowest.find(pair);
    if (it != narrowest.end() && it->second < width) continue;
    const Eigen::Vector2d &from = positions[std::size_t(k)], &to = positions[std::size_t(k + 1)];
    double chord = 0.0;  // a step from or to an observation without a position is no evidence
    if (from.allFinite() && to.allFinite()) {
      chord = walkChords(from, to, cell, width, width, walls);
      // Open floor (rare): walk every line in full, for the join's record.
      if (chord >= width) chord = narrowestChord(from, to, cell, width, walls);
      if (chord >= width && !enclosedAlong(from, to, cell, reach, occupied, seen)) chord = 0.0;
    }
    if (it == narrowest.end())
      narrowest.emplace(pair, chord);
    else
      it->second = std::min(it->second, chord);
  }
  std::vector<OpenFloorJoin> joins;
  UnionFind sets(int(partition.groups.size()));
  for (const auto& [pair, chord] : narrowest)
    if (chord >= width && sets.join(pair.first, pair.second)) joins.push_back({pair.first, pair.second, chord});
  if (joins.empty()) return joins;
  std::vector<std::pair<int, int>> pairs;
  for (const OpenFloorJoin& join : joins) pairs.emplace_back(join.first, join.second);
  joinGroups(partition, pairs);
  return joins;
}

}  // namespace obsgroup
