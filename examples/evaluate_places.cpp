// The evidence of docs/places.md: the place label map of simulated buildings
// scored against their true rooms as room-segmentation papers score a
// segmentation, and "which place am I in" for a second visit.
//
//   evaluate_places [--datasets office,loop,rooms20,smallrooms,hall]
//                   [--sensors laser360,laser180,depth] [--poses exact,drift]
//                   [--join-passages on|off] [--output docs/places.md]
//
// Label map: for each true room the place holding most of its floor cells
// (its best match); precision = sum of the overlaps / sum of the best
// matches' cells, recall = sum of the overlaps / sum of the rooms' cells
// (micro-averaged), over the floor cells the places label that lie in a
// visited room. "rooms only" leaves the corridors out of the rooms scored.
// Locate: each pose of the second visit standing in a room is located in
// the map of the first (PlaceMap::locate, 1 m tolerance); it is right when
// the place's scans are mostly of that room.

#include "generated_section.h"
#include "scenarios.h"
#include "to_cloud.h"

#include <obsgroup/observation_grouping.h>
#include <obsgroup/places/place_map.h>

#include <pcl/point_types.h>

#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace obsgroup;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using obsgroup::examples::splitList;
using obsgroup::examples::writeGeneratedSection;

constexpr std::uint64_t kDriftSeed = 7;  // the drift of docs/grouping.md
constexpr double kLocateTolerance = 1.0;

Cloud::ConstPtr cloudOf(const sim::Building& b, const sim::Pose2D& pose, sim::Sensor sensor, std::size_t seed) {
  switch (sensor) {
    case sim::Sensor::Laser360:
      return sim::scanCloud<pcl::PointXYZ>(b.plan, pose, sim::laser360(), seed);
    case sim::Sensor::Laser180:
      return sim::scanCloud<pcl::PointXYZ>(b.plan, pose, sim::laser180(), seed);
    case sim::Sensor::Lidar:
      return sim::lidarCloud<pcl::PointXYZ>(b.plan, pose, sim::lidar(), seed);
    case sim::Sensor::Depth:
      break;
  }
  return sim::depthCloud<pcl::PointXYZ>(b.plan, pose, sim::depthCamera(), seed);
}

struct Score {
  std::string label;
  int places = 0, doors = 0, rooms = 0;
  double precision = 0, recall = 0;            // every visited region (rooms and corridors)
  double room_precision = 0, room_recall = 0;  // rooms only
  double coverage = 0;                         // visited regions' floor cells labelled by a place
  int located = 0, located_right = 0;          // second-visit poses in rooms
  double seconds = 0;
};

/// Micro-averaged precision and recall of the best match of each scored room.
void segmentationScore(const std::map<int, std::map<int, std::size_t>>& overlap,  // room -> place -> cells
                       const std::map<int, std::size_t>& place_cells, const std::map<int, std::size_t>& room_cells,
                       const std::set<int>& scored, double& precision, double& recall) {
  std::size_t hit = 0, matched = 0, truth = 0;
  for (int room : scored) {
    truth += room_cells.count(room) ? room_cells.at(room) : 0;
    const auto it = overlap.find(room);
    if (it == overlap.end()) continue;
    int best = -1;
    std::size_t best_cells = 0;
    for (const auto& [place, cells] : it->second)
      if (cells > best_cells) best = place, best_cells = cells;
    hit += best_cells;
    matched += place_cells.at(best);
  }
  precision = matched ? double(hit) / double(matched) : 0.0;
  recall = truth ? double(hit) / double(truth) : 0.0;
}

Score evaluate(const sim::Building& b, sim::Sensor sensor, bool drifted, bool join_passages) {
  Score s;
  s.label = b.title + "; " + sim::describe(sensor) + ", " + (drifted ? "drifted" : "exact") + " poses";
  const double height = sim::sensorHeight(sensor);
  std::vector<Eigen::Isometry3d> truth;
  for (const auto& pose : b.route) truth.push_back(sim::toIsometry(pose, height));
  const std::vector<Eigen::Isometry3d> poses = drifted ? sim::drift(truth, kDriftSeed) : truth;
  std::vector<Observation<pcl::PointXYZ>> observations;
  for (std::size_t k = 0; k < b.route.size(); ++k) observations.push_back({cloudOf(b, b.route[k], sensor, k), poses[k]});

  const auto start = std::chrono::steady_clock::now();
  ObservationGrouping<pcl::PointXYZ> grouping;
  grouping.setKeepWorldPoints(true);
  for (const auto& o : observations) grouping.addObservation(o.cloud, o.pose);
  Partition partition = grouping.compute();
  const WorldPoints& world = grouping.getWorldPoints();
  const ObservationRegions regions = grouping.getSensedSpaceOverlap().computeRegions(observations, world);
  std::vector<Eigen::Vector3d> sensors;
  for (const auto& o : observations) sensors.push_back(o.pose.translation() - world.origin);
  std::vector<int> ids(partition.groups.size());
  for (std::size_t g = 0; g < ids.size(); ++g) ids[g] = int(g);
  PlaceMap map = buildPlaceMap(regions, world, sensors, partition.groups, ids);
  // As `obsgroup partition` does: groups meeting through a passage joined, their places cut again.
  if (join_passages && !joinThroughPassages(partition, ids, map).empty()) {
    std::iota(ids.begin(), ids.end(), 0);
    map = buildPlaceMap(regions, world, sensors, partition.groups, ids);
  }
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  s.places = int(map.places.size());
  s.doors = int(map.doors.size());

  // The true room of every labelled floor cell (the floor plan's rooms, true frame).
  const auto& names = b.plan.roomNames();
  std::set<int> visited, visited_rooms;
  for (const auto& pose : b.route) {
    const int room = b.plan.roomAt(pose.x, pose.y);
    if (room < 0) continue;
    visited.insert(room);
    if (names[room].find("corridor") == std::string::npos) visited_rooms.insert(room);
  }
  s.rooms = int(visited_rooms.size());
  std::map<int, std::map<int, std::size_t>> overlap;
  std::map<int, std::size_t> place_cells, room_cells, room_floor;
  for (int j = 0; j < map.grid.height; ++j)
    for (int i = 0; i < map.grid.width; ++i) {
      const Eigen::Vector2d c = map.grid.cellCentre(i, j);
      const int room = b.plan.roomAt(c.x(), c.y());
      if (room < 0 || !visited.count(room)) continue;
      const std::size_t k = map.grid.index(i, j);
      if (map.occupancy[k] == Occupancy::Free) ++room_floor[room];
      const int place = map.labels[k];
      if (place < 0) continue;
      ++overlap[room][place];
      ++place_cells[place];
      ++room_cells[room];
    }
  segmentationScore(overlap, place_cells, room_cells, visited, s.precision, s.recall);
  segmentationScore(overlap, place_cells, room_cells, visited_rooms, s.room_precision, s.room_recall);
  std::size_t labelled = 0, floor = 0;
  for (const auto& [room, cells] : room_cells) labelled += cells;
  for (const auto& [room, cells] : room_floor) floor += cells;
  s.coverage = floor ? double(labelled) / double(floor) : 0.0;

  // Locate the second visit (exact poses: the map's frame is the true one).
  if (!drifted && !b.second_visit.empty()) {
    std::vector<int> majority(partition.groups.size(), -1);  // each place's most frequent true room
    for (std::size_t g = 0; g < partition.groups.size(); ++g) {
      std::map<int, int> votes;
      for (int i : partition.groups[g]) ++votes[b.plan.roomAt(b.route[i].x, b.route[i].y)];
      int best = 0;
      for (const auto& [room, count] : votes)
        if (count > best) majority[g] = room, best = count;
    }
    for (const auto& pose : b.second_visit) {
      const int room = b.plan.roomAt(pose.x, pose.y);
      if (room < 0 || !visited_rooms.count(room)) continue;
      ++s.located;
      const Location l = map.locate(Eigen::Vector2d(pose.x, pose.y), kLocateTolerance);
      if (l.place && majority[*l.place] == room) ++s.located_right;
    }
  }
  return s;
}

std::string percent(double v) {
  char text[16];
  std::snprintf(text, sizeof text, "%.1f%%", 100 * v);
  return text;
}

std::string table(const std::vector<Score>& scores) {
  std::ostringstream out;
  out << "| dataset | places | doors | precision | recall | precision, rooms | recall, rooms | floor labelled | "
         "second visit located right | seconds |\n|---|---|---|---|---|---|---|---|---|---|\n";
  double p = 0, r = 0, rp = 0, rr = 0;
  int located = 0, right = 0;
  for (const Score& s : scores) {
    out << "| " << s.label << " | " << s.places << " | " << s.doors << " | " << percent(s.precision) << " | "
        << percent(s.recall) << " | " << percent(s.room_precision) << " | " << percent(s.room_recall) << " | "
        << percent(s.coverage) << " | "
        << (s.located ? std::to_string(s.located_right) + " of " + std::to_string(s.located) : std::string("-"))
        << " | " << std::fixed << std::setprecision(1) << s.seconds << std::defaultfloat << " |\n";
    p += s.precision, r += s.recall, rp += s.room_precision, rr += s.room_recall;
    located += s.located, right += s.located_right;
  }
  const double n = double(std::max<std::size_t>(1, scores.size()));
  out << "| **mean over datasets** | | | **" << percent(p / n) << "** | **" << percent(r / n) << "** | **"
      << percent(rp / n) << "** | **" << percent(rr / n) << "** | | **" << right << " of " << located << "** | |\n";
  return out.str();
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> buildings = sim::buildingKeys();
  std::vector<sim::Sensor> sensors{sim::Sensor::Laser360, sim::Sensor::Laser180, sim::Sensor::Depth};
  std::vector<bool> drift{false};  // drifted maps lie in another frame than the floor plan's rooms
  std::string output;
  bool join_passages = true;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    const bool has_value = a + 1 < argc;
    try {
      if (arg == "--datasets" && has_value) {
        buildings = splitList(argv[++a]);
      } else if (arg == "--sensors" && has_value) {
        sensors.clear();
        for (const auto& name : splitList(argv[++a])) sensors.push_back(sim::sensorFromString(name));
      } else if (arg == "--poses" && has_value) {
        drift.clear();
        for (const auto& name : splitList(argv[++a])) {
          if (name != "exact" && name != "drift") throw std::invalid_argument("'" + name + "' is not exact or drift");
          drift.push_back(name == "drift");
        }
      } else if (arg == "--output" && has_value) {
        output = argv[++a];
      } else if (arg == "--join-passages" && has_value) {
        const std::string v = argv[++a];
        if (v != "on" && v != "off") throw std::invalid_argument("takes on or off, not '" + v + "'");
        join_passages = v == "on";
      } else {
        std::cerr << "usage: " << argv[0]
                  << " [--datasets office,loop,...] [--sensors laser360,laser180,depth] [--poses exact,drift]"
                     " [--join-passages on|off] [--output docs/places.md]\n";
        return 2;
      }
    } catch (const std::exception& e) {
      std::cerr << "error: option " << arg << ": " << e.what() << "\n";
      return 2;
    }
  }
  std::vector<Score> scores;
  for (const std::string& key : buildings) {
    sim::Building building;
    try {
      building = sim::makeBuilding(key);
    } catch (const std::exception& e) {
      std::cerr << "error: option --datasets: " << e.what() << "\n";
      return 2;
    }
    for (sim::Sensor sensor : sensors)
      for (bool drifted : drift) {
        scores.push_back(evaluate(building, sensor, drifted, join_passages));
        const Score& s = scores.back();
        std::cout << s.label << ": " << s.places << " places, " << s.doors << " doors, precision "
                  << percent(s.precision) << ", recall " << percent(s.recall) << " (rooms " << percent(s.room_precision)
                  << ", " << percent(s.room_recall) << "), located " << s.located_right << " of " << s.located
                  << std::endl;
      }
  }
  const std::string report = table(scores);
  if (output.empty()) {
    std::cout << report;
    return 0;
  }
  return writeGeneratedSection(output, report);
}
