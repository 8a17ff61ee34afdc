#include "scenarios.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>
#include <utility>

namespace obsgroup::sim {

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

Building makeBuilding(const std::string& key) {
  if (key == "office")
    return {key, "Office: a corridor and four rooms", office(), officeRoute(150), officeSecondVisitRoute(40)};
  if (key == "loop")
    return {key, "Building with a loop: a corridor ring around six rooms", loopBuilding(), loopBuildingRoute(300),
            loopBuildingSecondVisitRoute(70)};
  if (key == "rooms20")
    return {key, "Twenty rooms around a loop: a corridor ring, rooms inside and outside it", twentyRoomBuilding(),
            twentyRoomBuildingRoute(600), twentyRoomBuildingSecondVisitRoute(140)};
  if (key == "smallrooms")
    return {key, "Small rooms looked into from the door: a corridor ring, 36 rooms of 3 to 5 m", smallRoomsBuilding(),
            smallRoomsRoute(900), {}};
  if (key == "hall")
    return {key, "A hall larger than the sensors' reach, with rooms and a corridor off it", hallBuilding(),
            hallBuildingRoute(400), {}};
  throw std::invalid_argument("unknown building '" + key + "' (office, loop, rooms20, smallrooms or hall)");
}

std::vector<std::string> buildingKeys() { return {"office", "loop", "rooms20", "smallrooms", "hall"}; }

std::string toString(Sensor sensor) {
  switch (sensor) {
    case Sensor::Laser360: return "laser360";
    case Sensor::Laser180: return "laser180";
    case Sensor::Depth: return "depth";
    case Sensor::Lidar: return "lidar";
  }
  return "?";
}

Sensor sensorFromString(const std::string& name) {
  for (Sensor s : {Sensor::Laser360, Sensor::Laser180, Sensor::Depth, Sensor::Lidar})
    if (toString(s) == name) return s;
  throw std::invalid_argument("unknown sensor '" + name + "' (laser360, laser180, depth or lidar)");
}

std::string describe(Sensor sensor) {
  switch (sensor) {
    case Sensor::Laser360: return "360° laser";
    case Sensor::Laser180: return "forward 180° laser";
    case Sensor::Depth: return "depth camera";
    case Sensor::Lidar: return "64-beam lidar";
  }
  return "?";
}

LaserModel laser360() {
  LaserModel laser = fullTurnLaser(720);
  laser.range_noise = 0.01;
  return laser;
}

LaserModel laser180() {
  LaserModel laser;
  laser.range_noise = 0.01;
  return laser;
}

Lidar lidar() {
  Lidar l;
  l.range_noise = 0.01;
  return l;
}

double sensorHeight(Sensor sensor) {
  switch (sensor) {
    case Sensor::Depth: return depthCamera().height_above_floor;
    case Sensor::Lidar: return lidar().height_above_floor;
    case Sensor::Laser360:
    case Sensor::Laser180: break;
  }
  return 0.0;
}

DepthCamera depthCamera() {
  DepthCamera camera;
  camera.range_noise = 0.01;
  return camera;
}

Places placesAlong(const FloorPlan& plan, const std::vector<Pose2D>& route, double stretch_length) {
  // Each (room, stretch) met along the route becomes a place, numbered in
  // the order of the plan's rooms so that the labels do not depend on the route.
  std::map<std::pair<int, int>, int> place_of_key;
  std::vector<std::pair<int, int>> keys;
  std::vector<int> stretches_of_room(plan.rooms().size(), 1);
  keys.reserve(route.size());
  for (const Pose2D& pose : route) {
    const int room = plan.roomAt(pose.x, pose.y);
    int stretch = 0;
    if (room >= 0 && plan.roomNames()[room].find("corridor") != std::string::npos) {
      const FloorPlan::Room& box = plan.rooms()[room];
      const bool along_x = box.x1 - box.x0 >= box.y1 - box.y0;
      const double start = along_x ? box.x0 : box.y0, length = along_x ? box.x1 - box.x0 : box.y1 - box.y0;
      const int count = std::max(1, static_cast<int>(std::lround(length / stretch_length)));
      stretches_of_room[room] = count;
      const double position = (along_x ? pose.x : pose.y) - start;
      stretch = std::clamp(static_cast<int>(std::floor(position / (length / count))), 0, count - 1);
    }
    keys.emplace_back(room, stretch);
    place_of_key[keys.back()] = 0;
  }
  Places places;
  for (auto& [key, place] : place_of_key) {  // std::map: room -1 first, then the plan's order
    place = static_cast<int>(places.names.size());
    const auto [room, stretch] = key;
    if (room < 0) {
      places.names.push_back("(outside every room)");
      places.is_room.push_back(false);
    } else if (plan.roomNames()[room].find("corridor") != std::string::npos) {
      places.names.push_back(plan.roomNames()[room] + " " + std::to_string(stretch + 1) + "/" +
                             std::to_string(stretches_of_room[room]));
      places.is_room.push_back(false);
    } else {
      places.names.push_back(plan.roomNames()[room]);
      places.is_room.push_back(true);
    }
  }
  for (const auto& key : keys) places.of_pose.push_back(place_of_key.at(key));
  return places;
}

RoomScores scoreRooms(const std::vector<int>& place_of, const std::vector<bool>& is_room,
                      const std::vector<int>& group_of) {
  if (place_of.size() != group_of.size())
    throw std::invalid_argument("scoreRooms: one place and one group per observation expected");
  const auto room = [&](int place) { return place >= 0 && std::size_t(place) < is_room.size() && is_room[place]; };
  std::map<int, std::map<int, int>> groups_of_room;  // room -> group -> observations
  std::map<int, std::map<int, int>> rooms_of_group;  // group -> room -> observations
  for (std::size_t i = 0; i < place_of.size(); ++i) {
    if (!room(place_of[i])) continue;
    ++groups_of_room[place_of[i]][group_of[i]];
    ++rooms_of_group[group_of[i]][place_of[i]];
  }
  RoomScores scores;
  for (const auto& [place, groups] : groups_of_room) {
    ++scores.rooms;
    int total = 0, best = 0, best_group = -1;
    for (const auto& [group, n] : groups) {
      total += n;
      if (n > best) best = n, best_group = group;
    }
    int in_best = 0;
    for (const auto& [other, n] : rooms_of_group.at(best_group)) in_best += n;
    scores.whole += groups.size() == 1;
    scores.pure += groups.size() == 1 && rooms_of_group.at(best_group).size() == 1;
    scores.found += 10 * best >= 9 * total && 10 * best >= 9 * in_best;
  }
  return scores;
}

Eigen::Isometry3d toIsometry(const Pose2D& pose, double z) {
  Eigen::Isometry3d isometry = Eigen::Isometry3d::Identity();
  isometry.translation() << pose.x, pose.y, z;
  isometry.linear() = Eigen::AngleAxisd(pose.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return isometry;
}

std::vector<Eigen::Isometry3d> drift(const std::vector<Eigen::Isometry3d>& truth, std::uint64_t seed) {
  if (truth.empty()) return {};
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Isometry3d> out{truth.front()};
  for (std::size_t k = 1; k < truth.size(); ++k) {
    const Eigen::Isometry3d step = truth[k - 1].inverse() * truth[k];
    const double length = step.translation().norm();
    // Drawn one at a time so that the order, hence the numbers, do not depend on the compiler.
    const double dx = 0.02 * length * unit(rng);
    const double dy = 0.02 * length * unit(rng);
    const double dyaw = (kPi / 180.0) * length * unit(rng);
    out.push_back(out.back() * step * toIsometry({dx, dy, dyaw}));
  }
  return out;
}

std::vector<Eigen::Isometry3d> biasedDrift(const std::vector<Eigen::Isometry3d>& truth, double scale,
                                           double degrees_per_metre) {
  if (truth.empty()) return {};
  std::vector<Eigen::Isometry3d> out{truth.front()};
  for (std::size_t k = 1; k < truth.size(); ++k) {
    Eigen::Isometry3d step = truth[k - 1].inverse() * truth[k];
    const double length = step.translation().head<2>().norm();
    step.translation() *= scale;
    step.rotate(Eigen::AngleAxisd(kPi / 180.0 * degrees_per_metre * length, Eigen::Vector3d::UnitZ()));
    out.push_back(out.back() * step);
  }
  return out;
}

double rmsPositionError(const std::vector<Eigen::Isometry3d>& a, const std::vector<Eigen::Isometry3d>& b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n == 0) return 0.0;
  double sum = 0.0;
  for (std::size_t k = 0; k < n; ++k) sum += (a[k].translation() - b[k].translation()).squaredNorm();
  return std::sqrt(sum / double(n));
}

double adjustedRandIndex(const std::vector<int>& a, const std::vector<int>& b) {
  std::map<std::pair<int, int>, double> table;
  std::map<int, double> rows, cols;
  for (std::size_t i = 0; i < a.size(); ++i) {
    table[{a[i], b[i]}] += 1;
    rows[a[i]] += 1;
    cols[b[i]] += 1;
  }
  const auto pairs = [](double n) { return n * (n - 1) / 2; };
  double index = 0, sum_rows = 0, sum_cols = 0;
  for (const auto& [key, n] : table) index += pairs(n);
  for (const auto& [key, n] : rows) sum_rows += pairs(n);
  for (const auto& [key, n] : cols) sum_cols += pairs(n);
  const double expected = sum_rows * sum_cols / pairs(double(a.size()));
  const double maximum = (sum_rows + sum_cols) / 2;
  return maximum == expected ? 0.0 : (index - expected) / (maximum - expected);
}

}  // namespace obsgroup::sim
