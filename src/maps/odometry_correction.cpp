#include "obsgroup/maps/odometry_correction.h"

#include "refinement/pair_aligner.h"
#include "refinement/prepared_member.h"
#include "refinement/se3.h"
#include "../overlap/region_cells.h"

#include "obsgroup/common/parallel_for.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

namespace obsgroup {

using namespace refinement;

namespace {

/// Soft share of `source`'s points on `target`'s surfaces with the source at
/// `pose` in the target's frame, as refinement weighs a member's consistency:
/// each point counts 1 - (r / inlier)^2 for its match (0 beyond), times what
/// the match says about a ground robot's x, y and yaw.
double consistencyAt(const PreparedMember& source, const PreparedMember& target, const Eigen::Isometry3d& pose,
                     bool planar, double inlier) {
  const auto& points = source.cloud->points;
  if (points.empty()) return 0;
  flann::KNNSimpleResultSet<float> nearest(1);
  double sum = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    double r;
    Eigen::Vector3d n;
    if (residual(target, pose * points[i].getVector3fMap().cast<double>(), pose.linear() * source.normals[i],
                 3 * inlier, r, n, nearest))
      sum += std::max(0.0, 1.0 - (r / inlier) * (r / inlier)) * (planar ? n.head<2>().squaredNorm() : 1.0);
  }
  return sum / double(points.size());
}

enum class StepOutcome { Matched, Kept, Unaligned };

/// A step of a ground robot: a turn about the vertical and a move in the
/// plane, within `tolerance` (a depth camera's match, in 6 DoF, tilts and
/// climbs a little).
bool groundStep(const Eigen::Isometry3d& step, double tolerance = 1e-9) {
  return std::abs(step.linear()(2, 2) - 1) < tolerance && std::abs(step.translation().z()) < tolerance;
}

double yawOf(const Eigen::Isometry3d& pose) { return std::atan2(pose.linear()(1, 0), pose.linear()(0, 0)); }

double wrapped(double angle) { return std::atan2(std::sin(angle), std::cos(angle)); }

/// The median of `values` when they lie on one side of `neutral` more often
/// than chance allows (a sign test: the excess beyond three standard
/// deviations of a fair coin, and at least 20 of them) and it differs from
/// `neutral` by at least `least`, else `neutral`. The floor keeps a matcher's
/// own faint leaning, which a long log makes significant, from being taken
/// for the odometry's.
double consistentMedian(std::vector<double> values, double neutral, double least) {
  std::size_t above = 0, below = 0;
  for (double v : values) {
    above += v > neutral;
    below += v < neutral;
  }
  const double decided = double(above + below);
  if (decided < 20 || std::abs(double(above) - double(below)) <= 3.0 * std::sqrt(decided)) return neutral;
  const auto middle = values.begin() + std::ptrdiff_t(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return std::abs(*middle - neutral) >= least ? *middle : neutral;
}

/// The step from the previous observation to `current`: the matched one
/// when it aligns and is better by min_gain, else the input's.
StepOutcome correctStep(const PreparedMember& current, const PreparedMember& previous, const Eigen::Isometry3d& input_step,
                        const Freedom& freedom, const OdometryCorrectionParameters& parameters, Eigen::Isometry3d& step) {
  step = input_step;
  if (!current.index || !previous.index) return StepOutcome::Unaligned;
  const RefinementParameters& alignment = parameters.alignment;
  const PairAlignment pair = alignPair(current, previous, input_step, freedom, alignment);
  if (!pair.usable) return StepOutcome::Unaligned;
  const double inlier = alignment.inlier_distance;
  if (!(consistencyAt(current, previous, pair.pose, freedom.planar, inlier) >
        consistencyAt(current, previous, input_step, freedom.planar, inlier) + parameters.min_gain))
    return StepOutcome::Kept;
  step = pair.pose;
  return StepOutcome::Matched;
}

/// Scan matching of the steps between consecutive observations. Each step
/// starts from the input's, not from the corrections before it: the steps
/// are independent, and the result does not depend on the thread count.
class StepMatcher {
 public:
  StepMatcher(const PointsOfObservation& points, const std::vector<Eigen::Isometry3d>& poses, bool planar,
              const OdometryCorrectionParameters& parameters)
      : points_(points), poses_(poses), planar_(planar), freedom_(planar && posesArePlanar(poses)),
        parameters_(parameters) {
    const RefinementParameters& given = parameters.alignment;
    voxel_ = planar ? given.alignment_voxel : given.alignment_voxel_3d;
    if (!planar) {  // 3D clouds: refinement's narrower gate and bounds
      parameters_.alignment.max_correspondence_distance = given.max_correspondence_distance_3d;
      parameters_.alignment.max_translation_correction = given.max_translation_correction_3d;
      parameters_.alignment.max_rotation_correction = given.max_rotation_correction_3d;
    }
    steps_.assign(poses.size(), Eigen::Isometry3d::Identity());
    outcomes_.assign(poses.size(), StepOutcome::Kept);
  }

  /// Matches the steps into observations first, first + 1, ..., last - 1,
  /// each observation prepared once.
  void matchRun(std::size_t first, std::size_t last, const std::function<void()>& step_done = {}) {
    std::unique_ptr<PreparedMember> previous = prepare(points_(first - 1), voxel_, planar_);
    for (std::size_t i = first; i < last; ++i) {
      throwIfInterrupted(parameters_.interrupt);
      std::unique_ptr<PreparedMember> current = prepare(points_(i), voxel_, planar_);
      outcomes_[i] = correctStep(*current, *previous, poses_[i - 1].inverse() * poses_[i], freedom_, parameters_, steps_[i]);
      previous = std::move(current);
      if (step_done) step_done();
    }
  }

  /// Every step, in contiguous runs over `threads` threads.
  void matchAll(int threads) {
    const std::size_t n = poses_.size() - 1;
    const std::size_t runs = std::min<std::size_t>(n, 64);
    std::mutex reporting;
    std::size_t done = 0;
    const std::function<void()> step_done = [&] {
      const std::lock_guard<std::mutex> lock(reporting);
      parameters_.progress(++done, n);
    };
    parallelFor(runs, threads, [&](std::size_t r) {
      matchRun(1 + n * r / runs, 1 + n * (r + 1) / runs, parameters_.progress ? step_done : std::function<void()>());
    });
  }

  /// Every `stride`-th step only; returns how many it matched of how many.
  std::pair<int, int> matchSample(std::size_t stride, int threads) {
    std::vector<std::size_t> sample;
    for (std::size_t i = 1; i < poses_.size(); i += stride) sample.push_back(i);
    parallelFor(sample.size(), threads, 8, [&](std::size_t k) { matchRun(sample[k], sample[k] + 1); });
    int matched = 0;
    for (std::size_t i : sample) matched += outcomes_[i] == StepOutcome::Matched;
    return {matched, static_cast<int>(sample.size())};
  }

  /// The odometry's systematic error, from the steps scan matching changed
  /// (ground steps only: no roll, pitch or climb), then taken out of the
  /// steps it kept as given. A term is used only when most of those steps
  /// err the same way (a sign test at three standard deviations): random
  /// drift leaves the kept steps as they were.
  void calibrateUnmatchedSteps(OdometryBias& bias) {
    constexpr double kMinLength = 0.05;                   // metres: shorter steps say nothing of scale or yaw rate
    constexpr double kDegree = 3.14159265358979323846 / 180.0;
    constexpr double kStraight = 2.0 * kDegree;  // a step turning less goes straight
    std::vector<double> scales, rates, turns;
    std::vector<std::size_t> turning;
    std::size_t used = 0;
    for (std::size_t i = 1; i < poses_.size(); ++i) {
      if (outcomes_[i] != StepOutcome::Matched) continue;
      const Eigen::Isometry3d input = poses_[i - 1].inverse() * poses_[i];
      if (!groundStep(input) || !groundStep(steps_[i], 1e-3)) continue;
      const double length = input.translation().head<2>().norm();
      const double error = wrapped(yawOf(steps_[i]) - yawOf(input));
      ++used;
      if (length >= kMinLength) scales.push_back(steps_[i].translation().head<2>().norm() / length);
      if (std::abs(yawOf(input)) < kStraight) {
        if (length >= kMinLength) rates.push_back(error / length);
      } else {
        turning.push_back(i);
      }
    }
    bias.steps = static_cast<int>(used);
    // Floors (docs/method.md): 1% of length, 0.25 degree per metre, 2% of a turn.
    bias.scale = consistentMedian(scales, 1.0, 0.01);
    bias.yaw_per_metre = consistentMedian(rates, 0.0, 0.25 * kDegree);
    for (std::size_t i : turning) {
      const Eigen::Isometry3d input = poses_[i - 1].inverse() * poses_[i];
      const double length = input.translation().head<2>().norm();
      const double error = wrapped(yawOf(steps_[i]) - yawOf(input)) - bias.yaw_per_metre * length;
      turns.push_back(error / yawOf(input));
    }
    bias.turn_scale = consistentMedian(turns, 0.0, 0.02);
    if (!bias.any()) return;
    for (std::size_t i = 1; i < poses_.size(); ++i) {
      if (outcomes_[i] == StepOutcome::Matched) continue;
      const Eigen::Isometry3d input = poses_[i - 1].inverse() * poses_[i];
      if (!groundStep(input)) continue;
      Eigen::Isometry3d step = input;
      const double length = input.translation().head<2>().norm();
      step.translation().head<2>() *= bias.scale;
      step.rotate(Eigen::AngleAxisd(bias.yaw_per_metre * length + bias.turn_scale * yawOf(input),
                                    Eigen::Vector3d::UnitZ()));
      steps_[i] = step;
    }
  }

  /// The poses chained from the first through every step; counts the outcomes.
  std::vector<Eigen::Isometry3d> chained(OdometryCorrectionReport& report) const {
    std::vector<Eigen::Isometry3d> corrected = poses_;
    for (std::size_t i = 1; i < poses_.size(); ++i) {
      corrected[i] = corrected[i - 1] * steps_[i];
      ++report.steps;
      report.matched += outcomes_[i] == StepOutcome::Matched;
      report.kept += outcomes_[i] == StepOutcome::Kept;
      report.unaligned += outcomes_[i] == StepOutcome::Unaligned;
    }
    return corrected;
  }

 private:
  const PointsOfObservation& points_;
  const std::vector<Eigen::Isometry3d>& poses_;
  const bool planar_;
  // SE(2) for a ground robot's 2D scans: z, roll and pitch stay exactly as
  // given. Depth clouds are matched in 6 DoF even when the camera moves in
  // a plane: in SE(2) their corrected maps were barely sharper than the
  // drifted ones (0.92-1.01 of the cells, against 0.69-0.76; docs/method.md).
  const Freedom freedom_;
  OdometryCorrectionParameters parameters_;
  double voxel_ = 0;
  std::vector<Eigen::Isometry3d> steps_;
  std::vector<StepOutcome> outcomes_;
};

}  // namespace

std::vector<Eigen::Isometry3d> scanMatchedPoses(const PointsOfObservation& points,
                                                const std::vector<Eigen::Isometry3d>& poses, bool planar,
                                                const OdometryCorrectionParameters& parameters,
                                                OdometryCorrectionReport& report) {
  if (poses.size() < 2) return poses;
  StepMatcher matcher(points, poses, planar, parameters);
  matcher.matchAll(parameters.threads);
  matcher.calibrateUnmatchedSteps(report.bias);
  return matcher.chained(report);
}

std::size_t occupiedCells(const PointsOfObservation& points, const std::vector<Eigen::Isometry3d>& poses,
                          double cell, bool planar) {
  std::unordered_set<std::uint64_t> cells;
  const auto key = [cell](double v) { return std::uint64_t(std::int64_t(std::floor(v / cell))) & 0x1FFFFF; };
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (const Eigen::Vector3f& p : points(i)) {
      const Eigen::Vector3d w = poses[i] * p.cast<double>();
      // 21 bits per axis: cells 0.2 m apart repeat every 419 km, beyond any building.
      cells.insert(key(w.x()) << 42 | key(w.y()) << 21 | (planar ? 0 : key(w.z())));
    }
  return cells.size();
}

namespace {

/// The occupied cells of a plane map, as bitmaps of 64 x 64 cells found
/// through a hash of their tiles: a drifted log's map may span kilometres
/// in both directions, which a single bitmap could not.
class PlaneOccupancy {
 public:
  explicit PlaneOccupancy(double cell) : cell_(cell) {}

  void add(const Eigen::Vector2d& p) {
    const auto [x, y] = cellOf(p);
    std::uint64_t& word = tile(tileKey(x, y))[std::size_t(y & 63)];
    const std::uint64_t bit = std::uint64_t(1) << (x & 63);
    count_ += (word & bit) == 0;
    word |= bit;
  }
  std::size_t count() const { return count_; }

  /// Whether the beam from `from` to `to` crosses an occupied cell between
  /// `start` metres from `from` and `end_margin` short of `to`, at most
  /// `reach` metres out. False for beams too short to follow.
  bool blocks(const Eigen::Vector2d& from, const Eigen::Vector2d& to, double start, double end_margin,
              double reach) const {
    const Eigen::Vector2d d = to - from;
    const double length = d.norm();
    const double end = std::min(length - end_margin, reach);
    if (!(end > start)) return false;
    const Eigen::Vector2d u = d / length;
    const Eigen::Vector2d a = (from + start * u) / cell_, b = (from + end * u) / cell_;
    bool blocked = false;
    region_cells::traverse<2>({a.x(), a.y()}, {b.x(), b.y()}, [&](const region_cells::Cell<2>& cell, double) {
      blocked = occupied(cell[0], cell[1]);
      return !blocked;
    });
    return blocked;
  }

 private:
  using Tile = std::array<std::uint64_t, 64>;
  std::pair<std::int64_t, std::int64_t> cellOf(const Eigen::Vector2d& p) const {
    return {std::int64_t(std::floor(p.x() / cell_)), std::int64_t(std::floor(p.y() / cell_))};
  }
  static std::uint64_t tileKey(std::int64_t x, std::int64_t y) {
    return (std::uint64_t(x >> 6) << 32) ^ (std::uint64_t(y >> 6) & 0xffffffffu);
  }
  Tile& tile(std::uint64_t key) {
    auto [it, added] = index_.try_emplace(key, tiles_.size());
    if (added) tiles_.emplace_back();
    return tiles_[it->second];
  }
  bool occupied(std::int64_t x, std::int64_t y) const {
    const auto it = index_.find(tileKey(x, y));
    return it != index_.end() && (tiles_[it->second][std::size_t(y & 63)] >> (x & 63) & 1);
  }

  double cell_;
  std::unordered_map<std::uint64_t, std::size_t> index_;
  std::vector<Tile> tiles_;
  std::size_t count_ = 0;
};

}  // namespace

MapConsistency mapConsistency(const PointsOfObservation& points, const std::vector<Eigen::Isometry3d>& poses,
                              double cell, int threads) {
  // Beams start off the sensor (a drifted pose may stand in a wall's cell, as
  // the visibility model's clearance allows) and end short of their point
  // (its own wall, give or take a cell); past 8 m they say little indoors.
  constexpr double kStart = 0.3, kEndMargin = 0.5, kReach = 8.0;
  PlaneOccupancy occupancy(cell);
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (const Eigen::Vector3f& p : points(i)) occupancy.add((poses[i] * p.cast<double>()).head<2>());
  MapConsistency out;
  out.occupied_cells = occupancy.count();
  std::vector<std::size_t> beams(poses.size(), 0), blocked(poses.size(), 0);
  parallelFor(poses.size(), threads, 16, [&](std::size_t i) {
    const Eigen::Vector2d from = poses[i].translation().head<2>();
    for (const Eigen::Vector3f& p : points(i)) {
      const Eigen::Vector2d to = (poses[i] * p.cast<double>()).head<2>();
      if (!((to - from).norm() - kEndMargin > kStart)) continue;
      ++beams[i];
      blocked[i] += occupancy.blocks(from, to, kStart, kEndMargin, kReach);
    }
  });
  for (std::size_t i = 0; i < poses.size(); ++i) {
    out.beams += beams[i];
    out.blocked_beams += blocked[i];
  }
  return out;
}

OdometryCorrectionReport correctOdometry(const PointsOfObservation& points, std::vector<Eigen::Isometry3d>& poses,
                                         bool planar, OdometryCorrection mode,
                                         const OdometryCorrectionParameters& parameters) {
  OdometryCorrectionReport report;
  if (mode == OdometryCorrection::Off || poses.size() < 2) return report;
  StepMatcher matcher(points, poses, planar, parameters);
  if (mode == OdometryCorrection::Auto) {
    // Poses that scan matching leaves as they are on a sample of the steps
    // (exact poses: none changes) are not matched at all: a long log of
    // consistent poses pays for the sample only. A first sample of a quarter
    // of the size decides when none of its steps changes: a depth camera's
    // step costs about 10 ms.
    const std::size_t steps = poses.size() - 1;
    const auto stride = [steps](int count) { return std::max<std::size_t>(1, steps / std::size_t(std::max(1, count))); };
    auto [matched, sampled] = matcher.matchSample(stride(parameters.sample_steps / 4), parameters.threads);
    if (matched > 0) std::tie(matched, sampled) = matcher.matchSample(stride(parameters.sample_steps), parameters.threads);
    report.sampled = sampled;
    report.sample_matched = matched;
    if (double(matched) < parameters.min_sample_share * double(sampled)) {
      report.steps = static_cast<int>(steps);
      return report;
    }
  }
  matcher.matchAll(parameters.threads);
  matcher.calibrateUnmatchedSteps(report.bias);
  std::vector<Eigen::Isometry3d> corrected = matcher.chained(report);
  if (planar) {
    const MapConsistency input = mapConsistency(points, poses, parameters.map_cell, parameters.threads);
    const MapConsistency matched = mapConsistency(points, corrected, parameters.map_cell, parameters.threads);
    report.input_cells = input.occupied_cells;
    report.corrected_cells = matched.occupied_cells;
    report.input_blocked_share = input.blockedShare();
    report.corrected_blocked_share = matched.blockedShare();
    report.applied = mode == OdometryCorrection::On ||
                     report.corrected_blocked_share <= parameters.max_conflict_ratio * report.input_blocked_share;
  } else {
    report.input_cells = occupiedCells(points, poses, parameters.map_cell, planar);
    report.corrected_cells = occupiedCells(points, corrected, parameters.map_cell, planar);
    report.applied = mode == OdometryCorrection::On ||
                     double(report.corrected_cells) <= parameters.max_cell_ratio * double(report.input_cells);
  }
  if (report.applied) poses = std::move(corrected);
  return report;
}

}  // namespace obsgroup
