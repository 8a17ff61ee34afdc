#include "group_colours.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <tuple>
#include <utility>

namespace obsgroup::render {

namespace {

/// A kd-tree over the group centres, re-centred on the first so that float
/// coordinates keep millimetres even at map coordinates like UTM's.
struct CentreTree {
  explicit CentreTree(const std::vector<Eigen::Vector3d>& centres) : cloud(new pcl::PointCloud<pcl::PointXYZ>) {
    if (centres.empty()) return;
    for (const auto& c : centres) {
      const Eigen::Vector3d p = c - centres[0];
      cloud->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
      extent = std::max(extent, p.cwiseAbs().maxCoeff());
    }
    tree.setInputCloud(cloud);
  }
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud;
  pcl::search::KdTree<pcl::PointXYZ> tree;
  double extent = 0.0;
};

/// The (up to) two centres nearest centre g, other than g, exactly as sorting
/// every other by (squared distance in double, index) would give them: the
/// kd-tree's three nearest bound the distance, and every centre within it
/// (plus the float coordinates' rounding) is ranked in double. A million
/// scans make 50,000 groups: all pairs would be 2.5 billion distances.
std::vector<int> twoNearestOthers(const std::vector<Eigen::Vector3d>& centre, int g, const CentreTree& t) {
  if (centre.size() < 2) return {};
  std::vector<int> index;
  std::vector<float> squared;
  t.tree.nearestKSearch(g, 3, index, squared);
  const double bound = std::sqrt(double(*std::max_element(squared.begin(), squared.end())));
  const double radius = bound * (1 + 1e-5) + 1e-5 * (1 + t.extent);
  t.tree.radiusSearch(g, radius, index, squared);
  std::vector<std::pair<double, int>> by_distance;
  for (int h : index)
    if (h != g) by_distance.emplace_back((centre[std::size_t(g)] - centre[std::size_t(h)]).squaredNorm(), h);
  const std::size_t k = std::min<std::size_t>(2, by_distance.size());
  std::partial_sort(by_distance.begin(), by_distance.begin() + k, by_distance.end());
  std::vector<int> nearest;
  for (std::size_t j = 0; j < k; ++j) nearest.push_back(by_distance[j].second);
  return nearest;
}

}  // namespace

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
  const CentreTree tree(centre);
  for (int g = 0; g < n; ++g)
    for (int h : twoNearestOthers(centre, g, tree))
      neighbours[g].push_back(h), neighbours[h].push_back(g);
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return neighbours;
}

namespace {

/// A greedy colouring (DSATUR: next the node whose neighbours hold the most
/// distinct colours, then the most neighbours, then the lowest index; the
/// smallest colour none of them holds).
std::vector<int> colourGraph(const std::vector<std::vector<int>>& neighbours) {
  const int n = static_cast<int>(neighbours.size());
  std::vector<int> colour(n, -1);
  std::vector<std::vector<char>> seen(n);  // colours held by each node's neighbours
  std::vector<int> saturation(n, 0);
  // The uncoloured nodes by (saturation, neighbours) descending, then index:
  // the first is the next, found in log n where a scan of all is n (50,000
  // groups at a million scans).
  using Key = std::tuple<int, long long, int>;
  const auto key = [&](int g) { return Key{-saturation[g], -static_cast<long long>(neighbours[g].size()), g}; };
  std::set<Key> waiting;
  for (int g = 0; g < n; ++g) waiting.insert(key(g));
  while (!waiting.empty()) {
    const int next = std::get<2>(*waiting.begin());
    waiting.erase(waiting.begin());
    const auto free = std::find(seen[next].begin(), seen[next].end(), 0);
    colour[next] = int(free - seen[next].begin());
    for (int h : neighbours[next]) {
      if (seen[h].size() <= std::size_t(colour[next])) seen[h].resize(colour[next] + 1, 0);
      if (!seen[h][colour[next]]) {
        if (colour[h] < 0) waiting.erase(key(h));
        seen[h][colour[next]] = 1, ++saturation[h];
        if (colour[h] < 0) waiting.insert(key(h));
      }
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
