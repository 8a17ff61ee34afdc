#include "obsgroup/maps/refinement.h"

#include <pcl/filters/voxel_grid.h>
#include <pcl/point_types.h>

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <flann/util/result_set.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

namespace obsgroup {

std::string RefinementReport::warning() const {
  if (kept_beyond_bound == 0 && kept_unaligned == 0 && pairs_partial == 0 &&
      static_cast<int>(unlinked.size()) <= kept_unaligned)
    return "";
  std::string text = "refined " + std::to_string(moved) + " of " + std::to_string(members) + " members";
  if (kept_beyond_bound > 0)
    text += "; " + std::to_string(kept_beyond_bound) + " kept their input pose (the correction exceeded its bound)";
  if (kept_unaligned > 0)
    text += "; " + std::to_string(kept_unaligned) + " kept their input pose (no pair aligned: " +
            std::to_string(pairs_refused) + " of " + std::to_string(pairs) + " pairs refused)";
  if (pairs_partial > 0)
    text += "; " + std::to_string(pairs_partial) + " of " + std::to_string(pairs) +
            " pairs constrain only some directions (a corridor): the others keep the input poses";
  // The unaligned members are unlinked too, and already said.
  const int apart = static_cast<int>(unlinked.size()) - kept_unaligned;
  if (apart > 0)
    text += "; " + std::to_string(apart) +
            " aligned only with members that no alignment joins to their map's reference (no surface in common "
            "with it): their place relative to it is the input's";
  return text;
}

RefinementReport& RefinementReport::operator+=(const RefinementReport& other) {
  members += other.members;
  moved += other.moved;
  kept_not_better += other.kept_not_better;
  kept_beyond_bound += other.kept_beyond_bound;
  kept_unaligned += other.kept_unaligned;
  pairs += other.pairs;
  pairs_refused += other.pairs_refused;
  pairs_partial += other.pairs_partial;
  unlinked.insert(unlinked.end(), other.unlinked.begin(), other.unlinked.end());
  return *this;
}

namespace {

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
Eigen::Isometry3d exponential(const Vector6d& d, bool planar) {
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
Vector6d logarithm(const Eigen::Isometry3d& pose, bool planar) {
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

double rotationAngle(const Eigen::Isometry3d& pose) { return Eigen::AngleAxisd(pose.linear()).angle(); }

constexpr double kNearAngle = 0.0017453292519943296;  ///< 0.1 degree, see PairAligner::bestStart()

/// A member thinned for alignment, with a surface normal per point (zero
/// where the neighbourhood is no line or plane) and a search tree. The tree
/// is FLANN's single-tree index queried directly: its knnSearch opens an
/// OpenMP region per call, which cost more than the search for one point.
struct PreparedMember {
  using Index = flann::KDTreeSingleIndex<flann::L2_Simple<float>>;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud;
  std::vector<Eigen::Vector3d> normals;
  std::unique_ptr<Index> index;  ///< null when the cloud is too small to match against

  /// The `k` nearest points of `query` (fewer if the cloud is smaller), by
  /// squared distance; `result` is the caller's, reused across queries.
  void nearest(const Eigen::Vector3f& query, flann::KNNSimpleResultSet<float>& result) const {
    result.clear();
    index->findNeighbors(result, query.data(), flann::SearchParams(-1));
  }
};

std::unique_ptr<PreparedMember> prepare(const MemberPoints& points, double voxel, bool planar) {
  auto member = std::make_unique<PreparedMember>();
  pcl::PointCloud<pcl::PointXYZ>::Ptr raw(new pcl::PointCloud<pcl::PointXYZ>);
  raw->reserve(points.size());
  for (const auto& p : points) raw->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  member->cloud.reset(new pcl::PointCloud<pcl::PointXYZ>);
  if (voxel > 0 && !raw->empty()) {
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    grid.setLeafSize(float(voxel), float(voxel), float(voxel));
    grid.setInputCloud(raw);
    grid.filter(*member->cloud);
  } else {
    member->cloud = raw;
  }
  auto& cloud = *member->cloud;
  member->normals.assign(cloud.size(), Eigen::Vector3d::Zero());
  if (cloud.size() < 3) return member;
  const flann::Matrix<float> data(&cloud.points[0].x, cloud.size(), 3, sizeof(pcl::PointXYZ));
  member->index = std::make_unique<PreparedMember::Index>(data, flann::KDTreeSingleIndexParams(10));
  member->index->buildIndex();
  // A line (2D) or plane (3D) fitted to the nearest points; a corner or a
  // scatter gives no normal, and the point then matches nothing.
  const std::size_t k = std::min<std::size_t>(planar ? 6 : 10, cloud.size());
  const double max_spread = std::max(0.5, 8 * voxel);
  flann::KNNSimpleResultSet<float> result(k);
  std::vector<std::size_t> neighbours(k);
  std::vector<float> distances(k);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    member->nearest(cloud[i].getVector3fMap(), result);
    result.copy(neighbours.data(), distances.data(), k);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    int used = 0;
    for (std::size_t j = 0; j < k; ++j)
      if (distances[j] <= max_spread * max_spread) {
        mean += cloud[neighbours[j]].getVector3fMap().cast<double>();
        ++used;
      }
    if (used < 3) continue;
    mean /= used;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (std::size_t j = 0; j < k; ++j)
      if (distances[j] <= max_spread * max_spread) {
        const Eigen::Vector3d d = cloud[neighbours[j]].getVector3fMap().cast<double>() - mean;
        covariance += d * d.transpose();
      }
    Eigen::Vector3d& normal = member->normals[i];
    if (planar) {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(covariance.topLeftCorner<2, 2>());
      if (eigen.eigenvalues()[0] < 0.1 * eigen.eigenvalues()[1]) normal << eigen.eigenvectors().col(0), 0;
    } else {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
      if (eigen.eigenvalues()[0] < 0.1 * eigen.eigenvalues()[1]) normal = eigen.eigenvectors().col(0);
    }
    // Towards the sensor (the frame's origin), as pcl::flipNormalTowardsViewpoint:
    // the two faces of a thin wall then point apart and do not match.
    if (normal.dot(cloud[i].getVector3fMap().cast<double>()) > 0) normal = -normal;
  }
  return member;
}

/// Point-to-surface residual of `x` (in the target's frame, its surface
/// normal `source_normal` turned into that frame too, zero if it has none)
/// against its nearest target point; false when none lies within `gate`,
/// the target point has no normal, or the normals differ by more than about
/// 35 degrees. Normals face their sensor, so this rejects a floor point
/// matched to a wall and, above all, the far face of a thin wall seen
/// through a door: that pulled exact depth-camera poses up to 30 cm away.
/// `nearest` is a one-point result set the caller reuses.
bool residual(const PreparedMember& target, const Eigen::Vector3d& x, const Eigen::Vector3d& source_normal,
              double gate, double& r, Eigen::Vector3d& normal, flann::KNNSimpleResultSet<float>& nearest) {
  if (!target.index) return false;
  target.nearest(x.cast<float>(), nearest);
  std::size_t index = 0;
  float distance = std::numeric_limits<float>::infinity();
  nearest.copy(&index, &distance, 1);
  if (!(distance <= gate * gate)) return false;
  normal = target.normals[index];
  if (normal.isZero() || (!source_normal.isZero() && normal.dot(source_normal) < 0.8)) return false;
  r = normal.dot(x - target.cloud->points[index].getVector3fMap().cast<double>());
  return true;
}

/// The columns of `freedom`'s perturbations (left, about the frame's
/// origin) that a unit step of each normalised coordinate makes: rotations
/// about `centre` (where the matched points are, so that turning does not
/// also shift them) and scaled by `radius` (their spread), so that every
/// coordinate moves the points by about a metre per unit.
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

/// `step` (in `freedom`'s coordinates) with its components along the
/// directions `h` barely constrains removed, as constrain() decides them.
Eigen::VectorXd keepConstrained(const Eigen::VectorXd& step, const Eigen::MatrixXd& h, const Eigen::MatrixXd& N,
                                double threshold) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(N.transpose() * h * N);
  Eigen::VectorXd u = eigen.eigenvectors().transpose() * N.inverse() * step;
  for (int a = 0; a < u.size(); ++a)
    if (!(eigen.eigenvalues()[a] > threshold)) u[a] = 0;
  return N * (eigen.eigenvectors() * u);
}

/// The Gauss-Newton step of one iteration in the well-constrained
/// directions only: the others stay where the guess put them.
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
class PairAligner {
 public:
  PairAligner(const PreparedMember& source, const PreparedMember& target, const Eigen::Isometry3d& guess,
              const Freedom& freedom, const RefinementParameters& parameters)
      : source_(source), target_(target), guess_(guess), freedom_(freedom), parameters_(parameters),
        inlier_(parameters.inlier_distance), final_gate_(3 * parameters.inlier_distance) {}

  PairAlignment align() {
    if (source_.cloud->size() < 6 || target_.cloud->size() < 6) return {};
    pose_ = bestStart();
    if (!pose_.matrix().allFinite() || accumulate(final_gate_) < 6) return {};
    const double overlap = double(inliers_) / double(source_.cloud->size());
    const Eigen::Isometry3d correction = guess_.inverse() * pose_;
    if (overlap < parameters_.min_overlap ||
        correction.translation().norm() > parameters_.max_translation_correction ||
        rotationAngle(correction) > parameters_.max_rotation_correction)
      return {};
    return result();
  }

 private:
  /// The normal equations of the matches within `gate` at pose_, and the
  /// soft inlier score (as consistency()); returns the number of matches.
  int accumulate(double gate) {
    weight_sum_ = score_ = squares_ = 0;
    H_.setZero();
    gradient_.setZero();
    inliers_ = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double squared_sum = 0;
    int used = 0;
    const auto& points = source_.cloud->points;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d x = pose_ * points[i].getVector3fMap().cast<double>();
      double r;
      Eigen::Vector3d n;
      if (!residual(target_, x, pose_.linear() * source_.normals[i], gate, r, n, nearest_)) continue;
      Vector6d J;
      J << n, x.cross(n);
      const double w = 1.0 / (1.0 + (r / inlier_) * (r / inlier_));  // Cauchy: far matches barely pull
      H_ += w * J * J.transpose();
      // What the match can tell in the moving directions: a floor tells a
      // ground robot nothing about x, y or yaw.
      const double telling = freedom_.planar ? n.head<2>().squaredNorm() : 1.0;
      weight_sum_ += w * telling;
      score_ += std::max(0.0, 1.0 - (r / inlier_) * (r / inlier_)) * telling;
      gradient_ += w * J * r;
      sum += x;
      squared_sum += x.squaredNorm();
      ++used;
      if (std::abs(r) < inlier_) {
        squares_ += r * r;
        ++inliers_;
      }
    }
    if (used > 0) {
      centre_ = sum / used;
      radius_ = std::max(0.5, std::sqrt(std::max(0.0, squared_sum / used - centre_.squaredNorm())));
    }
    return used;
  }

  /// Gauss-Newton from the guess with the gate shrinking from `gate`; the
  /// soft inlier score of where it ends (in pose_), -1 if it failed.
  double descend(double gate) {
    pose_ = guess_;
    for (int iteration = 0; iteration < parameters_.max_iterations; ++iteration) {
      if (accumulate(gate) < 6) return -1.0;
      const Vector6d step = constrainedStep(H_, gradient_, freedom_, normaliser(freedom_, centre_, radius_),
                                            parameters_.min_constraint_ratio * weight_sum_);
      pose_ = exponential(step, freedom_.planar) * pose_;
      const bool at_final_gate = gate <= final_gate_;
      gate = std::max(final_gate_, gate * 0.7);
      if (at_final_gate && step.head<3>().norm() < 1e-5 && step.tail<3>().norm() < 1e-6) break;
    }
    return accumulate(final_gate_) < 6 ? -1.0 : score_;
  }

  /// A wide first gate reaches larger errors but, on a small one, lets far
  /// surfaces pull the pose into another basin (seen with depth cameras:
  /// 3 cm off became 30 cm off). Both are tried (the wide one only when the
  /// narrow one had something to correct), and the guess itself: the pose
  /// that puts most points on the target's surface wins. A NaN pose when
  /// none matched.
  Eigen::Isometry3d bestStart() {
    pose_ = guess_;
    double best_score = accumulate(final_gate_) < 6 ? -1.0 : score_;
    Eigen::Isometry3d best = guess_;
    for (const double gate : {final_gate_, std::max(parameters_.max_correspondence_distance, final_gate_)}) {
      const double s = descend(gate);
      if (s > best_score) {
        best_score = s;
        best = pose_;
      }
      // The narrow start stayed near where the guess put it and found the
      // target's surface there: the guess was right (exact poses), and the
      // wide start, for errors the narrow one cannot reach, would only cost
      // time. "Near" is a fifth of the inlier distance and 0.1 degree: range
      // noise alone moves exact 2D poses by 1.0 mm median, 2.7 mm p90 and
      // 7 mm p99 (10,000 scans), and a 1 mm test ran the wide start for 85%
      // of the pairs, half of the refinement's time.
      const Eigen::Isometry3d moved = guess_.inverse() * pose_;
      if (s >= 0 && inliers_ >= parameters_.min_overlap * double(source_.cloud->size()) &&
          moved.translation().norm() < 0.2 * parameters_.inlier_distance && rotationAngle(moved) < kNearAngle)
        break;
    }
    if (best_score < 0) best.matrix().setConstant(std::numeric_limits<double>::quiet_NaN());
    return best;
  }

  /// The alignment at pose_ (accumulated at the final gate) with its
  /// information, well-conditioned directions only.
  PairAlignment result() const {
    // Noise of the matches, from the inliers; a floor keeps near-perfect
    // simulated data from claiming an absurd certainty.
    const double sigma2 = std::max(squares_ / std::max(inliers_, 1), 1e-6);
    const Constrained c = constrain(activeBlock(H_, freedom_) / sigma2, normaliser(freedom_, centre_, radius_),
                                    parameters_.min_constraint_ratio * weight_sum_ / sigma2);
    PairAlignment out;
    out.usable = true;
    out.pose = pose_;
    out.information = c.information;
    out.partial = c.dropped > 0;
    out.floor = parameters_.min_constraint_ratio * weight_sum_ / sigma2;
    out.radius = radius_;
    out.centre = centre_;
    return out;
  }

  const PreparedMember& source_;
  const PreparedMember& target_;
  const Eigen::Isometry3d guess_;
  const Freedom& freedom_;
  const RefinementParameters& parameters_;
  const double inlier_, final_gate_;
  flann::KNNSimpleResultSet<float> nearest_{1};
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  double radius_ = 1.0;
  double weight_sum_ = 0, score_ = 0, squares_ = 0;
  int inliers_ = 0;
  Matrix6d H_;
  Vector6d gradient_;
};

PairAlignment alignPair(const PreparedMember& source, const PreparedMember& target, const Eigen::Isometry3d& guess,
                        const Freedom& freedom, const RefinementParameters& parameters) {
  return PairAligner(source, target, guess, freedom, parameters).align();
}

struct GraphEdge {
  int a = 0, b = 0;                 ///< target and source member positions
  Eigen::Isometry3d measured;       ///< pose of b in a's frame
  Eigen::MatrixXd information;      ///< of the left perturbation of `measured`
  double floor = 0, radius = 1;     ///< as PairAlignment's
  Eigen::Vector3d centre;           ///< PairAlignment's, in the map frame
};

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

std::vector<Eigen::Isometry3d> solvePoseGraph(const std::vector<Eigen::Isometry3d>& input, int reference,
                                              const std::vector<GraphEdge>& edges, const Freedom& freedom,
                                              const RefinementParameters& parameters) {
  return PoseGraph(input, reference, edges, freedom, parameters).solve();
}

/// Soft share of member k's points that lie on a neighbour's surface at the
/// poses X: each point counts 1 - (r / inlier_distance)^2 for its best
/// neighbour (0 beyond). Higher is a more consistent map around k.
double consistency(int k, const std::vector<int>& neighbours, const std::vector<std::unique_ptr<PreparedMember>>& members,
                   const std::vector<Eigen::Isometry3d>& X, const Freedom& freedom,
                   const RefinementParameters& parameters) {
  const auto& points = members[k]->cloud->points;
  if (points.empty() || neighbours.empty()) return 0;
  const double inlier = parameters.inlier_distance;
  flann::KNNSimpleResultSet<float> nearest(1);
  std::vector<Eigen::Isometry3d> into;  // k's frame into each neighbour's
  for (int j : neighbours) into.push_back(X[j].inverse() * X[k]);
  double sum = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d local = points[i].getVector3fMap().cast<double>();
    double best = 0;
    for (std::size_t s = 0; s < neighbours.size(); ++s) {
      double r;
      Eigen::Vector3d n;
      // Weighted by what the match says about the moving directions: a
      // floor is always matched and says nothing about a ground robot's x, y or yaw.
      if (residual(*members[neighbours[s]], into[s] * local, into[s].linear() * members[k]->normals[i], 3 * inlier, r, n,
                   nearest))
        best = std::max(best, (1.0 - (r / inlier) * (r / inlier)) * (freedom.planar ? n.head<2>().squaredNorm() : 1.0));
    }
    sum += best;
  }
  return sum / double(points.size());
}

bool posesArePlanar(const std::vector<Eigen::Isometry3d>& poses) {
  for (const auto& pose : poses) {
    const Eigen::Matrix3d& R = pose.linear();
    if (std::abs(R(2, 2) - 1) > 1e-9 || std::abs(R(0, 2)) > 1e-9 || std::abs(R(1, 2)) > 1e-9 ||
        std::abs(pose.translation().z()) > 1e-9)
      return false;
  }
  return true;
}

}  // namespace

namespace {

/// The pairwise alignments of a group and what they connect.
struct PairGraph {
  std::vector<GraphEdge> edges;             ///< the usable alignments
  std::vector<std::vector<int>> neighbours;  ///< per member: every member it was paired with
  std::vector<bool> aligned;                 ///< per member: in at least one usable alignment
};

PairGraph alignPairs(const std::vector<std::pair<int, int>>& pairs,
                     const std::vector<std::unique_ptr<PreparedMember>>& members,
                     const std::vector<Eigen::Isometry3d>& input, int reference, const Freedom& freedom,
                     const RefinementParameters& parameters, RefinementReport& report) {
  PairGraph graph;
  graph.neighbours.resize(members.size());
  graph.aligned.assign(members.size(), false);
  graph.aligned[reference] = true;
  for (const auto& [a, b] : pairs) {
    ++report.pairs;
    graph.neighbours[a].push_back(b);
    graph.neighbours[b].push_back(a);
    const PairAlignment pair = alignPair(*members[b], *members[a], input[a].inverse() * input[b], freedom, parameters);
    if (!pair.usable) {
      ++report.pairs_refused;
      continue;
    }
    if (pair.partial) ++report.pairs_partial;
    graph.aligned[a] = graph.aligned[b] = true;
    graph.edges.push_back({a, b, pair.pose, pair.information, pair.floor, pair.radius, input[a] * pair.centre});
  }
  return graph;
}

enum class Outcome { Moved, NotBetter, BeyondBound, Unaligned };

/// A block of members the pose graph moved together (a whole later visit
/// of a place, shifted by a loop's drift) is consistent within itself at
/// its input poses and after, so the test of one member against its
/// neighbours cannot see that it now fits the rest: members reverted as
/// not better whose corrections (in the map frame) agree within the inlier
/// distance and a degree, and exceed what range noise moves (1 cm, 0.2°), are tested
/// together against their neighbours outside the block, and kept if that
/// puts more of their points on those surfaces.
void keepBlocksThatHelp(const std::vector<Eigen::Isometry3d>& input, const std::vector<Eigen::Isometry3d>& solved,
                        std::vector<Eigen::Isometry3d>& refined, std::vector<Outcome>& outcome, const PairGraph& graph,
                        const std::vector<std::unique_ptr<PreparedMember>>& members, const Freedom& freedom,
                        const RefinementParameters& parameters) {
  const int m = static_cast<int>(input.size());
  constexpr double kDegree = 0.017453292519943295;
  // A block's members moved by more than range noise moves exact poses
  // (up to 7 mm, see PairAligner::bestStart): drifted members left 1 to
  // 5 cm off are brought back too (office, 360° laser, p90 2.3 to 0.24 cm).
  constexpr double kBlockMinShift = 0.01, kBlockMinTurn = 0.2 * kDegree;
  std::vector<Eigen::Isometry3d> shift(m);
  std::vector<int> candidates;
  for (int k = 0; k < m; ++k) {
    if (outcome[k] != Outcome::NotBetter) continue;
    shift[k] = solved[k] * input[k].inverse();
    if (shift[k].translation().norm() > kBlockMinShift || rotationAngle(shift[k]) > kBlockMinTurn)
      candidates.push_back(k);
  }
  std::vector<bool> taken(m, false);
  for (int seed : candidates) {
    if (taken[seed]) continue;
    std::vector<int> block;
    std::vector<bool> in_block(m, false);
    for (int k : candidates) {
      const Eigen::Isometry3d d = shift[seed].inverse() * shift[k];
      if (!taken[k] && d.translation().norm() <= parameters.inlier_distance && rotationAngle(d) <= kDegree) {
        block.push_back(k);
        in_block[k] = true;
      }
    }
    if (block.size() < 2) continue;
    std::vector<Eigen::Isometry3d> moved = refined;
    for (int k : block) moved[k] = solved[k];
    double before = 0, after = 0;
    for (int k : block) {
      std::vector<int> outside;
      for (int j : graph.neighbours[k])
        if (!in_block[j]) outside.push_back(j);
      before += consistency(k, outside, members, refined, freedom, parameters);
      after += consistency(k, outside, members, moved, freedom, parameters);
    }
    if (!(after > before * (1 + parameters.min_gain))) continue;
    for (int k : block) {
      taken[k] = true;
      refined[k] = solved[k];
      outcome[k] = Outcome::Moved;
    }
  }
}

/// Which members keep their refined pose: those within the bounds whose
/// points the refined map puts better on their neighbours' surfaces; the
/// others are put back to `input` in `refined`. A second pass rechecks the
/// rest once the first reverts are in.
std::vector<Outcome> keepWhatHelps(const std::vector<Eigen::Isometry3d>& input, std::vector<Eigen::Isometry3d>& refined,
                                   int reference, const PairGraph& graph,
                                   const std::vector<std::unique_ptr<PreparedMember>>& members,
                                   const Freedom& freedom, const RefinementParameters& parameters, bool test_blocks) {
  const int m = static_cast<int>(input.size());
  const std::vector<Eigen::Isometry3d> solved = refined;
  std::vector<Outcome> outcome(m, Outcome::Moved);
  for (int k = 0; k < m; ++k) {
    if (k == reference) continue;
    const Eigen::Isometry3d correction = input[k].inverse() * refined[k];
    if (!graph.aligned[k]) outcome[k] = Outcome::Unaligned;
    else if (!refined[k].matrix().allFinite() ||
             correction.translation().norm() > parameters.max_translation_correction ||
             rotationAngle(correction) > parameters.max_rotation_correction)
      outcome[k] = Outcome::BeyondBound;
    if (outcome[k] != Outcome::Moved) refined[k] = input[k];
  }
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int> revert;
    for (int k = 0; k < m; ++k) {
      if (k == reference || outcome[k] != Outcome::Moved) continue;
      const double before = consistency(k, graph.neighbours[k], members, input, freedom, parameters);
      const double after = consistency(k, graph.neighbours[k], members, refined, freedom, parameters);
      if (!(after > before * (1 + parameters.min_gain))) revert.push_back(k);
    }
    for (int k : revert) {
      outcome[k] = Outcome::NotBetter;
      refined[k] = input[k];
    }
    if (revert.empty()) break;
  }
  if (test_blocks) keepBlocksThatHelp(input, solved, refined, outcome, graph, members, freedom, parameters);
  return outcome;
}

/// Per member: whether a chain of usable alignments joins it to the reference.
std::vector<bool> linkedToReference(int m, int reference, const std::vector<GraphEdge>& edges) {
  std::vector<std::vector<int>> adjacent(m);
  for (const GraphEdge& e : edges) {
    adjacent[e.a].push_back(e.b);
    adjacent[e.b].push_back(e.a);
  }
  std::vector<bool> linked(m, false);
  std::vector<int> open{reference};
  linked[reference] = true;
  while (!open.empty()) {
    const int k = open.back();
    open.pop_back();
    for (int j : adjacent[k])
      if (!linked[j]) {
        linked[j] = true;
        open.push_back(j);
      }
  }
  return linked;
}

/// The member the map is anchored at: the reference, unless the usable
/// alignments join more members to another part of the map than to the
/// reference's; then that part's member with the most alignments (ties:
/// the smallest position).
int largestJoinedPart(int m, int reference, const std::vector<GraphEdge>& edges) {
  std::vector<int> part(m, -1), degree(m, 0);
  for (const GraphEdge& e : edges) {
    ++degree[e.a];
    ++degree[e.b];
  }
  std::vector<int> size;
  for (int k = 0; k < m; ++k) {
    if (part[k] >= 0) continue;
    const std::vector<bool> joined = linkedToReference(m, k, edges);
    size.push_back(0);
    for (int j = 0; j < m; ++j)
      if (joined[j]) {
        part[j] = static_cast<int>(size.size()) - 1;
        ++size.back();
      }
  }
  int best = part[reference];
  for (int p = 0; p < static_cast<int>(size.size()); ++p)
    if (size[p] > size[best]) best = p;
  if (best == part[reference]) return reference;
  int anchor = -1;
  for (int k = 0; k < m; ++k)
    if (part[k] == best && (anchor < 0 || degree[k] > degree[anchor])) anchor = k;
  return anchor;
}

/// The parameters with the 3D clouds' voxel, gate and bounds in the
/// planar fields when the points are not planar: one set is used below.
RefinementParameters forPoints(const RefinementParameters& given, bool planar) {
  RefinementParameters p = given;
  if (!planar) {
    p.alignment_voxel = given.alignment_voxel_3d;
    p.max_correspondence_distance = given.max_correspondence_distance_3d;
    p.max_translation_correction = given.max_translation_correction_3d;
    p.max_rotation_correction = given.max_rotation_correction_3d;
  }
  return p;
}

}  // namespace

RefinementReport refineMemberPoses(Refinement refinement, const std::vector<MemberPoints>& points,
                                   const std::vector<std::pair<int, int>>& pairs, bool planar,
                                   const RefinementParameters& given, LocalMapFrame& frame) {
  RefinementReport report;
  const int m = static_cast<int>(frame.members.size());
  if (static_cast<int>(points.size()) != m || static_cast<int>(frame.member_poses.size()) != m)
    throw std::invalid_argument("refineMemberPoses: one point list and one pose per member expected");
  if (m > 0) checkMembers("refineMemberPoses", frame.members, std::numeric_limits<int>::max());
  if (m > 0 && !std::binary_search(frame.members.begin(), frame.members.end(), frame.reference))
    throw std::invalid_argument("refineMemberPoses: the reference " + std::to_string(frame.reference) +
                                " is not a member");
  for (int k = 0; k < m; ++k)
    if (!frame.member_poses[k].matrix().allFinite())
      throw std::invalid_argument("refineMemberPoses: the pose of member " + std::to_string(frame.members[k]) +
                                  " is not finite");
  for (const auto& [target, source] : pairs)
    if (target < 0 || target >= m || source < 0 || source >= m || target == source)
      throw std::invalid_argument("refineMemberPoses: pair (" + std::to_string(target) + ", " +
                                  std::to_string(source) + ") is not two member positions of " + std::to_string(m));
  const int reference = static_cast<int>(std::lower_bound(frame.members.begin(), frame.members.end(), frame.reference) -
                                         frame.members.begin());
  report.members = m - 1;
  if (refinement == Refinement::None || m < 2) return report;
  // Poses in one horizontal plane (a ground robot, whatever its sensor) are
  // refined in SE(2); the points decide only how normals are fitted.
  const Freedom freedom(posesArePlanar(frame.member_poses));
  const RefinementParameters parameters = forPoints(given, planar);
  std::vector<std::unique_ptr<PreparedMember>> members;
  members.reserve(m);
  for (const auto& p : points) members.push_back(prepare(p, parameters.alignment_voxel, planar));

  const std::vector<Eigen::Isometry3d> input = frame.member_poses;
  const PairGraph graph = alignPairs(pairs, members, input, reference, freedom, parameters, report);
  std::vector<Eigen::Isometry3d> refined = solvePoseGraph(input, reference, graph.edges, freedom, parameters);
  // Blocks for planar scans only: depth clouds' pairs that settle a few
  // centimetres off (see PairAligner::bestStart) agree with each other
  // often enough that blocks of them passed, and exact poses moved by
  // 2.75 cm at p90 in the loop building.
  const std::vector<Outcome> outcome =
      keepWhatHelps(input, refined, reference, graph, members, freedom, parameters, planar);
  refined[reference] = Eigen::Isometry3d::Identity();
  const int anchor = largestJoinedPart(m, reference, graph.edges);
  if (anchor != reference) {
    // A planar move for SE(2) maps: z, roll and pitch that are exactly 0 stay so.
    const Eigen::Isometry3d to_anchor = exponential(logarithm(refined[anchor].inverse(), freedom.planar), freedom.planar);
    for (auto& pose : refined) pose = to_anchor * pose;
    refined[anchor] = Eigen::Isometry3d::Identity();
    frame.pose = frame.pose * to_anchor.inverse();
    frame.reference = frame.members[anchor];
  }
  const std::vector<bool> linked = linkedToReference(m, anchor, graph.edges);
  for (int k = 0; k < m; ++k)
    if (!linked[k]) report.unlinked.push_back(frame.members[k]);
  for (int k = 0; k < m; ++k) {
    if (k == anchor) continue;
    switch (outcome[k]) {
      case Outcome::Moved: ++report.moved; break;
      case Outcome::NotBetter: ++report.kept_not_better; break;
      case Outcome::BeyondBound: ++report.kept_beyond_bound; break;
      case Outcome::Unaligned: ++report.kept_unaligned; break;
    }
  }
  frame.member_poses = refined;
  return report;
}

}  // namespace obsgroup
