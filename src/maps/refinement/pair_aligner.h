#pragma once
// One pairwise alignment of a local map's members: robust point-to-line
// (2D) or point-to-plane (3D) Gauss-Newton, only in the directions the
// matches constrain.

#include "prepared_member.h"
#include "se3.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace obsgroup::refinement {

/// What an alignment found: the source's pose in the target's frame and
/// its information, or that the pair is not usable.
struct PairAlignment {
  bool usable = false;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< source in the target's frame
  Eigen::MatrixXd information;                             ///< of `pose`, left perturbations
  bool partial = false;                                    ///< some directions were left to the guess
  double floor = 0;   ///< information below which a direction counts as unconstrained
  double radius = 1;  ///< of the matched points: the scale of rotations
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< of the matched points, target frame
};

/// Aligns `source` onto `target` from `guess` (the source's pose in the
/// target's frame): robust (Cauchy) point-to-line or point-to-plane
/// Gauss-Newton, the correspondence gate shrinking from
/// max_correspondence_distance to 3 x inlier_distance.
PairAlignment alignPair(const PreparedMember& source, const PreparedMember& target, const Eigen::Isometry3d& guess,
                        const Freedom& freedom, const RefinementParameters& parameters);

}  // namespace obsgroup::refinement
