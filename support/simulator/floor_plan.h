#pragma once
/// \file
/// A small 2D scan simulator: walls are solid boxes in a floor plan and a
/// laser casts rays against them. Used by the examples, tests and benchmarks
/// to make maps whose true rooms are known. Eigen only, no PCL.

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace obsgroup::sim {

struct Pose2D {
  double x = 0.0, y = 0.0, yaw = 0.0;
};

struct LaserModel {
  int beams = 361;
  double field_of_view = 3.14159265358979323846;  ///< centred ahead, counter-clockwise
  double max_range = 30.0;                         ///< no return at or beyond
  double range_noise = 0.0;                        ///< Gaussian sigma, metres
  /// The beams cover a full turn (field_of_view = 2 pi): they are spaced
  /// field_of_view / beams apart, so that no direction is scanned twice (the
  /// first beam points backwards, at -pi, and +pi is not repeated). Otherwise
  /// the first and last beams lie on the edges of the field of view.
  bool full_turn = false;

  /// Direction of beam k, counter-clockwise, in a scan of `count` beams
  /// (normally `beams`) taken facing `heading` (0: the angle in the sensor
  /// frame).
  double beamAngle(std::size_t k, std::size_t count, double heading = 0.0) const;
};

/// A laser scanning all around: 720 beams, one every half degree, 30 m.
LaserModel fullTurnLaser(int beams = 720);

/// A depth camera looking along the pose's heading, its optical axis level.
/// Points come in the sensor frame: x ahead, y left, z up.
struct DepthCamera {
  int width = 80, height = 60;
  double horizontal_fov = 58.0 * 3.14159265358979323846 / 180.0;
  double height_above_floor = 1.0;  ///< metres
  double max_range = 6.0;           ///< metres; no point beyond
  double range_noise = 0.0;         ///< Gaussian sigma along the ray, metres
};

/// A spinning multi-beam lidar (a Velodyne HDL-64E's geometry): `rings`
/// beams spread evenly over [lowest, highest] elevation, each fired at
/// `columns` azimuths over a full turn. Points in the sensor frame.
struct Lidar {
  int rings = 64, columns = 1875;  ///< 120,000 beams a sweep
  double lowest = -24.9 * 3.14159265358979323846 / 180.0;
  double highest = 2.0 * 3.14159265358979323846 / 180.0;
  double height_above_floor = 1.7;  ///< metres
  double max_range = 80.0;          ///< metres; no point beyond
  double range_noise = 0.0;         ///< Gaussian sigma along the ray, metres
};

class FloorPlan {
 public:
  /// A solid axis-aligned box (a wall segment, a pillar, a cupboard).
  void addBox(double x0, double y0, double x1, double y1);
  /// A wall of the given thickness along x (horizontal) or y (vertical) from
  /// `from` to `to`, with openings given as (start, end) coordinates along it.
  void addWallX(double y, double from, double to, std::vector<std::pair<double, double>> openings = {},
                double thickness = 0.2);
  void addWallY(double x, double from, double to, std::vector<std::pair<double, double>> openings = {},
                double thickness = 0.2);
  /// A named room, used only as ground truth (which room a pose is in).
  void addRoom(std::string name, double x0, double y0, double x1, double y1);

  /// Ranges of one scan (max_range where no wall is hit), beam k at angle
  /// laser.beamAngle(k, beams, yaw): yaw - fov/2 + k * fov/(beams-1), or
  /// yaw - fov/2 + k * fov/beams for a full turn. Noise comes from `seed`.
  std::vector<double> scan(const Pose2D& pose, const LaserModel& laser, std::uint64_t seed = 0) const;

  /// Points of one depth image in the sensor frame, the camera standing at
  /// `camera.height_above_floor` over `pose`. Walls rise from the floor
  /// (z = 0) to the ceiling; floor and ceiling are seen too.
  std::vector<Eigen::Vector3d> depthImage(const Pose2D& pose, const DepthCamera& camera,
                                          std::uint64_t seed = 0) const;
  /// Points of one lidar sweep in the sensor frame (x ahead, y left, z up),
  /// the lidar at `lidar.height_above_floor` over `pose`; walls, floor and
  /// ceiling as for depthImage.
  std::vector<Eigen::Vector3d> lidarSweep(const Pose2D& pose, const Lidar& lidar, std::uint64_t seed = 0) const;
  void setCeilingHeight(double height) { ceiling_ = height; }

  /// The box of a room given to addRoom.
  struct Room {
    double x0, y0, x1, y1;
  };

  /// Index of the room containing (x, y), or -1; where rooms overlap, the
  /// one added first.
  int roomAt(double x, double y) const;
  const std::vector<std::string>& roomNames() const { return room_names_; }
  const std::vector<Room>& rooms() const { return rooms_; }

  /// Distance from (x, y) to the nearest wall in any horizontal direction
  /// (sampled every degree), up to `max_distance`: a route's pose that is
  /// closer to a wall than a robot's radius, or inside furniture, is a bug.
  double clearanceAt(double x, double y, double max_distance = 5.0) const;

 private:
  struct Segment {
    Eigen::Vector2d a, b;
  };
  /// Distance along a horizontal ray to the first wall; infinity if none
  /// lies within `max_distance` (the search may stop there).
  double castHorizontal(const Eigen::Vector2d& origin, double angle, double max_distance) const;

  /// Segments by grid cell, so that a ray only tests the walls near it.
  void index(std::size_t segment);
  static constexpr double kCell = 2.0;
  std::vector<Segment> segments_;
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> cells_;
  double ceiling_ = 2.6;
  std::vector<Room> rooms_;
  std::vector<std::string> room_names_;
};

/// Points of a scan in the sensor frame (x ahead, y left); beams with no
/// return give no point.
std::vector<Eigen::Vector2d> scanToPoints(const std::vector<double>& ranges, const LaserModel& laser);

/// Poses every `spacing` metres along a polyline, heading along the path.
std::vector<Pose2D> samplePath(const std::vector<Eigen::Vector2d>& waypoints, double spacing);
/// At most `count` poses evenly spaced along a polyline.
std::vector<Pose2D> evenlySpaced(const std::vector<Eigen::Vector2d>& waypoints, int count);

/// Three 6 x 5 m rooms in a row joined by 1 m doors (the situation of the
/// paper's Fig. 3).
FloorPlan threeRooms();
/// Scans taken inside each of the three rooms, `per_room` per room, facing
/// every direction.
std::vector<Pose2D> threeRoomsPoses(int per_room = 5);

/// An office: a 32 m corridor with four rooms along it (the setting of the
/// paper's Fig. 5).
FloorPlan office();
/// A route along the corridor that visits every room, `count` poses.
std::vector<Pose2D> officeRoute(int count = 77);
/// The robot's next visit to office(): it starts at the corridor's east end
/// and visits the rooms in another order (3, 1, 2, 4), going round each the
/// other way and nearer its walls, and keeps to other lanes of the corridor
/// than officeRoute, so that few of its poses and headings repeat run 1's.
/// `count` poses.
std::vector<Pose2D> officeSecondVisitRoute(int count = 60);

/// A long building for scaling runs: `length` metres of 3 m corridor with
/// 8 x 6 m rooms on both sides, each with a door; the local density of the
/// map stays bounded however long it is.
FloorPlan longBuilding(double length);
/// A route along the corridor of longBuilding(length) that enters every
/// room; `count` poses, evenly spaced.
std::vector<Pose2D> longBuildingRoute(double length, int count);

/// A larger building with a loop: a 3 m corridor ring around six rooms
/// (40 x 26 m), each room with a door onto the ring.
FloorPlan loopBuilding();
/// A route around the whole ring that enters every room and closes the loop
/// where it started, `count` poses.
std::vector<Pose2D> loopBuildingRoute(int count = 260);
/// The robot's next visit to loopBuilding(): it starts half-way up the west
/// corridor, goes round the ring clockwise (run 1 goes counter-clockwise),
/// in other lanes, and visits the rooms in another order (north 2, north 3,
/// south 3, south 1, south 2, north 1) on rectangular paths, where run 1
/// walks diamonds. `count` poses.
std::vector<Pose2D> loopBuildingSecondVisitRoute(int count = 100);

/// A building of twenty rooms around a loop (46 x 40 m): a 3 m corridor
/// ring around a block of eight rooms (four opening south, four north) and
/// six rooms on each outer side of the ring, 5 to 12 m wide and 8 or 9 m
/// deep, each with one 1 m door onto the ring and furniture of its own. The
/// rooms are "room 1" to "room 20"; the ring is "south corridor", "east
/// corridor", "north corridor" and "west corridor".
FloorPlan twentyRoomBuilding();
/// A route around the whole ring that enters every room of
/// twentyRoomBuilding(), goes once round each room (facing all four ways)
/// and closes the loop where it started, `count` poses.
std::vector<Pose2D> twentyRoomBuildingRoute(int count = 600);
/// The robot's next visit to twentyRoomBuilding(): clockwise round the ring
/// (run 1 goes counter-clockwise), in other lanes, entering the rooms in the
/// order their doors come that way, going round each the other way than
/// run 1 and further from its walls. `count` poses.
std::vector<Pose2D> twentyRoomBuildingSecondVisitRoute(int count = 300);

/// A building of small rooms like the Intel lab's: a 2.5 m corridor ring
/// (40 x 26 m) with 36 rooms 3 to 5 m wide and 4 or 4.5 m deep on both of
/// its sides, each with one 1 m door and a desk or cupboard. The rooms are
/// "room 1" to "room 36"; the ring is "south corridor", "north corridor",
/// "west corridor" and "east corridor".
FloorPlan smallRoomsBuilding();
/// A route round the ring of smallRoomsBuilding() that looks into every room
/// from its doorway, a step inside, turning to face the room's ends, and
/// never walks round it (as a robot mapping the Intel lab did); the loop
/// closes. `count` poses.
std::vector<Pose2D> smallRoomsRoute(int count = 900);

/// A hall larger than a depth camera's reach and the visibility model's
/// range: an open 24 x 16 m hall with six pillars, four 6 x 5 m rooms off
/// its north side, and a 3 m corridor along its east side (a wide opening
/// from the hall) with two rooms beyond it. Places: "hall", "room 1" to
/// "room 6", "east corridor".
FloorPlan hallBuilding();
/// Three lanes across the hall, once round each north room, then down the
/// corridor into its rooms and back into the hall. `count` poses.
std::vector<Pose2D> hallBuildingRoute(int count = 400);

}  // namespace obsgroup::sim
