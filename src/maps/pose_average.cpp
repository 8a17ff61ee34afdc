#include "obsgroup/maps/pose_average.h"

#include <Eigen/SVD>

#include <cmath>
#include <stdexcept>

namespace obsgroup {

PoseAverage averagePoses(const std::vector<Eigen::Isometry3d>& poses, const std::vector<double>& weights) {
  if (poses.empty() || poses.size() != weights.size())
    throw std::invalid_argument("averagePoses: one weight per pose, at least one pose");
  double total = 0.0;
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (!(weights[k] >= 0.0)) throw std::invalid_argument("averagePoses: negative weight");
    total += weights[k];
    t += weights[k] * poses[k].translation();
    sum += weights[k] * poses[k].linear();
  }
  if (!(total > 0.0)) throw std::invalid_argument("averagePoses: all weights are zero");

  // Chordal mean: the rotation nearest to the weighted sum, R = U diag(1, 1, det(U V^T)) V^T.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  PoseAverage out;
  out.mean.linear() = svd.matrixU() * fix * svd.matrixV().transpose();
  out.mean.translation() = t / total;

  double translation_sq = 0.0, rotation_sq = 0.0;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    translation_sq += weights[k] * (poses[k].translation() - out.mean.translation()).squaredNorm();
    const double angle = Eigen::AngleAxisd(out.mean.linear().transpose() * poses[k].linear()).angle();
    rotation_sq += weights[k] * angle * angle;
  }
  out.translation_spread = std::sqrt(translation_sq / total);
  out.rotation_spread = std::sqrt(rotation_sq / total);
  return out;
}

}  // namespace obsgroup
