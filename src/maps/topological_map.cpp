#include "obsgroup/maps/topological_map.h"

#include "obsgroup/maps/pose_average.h"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <utility>

namespace obsgroup {

const Eigen::Isometry3d& LocalMapFrame::memberPose(int i) const {
  const auto it = std::lower_bound(members.begin(), members.end(), i);
  if (it == members.end() || *it != i) throw std::out_of_range("LocalMapFrame: not a member");
  return member_poses[it - members.begin()];
}

int strongestMember(const std::vector<int>& group, const WeightMatrix& W) {
  int best = group.front();
  double best_strength = -1.0;
  for (int i : group) {
    double strength = 0.0;
    for (WeightMatrix::InnerIterator it(W, i); it; ++it)
      if (it.row() != i && std::binary_search(group.begin(), group.end(), static_cast<int>(it.row())))
        strength += it.value();
    if (strength > best_strength) {  // strict: ties keep the smaller index
      best = i;
      best_strength = strength;
    }
  }
  return best;
}

LocalMapFrame initialFrame(const std::vector<int>& group, const WeightMatrix& W,
                           const std::vector<Eigen::Isometry3d>& poses) {
  LocalMapFrame frame;
  frame.members = group;
  frame.reference = strongestMember(group, W);
  frame.pose = poses[frame.reference];
  const Eigen::Isometry3d inverse = frame.pose.inverse();
  for (int i : group) frame.member_poses.push_back(i == frame.reference ? Eigen::Isometry3d::Identity() : inverse * poses[i]);
  return frame;
}

std::vector<LocalMapFrame> initialFrames(const Partition& partition, const WeightMatrix& W,
                                         const std::vector<Eigen::Isometry3d>& poses) {
  std::vector<LocalMapFrame> frames;
  for (const auto& group : partition.groups) frames.push_back(initialFrame(group, W, poses));
  return frames;
}

namespace {

struct ArcSupport {
  std::map<std::pair<int, int>, double> pairs;  // (a, b) with a in `from`, b in `to` -> weight
  int overlapping = 0, sequence = 0;
  double weight = 0.0;
};

}  // namespace

TopologicalMap buildTopologicalMap(std::vector<LocalMapFrame> nodes, const WeightMatrix& W,
                                   const std::vector<Eigen::Isometry3d>& poses) {
  const int n = static_cast<int>(poses.size());
  if (W.rows() != n) throw std::invalid_argument("buildTopologicalMap: W and poses disagree in size");
  std::vector<int> node_of(n, -1);
  for (std::size_t k = 0; k < nodes.size(); ++k)
    for (int i : nodes[k].members) node_of.at(i) = static_cast<int>(k);
  for (int i = 0; i < n; ++i)
    if (node_of[i] < 0) throw std::invalid_argument("buildTopologicalMap: an observation is in no local map");

  std::map<std::pair<int, int>, ArcSupport> support;
  const auto add = [&](int a, int b, double w, bool overlap) {
    if (node_of[a] == node_of[b]) return;
    if (node_of[a] > node_of[b]) std::swap(a, b);
    ArcSupport& s = support[{node_of[a], node_of[b]}];
    auto [it, inserted] = s.pairs.emplace(std::make_pair(a, b), w);
    if (!inserted) it->second = std::max(it->second, w);
    (overlap ? s.overlapping : s.sequence) += 1;
    if (overlap) s.weight += w;
  };
  for (int b = 0; b < W.outerSize(); ++b)
    for (WeightMatrix::InnerIterator it(W, b); it; ++it)
      if (it.row() < b && it.value() > 0.0) add(static_cast<int>(it.row()), b, it.value(), true);
  for (int i = 0; i + 1 < n; ++i) add(i, i + 1, kSequencePairWeight, false);

  TopologicalMap map;
  map.nodes = std::move(nodes);
  for (const auto& [key, s] : support) {
    const LocalMapFrame& A = map.nodes[key.first];
    const LocalMapFrame& B = map.nodes[key.second];
    std::vector<Eigen::Isometry3d> estimates;
    std::vector<double> weights;
    for (const auto& [pair, w] : s.pairs) {
      const auto [a, b] = pair;
      estimates.push_back(A.memberPose(a) * (poses[a].inverse() * poses[b]) * B.memberPose(b).inverse());
      weights.push_back(w);
    }
    const PoseAverage average = averagePoses(estimates, weights);
    TopologicalArc arc;
    arc.from = key.first;
    arc.to = key.second;
    arc.transform = average.mean;
    arc.translation_spread = average.translation_spread;
    arc.rotation_spread = average.rotation_spread;
    arc.weight = s.weight;
    arc.overlapping_pairs = s.overlapping;
    arc.sequence_pairs = s.sequence;
    arc.pairs = static_cast<int>(s.pairs.size());
    map.arcs.push_back(arc);
  }
  return map;
}

}  // namespace obsgroup
