#include "pose_graph.h"

#include "constraints.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>

namespace obsgroup::refinement {

namespace {


/// Residual of an edge, in `freedom`'s coordinates: log(X_a^-1 X_b Z^-1).
Eigen::VectorXd edgeResidual(const Eigen::Isometry3d& Xa, const Eigen::Isometry3d& Xb, const Eigen::Isometry3d& Z,
                             const Freedom& freedom) {
  const Vector6d e = logarithm(Xa.inverse() * Xb * Z.inverse(), freedom.planar);
  Eigen::VectorXd r(freedom.size());
  for (int a = 0; a < freedom.size(); ++a) r[a] = e[freedom.active[a]];
  return r;
}

/// Lu & Milios: the member poses that best agree with every pairwise
/// alignment, each weighted by its information, and a weak prior keeping
/// every member near its input pose in the directions no pair constrains.
/// Gauss-Newton on left perturbations, the reference fixed.
class PoseGraph {
 public:
  PoseGraph(const std::vector<Eigen::Isometry3d>& input, int reference, const std::vector<GraphEdge>& edges,
            const Freedom& freedom, const RefinementParameters& parameters)
      : input_(input), edges_(edges), freedom_(freedom), m_(static_cast<int>(input.size())), n_(freedom.size()),
        column_(m_, -1), X_(input) {
    for (int k = 0; k < m_; ++k)
      if (k != reference) column_[k] = n_ * variables_++;
    prior_ = Eigen::MatrixXd::Zero(n_, n_);
    for (int a = 0; a < n_; ++a) {
      const double sigma =
          freedom.active[a] < 3 ? parameters.max_translation_correction : parameters.max_rotation_correction;
      prior_(a, a) = 1.0 / (sigma * sigma);
    }
    summariseEdges();
  }

  std::vector<Eigen::Isometry3d> solve() {
    for (int iteration = 0; iteration < 10; ++iteration) {
      linearise();
      Eigen::SparseMatrix<double> H(n_ * variables_, n_ * variables_);
      H.setFromTriplets(triplets_.begin(), triplets_.end());
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(H);
      if (solver.info() != Eigen::Success) break;
      const Eigen::VectorXd step = solver.solve(-gradient_);
      if (solver.info() != Eigen::Success || !step.allFinite()) break;
      applyStep(step);
      if (step.lpNorm<Eigen::Infinity>() < 1e-9) break;
    }
    return X_;
  }

 private:
  /// Per member: the sum of its pairs' floors (see PairAlignment) and their
  /// mean radius and centre. The directions a member's pairs pin down are
  /// judged about where their matched points lie, as each pair judged its own.
  void summariseEdges() {
    floor_.assign(m_, 0.0);
    radius_.assign(m_, 0.0);
    centre_.assign(m_, Eigen::Vector3d::Zero());
    std::vector<int> incident(m_, 0);
    for (const GraphEdge& e : edges_)
      for (int k : {e.a, e.b}) {
        floor_[k] += e.floor;
        radius_[k] += e.radius;
        centre_[k] += e.centre;
        ++incident[k];
      }
    for (int k = 0; k < m_; ++k) {
      radius_[k] = incident[k] > 0 ? radius_[k] / incident[k] : 1.0;
      if (incident[k] > 0) centre_[k] /= incident[k];
    }
  }

  /// The normal equations at X_: every pair, then every member's prior.
  void linearise() {
    triplets_.clear();
    gradient_ = Eigen::VectorXd::Zero(n_ * variables_);
    own_.assign(m_, Eigen::MatrixXd::Zero(n_, n_));
    for (const GraphEdge& e : edges_) {
      const Eigen::VectorXd r = edgeResidual(X_[e.a], X_[e.b], e.measured, freedom_);
      const Eigen::MatrixXd Ja = jacobian(
          [&](const Eigen::Isometry3d& Y) { return edgeResidual(Y, X_[e.b], e.measured, freedom_); }, X_[e.a], r);
      const Eigen::MatrixXd Jb = jacobian(
          [&](const Eigen::Isometry3d& Y) { return edgeResidual(X_[e.a], Y, e.measured, freedom_); }, X_[e.b], r);
      add(e.a, e.b, Ja, Jb, r, e.information, true);
    }
    const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
    for (int k = 0; k < m_; ++k) {
      if (column_[k] < 0) continue;
      const Eigen::VectorXd r = edgeResidual(identity, X_[k], input_[k], freedom_);
      const Eigen::MatrixXd J = jacobian(
          [&](const Eigen::Isometry3d& Y) { return edgeResidual(identity, Y, input_[k], freedom_); }, X_[k], r);
      add(k, -1, J, J, r, prior_, false);
    }
  }

  /// Numerical Jacobians: a few small matrix products per edge, and no
  /// hand-derived SE(3) adjoints to get wrong.
  template <typename ResidualOf>
  Eigen::MatrixXd jacobian(const ResidualOf& residualOf, const Eigen::Isometry3d& X0, const Eigen::VectorXd& r0) const {
    constexpr double kStep = 1e-6;
    Eigen::MatrixXd J(n_, n_);
    for (int a = 0; a < n_; ++a) {
      Vector6d d = Vector6d::Zero();
      d[freedom_.active[a]] = kStep;
      J.col(a) = (residualOf(exponential(d, freedom_.planar) * X0) - r0) / kStep;
    }
    return J;
  }

  /// Adds one residual's blocks; `pair` ones also go into the members' own blocks.
  void add(int ka, int kb, const Eigen::MatrixXd& Ja, const Eigen::MatrixXd& Jb, const Eigen::VectorXd& r,
           const Eigen::MatrixXd& omega, bool pair) {
    const int ks[2] = {ka, kb};
    const Eigen::MatrixXd* Js[2] = {&Ja, &Jb};
    for (int s = 0; s < 2; ++s) {
      if (ks[s] < 0 || column_[ks[s]] < 0) continue;
      if (pair) own_[ks[s]] += Js[s]->transpose() * omega * *Js[s];
      gradient_.segment(column_[ks[s]], n_) += Js[s]->transpose() * omega * r;
      for (int t = 0; t < 2; ++t) {
        if (ks[t] < 0 || column_[ks[t]] < 0) continue;
        const Eigen::MatrixXd block = Js[s]->transpose() * omega * *Js[t];
        for (int i = 0; i < n_; ++i)
          for (int j = 0; j < n_; ++j) triplets_.emplace_back(column_[ks[s]] + i, column_[ks[t]] + j, block(i, j));
      }
    }
  }

  void applyStep(const Eigen::VectorXd& step) {
    for (int k = 0; k < m_; ++k) {
      if (column_[k] < 0) continue;
      // Solution remapping (Zhang et al., ICRA 2016): a member moves only
      // in the directions its own pairs pin down. Many pairs that each
      // leave a corridor's axis free would otherwise pin it together
      // through the noise in their normals.
      const Eigen::VectorXd local = keepConstrained(step.segment(column_[k], n_), own_[k],
                                                    normaliser(freedom_, centre_[k], radius_[k]), floor_[k]);
      Vector6d d = Vector6d::Zero();
      for (int a = 0; a < n_; ++a) d[freedom_.active[a]] = local[a];
      X_[k] = exponential(d, freedom_.planar) * X_[k];
    }
  }

  const std::vector<Eigen::Isometry3d>& input_;
  const std::vector<GraphEdge>& edges_;
  const Freedom& freedom_;
  const int m_, n_;
  std::vector<int> column_;
  int variables_ = 0;
  Eigen::MatrixXd prior_;
  std::vector<double> floor_, radius_;
  std::vector<Eigen::Vector3d> centre_;
  std::vector<Eigen::Isometry3d> X_;
  std::vector<Eigen::Triplet<double>> triplets_;
  Eigen::VectorXd gradient_;
  std::vector<Eigen::MatrixXd> own_;  ///< each member's block from the pairs alone
};

}  // namespace

std::vector<Eigen::Isometry3d> solvePoseGraph(const std::vector<Eigen::Isometry3d>& input, int reference,
                                              const std::vector<GraphEdge>& edges, const Freedom& freedom,
                                              const RefinementParameters& parameters) {
  return PoseGraph(input, reference, edges, freedom, parameters).solve();
}


}  // namespace obsgroup::refinement
