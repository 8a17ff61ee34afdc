#include "constraints.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace obsgroup::refinement {

Eigen::MatrixXd normaliser(const Freedom& freedom, const Eigen::Vector3d& centre, double radius) {
  Matrix6d full = Matrix6d::Identity();
  full.block<3, 3>(0, 3) << 0, -centre.z(), centre.y(), centre.z(), 0, -centre.x(), -centre.y(), centre.x(), 0;
  full.block<6, 3>(0, 3) /= radius;
  const int n = freedom.size();
  Eigen::MatrixXd N(n, n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) N(a, b) = full(freedom.active[a], freedom.active[b]);
  return N;
}

Eigen::MatrixXd activeBlock(const Matrix6d& H, const Freedom& freedom) {
  const int n = freedom.size();
  Eigen::MatrixXd h(n, n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) h(a, b) = H(freedom.active[a], freedom.active[b]);
  return h;
}

Constrained constrain(const Eigen::MatrixXd& h, const Eigen::MatrixXd& N, double threshold) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(N.transpose() * h * N);
  Eigen::VectorXd values = eigen.eigenvalues();
  Constrained result;
  for (int a = 0; a < values.size(); ++a)
    if (!(values[a] > threshold)) {
      values[a] = 0;
      ++result.dropped;
    }
  const Eigen::MatrixXd inverse = N.inverse();
  result.information = inverse.transpose() * (eigen.eigenvectors() * values.asDiagonal() *
                                              eigen.eigenvectors().transpose()) * inverse;
  return result;
}

Eigen::VectorXd keepConstrained(const Eigen::VectorXd& step, const Eigen::MatrixXd& h, const Eigen::MatrixXd& N,
                                double threshold) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(N.transpose() * h * N);
  Eigen::VectorXd u = eigen.eigenvectors().transpose() * N.inverse() * step;
  for (int a = 0; a < u.size(); ++a)
    if (!(eigen.eigenvalues()[a] > threshold)) u[a] = 0;
  return N * (eigen.eigenvectors() * u);
}

Vector6d constrainedStep(const Matrix6d& H, const Vector6d& g, const Freedom& freedom, const Eigen::MatrixXd& N,
                         double threshold) {
  const int n = freedom.size();
  Eigen::VectorXd gradient(n);
  for (int a = 0; a < n; ++a) gradient[a] = g[freedom.active[a]];
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(N.transpose() * activeBlock(H, freedom) * N);
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(n);
  for (int a = 0; a < n; ++a)
    if (eigen.eigenvalues()[a] > threshold) inverse[a] = 1.0 / eigen.eigenvalues()[a];
  const Eigen::VectorXd step =
      -(N * (eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose()) * N.transpose() * gradient);
  Vector6d d = Vector6d::Zero();
  for (int a = 0; a < n; ++a) d[freedom.active[a]] = step[a];
  return d;
}


}  // namespace obsgroup::refinement
