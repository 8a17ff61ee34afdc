#pragma once
/// \file
/// Groups joined across open floor. A hall or a large room that no view
/// spans (the regions reach 6 m) has a W like a chain of overlapping
/// neighbourhoods, and recursive bisection cuts it into bands as cheaply as
/// it cuts a building at its doors. What tells the two cuts apart is where
/// the robot went from one side to the other: through a door or a corridor,
/// a few metres wide at most, or through open floor. Two groups are joined
/// when every step of the route between them (consecutive observations, one
/// in each) passes only through places where the free space is at least
/// `width` across in every direction (docs/method.md, "Open floor").

#include "obsgroup/partition/recursive_partitioner.h"

#include <Eigen/Core>

#include <functional>
#include <utility>
#include <vector>

namespace obsgroup {

/// Whether the plane cell holding a point (in the caller's frame) is
/// occupied.
using OccupiedAt = std::function<bool(const Eigen::Vector2d&)>;

/// Two groups joined across open floor: their indices in the partition
/// given, and the narrowest free chord met on the steps between them, metres.
struct OpenFloorJoin {
  int first = 0, second = 0;
  double narrowest = 0.0;
};

/// The narrowest free chord through the points of the segment from `a` to
/// `b` (sampled every `cell` metres, both ends included): at each point the
/// shortest of the free runs through it along eight lines 22.5 degrees apart
/// (a run walked in half-cell steps up to the first occupied cell), each
/// side counted up to `cap` metres. A point in an occupied cell has 0.
double narrowestChord(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double cell, double cap,
                      const OccupiedAt& occupied);

/// Whether a point is near enough to an observation to have been seen from
/// near (within a view's range of one).
using SeenAt = std::function<bool(const Eigen::Vector2d&)>;

/// Rays of enclosedAlong that may meet no occupied cell within reach, of
/// sixteen: a forward camera leaves stretches of a hall's walls unseen, and
/// a ray slips out through such a gap (docs/method.md, "Open floor").
constexpr int kMaxOpenDirections = 2;

/// Whether every point of the segment from `a` to `b` (sampled as by
/// narrowestChord) meets, in each of sixteen directions within `reach`
/// metres, an occupied cell that the observations saw from near (`seen`),
/// but for at most kMaxOpenDirections directions that meet none: the floor
/// is enclosed by walls the route came near, as a room's or a hall's is.
/// Outdoors, round a building, rays pass between trees and posts to
/// structures no view reached.
bool enclosedAlong(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double cell, double reach,
                   const OccupiedAt& occupied, const SeenAt& seen);

/// How far walls may stand and the floor still count as enclosed
/// (enclosedAlong): a hall up to about 30 m across.
constexpr double kOpenFloorReach = 30.0;
/// A wall encloses when it lies within this many times a view's range of an
/// observation: with walls within 6 m, a route along the walls of a room of
/// about 11 x 25 m left it unjoined on one run of three; the structures
/// round a building outdoors lie farther (docs/method.md, "Open floor").
constexpr double kSeenBeyondViews = 4.0 / 3.0;

/// Occupied pieces that fit within this many metres along both axes (a
/// pillar, a piece of furniture) do not narrow the chords of
/// joinAcrossOpenFloor: the free space flows round them (docs/method.md,
/// "Open floor").
constexpr double kClutterExtent = 1.0;

/// Joins the groups of `partition` named in `pairs` (indices of its groups),
/// and through them the groups joined to those. The groups stay ascending
/// and ordered by their first observation; the split tree and warnings are
/// kept. Returns, for each group of the result, the index (before the join)
/// of the first of the groups it holds. Throws std::invalid_argument on an
/// index out of range.
std::vector<int> joinGroups(Partition& partition, const std::vector<std::pair<int, int>>& pairs);

/// Joins the groups of `partition` between which every step of the route
/// has a narrowest chord (narrowestChord, sides capped at `width`, pieces
/// within kClutterExtent free) of at least `width` metres and is enclosed
/// (enclosedAlong, `reach`; a wall seen from near: within kSeenBeyondViews x
/// `view_range` metres of an observation's position).
/// Observation k stands at positions[k] and the route goes through the
/// observations in index order; a non-finite position (an observation with
/// no point) joins nothing. The groups stay ascending and ordered by their
/// first observation; the split tree and warnings are kept. Returns the
/// joins made, in the order of their pairs of groups. Throws
/// std::invalid_argument when positions are not one per observation, or
/// width, cell, view_range or reach is not finite and positive.
std::vector<OpenFloorJoin> joinAcrossOpenFloor(Partition& partition, const std::vector<Eigen::Vector2d>& positions,
                                               double width, double cell, const OccupiedAt& occupied,
                                               double view_range, double reach = kOpenFloorReach);

}  // namespace obsgroup
