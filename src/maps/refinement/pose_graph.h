#pragma once
// Lu & Milios' pose graph of a local map's members: the poses that best
// agree with every pairwise alignment.

#include "se3.h"

#include "obsgroup/maps/refinement.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace obsgroup::refinement {

/// One usable pairwise alignment, as the pose graph weighs it.
struct GraphEdge {
  int a = 0, b = 0;                 ///< target and source member positions
  Eigen::Isometry3d measured;       ///< pose of b in a's frame
  Eigen::MatrixXd information;      ///< of the left perturbation of `measured`
  double floor = 0, radius = 1;     ///< as PairAlignment's
  Eigen::Vector3d centre;           ///< PairAlignment's, in the map frame
};

/// Lu & Milios: the member poses that best agree with every pairwise
/// alignment, each weighted by its information, and a weak prior keeping
/// every member near its input pose in the directions no pair constrains.
/// Gauss-Newton on left perturbations, the member `reference` fixed.
std::vector<Eigen::Isometry3d> solvePoseGraph(const std::vector<Eigen::Isometry3d>& input, int reference,
                                              const std::vector<GraphEdge>& edges, const Freedom& freedom,
                                              const RefinementParameters& parameters);

}  // namespace obsgroup::refinement
