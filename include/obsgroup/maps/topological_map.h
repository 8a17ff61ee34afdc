#pragma once
/// \file
/// The metric-topological map of paper sec. IV-A, step 4: one node per group
/// (local map), arcs between groups whose observations overlap, each holding
/// the relative transform between the two local maps' reference frames.

#include "obsgroup/graph/observation_graph.h"
#include "obsgroup/partition/recursive_partitioner.h"

#include <Eigen/Geometry>

#include <vector>

namespace obsgroup {

struct TopologicalNode {
  std::vector<int> members;  ///< Observation indices of the group, ascending.
  int reference = -1;        ///< Observation whose frame is the local map's frame.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< Reference pose in the global frame.
};

struct TopologicalArc {
  int from = 0, to = 0;        ///< Node indices, from < to.
  double weight = 0.0;         ///< Sum of W over the cross pairs: cut(from, to) of eq. (2).
  int pairs = 0;               ///< Overlapping cross pairs (a in from, b in to, W_ab > 0).
  /// Pose of `to`'s reference frame in `from`'s: pose_from^-1 * pose_to.
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
};

struct TopologicalMap {
  std::vector<TopologicalNode> nodes;
  std::vector<TopologicalArc> arcs;  ///< Ordered by (from, to).
};

/// Builds the topological map of a partition: each group's reference is its
/// first observation, and an arc joins two groups when W is non-zero across
/// them. With the observations' poses in one global frame, every cross pair
/// (a, b) gives the same estimate pose_from^-1 pose_a (pose_a^-1 pose_b)
/// pose_b^-1 pose_to of the arc's transform, which is therefore exact.
TopologicalMap buildTopologicalMap(const Partition& partition, const WeightMatrix& W,
                                   const std::vector<Eigen::Isometry3d>& poses);

}  // namespace obsgroup
