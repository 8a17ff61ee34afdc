#pragma once
/// \file
/// The simulated datasets that evaluations share: buildings with their
/// routes, the sensors that scan them, the true places of the poses and an
/// odometry-like drift of the poses. Eigen only, no PCL.

#include "floor_plan.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace obsgroup::sim {

/// A floor plan and the routes a robot takes through it.
struct Building {
  std::string key;    ///< short name for command lines: "office", "loop", "rooms20", ...
  std::string title;  ///< for reports
  FloorPlan plan;
  std::vector<Pose2D> route;        ///< run 1: the route its maps are built from
  std::vector<Pose2D> second_visit;  ///< run 2: the robot's next visit, another way through the same rooms
};

/// The buildings by key: "office" (office(), officeRoute(150),
/// officeSecondVisitRoute(40)), "loop" (loopBuilding(), loopBuildingRoute(300),
/// loopBuildingSecondVisitRoute(70)), "rooms20" (twentyRoomBuilding(),
/// twentyRoomBuildingRoute(600), twentyRoomBuildingSecondVisitRoute(140)),
/// "smallrooms" (smallRoomsBuilding(), smallRoomsRoute(900)) and "hall"
/// (hallBuilding(), hallBuildingRoute(400)); the last two have no second visit.
/// Throws std::invalid_argument for another key.
Building makeBuilding(const std::string& key);
/// The keys of makeBuilding, smallest building first.
std::vector<std::string> buildingKeys();

/// The sensors of the evaluations, all with 1 cm range noise.
enum class Sensor {
  Laser360,  ///< fullTurnLaser(): 720 beams, 30 m
  Laser180,  ///< the default LaserModel: forward 180 degrees, 361 beams, 30 m
  Depth,     ///< the default DepthCamera: 80 x 60 pixels, 58 degrees, 6 m, 1 m over the floor
  Lidar      ///< lidar(): a 64-beam spinning lidar, 120,000 beams a sweep, 1.7 m over the floor
};
std::string toString(Sensor sensor);  ///< "laser360", "laser180", "depth", "lidar"
/// Parses the names of toString; throws std::invalid_argument otherwise.
Sensor sensorFromString(const std::string& name);
/// A few words for reports: "360° laser" and so on.
std::string describe(Sensor sensor);

LaserModel laser360();
LaserModel laser180();
DepthCamera depthCamera();
Lidar lidar();
/// The height of the sensor frame over the floor: a depth camera and a lidar
/// stand over it, a laser scans in the plane z = 0.
double sensorHeight(Sensor sensor);

/// The true place of every pose of a route: the plan's rooms, except that a
/// corridor (a room whose name contains "corridor") is cut along its length
/// into stretches of about `stretch_length` metres, each a place of its own:
/// a long corridor is not one place that any sensor sees at once.
struct Places {
  std::vector<int> of_pose;        ///< place of each pose; poses in no room share one extra place
  std::vector<std::string> names;  ///< e.g. "room 3", "south corridor 2/5", "(outside every room)"
  std::vector<bool> is_room;       ///< false for corridor stretches and the extra place
};
Places placesAlong(const FloorPlan& plan, const std::vector<Pose2D>& route, double stretch_length = 8.0);

/// A planar pose as an isometry, `z` over the floor: x ahead, y left, z up.
Eigen::Isometry3d toIsometry(const Pose2D& pose, double z = 0.0);

/// Odometry-like drift: each step's motion is perturbed by Gaussian noise of
/// 2% of its length in x and y and 1 degree per metre in heading (the model
/// of evaluate_local_maps). The first pose is kept; deterministic for a seed.
std::vector<Eigen::Isometry3d> drift(const std::vector<Eigen::Isometry3d>& truth, std::uint64_t seed);

/// Biased odometry, as a miscalibrated wheel radius and track width give:
/// each step `scale` times as long as it was, and turned `degrees_per_metre`
/// further to the left for each metre of it. A long route curls up into
/// turns that fall on each other. The first pose is kept.
std::vector<Eigen::Isometry3d> biasedDrift(const std::vector<Eigen::Isometry3d>& truth, double scale = 1.02,
                                           double degrees_per_metre = 1.0);

/// How well groups match rooms, as a user checks a map against a floor
/// plan's rooms (corridor observations may join any room's group):
/// a room is *found* when at least 90% of its observations are in one group
/// and at least 90% of that group's room observations are this room's; it
/// is *pure* when all of its observations are in one group holding no
/// observation of another room.
struct RoomScores {
  int rooms = 0;  ///< rooms with at least one observation
  int found = 0;
  int pure = 0;
  int whole = 0;  ///< all of the room's observations in one group (which may hold other rooms)
};
/// `place_of[i]` is observation i's place (or -1: no label), `is_room[place]`
/// whether the place is a room; `group_of[i]` its group.
RoomScores scoreRooms(const std::vector<int>& place_of, const std::vector<bool>& is_room,
                      const std::vector<int>& group_of);

/// Adjusted Rand index of two labellings (Hubert and Arabie): 1 when they
/// are the same partition, about 0 for a chance agreement.
double adjustedRandIndex(const std::vector<int>& a, const std::vector<int>& b);

/// Root mean square distance between the positions of two pose lists.
double rmsPositionError(const std::vector<Eigen::Isometry3d>& a, const std::vector<Eigen::Isometry3d>& b);

}  // namespace obsgroup::sim
