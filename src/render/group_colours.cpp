#include "group_colours.h"

#include <algorithm>
#include <numeric>
#include <tuple>
#include <utility>

namespace obsgroup::render {

namespace {

/// Neighbours of each node, ascending: joined by one of `arcs` (indices into
/// topology.arcs), or among each other's two nearest centres (the mean of
/// the members' global poses).
std::vector<std::vector<int>> groupNeighbours(const TopologicalMap& topology, const std::vector<std::size_t>& arcs) {
  const int n = static_cast<int>(topology.nodes.size());
  std::vector<std::vector<int>> neighbours(n);
  for (std::size_t a : arcs) {
    const TopologicalArc& arc = topology.arcs[a];
    if (arc.from >= 0 && arc.to < n) neighbours[arc.from].push_back(arc.to), neighbours[arc.to].push_back(arc.from);
  }
  std::vector<Eigen::Vector3d> centre(n, Eigen::Vector3d::Zero());
  for (int g = 0; g < n; ++g) {
    const LocalMapFrame& node = topology.nodes[g];
    for (const auto& member : node.member_poses) centre[g] += (node.pose * member).translation();
    centre[g] /= double(std::max<std::size_t>(1, node.member_poses.size()));
  }
  for (int g = 0; g < n; ++g) {
    std::vector<std::pair<double, int>> by_distance;
    for (int h = 0; h < n; ++h)
      if (h != g) by_distance.emplace_back((centre[g] - centre[h]).squaredNorm(), h);
    const std::size_t k = std::min<std::size_t>(2, by_distance.size());
    std::partial_sort(by_distance.begin(), by_distance.begin() + k, by_distance.end());
    for (std::size_t j = 0; j < k; ++j)
      neighbours[g].push_back(by_distance[j].second), neighbours[by_distance[j].second].push_back(g);
  }
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return neighbours;
}

/// A greedy colouring (DSATUR: next the node whose neighbours hold the most
/// distinct colours, then the most neighbours, then the lowest index; the
/// smallest colour none of them holds).
std::vector<int> colourGraph(const std::vector<std::vector<int>>& neighbours) {
  const int n = static_cast<int>(neighbours.size());
  std::vector<int> colour(n, -1);
  std::vector<std::vector<char>> seen(n);  // colours held by each node's neighbours
  std::vector<int> saturation(n, 0);
  for (int step = 0; step < n; ++step) {
    int next = -1;
    for (int g = 0; g < n; ++g)
      if (colour[g] < 0 && (next < 0 || std::make_pair(saturation[g], neighbours[g].size()) >
                                            std::make_pair(saturation[next], neighbours[next].size())))
        next = g;
    const auto free = std::find(seen[next].begin(), seen[next].end(), 0);
    colour[next] = int(free - seen[next].begin());
    for (int h : neighbours[next]) {
      if (seen[h].size() <= std::size_t(colour[next])) seen[h].resize(colour[next] + 1, 0);
      if (!seen[h][colour[next]]) seen[h][colour[next]] = 1, ++saturation[h];
    }
  }
  return colour;
}

}  // namespace

std::vector<int> groupColours(const TopologicalMap& topology) {
  std::vector<std::size_t> all(topology.arcs.size());
  std::iota(all.begin(), all.end(), std::size_t(0));
  std::vector<int> colours = colourGraph(groupNeighbours(topology, all));
  if (!colours.empty() && *std::max_element(colours.begin(), colours.end()) >= kDistinctColours)
    colours = colourGraph(groupNeighbours(topology, shownArcs(topology, 3)));  // map.png's
  return colours;
}

std::vector<std::size_t> shownArcs(const TopologicalMap& topology, int per_node) {
  const auto stronger = [&](std::size_t a, std::size_t b) {
    const TopologicalArc &x = topology.arcs[a], &y = topology.arcs[b];
    return std::tie(x.weight, x.overlapping_pairs, x.sequence_pairs) >
           std::tie(y.weight, y.overlapping_pairs, y.sequence_pairs);
  };
  std::vector<std::vector<std::size_t>> of(topology.nodes.size());
  for (std::size_t a = 0; a < topology.arcs.size(); ++a) {
    const TopologicalArc& arc = topology.arcs[a];
    for (int node : {arc.from, arc.to})
      if (node >= 0 && std::size_t(node) < of.size()) of[node].push_back(a);
  }
  std::vector<char> shown(topology.arcs.size(), 0);
  for (auto& arcs : of) {
    const std::size_t k = std::min<std::size_t>(std::max(0, per_node), arcs.size());
    std::partial_sort(arcs.begin(), arcs.begin() + k, arcs.end(), stronger);
    for (std::size_t j = 0; j < k; ++j) shown[arcs[j]] = 1;
  }
  std::vector<std::size_t> result;
  for (std::size_t a = 0; a < shown.size(); ++a)
    if (shown[a]) result.push_back(a);
  return result;
}

}  // namespace obsgroup::render
