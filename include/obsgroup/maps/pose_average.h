#pragma once
/// \file
/// Weighted mean of rigid transforms, for the arcs of the topological map
/// (paper sec. IV-A, step 4: "averaging the differential poses").

#include <Eigen/Geometry>

#include <vector>

namespace obsgroup {

struct PoseAverage {
  Eigen::Isometry3d mean = Eigen::Isometry3d::Identity();
  double translation_spread = 0.0;  ///< weighted RMS distance of the translations to the mean, metres
  double rotation_spread = 0.0;     ///< weighted RMS angle of the rotations to the mean, radians
};

/// Weighted mean of `poses`: the translations averaged, the rotations by
/// their chordal L2 mean (the rotation closest in Frobenius norm to the
/// weighted sum of the rotation matrices, found by SVD), which unlike Euler
/// angles is well defined across +-pi. Throws std::invalid_argument when the
/// inputs are empty, sizes differ, or a weight is negative or all are zero.
PoseAverage averagePoses(const std::vector<Eigen::Isometry3d>& poses, const std::vector<double>& weights);

}  // namespace obsgroup
