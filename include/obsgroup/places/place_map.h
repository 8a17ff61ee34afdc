#pragma once
/// \file
/// Places a robot can use: each group of observations as a floor area (an
/// outline with its area, centroid and neighbours), the doors between
/// places, a label grid and an occupancy grid on the same cells, and "which
/// place holds this pose". Built from the sensed regions the grouping
/// measured (sensed_regions.h); no PCL.

#include "obsgroup/common/interrupt.h"
#include "obsgroup/overlap/sensed_regions.h"
#include "obsgroup/overlap/world_points.h"
#include "obsgroup/partition/recursive_partitioner.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

namespace obsgroup {

/// A grid over the floor in the world frame: cell (i, j) spans
/// [origin.x + i * resolution, origin.x + (i + 1) * resolution) in x and the
/// same in y from origin.y; row j = 0 is the lowest (ROS map_server's
/// origin is the lower-left corner, as here).
struct FloorGrid {
  double resolution = 0.2;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  int width = 0, height = 0;

  std::size_t index(int i, int j) const { return std::size_t(j) * std::size_t(width) + std::size_t(i); }
  bool contains(int i, int j) const { return i >= 0 && j >= 0 && i < width && j < height; }
  /// The cell holding a point of the world frame (it may lie outside the grid).
  Eigen::Vector2i cellOf(const Eigen::Vector2d& p) const;
  Eigen::Vector2d cellCentre(int i, int j) const;
};

/// What the observations say of a cell.
enum class Occupancy : std::uint8_t { Unknown = 0, Free = 1, Occupied = 2 };

/// One place: a group of observations and the floor it holds.
struct Place {
  int id = -1;                ///< the group's id (stable across online updates)
  std::vector<int> members;   ///< observation indices, ascending
  /// The floor the place holds, as rings of [x, y] in the world frame: outer
  /// rings counter-clockwise, holes clockwise, each closed implicitly (the
  /// last vertex joins the first) and simple; rings meet at most at a vertex.
  std::vector<std::vector<Eigen::Vector2d>> outline;
  double area_m2 = 0.0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  /// Where to write the place's name: the centre of its cell farthest from
  /// the edge of its floor, always on its floor (a corridor's or an L-shaped
  /// room's centroid may lie outside it).
  Eigen::Vector2d label_point = Eigen::Vector2d::Zero();
  Eigen::AlignedBox2d bbox;    ///< of the outline (empty when the place holds no floor)
  std::vector<int> neighbours; ///< ids of the places whose floor touches this one's, ascending
};

/// An opening between two places narrower than a door.
struct Door {
  int place_a = -1, place_b = -1;  ///< place ids, place_a < place_b
  Eigen::Vector2d end_a = Eigen::Vector2d::Zero(), end_b = Eigen::Vector2d::Zero();  ///< the segment across it
  Eigen::Vector2d midpoint = Eigen::Vector2d::Zero();
  double width_m = 0.0;
};

struct PlaceOptions {
  /// Where two places touch, each cluster of their shared cell edges (edges
  /// at most two cells apart) is a door when it spans at most this along its
  /// main direction, metres.
  double max_door_width = 2.0;
  /// Pieces of a place smaller than this are dropped (its largest piece is
  /// always kept), square metres.
  double min_piece_area = 0.5;
  /// Visibility in 3D: the points whose height above their sensor lies in
  /// [band_low, band_high] are obstacles (RegionParameters' band).
  double band_low = -0.7, band_high = 0.8;
};

/// The result of PlaceMap::locate.
struct Location {
  std::optional<int> place;  ///< the place id; empty when none is within the tolerance
  double distance_m = 0.0;   ///< 0 inside a place; else the distance to the nearest cell of `place`
};

/// Places, doors and the grids they are drawn on.
struct PlaceMap {
  FloorGrid grid;
  /// Per cell: the place id holding it, or -1.
  std::vector<std::int32_t> labels;
  /// Per cell: free where some observation sensed it and no point lies in
  /// it, occupied where points lie, unknown elsewhere.
  std::vector<Occupancy> occupancy;
  std::vector<Place> places;
  std::vector<Door> doors;

  /// The place holding (x, y) of `position`, or the nearest within
  /// `tolerance` metres (distance to the nearest cell centre), or none.
  Location locate(const Eigen::Vector2d& position, double tolerance = 1.0) const;
};

/// The rings of an outline grouped into polygons: for each outer ring (counter-
/// clockwise) its index first, then the indices of the holes (clockwise) that
/// lie in it (each in the smallest outer ring holding it). For GeoJSON's
/// MultiPolygon and the like.
std::vector<std::vector<std::size_t>> polygonsOf(const std::vector<std::vector<Eigen::Vector2d>>& rings);

/// Twice the signed area of a ring (positive: counter-clockwise).
double twiceSignedArea(const std::vector<Eigen::Vector2d>& ring);

/// Builds the places of a partition from the observations' sensed regions
/// (those the grouping measured, or computeRegions(Visibility, ...) for the
/// points model) and their points (for the obstacles):
/// - each floor cell (in some region, no point in it) goes to the group the
///   largest share of whose observations hold it (ties: the lower group): a
///   room's many scans that see the corridor in front of its door through the
///   door are a small share of the room's, and the corridor keeps that floor;
/// - a place's cells that lie on no 2x2 block of its own (one-cell spokes
///   reaching through a door) and pieces below options.min_piece_area are
///   left to no place;
/// - a place's floor beyond a neck of two cells or less that none of its
///   observations stood beyond (a fan its scans saw through a door at a
///   slant) is left to no place (docs/places.md);
/// - outlines follow the cell edges (4-connected pieces), doors are the
///   short contacts between two places (PlaceOptions::max_door_width).
/// `groups` are observation indices (Partition::groups), `place_ids` one id
/// per group. `world` is the points as the grouping saw them (re-centred on
/// world.origin, as the regions are), `sensor_origins` re-centred the same.
/// The grid covers the regions and one cell around them; obstacles beyond
/// (far returns) are left out. Throws std::invalid_argument on sizes that do
/// not match, options out of range, or a grid of more than 400 million cells.
PlaceMap buildPlaceMap(const ObservationRegions& regions, const WorldPoints& world,
                       const std::vector<Eigen::Vector3d>& sensor_origins,
                       const std::vector<std::vector<int>>& groups, const std::vector<int>& place_ids,
                       const PlaceOptions& options = {});

/// Observation i's points as WorldPoints holds them (re-centred on the
/// world origin, as the regions are), asked for once per observation, from
/// several threads at once, each with its own `scratch`: a source that makes
/// the points on demand fills `scratch` and returns its range; one that holds
/// them returns theirs.
using PlacePointSource = std::function<std::pair<const Eigen::Vector3f*, const Eigen::Vector3f*>(
    int i, std::vector<Eigen::Vector3f>& scratch)>;

/// buildPlaceMap with the points asked for one observation at a time, so
/// that a large run need not hold every observation's world points at once
/// (100,100 scans: about 430 MiB); `world_origin` is WorldPoints::origin.
/// The same places as from the WorldPoints holding the same points.
PlaceMap buildPlaceMap(const ObservationRegions& regions, const Eigen::Vector3d& world_origin,
                       const PlacePointSource& points_of, const std::vector<Eigen::Vector3d>& sensor_origins,
                       const std::vector<std::vector<int>>& groups, const std::vector<int>& place_ids,
                       const PlaceOptions& options = {});

/// What the observations' beams say of the places' grid, whatever the
/// groups: the first half of buildPlaceMap (a pass over every beam), which
/// needs the regions and the points alone, so that a caller can make it
/// while the partition is computed. Made by observeFloor, read by
/// buildPlaceMap with the same regions and band.
struct FloorEvidence {
  FloorGrid grid;  ///< the places' grid: the regions' cells and one cell around them
  /// Per cell of `grid`, as PlaceMap::occupancy: free where a region holds
  /// it and a beam crossed it, occupied where points lie (3D: points within
  /// the band), unknown elsewhere.
  std::vector<Occupancy> occupancy;
  double band_low = 0.0, band_high = 0.0;  ///< the PlaceOptions band the obstacles were found with
};

/// The beams' evidence of the places' grid, on `threads` threads (0:
/// OpenMP's default; the same bits for any count). Polls `interrupt` between
/// observations and throws Interrupted when it is set. Throws
/// std::invalid_argument, naming observeFloor, when the sensor origins are
/// not one per region, the band is not finite with low < high or the grid
/// would exceed 400 million cells (buildPlaceMap, which calls it, reports a
/// grid too large in the same words), and rethrows what points_of throws.
FloorEvidence observeFloor(const ObservationRegions& regions, const Eigen::Vector3d& world_origin,
                           const PlacePointSource& points_of, const std::vector<Eigen::Vector3d>& sensor_origins,
                           const PlaceOptions& options = {}, int threads = 0,
                           const InterruptFlag* interrupt = nullptr);

/// buildPlaceMap from the beams' evidence observeFloor made of the same
/// regions (and band): the same places as the overloads above. Throws
/// std::invalid_argument when the evidence is of another grid or band.
PlaceMap buildPlaceMap(const ObservationRegions& regions, const FloorEvidence& floor,
                       const std::vector<Eigen::Vector3d>& sensor_origins,
                       const std::vector<std::vector<int>>& groups, const std::vector<int>& place_ids,
                       const PlaceOptions& options = {});

/// An opening narrower than this is a door whatever lies beyond it, metres
/// (docs/method.md, "Passages").
constexpr double kMinPassageWidth = 1.2;
/// A door opens into free space at least this many times as wide as itself,
/// along the opening, on both of its sides (docs/method.md, "Passages").
constexpr double kDoorWidening = 1.5;

/// The doors of `map` (contacts up to PlaceOptions::max_door_width) that are
/// no door but a passage: a corridor cut across. The opening (the free run
/// through the contact's midpoint along it, on `map.occupancy`) is at least
/// kMinPassageWidth wide, the contact spans three quarters of it or more,
/// and on at least one side the free space along the opening, 0.4 to 1.6 m
/// from it (the lower median of seven lines), is less than kDoorWidening
/// times the opening: the corridor goes on as narrow there, where a door
/// opens into a corridor or a room on both sides.
std::vector<Door> passagesOf(const PlaceMap& map);

/// Joins the groups of `partition` whose places (`place_ids`, one per group,
/// as `map` was built with) meet through a passage (passagesOf(map)), as
/// joinGroups does. `place_ids` becomes one per joined group: the id of its
/// first group. Returns the passages that joined two groups not already
/// joined, in passagesOf's order. Throws std::invalid_argument when
/// place_ids is not one per group.
std::vector<Door> joinThroughPassages(Partition& partition, std::vector<int>& place_ids, const PlaceMap& map);

}  // namespace obsgroup
