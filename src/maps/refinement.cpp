#include "obsgroup/maps/refinement.h"

#include "refinement/pair_aligner.h"
#include "refinement/pose_graph.h"
#include "refinement/prepared_member.h"
#include "refinement/se3.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

namespace obsgroup {

std::string RefinementReport::warning() const {
  // The unaligned members are unlinked too: counted once, as kept.
  const int kept = kept_beyond_bound + kept_unaligned;
  const int apart = static_cast<int>(unlinked.size()) - kept_unaligned;
  if (kept <= 0 && apart <= 0) return "";  // pairs that leave a corridor's length free are expected
  std::string text;
  if (kept > 0) text = std::to_string(kept) + " of " + std::to_string(members) + " members kept the input pose";
  if (apart > 0)
    text += (text.empty() ? "" : "; ") + std::to_string(apart) + (text.empty() ? " of " + std::to_string(members) + " members" : "") +
            " not linked to their map's reference";
  return text;
}

RefinementReport& RefinementReport::operator+=(const RefinementReport& other) {
  members += other.members;
  moved += other.moved;
  kept_not_better += other.kept_not_better;
  kept_beyond_bound += other.kept_beyond_bound;
  kept_unaligned += other.kept_unaligned;
  pairs += other.pairs;
  pairs_refused += other.pairs_refused;
  pairs_partial += other.pairs_partial;
  unlinked.insert(unlinked.end(), other.unlinked.begin(), other.unlinked.end());
  return *this;
}

// The pieces of refinement (src/maps/refinement/): pose algebra, prepared
// members, the pairwise aligner and the pose graph.
using namespace refinement;

namespace {

/// Soft share of member k's points that lie on a neighbour's surface at the
/// poses X: each point counts 1 - (r / inlier_distance)^2 for its best
/// neighbour (0 beyond). Higher is a more consistent map around k.
double consistency(int k, const std::vector<int>& neighbours, const std::vector<std::unique_ptr<PreparedMember>>& members,
                   const std::vector<Eigen::Isometry3d>& X, const Freedom& freedom,
                   const RefinementParameters& parameters) {
  const auto& points = members[k]->cloud->points;
  if (points.empty() || neighbours.empty()) return 0;
  const double inlier = parameters.inlier_distance;
  flann::KNNSimpleResultSet<float> nearest(1);
  std::vector<Eigen::Isometry3d> into;  // k's frame into each neighbour's
  for (int j : neighbours) into.push_back(X[j].inverse() * X[k]);
  double sum = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d local = points[i].getVector3fMap().cast<double>();
    double best = 0;
    for (std::size_t s = 0; s < neighbours.size(); ++s) {
      double r;
      Eigen::Vector3d n;
      // Weighted by what the match says about the moving directions: a
      // floor is always matched and says nothing about a ground robot's x, y or yaw.
      if (residual(*members[neighbours[s]], into[s] * local, into[s].linear() * members[k]->normals[i], 3 * inlier, r, n,
                   nearest))
        best = std::max(best, (1.0 - (r / inlier) * (r / inlier)) * (freedom.planar ? n.head<2>().squaredNorm() : 1.0));
    }
    sum += best;
  }
  return sum / double(points.size());
}


}  // namespace

namespace {

/// The pairwise alignments of a group and what they connect.
struct PairGraph {
  std::vector<GraphEdge> edges;             ///< the usable alignments
  std::vector<std::vector<int>> neighbours;  ///< per member: every member it was paired with
  std::vector<bool> aligned;                 ///< per member: in at least one usable alignment
};

PairGraph alignPairs(const std::vector<std::pair<int, int>>& pairs,
                     const std::vector<std::unique_ptr<PreparedMember>>& members,
                     const std::vector<Eigen::Isometry3d>& input, int reference, const Freedom& freedom,
                     const RefinementParameters& parameters, RefinementReport& report) {
  PairGraph graph;
  graph.neighbours.resize(members.size());
  graph.aligned.assign(members.size(), false);
  graph.aligned[reference] = true;
  for (const auto& [a, b] : pairs) {
    ++report.pairs;
    graph.neighbours[a].push_back(b);
    graph.neighbours[b].push_back(a);
    const PairAlignment pair = alignPair(*members[b], *members[a], input[a].inverse() * input[b], freedom, parameters);
    if (!pair.usable) {
      ++report.pairs_refused;
      continue;
    }
    if (pair.partial) ++report.pairs_partial;
    graph.aligned[a] = graph.aligned[b] = true;
    graph.edges.push_back({a, b, pair.pose, pair.information, pair.floor, pair.radius, input[a] * pair.centre});
  }
  return graph;
}

enum class Outcome { Moved, NotBetter, BeyondBound, Unaligned };

/// A block of members the pose graph moved together (a whole later visit
/// of a place, shifted by a loop's drift) is consistent within itself at
/// its input poses and after, so the test of one member against its
/// neighbours cannot see that it now fits the rest: members reverted as
/// not better whose corrections (in the map frame) agree within the inlier
/// distance and a degree, and exceed what range noise moves (1 cm, 0.2°), are tested
/// together against their neighbours outside the block, and kept if that
/// puts more of their points on those surfaces.
void keepBlocksThatHelp(const std::vector<Eigen::Isometry3d>& input, const std::vector<Eigen::Isometry3d>& solved,
                        std::vector<Eigen::Isometry3d>& refined, std::vector<Outcome>& outcome, const PairGraph& graph,
                        const std::vector<std::unique_ptr<PreparedMember>>& members, const Freedom& freedom,
                        const RefinementParameters& parameters) {
  const int m = static_cast<int>(input.size());
  constexpr double kDegree = 0.017453292519943295;
  // A block's members moved by more than range noise moves exact poses
  // (up to 7 mm, see PairAligner::bestStart): drifted members left 1 to
  // 5 cm off are brought back too (office, 360° laser, p90 2.3 to 0.24 cm).
  constexpr double kBlockMinShift = 0.01, kBlockMinTurn = 0.2 * kDegree;
  std::vector<Eigen::Isometry3d> shift(m);
  std::vector<int> candidates;
  for (int k = 0; k < m; ++k) {
    if (outcome[k] != Outcome::NotBetter) continue;
    shift[k] = solved[k] * input[k].inverse();
    if (shift[k].translation().norm() > kBlockMinShift || rotationAngle(shift[k]) > kBlockMinTurn)
      candidates.push_back(k);
  }
  std::vector<bool> taken(m, false);
  for (int seed : candidates) {
    if (taken[seed]) continue;
    std::vector<int> block;
    std::vector<bool> in_block(m, false);
    for (int k : candidates) {
      const Eigen::Isometry3d d = shift[seed].inverse() * shift[k];
      if (!taken[k] && d.translation().norm() <= parameters.inlier_distance && rotationAngle(d) <= kDegree) {
        block.push_back(k);
        in_block[k] = true;
      }
    }
    if (block.size() < 2) continue;
    std::vector<Eigen::Isometry3d> moved = refined;
    for (int k : block) moved[k] = solved[k];
    double before = 0, after = 0;
    for (int k : block) {
      std::vector<int> outside;
      for (int j : graph.neighbours[k])
        if (!in_block[j]) outside.push_back(j);
      before += consistency(k, outside, members, refined, freedom, parameters);
      after += consistency(k, outside, members, moved, freedom, parameters);
    }
    if (!(after > before * (1 + parameters.min_gain))) continue;
    for (int k : block) {
      taken[k] = true;
      refined[k] = solved[k];
      outcome[k] = Outcome::Moved;
    }
  }
}

/// Which members keep their refined pose: those within the bounds whose
/// points the refined map puts better on their neighbours' surfaces; the
/// others are put back to `input` in `refined`. A second pass rechecks the
/// rest once the first reverts are in.
std::vector<Outcome> keepWhatHelps(const std::vector<Eigen::Isometry3d>& input, std::vector<Eigen::Isometry3d>& refined,
                                   int reference, const PairGraph& graph,
                                   const std::vector<std::unique_ptr<PreparedMember>>& members,
                                   const Freedom& freedom, const RefinementParameters& parameters, bool test_blocks) {
  const int m = static_cast<int>(input.size());
  const std::vector<Eigen::Isometry3d> solved = refined;
  std::vector<Outcome> outcome(m, Outcome::Moved);
  for (int k = 0; k < m; ++k) {
    if (k == reference) continue;
    const Eigen::Isometry3d correction = input[k].inverse() * refined[k];
    if (!graph.aligned[k]) outcome[k] = Outcome::Unaligned;
    else if (!refined[k].matrix().allFinite() ||
             correction.translation().norm() > parameters.max_translation_correction ||
             rotationAngle(correction) > parameters.max_rotation_correction)
      outcome[k] = Outcome::BeyondBound;
    if (outcome[k] != Outcome::Moved) refined[k] = input[k];
  }
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int> revert;
    for (int k = 0; k < m; ++k) {
      if (k == reference || outcome[k] != Outcome::Moved) continue;
      const double before = consistency(k, graph.neighbours[k], members, input, freedom, parameters);
      const double after = consistency(k, graph.neighbours[k], members, refined, freedom, parameters);
      if (!(after > before * (1 + parameters.min_gain))) revert.push_back(k);
    }
    for (int k : revert) {
      outcome[k] = Outcome::NotBetter;
      refined[k] = input[k];
    }
    if (revert.empty()) break;
  }
  if (test_blocks) keepBlocksThatHelp(input, solved, refined, outcome, graph, members, freedom, parameters);
  return outcome;
}

/// Per member: whether a chain of usable alignments joins it to the reference.
std::vector<bool> linkedToReference(int m, int reference, const std::vector<GraphEdge>& edges) {
  std::vector<std::vector<int>> adjacent(m);
  for (const GraphEdge& e : edges) {
    adjacent[e.a].push_back(e.b);
    adjacent[e.b].push_back(e.a);
  }
  std::vector<bool> linked(m, false);
  std::vector<int> open{reference};
  linked[reference] = true;
  while (!open.empty()) {
    const int k = open.back();
    open.pop_back();
    for (int j : adjacent[k])
      if (!linked[j]) {
        linked[j] = true;
        open.push_back(j);
      }
  }
  return linked;
}

/// The member the map is anchored at: the reference, unless the usable
/// alignments join more members to another part of the map than to the
/// reference's; then that part's member with the most alignments (ties:
/// the smallest position).
int largestJoinedPart(int m, int reference, const std::vector<GraphEdge>& edges) {
  std::vector<int> part(m, -1), degree(m, 0);
  for (const GraphEdge& e : edges) {
    ++degree[e.a];
    ++degree[e.b];
  }
  std::vector<int> size;
  for (int k = 0; k < m; ++k) {
    if (part[k] >= 0) continue;
    const std::vector<bool> joined = linkedToReference(m, k, edges);
    size.push_back(0);
    for (int j = 0; j < m; ++j)
      if (joined[j]) {
        part[j] = static_cast<int>(size.size()) - 1;
        ++size.back();
      }
  }
  int best = part[reference];
  for (int p = 0; p < static_cast<int>(size.size()); ++p)
    if (size[p] > size[best]) best = p;
  if (best == part[reference]) return reference;
  int anchor = -1;
  for (int k = 0; k < m; ++k)
    if (part[k] == best && (anchor < 0 || degree[k] > degree[anchor])) anchor = k;
  return anchor;
}

/// The parameters with the 3D clouds' voxel, gate and bounds in the
/// planar fields when the points are not planar: one set is used below.
RefinementParameters forPoints(const RefinementParameters& given, bool planar) {
  RefinementParameters p = given;
  if (!planar) {
    p.alignment_voxel = given.alignment_voxel_3d;
    p.max_correspondence_distance = given.max_correspondence_distance_3d;
    p.max_translation_correction = given.max_translation_correction_3d;
    p.max_rotation_correction = given.max_rotation_correction_3d;
  }
  return p;
}

}  // namespace

RefinementReport refineMemberPoses(Refinement refinement, const std::vector<MemberPoints>& points,
                                   const std::vector<std::pair<int, int>>& pairs, bool planar,
                                   const RefinementParameters& given, LocalMapFrame& frame) {
  RefinementReport report;
  const int m = static_cast<int>(frame.members.size());
  if (static_cast<int>(points.size()) != m || static_cast<int>(frame.member_poses.size()) != m)
    throw std::invalid_argument("refineMemberPoses: one point list and one pose per member expected");
  if (m > 0) checkMembers("refineMemberPoses", frame.members, std::numeric_limits<int>::max());
  if (m > 0 && !std::binary_search(frame.members.begin(), frame.members.end(), frame.reference))
    throw std::invalid_argument("refineMemberPoses: the reference " + std::to_string(frame.reference) +
                                " is not a member");
  for (int k = 0; k < m; ++k)
    if (!frame.member_poses[k].matrix().allFinite())
      throw std::invalid_argument("refineMemberPoses: the pose of member " + std::to_string(frame.members[k]) +
                                  " is not finite");
  for (const auto& [target, source] : pairs)
    if (target < 0 || target >= m || source < 0 || source >= m || target == source)
      throw std::invalid_argument("refineMemberPoses: pair (" + std::to_string(target) + ", " +
                                  std::to_string(source) + ") is not two member positions of " + std::to_string(m));
  const int reference = static_cast<int>(std::lower_bound(frame.members.begin(), frame.members.end(), frame.reference) -
                                         frame.members.begin());
  report.members = m - 1;
  if (refinement == Refinement::None || m < 2) return report;
  // Poses in one horizontal plane (a ground robot, whatever its sensor) are
  // refined in SE(2); the points decide only how normals are fitted.
  const Freedom freedom(posesArePlanar(frame.member_poses));
  const RefinementParameters parameters = forPoints(given, planar);
  std::vector<std::unique_ptr<PreparedMember>> members;
  members.reserve(m);
  for (const auto& p : points) members.push_back(prepare(p, parameters.alignment_voxel, planar));

  const std::vector<Eigen::Isometry3d> input = frame.member_poses;
  const PairGraph graph = alignPairs(pairs, members, input, reference, freedom, parameters, report);
  std::vector<Eigen::Isometry3d> refined = solvePoseGraph(input, reference, graph.edges, freedom, parameters);
  // Blocks for planar scans only: depth clouds' pairs that settle a few
  // centimetres off (see PairAligner::bestStart) agree with each other
  // often enough that blocks of them passed, and exact poses moved by
  // 2.75 cm at p90 in the loop building.
  const std::vector<Outcome> outcome =
      keepWhatHelps(input, refined, reference, graph, members, freedom, parameters, planar);
  refined[reference] = Eigen::Isometry3d::Identity();
  const int anchor = largestJoinedPart(m, reference, graph.edges);
  if (anchor != reference) {
    // A planar move for SE(2) maps: z, roll and pitch that are exactly 0 stay so.
    const Eigen::Isometry3d to_anchor = exponential(logarithm(refined[anchor].inverse(), freedom.planar), freedom.planar);
    for (auto& pose : refined) pose = to_anchor * pose;
    refined[anchor] = Eigen::Isometry3d::Identity();
    frame.pose = frame.pose * to_anchor.inverse();
    frame.reference = frame.members[anchor];
  }
  const std::vector<bool> linked = linkedToReference(m, anchor, graph.edges);
  for (int k = 0; k < m; ++k)
    if (!linked[k]) report.unlinked.push_back(frame.members[k]);
  for (int k = 0; k < m; ++k) {
    if (k == anchor) continue;
    switch (outcome[k]) {
      case Outcome::Moved: ++report.moved; break;
      case Outcome::NotBetter: ++report.kept_not_better; break;
      case Outcome::BeyondBound: ++report.kept_beyond_bound; break;
      case Outcome::Unaligned: ++report.kept_unaligned; break;
    }
  }
  frame.member_poses = refined;
  return report;
}

}  // namespace obsgroup
