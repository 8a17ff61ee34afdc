#include "floor_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

namespace obsgroup::sim {

namespace {
std::int64_t cellKey(long cx, long cy) {
  return std::int64_t((std::uint64_t(cx) << 32) ^ (std::uint64_t(cy) & 0xffffffffu));  // unsigned: no UB for cx < 0
}
}  // namespace

void FloorPlan::addBox(double x0, double y0, double x1, double y1) {
  const Eigen::Vector2d p00(x0, y0), p10(x1, y0), p11(x1, y1), p01(x0, y1);
  for (const auto& [a, b] : {std::pair{p00, p10}, {p10, p11}, {p11, p01}, {p01, p00}}) {
    segments_.push_back({a, b});
    index(segments_.size() - 1);
  }
}

void FloorPlan::index(std::size_t segment) {
  const Segment& s = segments_[segment];
  const long cx0 = long(std::floor(std::min(s.a.x(), s.b.x()) / kCell)), cx1 = long(std::floor(std::max(s.a.x(), s.b.x()) / kCell));
  const long cy0 = long(std::floor(std::min(s.a.y(), s.b.y()) / kCell)), cy1 = long(std::floor(std::max(s.a.y(), s.b.y()) / kCell));
  for (long cx = cx0; cx <= cx1; ++cx)
    for (long cy = cy0; cy <= cy1; ++cy) cells_[cellKey(cx, cy)].push_back(static_cast<std::uint32_t>(segment));
}

namespace {
/// The solid pieces of [from, to] once the openings are cut out.
std::vector<std::pair<double, double>> solidPieces(double from, double to,
                                                   std::vector<std::pair<double, double>> openings) {
  std::sort(openings.begin(), openings.end());
  std::vector<std::pair<double, double>> pieces;
  double start = from;
  for (const auto& [a, b] : openings) {
    if (a > start) pieces.emplace_back(start, a);
    start = std::max(start, b);
  }
  if (to > start) pieces.emplace_back(start, to);
  return pieces;
}
}  // namespace

void FloorPlan::addWallX(double y, double from, double to, std::vector<std::pair<double, double>> openings,
                         double thickness) {
  for (const auto& [a, b] : solidPieces(from, to, std::move(openings)))
    addBox(a, y - thickness / 2, b, y + thickness / 2);
}

void FloorPlan::addWallY(double x, double from, double to, std::vector<std::pair<double, double>> openings,
                         double thickness) {
  for (const auto& [a, b] : solidPieces(from, to, std::move(openings)))
    addBox(x - thickness / 2, a, x + thickness / 2, b);
}

void FloorPlan::addRoom(std::string name, double x0, double y0, double x1, double y1) {
  rooms_.push_back({x0, y0, x1, y1});
  room_names_.push_back(std::move(name));
}

double FloorPlan::castHorizontal(const Eigen::Vector2d& origin, double angle, double max_distance) const {
  const Eigen::Vector2d dir(std::cos(angle), std::sin(angle));
  const auto hit = [&](const Segment& s) {
    // origin + t dir = a + u (b - a), t > 0, u in [0, 1]
    const Eigen::Vector2d e = s.b - s.a;
    const double den = dir.x() * (-e.y()) - dir.y() * (-e.x());
    if (std::abs(den) < 1e-12) return std::numeric_limits<double>::infinity();
    const Eigen::Vector2d r = s.a - origin;
    const double t = (r.x() * (-e.y()) - r.y() * (-e.x())) / den;
    const double u = (dir.x() * r.y() - dir.y() * r.x()) / den;
    return t > 1e-9 && u >= 0.0 && u <= 1.0 ? t : std::numeric_limits<double>::infinity();
  };
  // Walk the grid cells the ray crosses (Amanatides and Woo); stop at the
  // first cell whose walls give a hit no further than the cell's far edge.
  long cx = long(std::floor(origin.x() / kCell)), cy = long(std::floor(origin.y() / kCell));
  const int step_x = dir.x() > 0 ? 1 : -1, step_y = dir.y() > 0 ? 1 : -1;
  const double inf = std::numeric_limits<double>::infinity();
  const double delta_x = dir.x() != 0 ? kCell / std::abs(dir.x()) : inf;
  const double delta_y = dir.y() != 0 ? kCell / std::abs(dir.y()) : inf;
  double next_x = dir.x() != 0 ? ((cx + (step_x > 0)) * kCell - origin.x()) / dir.x() : inf;
  double next_y = dir.y() != 0 ? ((cy + (step_y > 0)) * kCell - origin.y()) / dir.y() : inf;
  double best = inf;
  for (;;) {
    const auto it = cells_.find(cellKey(cx, cy));
    if (it != cells_.end())
      for (std::uint32_t k : it->second) best = std::min(best, hit(segments_[k]));
    const double leave = std::min(next_x, next_y);
    if (best <= leave || leave > max_distance) break;
    if (next_x < next_y) {
      cx += step_x;
      next_x += delta_x;
    } else {
      cy += step_y;
      next_y += delta_y;
    }
  }
  return best;
}

double LaserModel::beamAngle(std::size_t k, std::size_t count, double heading) const {
  // Evaluated in this order, the angles are bit for bit those of the scans
  // made before full turns existed (the committed datasets stay as they are).
  const double step = full_turn ? field_of_view / count : count > 1 ? field_of_view / (count - 1) : 0.0;
  return heading - field_of_view / 2 + k * step;
}

LaserModel fullTurnLaser(int beams) {
  LaserModel laser;
  laser.beams = beams;
  laser.field_of_view = 2 * 3.14159265358979323846;
  laser.full_turn = true;
  return laser;
}

std::vector<double> FloorPlan::scan(const Pose2D& pose, const LaserModel& laser, std::uint64_t seed) const {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, laser.range_noise > 0 ? laser.range_noise : 1.0);
  std::vector<double> ranges(laser.beams, laser.max_range);
  for (int k = 0; k < laser.beams; ++k) {
    const double best = castHorizontal({pose.x, pose.y}, laser.beamAngle(k, laser.beams, pose.yaw), laser.max_range);
    const double n = laser.range_noise > 0 ? noise(rng) : 0.0;
    if (best < laser.max_range) ranges[k] = std::min(best + n, laser.max_range);
  }
  return ranges;
}

std::vector<Eigen::Vector3d> FloorPlan::depthImage(const Pose2D& pose, const DepthCamera& camera,
                                                   std::uint64_t seed) const {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, camera.range_noise > 0 ? camera.range_noise : 1.0);
  const double f = (camera.width / 2.0) / std::tan(camera.horizontal_fov / 2);
  const double cx = (camera.width - 1) / 2.0, cy = (camera.height - 1) / 2.0;
  const double h = camera.height_above_floor;
  std::vector<Eigen::Vector3d> points;
  for (int u = 0; u < camera.width; ++u) {
    // A pixel column shares one horizontal direction: one 2D cast per column.
    const double lateral = -(u - cx) / f;
    const double wall = castHorizontal({pose.x, pose.y}, pose.yaw + std::atan(lateral), camera.max_range);
    for (int v = 0; v < camera.height; ++v) {
      const Eigen::Vector3d ray = Eigen::Vector3d(1.0, lateral, -(v - cy) / f).normalized();
      double s = wall / ray.head<2>().norm();  // the ray's length to the wall
      const double z = h + s * ray.z();
      if (z < 0.0) s = h / -ray.z();                      // the floor
      else if (z > ceiling_) s = (ceiling_ - h) / ray.z();  // the ceiling
      const double n = camera.range_noise > 0 ? noise(rng) : 0.0;
      if (!(s + n < camera.max_range) || !(s + n > 0)) continue;
      points.push_back(ray * (s + n));
    }
  }
  return points;
}

std::vector<Eigen::Vector3d> FloorPlan::lidarSweep(const Pose2D& pose, const Lidar& lidar, std::uint64_t seed) const {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, lidar.range_noise > 0 ? lidar.range_noise : 1.0);
  const double h = lidar.height_above_floor;
  const double step = lidar.rings > 1 ? (lidar.highest - lidar.lowest) / (lidar.rings - 1) : 0.0;
  std::vector<Eigen::Vector3d> points;
  points.reserve(std::size_t(lidar.rings) * lidar.columns);
  for (int c = 0; c < lidar.columns; ++c) {
    // A column of beams shares one azimuth: one 2D cast per column.
    const double azimuth = 2.0 * 3.14159265358979323846 * c / lidar.columns;
    const double wall = castHorizontal({pose.x, pose.y}, pose.yaw + azimuth, lidar.max_range);
    for (int r = 0; r < lidar.rings; ++r) {
      const double elevation = lidar.lowest + r * step;
      const Eigen::Vector3d ray(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                std::sin(elevation));
      double s = wall / ray.head<2>().norm();
      const double z = h + s * ray.z();
      if (z < 0.0) s = h / -ray.z();
      else if (z > ceiling_) s = (ceiling_ - h) / ray.z();
      const double n = lidar.range_noise > 0 ? noise(rng) : 0.0;
      if (!(s + n < lidar.max_range) || !(s + n > 0)) continue;
      points.push_back(ray * (s + n));
    }
  }
  return points;
}

double FloorPlan::clearanceAt(double x, double y, double max_distance) const {
  double nearest = max_distance;
  for (int degree = 0; degree < 360; ++degree)
    nearest = std::min(nearest, castHorizontal({x, y}, degree * 3.14159265358979323846 / 180.0, max_distance));
  return nearest;
}

int FloorPlan::roomAt(double x, double y) const {
  for (std::size_t r = 0; r < rooms_.size(); ++r)
    if (x >= rooms_[r].x0 && x <= rooms_[r].x1 && y >= rooms_[r].y0 && y <= rooms_[r].y1)
      return static_cast<int>(r);
  return -1;
}

std::vector<Eigen::Vector2d> scanToPoints(const std::vector<double>& ranges, const LaserModel& laser) {
  std::vector<Eigen::Vector2d> points;
  for (std::size_t k = 0; k < ranges.size(); ++k) {
    if (!(ranges[k] < laser.max_range)) continue;
    const double angle = laser.beamAngle(k, ranges.size());
    points.emplace_back(ranges[k] * std::cos(angle), ranges[k] * std::sin(angle));
  }
  return points;
}

std::vector<Pose2D> samplePath(const std::vector<Eigen::Vector2d>& waypoints, double spacing) {
  std::vector<Pose2D> poses;
  double next = 0.0;  // distance from the start of the current segment to the next pose
  for (std::size_t w = 0; w + 1 < waypoints.size(); ++w) {
    const Eigen::Vector2d d = waypoints[w + 1] - waypoints[w];
    const double length = d.norm();
    const double yaw = std::atan2(d.y(), d.x());
    double s = next;
    for (; s < length; s += spacing) {
      const Eigen::Vector2d p = waypoints[w] + d * (s / length);
      poses.push_back({p.x(), p.y(), yaw});
    }
    next = s - length;  // a segment shorter than the spacing carries it over
  }
  return poses;
}

std::vector<Pose2D> evenlySpaced(const std::vector<Eigen::Vector2d>& waypoints, int count) {
  double length = 0.0;
  for (std::size_t w = 0; w + 1 < waypoints.size(); ++w) length += (waypoints[w + 1] - waypoints[w]).norm();
  std::vector<Pose2D> poses = samplePath(waypoints, length / count);
  poses.resize(std::min<std::size_t>(poses.size(), count));
  return poses;
}

FloorPlan threeRooms() {
  FloorPlan plan;
  plan.addWallX(0.0, -0.1, 18.1);
  plan.addWallX(5.0, -0.1, 18.1);
  plan.addWallY(0.0, 0.0, 5.0);
  plan.addWallY(18.0, 0.0, 5.0);
  plan.addWallY(6.0, 0.0, 5.0, {{2.0, 3.0}});
  plan.addWallY(12.0, 0.0, 5.0, {{2.0, 3.0}});
  // Furniture, so that the rooms do not look alike.
  plan.addBox(1.0, 3.8, 2.5, 4.6);
  plan.addBox(9.0, 0.4, 10.5, 1.0);
  plan.addBox(15.5, 3.0, 16.5, 4.0);
  plan.addRoom("west", 0.0, 0.0, 6.0, 5.0);
  plan.addRoom("middle", 6.0, 0.0, 12.0, 5.0);
  plan.addRoom("east", 12.0, 0.0, 18.0, 5.0);
  return plan;
}

std::vector<Pose2D> threeRoomsPoses(int per_room) {
  std::vector<Pose2D> poses;
  for (int room = 0; room < 3; ++room) {
    for (int k = 0; k < per_room; ++k) {
      const double t = (k + 0.5) / per_room;
      poses.push_back({room * 6.0 + 1.5 + 3.0 * t, 1.5 + 2.0 * std::sin(6.28318530718 * t) * 0.5 + 1.0 * t,
                       6.28318530718 * t});
    }
  }
  return poses;
}

FloorPlan office() {
  // Corridor y in [0, 2.5], x in [0, 32]; rooms above it, 8 m wide, 6 m deep.
  FloorPlan plan;
  plan.addWallX(0.0, -0.1, 32.1);
  plan.addWallY(0.0, 0.0, 8.5);
  plan.addWallY(32.0, 0.0, 8.5);
  plan.addWallX(8.5, -0.1, 32.1);
  std::vector<std::pair<double, double>> doors;
  for (int r = 0; r < 4; ++r) doors.emplace_back(r * 8.0 + 3.5, r * 8.0 + 4.5);
  plan.addWallX(2.5, 0.0, 32.0, doors);
  for (int r = 1; r < 4; ++r) plan.addWallY(r * 8.0, 2.5, 8.5);
  // A little furniture per room and a pillar in the corridor.
  // Furniture in the rooms' corners, out of the route's way: a robot does
  // not drive through a cupboard.
  plan.addBox(0.3, 7.6, 2.0, 8.3);
  plan.addBox(14.6, 6.9, 15.6, 8.2);
  plan.addBox(16.6, 7.7, 18.6, 8.3);
  plan.addBox(30.8, 2.8, 31.7, 4.0);
  plan.addBox(15.8, 0.2, 16.2, 0.6);
  plan.addRoom("corridor", 0.0, 0.0, 32.0, 2.5);
  for (int r = 0; r < 4; ++r) plan.addRoom("room " + std::to_string(r + 1), r * 8.0, 2.5, r * 8.0 + 8.0, 8.5);
  return plan;
}

std::vector<Pose2D> officeRoute(int count) {
  std::vector<Eigen::Vector2d> waypoints{{1.0, 1.25}};
  for (int r = 0; r < 4; ++r) {
    const double door = r * 8.0 + 4.0;
    waypoints.insert(waypoints.end(), {{door, 1.25}, {door, 4.0}, {door - 2.5, 5.5}, {door, 7.3},
                                        {door + 2.5, 5.5}, {door, 4.0}, {door, 1.25}});
  }
  waypoints.emplace_back(31.0, 1.25);
  return evenlySpaced(waypoints, count);
}

std::vector<Pose2D> officeSecondVisitRoute(int count) {
  // Run 1 keeps to the corridor's middle (y = 1.25) and goes round each room
  // clockwise on a diamond; this visit keeps to a lane on either side of it
  // (0.4 m clear of the pillar) and goes round a rectangle counter-clockwise.
  constexpr double westwards = 1.7, eastwards = 1.0;
  std::vector<Eigen::Vector2d> waypoints{{31.0, westwards}};
  const auto visit = [&waypoints](int room, double lane) {
    const double door = room * 8.0 + 4.0;
    waypoints.insert(waypoints.end(), {{door, lane}, {door, 3.6}, {door + 2.2, 4.3}, {door + 1.8, 6.8},
                                        {door - 2.2, 6.8}, {door - 2.2, 4.3}, {door, 3.6}, {door, lane}});
  };
  visit(2, westwards);  // room 3
  visit(0, westwards);  // room 1, then back east
  visit(1, eastwards);
  visit(3, eastwards);
  waypoints.emplace_back(31.0, eastwards);
  return evenlySpaced(waypoints, count);
}

FloorPlan longBuilding(double length) {
  FloorPlan plan;
  // Corridor y in [6, 9]; rooms 8 m wide below (y 0..6) and above (y 9..15), one door each.
  const int rooms = std::max(1, static_cast<int>(length / 8.0));
  const double end = rooms * 8.0;
  plan.addWallX(0.0, -0.1, end + 0.1);
  plan.addWallX(15.0, -0.1, end + 0.1);
  plan.addWallY(0.0, 0.0, 15.0);
  plan.addWallY(end, 0.0, 15.0);
  std::vector<std::pair<double, double>> doors;
  for (int r = 0; r < rooms; ++r) doors.emplace_back(r * 8.0 + 3.5, r * 8.0 + 4.5);
  plan.addWallX(6.0, 0.0, end, doors);
  plan.addWallX(9.0, 0.0, end, doors);
  for (int r = 1; r < rooms; ++r) {
    plan.addWallY(r * 8.0, 0.0, 6.0);
    plan.addWallY(r * 8.0, 9.0, 15.0);
  }
  for (int r = 0; r < rooms; ++r) {  // furniture that differs from room to room
    const double x = r * 8.0, shift = (r * 37 % 5) * 0.8;
    plan.addBox(x + 1.0 + shift, 1.0, x + 2.0 + shift, 2.2);
    plan.addBox(x + 5.5 - shift * 0.5, 12.0, x + 6.5 - shift * 0.5, 13.5);
    plan.addRoom("south room " + std::to_string(r + 1), x, 0.0, x + 8.0, 6.0);
    plan.addRoom("north room " + std::to_string(r + 1), x, 9.0, x + 8.0, 15.0);
  }
  plan.addRoom("corridor", 0.0, 6.0, end, 9.0);
  return plan;
}

std::vector<Pose2D> longBuildingRoute(double length, int count) {
  const int rooms = std::max(1, static_cast<int>(length / 8.0));
  std::vector<Eigen::Vector2d> waypoints{{1.0, 7.5}};
  for (int r = 0; r < rooms; ++r) {
    const double door = r * 8.0 + 4.0;
    const double inside = r % 2 ? 12.0 : 3.0, doorway = r % 2 ? 10.0 : 5.0;  // alternate sides
    waypoints.insert(waypoints.end(), {{door, 7.5}, {door, doorway}, {door - 2.0, inside}, {door + 2.0, inside},
                                        {door, doorway}, {door, 7.5}});
  }
  waypoints.emplace_back(rooms * 8.0 - 1.0, 7.5);
  return evenlySpaced(waypoints, count);
}

FloorPlan loopBuilding() {
  FloorPlan plan;
  // Outer walls.
  plan.addWallX(0.0, -0.1, 40.1);
  plan.addWallX(26.0, -0.1, 40.1);
  plan.addWallY(0.0, 0.0, 26.0);
  plan.addWallY(40.0, 0.0, 26.0);
  // The block of rooms inside the ring: doors on its south and north walls.
  const double xs[] = {3.0, 14.33, 25.67, 37.0};
  std::vector<std::pair<double, double>> doors;
  for (int r = 0; r < 3; ++r) doors.emplace_back((xs[r] + xs[r + 1]) / 2 - 0.5, (xs[r] + xs[r + 1]) / 2 + 0.5);
  plan.addWallX(3.0, 2.9, 37.1, doors);
  plan.addWallX(23.0, 2.9, 37.1, doors);
  plan.addWallY(3.0, 3.0, 23.0);
  plan.addWallY(37.0, 3.0, 23.0);
  plan.addWallX(13.0, 3.0, 37.0);  // between the south and north rooms
  for (int r = 1; r < 3; ++r) plan.addWallY(xs[r], 3.0, 23.0);
  // Furniture so that rooms and corridor stretches differ.
  // (in the rooms' corners, out of the route's way)
  plan.addBox(3.4, 11.4, 5.0, 12.6);
  plan.addBox(23.8, 3.3, 25.3, 4.3);
  plan.addBox(35.5, 10.5, 36.6, 12.6);
  plan.addBox(3.4, 13.4, 5.0, 14.4);
  plan.addBox(22.5, 20.0, 24.5, 21.5);
  plan.addBox(35.3, 13.4, 36.6, 15.0);
  plan.addBox(19.8, 0.2, 20.2, 0.6);
  plan.addBox(39.2, 12.8, 39.8, 13.2);
  plan.addBox(19.8, 25.4, 20.2, 25.8);
  for (int r = 0; r < 3; ++r) {
    plan.addRoom("south room " + std::to_string(r + 1), xs[r], 3.0, xs[r + 1], 13.0);
    plan.addRoom("north room " + std::to_string(r + 1), xs[r], 13.0, xs[r + 1], 23.0);
  }
  plan.addRoom("south corridor", 0.0, 0.0, 40.0, 3.0);
  plan.addRoom("north corridor", 0.0, 23.0, 40.0, 26.0);
  plan.addRoom("west corridor", 0.0, 3.0, 3.0, 23.0);
  plan.addRoom("east corridor", 37.0, 3.0, 40.0, 23.0);
  return plan;
}

std::vector<Pose2D> loopBuildingRoute(int count) {
  const double xs[] = {3.0, 14.33, 25.67, 37.0};
  std::vector<Eigen::Vector2d> waypoints{{1.5, 1.5}};
  for (int r = 0; r < 3; ++r) {  // eastwards along the south corridor, into each south room
    const double door = (xs[r] + xs[r + 1]) / 2;
    waypoints.insert(waypoints.end(), {{door, 1.5}, {door, 5.0}, {door - 3.0, 8.0}, {door, 11.5},
                                        {door + 3.0, 8.0}, {door, 5.0}, {door, 1.5}});
  }
  waypoints.emplace_back(38.5, 1.5);
  waypoints.emplace_back(38.5, 24.5);
  for (int r = 2; r >= 0; --r) {  // westwards along the north corridor, into each north room
    const double door = (xs[r] + xs[r + 1]) / 2;
    waypoints.insert(waypoints.end(), {{door, 24.5}, {door, 21.0}, {door + 3.0, 18.0}, {door, 14.5},
                                        {door - 3.0, 18.0}, {door, 21.0}, {door, 24.5}});
  }
  waypoints.emplace_back(1.5, 24.5);
  waypoints.emplace_back(1.5, 1.5);  // back where it started: the loop closes
  waypoints.emplace_back(6.0, 1.5);
  return evenlySpaced(waypoints, count);
}

std::vector<Pose2D> loopBuildingSecondVisitRoute(int count) {
  // Run 1 keeps to the corridors' middles and walks a diamond in each room;
  // this visit keeps 0.4 to 0.5 m to one side and walks rectangles the other way,
  // bent round the table of north room 2.
  const double xs[] = {3.0, 14.33, 25.67, 37.0};
  const auto door = [&xs](int room) { return (xs[room] + xs[room + 1]) / 2; };
  std::vector<Eigen::Vector2d> waypoints{{1.9, 13.0}};
  const auto north = [&waypoints](double x, double lane) {
    waypoints.insert(waypoints.end(), {{x, lane}, {x, 21.5}, {x - 3.8, 20.5}, {x - 3.5, 15.0}, {x + 3.5, 15.5},
                                        {x + 2.5, 18.5}, {x, 21.5}, {x, lane}});
  };
  const auto south = [&waypoints](double x, double lane) {
    waypoints.insert(waypoints.end(), {{x, lane}, {x, 4.5}, {x + 3.8, 5.5}, {x + 3.5, 11.0}, {x - 3.5, 10.5},
                                        {x - 3.8, 5.5}, {x, 4.5}, {x, lane}});
  };
  waypoints.emplace_back(1.9, 24.1);  // north, then clockwise round the ring
  north(door(1), 24.1);
  north(door(2), 24.1);
  waypoints.emplace_back(38.0, 24.1);
  waypoints.emplace_back(38.0, 1.9);
  south(door(2), 1.9);
  south(door(0), 1.9);
  south(door(1), 1.1);  // back east, then all the way west and up to north room 1
  waypoints.emplace_back(1.1, 1.1);
  waypoints.emplace_back(1.1, 24.9);
  north(door(0), 24.9);
  return evenlySpaced(waypoints, count);
}

namespace {

/// One room of twentyRoomBuilding(): x0..x1 along the ring, its door wall
/// on the ring at y = front, its back wall at y = back, the door centred at
/// x = door.
struct RingRoom {
  double x0, x1, front, back, door;
};

/// The twenty rooms, row by row from west to east: south outer row, the
/// block's south and north rows, north outer row. Widths and door places
/// differ so that no two rooms look alike.
std::vector<RingRoom> twentyRooms() {
  std::vector<RingRoom> rooms;
  const auto row = [&rooms](std::vector<double> walls, std::vector<double> doors, double front, double back) {
    for (std::size_t r = 0; r + 1 < walls.size(); ++r) rooms.push_back({walls[r], walls[r + 1], front, back, doors[r]});
  };
  row({0, 10, 16, 25, 30, 38, 46}, {4.0, 13.0, 22.5, 27.5, 35.0, 41.5}, 8.0, 0.0);
  row({3, 13, 21, 33, 43}, {7.0, 18.0, 26.0, 39.0}, 11.0, 20.0);
  row({3, 10, 22, 33, 43}, {6.0, 15.0, 29.0, 37.5}, 29.0, 20.0);
  row({0, 8, 18, 23, 32, 38, 46}, {3.5, 12.0, 20.5, 28.0, 34.0, 42.0}, 32.0, 40.0);
  return rooms;
}

/// How far inside its walls the route goes round a room of twentyRooms();
/// furniture stays at least 0.9 m clear of that loop.
constexpr double kRoomLoopInset = 1.6;

/// Through the door, once round the room `inset` metres inside its walls,
/// and back out to the corridor's lane at `corridor_y`.
void visitRingRoom(const RingRoom& r, double corridor_y, bool clockwise, double inset,
                   std::vector<Eigen::Vector2d>& waypoints) {
  const double inward = r.back > r.front ? 1.0 : -1.0;
  const double x0 = r.x0 + inset, x1 = r.x1 - inset;
  const double near_y = r.front + inward * inset, far_y = r.back - inward * inset;
  const Eigen::Vector2d door(r.door, corridor_y), entry(r.door, near_y);
  std::vector<Eigen::Vector2d> loop{{x1, near_y}, {x1, far_y}, {x0, far_y}, {x0, near_y}};
  if (clockwise) std::reverse(loop.begin(), loop.end());
  waypoints.push_back(door);
  waypoints.push_back(entry);
  waypoints.insert(waypoints.end(), loop.begin(), loop.end());
  waypoints.push_back(entry);
  waypoints.push_back(door);
}

/// The rooms in the order twentyRoomBuildingRoute() enters them: those onto
/// the south corridor eastwards, then those onto the north one westwards.
std::vector<const RingRoom*> runOneOrder(const std::vector<RingRoom>& rooms) {
  std::vector<const RingRoom*> order;
  for (bool south : {true, false}) {
    std::vector<const RingRoom*> side;
    for (const RingRoom& r : rooms)
      if ((r.front < 20.0) == south) side.push_back(&r);
    std::sort(side.begin(), side.end(), [south](const RingRoom* a, const RingRoom* b) {
      return south ? a->door < b->door : a->door > b->door;
    });
    order.insert(order.end(), side.begin(), side.end());
  }
  return order;
}

/// Run 1 goes round its k-th room clockwise and counter-clockwise in turn,
/// clockwise first.
bool runOneClockwise(std::size_t k) { return k % 2 == 0; }

}  // namespace

FloorPlan twentyRoomBuilding() {
  FloorPlan plan;
  // Outer walls, 46 x 40 m.
  plan.addWallX(0.0, -0.1, 46.1);
  plan.addWallX(40.0, -0.1, 46.1);
  plan.addWallY(0.0, 0.0, 40.0);
  plan.addWallY(46.0, 0.0, 40.0);
  const std::vector<RingRoom> rooms = twentyRooms();
  // Door walls: the outer rows face the ring at y = 8 and y = 32, the block
  // at y = 11 and y = 29; the block's rows meet at y = 20.
  for (double front : {8.0, 11.0, 29.0, 32.0}) {
    std::vector<std::pair<double, double>> doors;
    for (const RingRoom& r : rooms)
      if (r.front == front) doors.emplace_back(r.door - 0.5, r.door + 0.5);
    const bool block = front == 11.0 || front == 29.0;
    plan.addWallX(front, block ? 2.9 : 0.0, block ? 43.1 : 46.0, doors);
  }
  plan.addWallX(20.0, 3.0, 43.0);
  plan.addWallY(3.0, 11.0, 29.0);
  plan.addWallY(43.0, 11.0, 29.0);
  for (const RingRoom& r : rooms) {  // walls between neighbours
    const bool west_end = r.x0 == 0.0 || r.x0 == 3.0;
    if (!west_end) plan.addWallY(r.x0, std::min(r.front, r.back), std::max(r.front, r.back));
  }

  // Furniture, different in every room and at least 0.9 m clear of the
  // route's loop (kRoomLoopInset): a cupboard against the back wall, a
  // shelf against one side wall and, where the loop leaves room, a table in
  // the middle.
  for (std::size_t k = 0; k < rooms.size(); ++k) {
    const RingRoom& r = rooms[k];
    const double inward = r.back > r.front ? 1.0 : -1.0;  // from the door wall towards the back
    const double width = r.x1 - r.x0, depth = std::abs(r.back - r.front);
    const double cupboard = std::min(width - 1.0, 1.2 + double(k * 7 % 5) * 0.4);
    const double cupboard_x = r.x0 + 0.3 + (width - 0.6 - cupboard) * double(k * 3 % 7) / 6.0;
    const double back_face = r.back - inward * 0.15, back_depth = 0.45 + 0.05 * double(k % 3);
    plan.addBox(cupboard_x, std::min(back_face, back_face - inward * back_depth), cupboard_x + cupboard,
                std::max(back_face, back_face - inward * back_depth));
    const double shelf = 1.0 + 0.5 * double(k % 3);
    const double shelf_y = r.front + inward * (1.2 + (depth - 2.4 - shelf) * double(k * 5 % 4) / 3.0);
    const double side_x = k % 2 ? r.x1 - 0.15 - 0.5 : r.x0 + 0.15;
    const double shelf_end = shelf_y + inward * shelf;
    plan.addBox(side_x, std::min(shelf_y, shelf_end), side_x + 0.5, std::max(shelf_y, shelf_end));
    const double loop_width = width - 2 * kRoomLoopInset, loop_depth = depth - 2 * kRoomLoopInset;
    if (loop_width >= 3.0 && loop_depth >= 3.0) {
      const double half_x = std::min(loop_width / 2 - 0.9, 0.5 + 0.2 * double(k % 4));
      const double half_y = std::min(loop_depth / 2 - 0.9, 0.4 + 0.15 * double(k % 3));
      const double cx = (r.x0 + r.x1) / 2, cy = (r.front + r.back) / 2;
      plan.addBox(cx - half_x, cy - half_y, cx + half_x, cy + half_y);
    }
  }
  // Pillars and a bench along the ring, clear of the doors and the route.
  plan.addBox(19.0, 8.3, 19.4, 8.7);
  plan.addBox(45.3, 17.0, 45.8, 19.5);
  plan.addBox(24.8, 31.3, 25.2, 31.7);
  plan.addBox(0.2, 24.0, 0.6, 24.4);

  for (std::size_t k = 0; k < rooms.size(); ++k) {
    const RingRoom& r = rooms[k];
    plan.addRoom("room " + std::to_string(k + 1), r.x0, std::min(r.front, r.back), r.x1, std::max(r.front, r.back));
  }
  plan.addRoom("south corridor", 0.0, 8.0, 46.0, 11.0);
  plan.addRoom("north corridor", 0.0, 29.0, 46.0, 32.0);
  plan.addRoom("west corridor", 0.0, 11.0, 3.0, 29.0);
  plan.addRoom("east corridor", 43.0, 11.0, 46.0, 29.0);
  return plan;
}

std::vector<Pose2D> twentyRoomBuildingRoute(int count) {
  const std::vector<RingRoom> rooms = twentyRooms();
  std::vector<Eigen::Vector2d> waypoints;
  constexpr double south_y = 9.5, north_y = 30.5, west_x = 1.5, east_x = 44.5;
  waypoints.emplace_back(west_x, south_y);
  const std::vector<const RingRoom*> order = runOneOrder(rooms);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const bool south = order[k]->front < 20.0;
    if (!south && order[k - 1]->front < 20.0) {  // up the east corridor
      waypoints.emplace_back(east_x, south_y);
      waypoints.emplace_back(east_x, north_y);
    }
    visitRingRoom(*order[k], south ? south_y : north_y, runOneClockwise(k), kRoomLoopInset, waypoints);
  }
  waypoints.emplace_back(west_x, north_y);
  waypoints.emplace_back(west_x, south_y);  // back where it started: the loop closes
  waypoints.emplace_back(8.0, south_y);
  return evenlySpaced(waypoints, count);
}

std::vector<Pose2D> twentyRoomBuildingSecondVisitRoute(int count) {
  const std::vector<RingRoom> rooms = twentyRooms();
  const std::vector<const RingRoom*> run_one = runOneOrder(rooms);
  // Clockwise round the ring in lanes 0.4 m off run 1's, each room entered
  // the other way round than run 1 and 0.4 m further from its walls (the
  // furniture leaves 0.9 m round run 1's loop, so 0.5 m round this one).
  constexpr double south_y = 9.9, north_y = 30.1, west_x = 1.9, east_x = 44.1, inset = kRoomLoopInset + 0.4;
  std::vector<Eigen::Vector2d> waypoints{{west_x, 20.0}, {west_x, north_y}};
  std::vector<std::size_t> order(run_one.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = order.size() - 1 - k;  // run 1's, reversed
  bool turned = false;
  for (std::size_t k : order) {
    const bool south = run_one[k]->front < 20.0;
    if (south && !turned) {
      waypoints.emplace_back(east_x, north_y);
      waypoints.emplace_back(east_x, south_y);
      turned = true;
    }
    visitRingRoom(*run_one[k], south ? south_y : north_y, !runOneClockwise(k), inset, waypoints);
  }
  waypoints.emplace_back(west_x, south_y);
  waypoints.emplace_back(west_x, 20.0);  // back where it started
  return evenlySpaced(waypoints, count);
}

}  // namespace obsgroup::sim

namespace obsgroup::sim {

namespace {

/// A small room of smallRoomsBuilding(): x0..x1 along the corridor, its
/// door wall at y = front, its back wall at y = back, its door centred at x = door.
struct SmallRoom {
  double x0, x1, front, back, door;
};

/// Four rows of small rooms (3 to 5 m wide, 3.5 to 4.5 m deep), as in the
/// Intel lab: the outer rows face the ring from outside, the block's rows
/// from inside. Widths and doors differ so that no two rooms look alike.
std::vector<SmallRoom> smallRooms() {
  std::vector<SmallRoom> rooms;
  const auto row = [&rooms](std::vector<double> walls, double front, double back) {
    for (std::size_t r = 0; r + 1 < walls.size(); ++r) {
      const double x0 = walls[r], x1 = walls[r + 1];
      // The door near one end or the middle, in turn.
      const double offset = r % 3 == 0 ? 0.9 : r % 3 == 1 ? (x1 - x0) / 2 : x1 - x0 - 0.9;
      rooms.push_back({x0, x1, front, back, x0 + offset});
    }
  };
  row({0, 4, 8.5, 12, 16, 21, 25, 28.5, 33, 36, 40}, 4.0, 0.0);       // south outer row
  row({3, 7, 11.5, 15, 19.5, 24, 27.5, 32, 37}, 6.5, 10.5);           // block, facing south
  row({3, 6.5, 11, 15, 18.5, 23, 27, 32.5, 37}, 19.5, 15.0);          // block, facing north
  row({0, 3.5, 8, 12.5, 16, 20, 24.5, 28, 32, 36, 40}, 22.0, 26.0);   // north outer row
  return rooms;
}

}  // namespace

FloorPlan smallRoomsBuilding() {
  FloorPlan plan;
  plan.addWallX(0.0, -0.1, 40.1);
  plan.addWallX(26.0, -0.1, 40.1);
  plan.addWallY(0.0, 0.0, 26.0);
  plan.addWallY(40.0, 0.0, 26.0);
  const std::vector<SmallRoom> rooms = smallRooms();
  for (double front : {4.0, 6.5, 19.5, 22.0}) {
    std::vector<std::pair<double, double>> doors;
    for (const SmallRoom& r : rooms)
      if (r.front == front) doors.emplace_back(r.door - 0.5, r.door + 0.5);
    const bool block = front == 6.5 || front == 19.5;
    plan.addWallX(front, block ? 2.9 : 0.0, block ? 37.1 : 40.0, doors);
  }
  // The block's closed middle (labs with no door onto the ring) and its ends.
  plan.addWallX(10.5, 3.0, 37.0);
  plan.addWallX(15.0, 3.0, 37.0);
  plan.addWallY(3.0, 6.5, 19.5);
  plan.addWallY(37.0, 6.5, 19.5);
  for (const SmallRoom& r : rooms)
    if (r.x0 != 0.0 && r.x0 != 3.0) plan.addWallY(r.x0, std::min(r.front, r.back), std::max(r.front, r.back));
  // A desk or a cupboard in every room, against its back wall.
  for (std::size_t k = 0; k < rooms.size(); ++k) {
    const SmallRoom& r = rooms[k];
    const double inward = r.back > r.front ? 1.0 : -1.0;
    const double width = std::min(r.x1 - r.x0 - 1.2, 1.0 + 0.3 * double(k % 4));
    const double x = k % 2 ? r.x0 + 0.3 : r.x1 - 0.3 - width;
    const double face = r.back - inward * 0.15, depth = 0.5 + 0.1 * double(k % 3);
    plan.addBox(x, std::min(face, face - inward * depth), x + width, std::max(face, face - inward * depth));
  }
  for (std::size_t k = 0; k < rooms.size(); ++k) {
    const SmallRoom& r = rooms[k];
    plan.addRoom("room " + std::to_string(k + 1), r.x0, std::min(r.front, r.back), r.x1, std::max(r.front, r.back));
  }
  plan.addRoom("south corridor", 0.0, 4.0, 40.0, 6.5);
  plan.addRoom("north corridor", 0.0, 19.5, 40.0, 22.0);
  plan.addRoom("west corridor", 0.0, 6.5, 3.0, 19.5);
  plan.addRoom("east corridor", 37.0, 6.5, 40.0, 19.5);
  return plan;
}

std::vector<Pose2D> smallRoomsRoute(int count) {
  const std::vector<SmallRoom> rooms = smallRooms();
  std::vector<Eigen::Vector2d> waypoints;
  // Into the doorway and a step inside, turning to face the room's ends,
  // then back out: the room is looked into, never walked round.
  const auto look_into = [&waypoints](const SmallRoom& r, double lane) {
    const double inward = r.back > r.front ? 1.0 : -1.0;
    const double step = r.front + inward * 1.1, deeper = r.front + inward * 1.5;
    const double left = std::max(r.x0 + 0.7, r.door - 0.8), right = std::min(r.x1 - 0.7, r.door + 0.8);
    waypoints.insert(waypoints.end(), {{r.door, lane}, {r.door, step}, {left, deeper}, {right, deeper},
                                        {r.door, step}, {r.door, lane}});
  };
  constexpr double south_y = 5.25, north_y = 20.75, west_x = 1.5, east_x = 38.5;
  std::vector<const SmallRoom*> south, north;
  for (const SmallRoom& r : rooms) (r.front < 13.0 ? south : north).push_back(&r);
  std::sort(south.begin(), south.end(), [](const SmallRoom* a, const SmallRoom* b) { return a->door < b->door; });
  std::sort(north.begin(), north.end(), [](const SmallRoom* a, const SmallRoom* b) { return a->door > b->door; });
  waypoints.emplace_back(west_x, south_y);
  for (const SmallRoom* r : south) look_into(*r, south_y);
  waypoints.emplace_back(east_x, south_y);
  waypoints.emplace_back(east_x, north_y);
  for (const SmallRoom* r : north) look_into(*r, north_y);
  waypoints.emplace_back(west_x, north_y);
  waypoints.emplace_back(west_x, south_y);  // the loop closes
  return evenlySpaced(waypoints, count);
}

FloorPlan hallBuilding() {
  FloorPlan plan;
  // A 24 x 16 m hall (x 0..24, y 0..16), four 6 x 5 m rooms off its north
  // side, a 3 m corridor along its east side with two rooms beyond it.
  plan.addWallX(0.0, -0.1, 33.1);
  plan.addWallX(21.0, -0.1, 33.1);
  plan.addWallY(0.0, 0.0, 21.0);
  plan.addWallY(33.0, 0.0, 21.0);
  plan.addWallX(16.0, 0.0, 24.0, {{2.5, 3.5}, {9.0, 10.0}, {14.5, 15.5}, {20.0, 21.0}});
  for (double x : {6.0, 12.0, 18.0}) plan.addWallY(x, 16.0, 21.0);
  plan.addWallY(24.0, 0.0, 21.0, {{7.0, 9.0}, {17.5, 18.5}});  // a wide opening onto the corridor, a door to room 4
  plan.addWallY(27.0, 0.0, 21.0, {{3.5, 4.5}, {12.5, 13.5}});
  plan.addWallX(9.0, 27.0, 33.0);
  // Pillars and benches in the hall, a cupboard in each room.
  for (double x : {6.0, 12.0, 18.0})
    for (double y : {5.5, 10.5}) plan.addBox(x - 0.25, y - 0.25, x + 0.25, y + 0.25);
  plan.addBox(1.0, 0.3, 3.5, 0.8);
  plan.addBox(16.3, 15.2, 18.7, 15.7);
  plan.addBox(0.3, 19.5, 1.8, 20.7);
  plan.addBox(10.5, 20.2, 11.7, 20.7);
  plan.addBox(12.3, 16.3, 13.0, 17.8);
  plan.addBox(22.0, 20.2, 23.7, 20.7);
  plan.addBox(31.5, 1.0, 32.7, 3.5);
  plan.addBox(29.0, 20.2, 31.5, 20.7);
  plan.addRoom("hall", 0.0, 0.0, 24.0, 16.0);
  for (int k = 0; k < 4; ++k) plan.addRoom("room " + std::to_string(k + 1), 6.0 * k, 16.0, 6.0 * (k + 1), 21.0);
  plan.addRoom("east corridor", 24.0, 0.0, 27.0, 21.0);
  plan.addRoom("room 5", 27.0, 0.0, 33.0, 9.0);
  plan.addRoom("room 6", 27.0, 9.0, 33.0, 21.0);
  return plan;
}

std::vector<Pose2D> hallBuildingRoute(int count) {
  std::vector<Eigen::Vector2d> waypoints;
  // Lanes across the hall (x 1.5 to 22.5, every 3.5 m of y), clear of the pillars.
  const double lanes[] = {2.0, 8.0, 13.0};
  for (int k = 0; k < 3; ++k) {
    const bool east = k % 2 == 0;
    waypoints.emplace_back(east ? 1.5 : 22.5, lanes[k]);
    waypoints.emplace_back(east ? 22.5 : 1.5, lanes[k]);
  }
  // Round each north room (through its door at x = 3, 9.5, 15, 20.5).
  for (double door : {3.0, 9.5, 15.0, 20.5}) {
    const double x0 = std::floor(door / 6.0) * 6.0;
    waypoints.insert(waypoints.end(), {{door, 14.5}, {door, 17.2}, {x0 + 4.6, 17.4}, {x0 + 4.6, 19.6},
                                        {x0 + 2.2, 19.6}, {x0 + 1.4, 17.4}, {door, 17.2}, {door, 14.5}});
  }
  // Out into the corridor, down it with a look into each of its rooms, and back.
  waypoints.insert(waypoints.end(), {{22.5, 8.0}, {25.5, 8.0}, {25.5, 18.0}, {25.5, 13.0}, {28.5, 13.0},
                                      {31.5, 11.0}, {31.5, 18.5}, {28.5, 18.5}, {28.5, 13.0}, {25.5, 13.0},
                                      {25.5, 4.0}, {28.5, 4.0}, {31.0, 6.5}, {28.5, 7.5}, {28.5, 4.0},
                                      {25.5, 4.0}, {25.5, 8.0}, {22.5, 8.0}, {12.0, 8.0}});
  return evenlySpaced(waypoints, count);
}

}  // namespace obsgroup::sim
