#include "obsgroup/maps/alignment_pairs.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <queue>
#include <tuple>

namespace obsgroup::detail {

std::vector<std::pair<int, int>> maximumSpanningTree(const LocalMapFrame& frame, const WeightMatrix& W) {
  const auto& members = frame.members;
  const auto local = [&members](int i) {
    const auto it = std::lower_bound(members.begin(), members.end(), i);
    return it != members.end() && *it == i ? static_cast<int>(it - members.begin()) : -1;
  };
  std::vector<bool> done(members.size(), false);
  std::vector<std::pair<int, int>> order;  // (member, parent)
  // (weight, -child, parent): the heaviest edge first, ties to the smaller child.
  std::priority_queue<std::tuple<double, int, int>> edges;
  const int root = local(frame.reference);
  edges.emplace(std::numeric_limits<double>::infinity(), -root, -1);
  while (!edges.empty()) {
    const auto [w, negative_child, parent] = edges.top();
    edges.pop();
    const int child = -negative_child;
    if (done[child]) continue;
    done[child] = true;
    order.emplace_back(child, parent);
    for (WeightMatrix::InnerIterator it(W, members[child]); it; ++it) {
      const int next = local(static_cast<int>(it.row()));
      if (next >= 0 && !done[next] && it.value() > 0.0) edges.emplace(it.value(), -next, child);
    }
  }
  for (std::size_t k = 0; k < members.size(); ++k)
    if (!done[k]) order.emplace_back(static_cast<int>(k), -1);
  return order;
}

WeightMatrix pointOverlap(const LocalMapFrame& frame, const std::vector<MemberPoints>& points, double cell,
                                 Eigen::Index size) {
  std::vector<std::pair<std::uint64_t, int>> cells;  // (cell key, member position)
  std::vector<double> counts(points.size(), 0.0);
  const auto index = [cell](double v) { return std::uint64_t(std::int64_t(std::floor(v / cell)) + (1 << 20)) & 0x1FFFFF; };
  for (std::size_t k = 0; k < points.size(); ++k) {
    std::vector<std::uint64_t> keys;
    keys.reserve(points[k].size());
    for (const auto& p : points[k]) {
      const Eigen::Vector3d x = frame.member_poses[k] * p.cast<double>();
      keys.push_back(index(x.x()) << 42 | index(x.y()) << 21 | index(x.z()));
    }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    counts[k] = double(keys.size());
    for (const auto key : keys) cells.emplace_back(key, static_cast<int>(k));
  }
  std::sort(cells.begin(), cells.end());
  std::map<std::pair<int, int>, double> shared;
  for (std::size_t begin = 0, end; begin < cells.size(); begin = end) {
    for (end = begin; end < cells.size() && cells[end].first == cells[begin].first; ++end) {
    }
    for (std::size_t a = begin; a < end; ++a)
      for (std::size_t b = a + 1; b < end; ++b) shared[{cells[a].second, cells[b].second}] += 1.0;
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (const auto& [pair, n] : shared) {
    const double w = n / std::sqrt(counts[pair.first] * counts[pair.second]);
    const int a = frame.members[pair.first], b = frame.members[pair.second];
    entries.emplace_back(a, b, w);
    entries.emplace_back(b, a, w);
  }
  WeightMatrix overlap(size, size);
  overlap.setFromTriplets(entries.begin(), entries.end());
  return overlap;
}

void addStrongestPartners(const std::vector<int>& members, const WeightMatrix& by, int count,
                                 std::set<std::pair<int, int>>& taken, std::vector<std::pair<int, int>>& pairs) {
  for (std::size_t k = 0; k < members.size(); ++k) {
    std::vector<std::pair<double, int>> overlapping;  // (-weight, member position): strongest first
    for (WeightMatrix::InnerIterator it(by, members[k]); it; ++it) {
      const auto found = std::lower_bound(members.begin(), members.end(), static_cast<int>(it.row()));
      if (found != members.end() && *found == it.row() && it.value() > 0 && *found != members[k])
        overlapping.emplace_back(-it.value(), static_cast<int>(found - members.begin()));
    }
    std::sort(overlapping.begin(), overlapping.end());
    const std::size_t n = std::min<std::size_t>(overlapping.size(), std::max(0, count));
    for (std::size_t s = 0; s < n; ++s) {
      const int a = static_cast<int>(k), b = overlapping[s].second;
      const std::pair<int, int> pair(std::min(a, b), std::max(a, b));
      if (taken.insert(pair).second) pairs.push_back(pair);
    }
  }
}

}  // namespace obsgroup::detail
