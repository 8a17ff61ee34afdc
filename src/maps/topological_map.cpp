#include "obsgroup/maps/topological_map.h"

#include <map>
#include <stdexcept>
#include <utility>

namespace obsgroup {

TopologicalMap buildTopologicalMap(const Partition& partition, const WeightMatrix& W,
                                   const std::vector<Eigen::Isometry3d>& poses) {
  const std::size_t n = partition.group_of.size();
  if (static_cast<std::size_t>(W.rows()) != n || poses.size() != n)
    throw std::invalid_argument("buildTopologicalMap: partition, W and poses disagree in size");
  TopologicalMap map;
  for (const auto& group : partition.groups) {
    TopologicalNode node;
    node.members = group;
    node.reference = group.front();
    node.pose = poses[node.reference];
    map.nodes.push_back(std::move(node));
  }
  std::map<std::pair<int, int>, TopologicalArc> arcs;  // ordered by (from, to)
  for (int b = 0; b < W.outerSize(); ++b) {
    for (WeightMatrix::InnerIterator it(W, b); it; ++it) {
      const int a = static_cast<int>(it.row());
      const int ga = partition.group_of[a], gb = partition.group_of[b];
      if (a >= b || ga == gb || it.value() == 0.0) continue;
      TopologicalArc& arc = arcs[{std::min(ga, gb), std::max(ga, gb)}];
      arc.weight += it.value();
      ++arc.pairs;
    }
  }
  for (auto& [key, arc] : arcs) {
    arc.from = key.first;
    arc.to = key.second;
    arc.transform = map.nodes[arc.from].pose.inverse() * map.nodes[arc.to].pose;
    map.arcs.push_back(arc);
  }
  return map;
}

}  // namespace obsgroup
