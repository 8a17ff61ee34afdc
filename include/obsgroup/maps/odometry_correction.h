#pragma once
/// \file
/// Odometry corrected by scan matching, before the grouping. Drifted
/// odometry draws a room's walls twice and lets scans of one room see each
/// other's floor in the wrong place, so their overlap (eq. 16-18) no longer
/// says which scans share a room. Each observation is aligned with the one
/// before it, from the step the input poses give (the pairwise aligner of
/// refinement, docs/refinement.md), and the matched step replaces the
/// input's where it puts the observation's points demonstrably better on
/// its predecessor's surfaces. In `Auto` mode the corrected trajectory is
/// kept only when the map it draws is more consistent than the input's: a log whose
/// poses a SLAM back-end already corrected, loop closures and all, keeps
/// them (chaining matched steps would undo the closures).

#include "obsgroup/cloud/finite_points.h"
#include "obsgroup/cloud/observation.h"
#include "obsgroup/common/enum_names.h"
#include "obsgroup/common/interrupt.h"
#include "obsgroup/maps/refinement.h"

#include <Eigen/Geometry>

#include <cmath>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace obsgroup {

/// Whether the input poses are corrected by scan matching before grouping.
enum class OdometryCorrection {
  Off,   ///< Keep the input poses.
  /// A sample of the steps is matched first, and poses it leaves as they
  /// are are kept; otherwise every step is matched, and the corrected poses
  /// are kept when their map is more consistent than the input's (2D scans:
  /// fewer beams through walls; 3D clouds: fewer occupied cells).
  Auto,
  On  ///< Always the corrected poses (planar scans and 3D clouds).
};

inline constexpr EnumName<OdometryCorrection> kOdometryCorrectionNames[] = {
    {OdometryCorrection::Off, "off"}, {OdometryCorrection::Auto, "auto"}, {OdometryCorrection::On, "on"}};

inline std::string toString(OdometryCorrection mode) { return nameOf(kOdometryCorrectionNames, mode); }
/// Parses "off", "auto" or "on"; throws std::invalid_argument otherwise.
inline OdometryCorrection odometryCorrectionFromString(const std::string& name) {
  return valueNamed(kOdometryCorrectionNames, name, "odometry correction");
}

struct OdometryCorrectionParameters {
  /// The pairwise aligner's parameters (thinning voxel, gates, bounds of a
  /// step's correction: 1.2 m and 20 degrees for planar scans).
  RefinementParameters alignment;
  /// A matched step replaces the input's only when it raises the soft share
  /// of the observation's points on its predecessor's surfaces by this much
  /// (exact poses then stay bit for bit as given).
  double min_gain = 0.02;
  /// Auto: the two maps are compared on cells of this size, metres (the
  /// visibility regions' cell; squares for 2D scans, cubes for 3D clouds).
  double map_cell = 0.2;
  /// 2D scans: the corrected poses are kept when the share of beams that
  /// pass through another scan's wall (mapConsistency) is at most this times
  /// the input map's. Measured: drifted runs of real floor plans, a real raw
  /// odometry log and a 2 km building with biased odometry 0.13-0.57,
  /// SLAM-corrected real logs 1.12-1.93 (docs/method.md). A count of occupied cells says the
  /// same on short logs, but drift that winds a long route over itself makes
  /// the drifted map the smaller one.
  double max_conflict_ratio = 0.8;
  /// 3D clouds: the corrected poses are kept when their map occupies at most
  /// this share of the input map's cells. Measured: drifted simulated depth
  /// cameras 0.69-0.76, SLAM-corrected real 2D logs 1.06-1.75 (docs/method.md).
  double max_cell_ratio = 0.9;
  /// Auto: about this many steps, evenly spread, are matched first (a
  /// quarter of them before, the rest only when one of those changed)...
  int sample_steps = 100;
  /// ...and the rest only when at least this share of them changed.
  double min_sample_share = 0.1;
  int threads = 0;  ///< 0: all cores; the result does not depend on it
  /// Polled between steps: when set, correctOdometry throws Interrupted (a
  /// drifted log matches every step, about a millisecond each for 2D scans).
  const InterruptFlag* interrupt = nullptr;
  /// Called with the steps matched so far (never fewer than the call
  /// before) and the steps to match, one thread at a time; the sample of
  /// `Auto` is not reported.
  std::function<void(std::size_t done, std::size_t total)> progress;
};

/// A ground robot's odometry error, as scan matching measured it on the steps
/// it changed (matched minus input): each step's length times `scale`, and
/// its heading turned by `yaw_per_metre` for each metre and by `turn_scale`
/// times its own turn (a miscalibrated wheel radius and track width). Each
/// term is 0 (scale 1) unless a sign test over those steps finds it.
struct OdometryBias {
  double scale = 1.0;
  double yaw_per_metre = 0.0;  ///< radians per metre
  double turn_scale = 0.0;
  int steps = 0;  ///< matched ground steps the estimate used
  bool any() const { return scale != 1.0 || yaw_per_metre != 0.0 || turn_scale != 0.0; }
};

/// What the correction did.
struct OdometryCorrectionReport {
  int steps = 0;      ///< observations after the first
  int matched = 0;    ///< steps the scan matching changed
  int kept = 0;       ///< input steps kept: the match was no better
  int unaligned = 0;  ///< input steps kept: the pair did not align
  /// The odometry's systematic error, found on the matched steps and taken
  /// out of the kept and unaligned ones (whose input error would otherwise
  /// add up along the route); none found: OdometryBias's defaults.
  OdometryBias bias;
  int sampled = 0;         ///< Auto: steps matched first, as a sample...
  int sample_matched = 0;  ///< ...and how many of them changed
  std::size_t input_cells = 0;      ///< occupied cells of the input poses' map
  std::size_t corrected_cells = 0;  ///< ... and of the corrected poses' map
  /// 2D scans: the share of beams through another scan's wall in the input
  /// poses' map and in the corrected poses' (mapConsistency; 0 for 3D clouds).
  double input_blocked_share = 0.0;
  double corrected_blocked_share = 0.0;
  bool applied = false;             ///< the corrected poses replaced the input's
};

/// Observation i's finite points in its sensor frame, made when asked for:
/// a long log's points are not copied all at once.
using PointsOfObservation = std::function<MemberPoints(std::size_t)>;

/// The poses each observation's scan matching gives: the first pose is kept,
/// every later one is its predecessor's corrected pose times the matched (or
/// the input) step. `planar`: every point lies in the sensor's plane (2D scans).
std::vector<Eigen::Isometry3d> scanMatchedPoses(const PointsOfObservation& points,
                                                const std::vector<Eigen::Isometry3d>& poses, bool planar,
                                                const OdometryCorrectionParameters& parameters,
                                                OdometryCorrectionReport& report);

/// Occupied cells of `cell` metres (squares in the xy plane for planar
/// scans, cubes otherwise) of every point at `poses`: fewer is a sharper map.
std::size_t occupiedCells(const PointsOfObservation& points, const std::vector<Eigen::Isometry3d>& poses,
                          double cell, bool planar);

/// How well the scans of a planar map agree: each beam (sensor to point) is
/// followed from 0.3 m off the sensor to 0.5 m short of its point, at most
/// 8 m, through the cells of `cell` metres that hold a point of any scan. A
/// beam that crosses one went through a wall: in a consistent map only clutter
/// and grazing beams do, where drift draws walls across the floor other scans
/// saw empty. The counts do not depend on `threads`.
struct MapConsistency {
  std::size_t occupied_cells = 0;
  std::size_t beams = 0;          ///< beams followed
  std::size_t blocked_beams = 0;  ///< ... that crossed an occupied cell
  double blockedShare() const { return beams ? double(blocked_beams) / double(beams) : 0.0; }
};
MapConsistency mapConsistency(const PointsOfObservation& points, const std::vector<Eigen::Isometry3d>& poses,
                              double cell, int threads = 0);

/// Corrects `poses` in place as `mode` says; returns what was done.
OdometryCorrectionReport correctOdometry(const PointsOfObservation& points, std::vector<Eigen::Isometry3d>& poses,
                                         bool planar, OdometryCorrection mode,
                                         const OdometryCorrectionParameters& parameters = {});

/// The same for observations: their poses are corrected in place.
template <typename PointT>
OdometryCorrectionReport correctOdometry(std::vector<Observation<PointT>>& observations, OdometryCorrection mode,
                                         const OdometryCorrectionParameters& parameters = {}) {
  if (mode == OdometryCorrection::Off || observations.size() < 2) return {};
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(observations.size());
  bool planar = true;  // every point in one plane of the sensor: a 2D scan
  bool first = true;
  float plane = 0.0f;
  for (const auto& observation : observations) {
    for (const PointT& p : observation.cloud->points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
      if (first) plane = p.z;
      first = false;
      planar = planar && p.z == plane;
    }
    poses.push_back(observation.pose);
  }
  const PointsOfObservation points = [&observations](std::size_t i) {
    MemberPoints out;
    for (const PointT& p : finitePoints(*observations[i].cloud).points) out.emplace_back(p.x, p.y, p.z);
    return out;
  };
  const OdometryCorrectionReport report = correctOdometry(points, poses, planar, mode, parameters);
  if (report.applied)
    for (std::size_t i = 0; i < observations.size(); ++i) observations[i].pose = poses[i];
  return report;
}

}  // namespace obsgroup
