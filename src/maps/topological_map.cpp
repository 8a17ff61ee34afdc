#include "obsgroup/maps/topological_map.h"

#include "obsgroup/common/parallel_for.h"
#include "obsgroup/maps/pose_average.h"

#include <algorithm>
#include <string>
#include <tuple>
#include <stdexcept>
#include <utility>

namespace obsgroup {

const Eigen::Isometry3d& LocalMapFrame::memberPose(int i) const {
  const auto it = std::lower_bound(members.begin(), members.end(), i);
  if (it == members.end() || *it != i) throw std::out_of_range("LocalMapFrame: not a member");
  return member_poses[it - members.begin()];
}

namespace {

void checkPosesFinite(const std::string& who, const std::vector<Eigen::Isometry3d>& poses) {
  for (std::size_t i = 0; i < poses.size(); ++i)
    if (!poses[i].matrix().allFinite())
      throw std::invalid_argument(who + ": the pose of observation " + std::to_string(i) + " is not finite");
}

}  // namespace

int strongestMember(const std::vector<int>& group, const WeightMatrix& W) {
  if (W.rows() != W.cols()) throw std::invalid_argument("strongestMember: W must be square");
  checkMembers("strongestMember", group, W.rows());
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
  const Eigen::Index n = Eigen::Index(poses.size());
  checkWeightMatrixSize("initialFrame", W, n);
  checkMembers("initialFrame", group, n);
  for (int i : group)
    if (!poses[i].matrix().allFinite())
      throw std::invalid_argument("initialFrame: the pose of observation " + std::to_string(i) + " is not finite");
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
  for (std::size_t g = 0; g < partition.groups.size(); ++g) try {
      frames.push_back(initialFrame(partition.groups[g], W, poses));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("group " + std::to_string(g) + ": " + e.what());
    }
  return frames;
}

namespace {

/// A pair of observations, a in local map A and b in a later map B, whose
/// relative pose supports the arc between the two maps.
struct CrossPair {
  int to, a, b;  ///< B, a, b
  double weight;
  bool overlap;  ///< W_ab > 0; otherwise a and b follow each other in the input
  auto key() const { return std::tie(to, a, b); }
};

/// The pairs joining the members of local map A to later maps, sorted by (B, a, b).
void crossPairsOf(const LocalMapFrame& A, int node, const std::vector<int>& node_of, const WeightMatrix& W,
                  std::vector<CrossPair>& pairs) {
  pairs.clear();
  const int n = static_cast<int>(node_of.size());
  for (int a : A.members) {
    for (WeightMatrix::InnerIterator it(W, a); it; ++it)
      if (node_of[it.row()] > node && it.value() > 0.0)
        pairs.push_back({node_of[it.row()], a, static_cast<int>(it.row()), it.value(), true});
    for (int b : {a - 1, a + 1})
      if (b >= 0 && b < n && node_of[b] > node) pairs.push_back({node_of[b], a, b, kSequencePairWeight, false});
  }
  std::sort(pairs.begin(), pairs.end(), [](const CrossPair& l, const CrossPair& r) { return l.key() < r.key(); });
}

/// The arc from map `from` supported by pairs[begin, end), which all join the
/// same later map, sorted by (a, b); a pair both overlapping and consecutive
/// counts once, with its larger weight. to_local[i] = M_i pose_i^-1 maps global
/// coordinates to the frame of i's local map, so a pair's estimate
/// M_a (pose_a^-1 pose_b) M_b^-1 is to_local[a] to_local[b]^-1.
TopologicalArc makeArc(int from, const std::vector<CrossPair>& pairs, std::size_t begin, std::size_t end,
                       const std::vector<Eigen::Isometry3d>& to_local) {
  TopologicalArc arc;
  arc.from = from;
  arc.to = pairs[begin].to;
  std::vector<Eigen::Isometry3d> estimates;
  std::vector<double> weights;
  for (std::size_t k = begin; k < end; ++k) {
    const CrossPair& p = pairs[k];
    (p.overlap ? arc.overlapping_pairs : arc.sequence_pairs) += 1;
    if (p.overlap) arc.weight += p.weight;
    if (k > begin && p.a == pairs[k - 1].a && p.b == pairs[k - 1].b) {
      weights.back() = std::max(weights.back(), p.weight);
      continue;
    }
    estimates.push_back(to_local[p.a] * to_local[p.b].inverse());
    weights.push_back(p.weight);
  }
  const PoseAverage average = averagePoses(estimates, weights);
  arc.transform = average.mean;
  arc.translation_spread = average.translation_spread;
  arc.rotation_spread = average.rotation_spread;
  arc.pairs = static_cast<int>(estimates.size());
  return arc;
}

}  // namespace

std::vector<Eigen::Isometry3d> globalPoses(const TopologicalMap& topology, std::size_t observations) {
  std::vector<Eigen::Isometry3d> poses(observations, Eigen::Isometry3d::Identity());
  for (std::size_t g = 0; g < topology.nodes.size(); ++g) {
    const LocalMapFrame& node = topology.nodes[g];
    if (node.member_poses.size() != node.members.size())
      throw std::invalid_argument("globalPoses: local map " + std::to_string(g) + " has " +
                                  std::to_string(node.member_poses.size()) + " member poses for " +
                                  std::to_string(node.members.size()) + " members");
    for (std::size_t k = 0; k < node.members.size(); ++k) {
      if (node.members[k] < 0 || std::size_t(node.members[k]) >= observations)
        throw std::invalid_argument("globalPoses: local map " + std::to_string(g) + " holds observation " +
                                    std::to_string(node.members[k]) + " of " + std::to_string(observations));
      poses[node.members[k]] = node.pose * node.member_poses[k];
    }
  }
  return poses;
}

TopologicalMap buildTopologicalMap(std::vector<LocalMapFrame> nodes, const WeightMatrix& W,
                                   const std::vector<Eigen::Isometry3d>& poses, int threads) {
  const int n = static_cast<int>(poses.size());
  checkWeightMatrixSize("buildTopologicalMap", W, n);
  checkPosesFinite("buildTopologicalMap", poses);
  std::vector<int> node_of(n, -1);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const std::string who = "buildTopologicalMap: local map " + std::to_string(k);
    const LocalMapFrame& node = nodes[k];
    checkMembers(who, node.members, n);
    if (node.member_poses.size() != node.members.size())
      throw std::invalid_argument(who + ": " + std::to_string(node.member_poses.size()) + " member poses for " +
                                  std::to_string(node.members.size()) + " members");
    for (std::size_t m = 0; m < node.members.size(); ++m)
      if (!node.member_poses[m].matrix().allFinite())
        throw std::invalid_argument(who + ": the pose of member " + std::to_string(node.members[m]) +
                                    " is not finite");
    for (int i : node.members) {
      if (node_of[i] >= 0)
        throw std::invalid_argument(who + ": observation " + std::to_string(i) + " is also in local map " +
                                    std::to_string(node_of[i]));
      node_of[i] = static_cast<int>(k);
    }
  }
  for (int i = 0; i < n; ++i)
    if (node_of[i] < 0)
      throw std::invalid_argument("buildTopologicalMap: observation " + std::to_string(i) + " is in no local map");

  std::vector<Eigen::Isometry3d> to_local(n);
  for (const LocalMapFrame& node : nodes)
    for (std::size_t k = 0; k < node.members.size(); ++k)
      to_local[node.members[k]] = node.member_poses.at(k) * poses[node.members[k]].inverse();

  TopologicalMap map;
  map.nodes = std::move(nodes);
  const int maps = static_cast<int>(map.nodes.size());
  std::vector<std::vector<TopologicalArc>> arcs_from(maps);  // arcs_from[A]: the arcs (A, B > A), by B
  parallelForWithScratch(
      std::size_t(maps), threads, 4, [] { return std::vector<CrossPair>(); },
      [&](std::size_t a, std::vector<CrossPair>& pairs) {
        const int A = static_cast<int>(a);
        crossPairsOf(map.nodes[A], A, node_of, W, pairs);
        for (std::size_t begin = 0, end; begin < pairs.size(); begin = end) {
          for (end = begin + 1; end < pairs.size() && pairs[end].to == pairs[begin].to;) ++end;
          arcs_from[A].push_back(makeArc(A, pairs, begin, end, to_local));
        }
      });
  for (auto& arcs : arcs_from) map.arcs.insert(map.arcs.end(), arcs.begin(), arcs.end());
  return map;
}

}  // namespace obsgroup
