#pragma once
/// \file
/// All observations' points in one common (world) frame, the input of the
/// neighbour back-ends. Plain Eigen, no PCL.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <vector>

namespace obsgroup {

/// Points of every observation in the world frame, concatenated. Coordinates
/// are stored re-centred on `origin` (world = stored + origin): poses are
/// applied in double and only the small re-centred values are rounded to
/// float, so maps far from the origin (UTM coordinates) keep their precision.
struct WorldPoints {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3f> points;
  /// Observation i owns points[offsets[i], offsets[i+1]).
  std::vector<std::size_t> offsets{0};
  /// Bounding box of each observation's points (empty for no points).
  std::vector<Eigen::AlignedBox3f> boxes;

  int size() const { return static_cast<int>(boxes.size()); }
  std::size_t count(int i) const { return offsets[i + 1] - offsets[i]; }
  const Eigen::Vector3f* begin(int i) const { return points.data() + offsets[i]; }
  const Eigen::Vector3f* end(int i) const { return points.data() + offsets[i + 1]; }

  /// Appends observations, one box each computed from its points; copies in
  /// parallel (threads <= 0: all threads).
  void appendAll(const std::vector<std::vector<Eigen::Vector3f>>& per_observation, int threads = 0);
};

/// For each observation j, the observations i != j (ascending) whose bounding
/// boxes, grown by `delta`, intersect j's. Pairs outside this list cannot
/// share a point within delta (eq. 16) and cost no neighbour query.
std::vector<std::vector<int>> overlappingBoxes(const WorldPoints& world, double delta);

/// The match predicate C of eq. (16): ||p - q|| <= delta, decided in double on
/// the stored coordinates so that every back-end decides a match at exactly
/// delta alike. A float test settles every pair that is clearly inside or
/// outside (its rounding error is far below the 1e-4 relative margin), so the
/// double test runs only within that margin of delta: same answers, faster.
class MatchDistance {
 public:
  explicit MatchDistance(double delta)
      : sq_(delta * delta), inside_(float(sq_ * (1.0 - 1e-4))), outside_(float(sq_ * (1.0 + 1e-4))) {}

  bool operator()(const Eigen::Vector3f& p, const Eigen::Vector3f& q) const {
    const float d = (p - q).squaredNorm();
    if (d < inside_) return true;
    if (d > outside_) return false;
    const double dx = double(p.x()) - double(q.x());
    const double dy = double(p.y()) - double(q.y());
    const double dz = double(p.z()) - double(q.z());
    return dx * dx + dy * dy + dz * dz <= sq_;
  }

 private:
  double sq_;
  float inside_, outside_;
};

}  // namespace obsgroup
