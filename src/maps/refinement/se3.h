#pragma once
// The pose algebra of refinement: left perturbations (x, y, z, roll, pitch,
// yaw) of SE(3), and SE(2) as its x, y and yaw for a ground robot.

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

namespace obsgroup::refinement {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// The coordinates a refinement moves, of (x, y, z, roll, pitch, yaw)
/// perturbations: SE(2) moves x, y and yaw only.
struct Freedom {
  explicit Freedom(bool planar_) : planar(planar_) {
    if (planar) active = {0, 1, 5};
    else active = {0, 1, 2, 3, 4, 5};
  }
  bool planar;
  std::vector<int> active;
  int size() const { return static_cast<int>(active.size()); }
};

/// exp of a perturbation (translation, rotation vector), applied on the
/// left. In SE(2) the rotation is written out so that z, roll and pitch of
/// the pose it moves stay bit for bit what they were.
inline Eigen::Isometry3d exponential(const Vector6d& d, bool planar) {
  Eigen::Isometry3d e = Eigen::Isometry3d::Identity();
  if (planar) {
    const double c = std::cos(d[5]), s = std::sin(d[5]);
    e.linear() << c, -s, 0, s, c, 0, 0, 0, 1;
    e.translation() << d[0], d[1], 0;
  } else {
    const double angle = d.tail<3>().norm();
    if (angle > 0) e.linear() = Eigen::AngleAxisd(angle, d.tail<3>() / angle).toRotationMatrix();
    e.translation() = d.head<3>();
  }
  return e;
}

/// The inverse of exponential().
inline Vector6d logarithm(const Eigen::Isometry3d& pose, bool planar) {
  Vector6d d = Vector6d::Zero();
  d.head<3>() = pose.translation();
  if (planar) {
    d[2] = 0;
    d[5] = std::atan2(pose.linear()(1, 0), pose.linear()(0, 0));
  } else {
    const Eigen::AngleAxisd a(pose.linear());
    d.tail<3>() = a.angle() * a.axis();
  }
  return d;
}

inline double rotationAngle(const Eigen::Isometry3d& pose) { return Eigen::AngleAxisd(pose.linear()).angle(); }

inline constexpr double kNearAngle = 0.0017453292519943296;  ///< 0.1 degree, see PairAligner::bestStart()

/// True when every pose lies in one horizontal plane: a ground robot, with
/// a laser or a depth camera, whose refinement stays in SE(2).
inline bool posesArePlanar(const std::vector<Eigen::Isometry3d>& poses) {
  for (const auto& pose : poses) {
    const Eigen::Matrix3d& R = pose.linear();
    if (std::abs(R(2, 2) - 1) > 1e-9 || std::abs(R(0, 2)) > 1e-9 || std::abs(R(1, 2)) > 1e-9 ||
        std::abs(pose.translation().z()) > 1e-9)
      return false;
  }
  return true;
}

}  // namespace obsgroup::refinement
