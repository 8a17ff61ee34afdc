#pragma once
/// \file
/// Refinement of a local map's member poses (paper sec. IV-A, step 3):
/// pairwise point-to-line (2D) or point-to-plane (3D) alignment of the
/// members that overlap, combined in a Lu & Milios pose graph, and a change
/// kept only where it makes the map demonstrably more consistent. Planar
/// data is refined in SE(2). Not templated: members come as plain points.

#include "obsgroup/common/enum_names.h"
#include "obsgroup/maps/topological_map.h"

#include <Eigen/Core>

#include <string>
#include <utility>
#include <vector>

namespace obsgroup {

/// How the members' relative poses are refined.
enum class Refinement {
  None,  ///< Keep the input poses.
  /// Pairwise alignment along the group's maximum spanning tree of W, from the reference outwards.
  Icp,
  /// Pairwise alignment of every member with its most overlapping members, all pairs
  /// combined in one pose graph (Lu & Milios' globally consistent alignment).
  Lum
};

inline constexpr EnumName<Refinement> kRefinementNames[] = {
    {Refinement::None, "none"}, {Refinement::Icp, "icp"}, {Refinement::Lum, "lum"}};

inline std::string toString(Refinement refinement) { return nameOf(kRefinementNames, refinement); }
/// Parses "none", "icp" or "lum"; throws std::invalid_argument otherwise.
inline Refinement refinementFromString(const std::string& name) {
  return valueNamed(kRefinementNames, name, "refinement");
}

struct RefinementParameters {
  /// Voxel leaf planar scans are thinned to before alignment, metres...
  double alignment_voxel = 0.05;
  /// ...and 3D clouds, whose surfaces hold far more points than a scan's lines.
  double alignment_voxel_3d = 0.1;
  /// Correspondence gate of the first alignment iteration for planar scans,
  /// metres; it shrinks towards 3 x inlier_distance. Bounds the pose error
  /// that can be corrected: a group holding two visits of a place, drifted
  /// apart by a loop, needs a metre (docs/refinement.md measures it).
  double max_correspondence_distance = 1.2;
  /// ...and for 3D clouds: a wide gate lets a narrow depth view's far
  /// surfaces pull it into another basin (drifted p90 9.9 to 11.1 cm in the
  /// office, 33.0 to 37.0 cm in the loop building with the 2D values).
  double max_correspondence_distance_3d = 0.5;
  /// A point lies on its neighbour's surface when nearer than this, metres:
  /// about three times the range noise.
  double inlier_distance = 0.05;
  int max_iterations = 30;  ///< Per pairwise alignment.
  /// A planar scan moves at most this far from its input pose (in the map frame)...
  double max_translation_correction = 1.2;
  /// ...and turns at most this much, radians (20 degrees): larger corrections are refused.
  double max_rotation_correction = 0.3490658503988659;
  /// The same bounds for 3D clouds: 0.5 m and 10 degrees.
  double max_translation_correction_3d = 0.5;
  double max_rotation_correction_3d = 0.17453292519943295;
  /// A pair is used only if this share of the source's points lands on the target's surface.
  double min_overlap = 0.3;
  /// A member's new pose is kept only if it puts this much larger a share of
  /// its points on its neighbours' surfaces (soft inliers, see docs/method.md).
  double min_gain = 0.02;
  /// A direction of a pairwise alignment held by less than this share of the
  /// matches (sum of squared normal components) is left to the input pose: a
  /// corridor seen without its ends does not say where along it the robot was.
  double min_constraint_ratio = 0.02;
  /// Lum: each member is aligned with up to this many of its most overlapping members (by W).
  int neighbours = 5;
  /// Lum, planar scans: and with up to this many of the members whose points
  /// share the most cells of `point_overlap_cell` metres with its own at the
  /// input poses. W pairs views of one place, which a forward laser turned the
  /// other way in a corridor shares no surface with: those pairs are refused,
  /// and members hang on partial constraints (docs/refinement.md measures it).
  int point_neighbours = 2;
  double point_overlap_cell = 0.5;
};

/// What refinement did to one local map.
struct RefinementReport {
  int members = 0;            ///< Members other than the reference.
  int moved = 0;              ///< Members whose refined pose was kept.
  int kept_not_better = 0;    ///< Input pose kept: the alignment did not make the map more consistent.
  int kept_beyond_bound = 0;  ///< Input pose kept: the correction exceeded the bounds.
  int kept_unaligned = 0;     ///< Input pose kept: no pair of this member aligned.
  int pairs = 0;              ///< Pairwise alignments tried.
  int pairs_refused = 0;      ///< Pairs that did not converge or overlap enough.
  int pairs_partial = 0;      ///< Pairs constraining only some directions (a corridor): the rest kept.
  /// Observations (indices) that no chain of usable alignments joins to
  /// their map's reference: only the input poses place them relative to it,
  /// however well they align with the members they are joined to. A narrow
  /// view (a depth camera) shares no surface with the views after a turn.
  std::vector<int> unlinked;

  /// One short line for the run's warnings ("3 of 40 members kept the input
  /// pose; 2 not linked to their map's reference"), or "" when nothing
  /// deserves one: members kept because their input pose was already as
  /// good, and pairs that leave a corridor's length to the input, are normal.
  std::string warning() const;
  /// Adds another map's counts: one report, and one warning, for a whole run.
  RefinementReport& operator+=(const RefinementReport& other);
};

/// The finite points of one member in its own sensor frame.
using MemberPoints = std::vector<Eigen::Vector3f>;

/// Refines `frame.member_poses` (the reference stays the identity). When
/// the usable alignments join more members to another part of the map than
/// to the reference's, the map is anchored at that part's member with the
/// most alignments: `frame.reference` and `frame.pose` change and the poses
/// are re-expressed in its frame (a planar move for planar poses).
/// `points[k]` belongs to `frame.members[k]`; `pairs` are the (target,
/// source) member positions to align, spanning tree pairs first. `planar`
/// says every point lies in one plane (2D scans: normals are fitted in it).
/// Members whose poses all lie in one horizontal plane (a ground robot,
/// with a laser or a depth camera) are refined in SE(2): z, roll and pitch
/// are left exactly as they were (re-anchoring keeps exact zeros zero).
RefinementReport refineMemberPoses(Refinement refinement, const std::vector<MemberPoints>& points,
                                   const std::vector<std::pair<int, int>>& pairs, bool planar,
                                   const RefinementParameters& parameters, LocalMapFrame& frame);

}  // namespace obsgroup
