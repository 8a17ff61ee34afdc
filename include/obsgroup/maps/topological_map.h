#pragma once
/// \file
/// The metric-topological map of paper sec. IV-A, step 4: one node per local
/// map, arcs between local maps whose observations overlap or follow each
/// other, each holding the relative transform between their reference frames.

#include "obsgroup/graph/observation_graph.h"
#include "obsgroup/partition/recursive_partitioner.h"

#include <Eigen/Geometry>

#include <vector>

namespace obsgroup {

/// The frame of one local map: its observations expressed relative to a
/// reference observation (paper sec. IV-A, step 3).
struct LocalMapFrame {
  std::vector<int> members;  ///< Observation indices, ascending.
  /// The member whose frame is the local map's frame: strongestMember, or
  /// after refinement the member the alignments join the most members to
  /// (refineMemberPoses).
  int reference = -1;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< Reference pose in the global frame.
  /// Pose of each member (in `members` order) in the reference frame; the
  /// reference's own is the identity. Refinement changes these.
  std::vector<Eigen::Isometry3d> member_poses;

  /// Pose of observation `i` (a member) in the reference frame.
  const Eigen::Isometry3d& memberPose(int i) const;
};

/// The member with the largest sum of W to the other members (the most
/// strongly connected); ties go to the smaller index.
int strongestMember(const std::vector<int>& group, const WeightMatrix& W);

/// A group's frame from the input poses: reference = strongestMember, member
/// poses = pose_ref^-1 * pose_i.
LocalMapFrame initialFrame(const std::vector<int>& group, const WeightMatrix& W,
                           const std::vector<Eigen::Isometry3d>& poses);

struct TopologicalArc {
  int from = 0, to = 0;           ///< Node indices, from < to.
  /// Pose of `to`'s reference frame in `from`'s, averaged over the supporting pairs.
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  double translation_spread = 0.0;  ///< Spread of the pair estimates: the arc's uncertainty, metres.
  double rotation_spread = 0.0;     ///< Same for rotation, radians.
  double weight = 0.0;              ///< Sum of W over the cross pairs: cut(from, to) of eq. (2).
  int overlapping_pairs = 0;        ///< Cross pairs (a, b) with W_ab > 0.
  int sequence_pairs = 0;           ///< Cross pairs (i, i+1) of consecutive observations.
  int pairs = 0;                    ///< Distinct pairs that support the arc.
};

struct TopologicalMap {
  std::vector<LocalMapFrame> nodes;
  std::vector<TopologicalArc> arcs;  ///< Ordered by (from, to).
};

/// Weight given to a pair of consecutive observations that do not overlap
/// (W = 0): it joins two local maps the robot drove between, but says little
/// about their relative pose next to pairs that overlap.
inline constexpr double kSequencePairWeight = 1e-3;

/// Builds the arcs between local maps. Each supporting cross pair (a in A, b
/// in B) gives the estimate M_a (pose_a^-1 pose_b) M_b^-1 of the transform
/// from A's reference frame to B's, where M are the members' (possibly
/// refined) poses in their local maps; the arc holds the W-weighted mean
/// (averagePoses) and its spread. With unrefined local maps all estimates
/// coincide and the spread is 0. The arcs are averaged on `threads` threads
/// (0 = all cores); the result is the same for any number.
TopologicalMap buildTopologicalMap(std::vector<LocalMapFrame> nodes, const WeightMatrix& W,
                                   const std::vector<Eigen::Isometry3d>& poses, int threads = 0);

/// The global pose of every observation as its local map places it: member
/// k of node g at nodes[g].pose * nodes[g].member_poses[k] (the reference's
/// input pose times the member's, possibly refined, pose in the reference
/// frame). Throws std::invalid_argument for a member not below `observations`.
std::vector<Eigen::Isometry3d> globalPoses(const TopologicalMap& topology, std::size_t observations);

/// The frames of all groups of a partition from the input poses.
std::vector<LocalMapFrame> initialFrames(const Partition& partition, const WeightMatrix& W,
                                         const std::vector<Eigen::Isometry3d>& poses);

}  // namespace obsgroup
