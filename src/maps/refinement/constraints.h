#pragma once
// Which directions the matches of an alignment constrain: information and
// steps restricted to them, in normalised coordinates (a rotation about the
// matched points, scaled by their spread). Shared by the pairwise aligner
// and the pose graph.

#include "se3.h"

#include <Eigen/Core>

namespace obsgroup::refinement {

/// The columns of `freedom`'s perturbations (left, about the frame's
/// origin) that a unit step of each normalised coordinate makes: rotations
/// about `centre` (where the matched points are, so that turning does not
/// also shift them) and scaled by `radius` (their spread), so that every
/// coordinate moves the points by about a metre per unit.
Eigen::MatrixXd normaliser(const Freedom& freedom, const Eigen::Vector3d& centre, double radius);

/// The block of H over the coordinates `freedom` moves.
Eigen::MatrixXd activeBlock(const Matrix6d& H, const Freedom& freedom);

/// The information `h` (in `freedom`'s coordinates) with the directions it
/// barely constrains removed: in normalised coordinates (normaliser()),
/// eigenvalues at or below `threshold` are set to 0. Each match adds at
/// most about 1 to an eigenvalue there (unit normals), so threshold =
/// ratio x matches asks a direction to be held by that share of the
/// matches: a dominant floor must not make the walls look negligible.
struct Constrained {
  Eigen::MatrixXd information;
  int dropped = 0;
};

Constrained constrain(const Eigen::MatrixXd& h, const Eigen::MatrixXd& N, double threshold);

/// `step` (in `freedom`'s coordinates) with its components along the
/// directions `h` barely constrains removed, as constrain() decides them.
Eigen::VectorXd keepConstrained(const Eigen::VectorXd& step, const Eigen::MatrixXd& h, const Eigen::MatrixXd& N,
                                double threshold);

/// The Gauss-Newton step of one iteration in the well-constrained
/// directions only: the others stay where the guess put them.
Vector6d constrainedStep(const Matrix6d& H, const Vector6d& g, const Freedom& freedom, const Eigen::MatrixXd& N,
                         double threshold);

}  // namespace obsgroup::refinement
