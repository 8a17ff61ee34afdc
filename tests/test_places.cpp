// Places: outlines that are valid polygons, doors between neighbours, the
// label grid and "which place holds this pose".
#include "scenarios.h"
#include "test_support.h"

#include <obsgroup/observation_grouping.h>
#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/places/localize.h>
#include <obsgroup/places/place_map.h>

#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <future>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>

namespace obsgroup {
namespace {

/// Whether segments ab and cd cross at a point inside both (touching at an
/// end point, as rings sharing a corner do, is not crossing).
bool properlyCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const auto side = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    const double v = (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x();
    return v > 1e-12 ? 1 : v < -1e-12 ? -1 : 0;
  };
  const int s1 = side(a, b, c), s2 = side(a, b, d), s3 = side(c, d, a), s4 = side(c, d, b);
  if (s1 * s2 < 0 && s3 * s4 < 0) return true;
  // Collinear overlap along a stretch.
  if (s1 == 0 && s2 == 0) {
    const Eigen::Vector2d u = b - a;
    const double t0 = (c - a).dot(u) / u.squaredNorm(), t1 = (d - a).dot(u) / u.squaredNorm();
    return std::max(std::min(t0, t1), 0.0) < std::min(std::max(t0, t1), 1.0) - 1e-9;
  }
  return false;
}

/// Every ring closed (3+ corners), simple (no corner twice, no crossing), and
/// no two rings crossing; outer rings counter-clockwise, holes clockwise, so
/// that the signed areas sum to the place's area.
void expectValidOutline(const Place& place, double cell_area) {
  double area = 0;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> edges;
  for (const auto& ring : place.outline) {
    ASSERT_GE(ring.size(), 4u) << "place " << place.id;  // cell outlines have right angles only
    std::set<std::pair<double, double>> corners;
    for (const auto& p : ring) EXPECT_TRUE(corners.insert({p.x(), p.y()}).second) << "place " << place.id;
    area += twiceSignedArea(ring) / 2;
    for (std::size_t k = 0; k < ring.size(); ++k) edges.push_back({ring[k], ring[(k + 1) % ring.size()]});
  }
  EXPECT_NEAR(area, place.area_m2, 1e-6 * std::max(1.0, place.area_m2)) << "place " << place.id;
  EXPECT_NEAR(std::fmod(place.area_m2 / cell_area + 0.5, 1.0), 0.5, 1e-6);
  for (std::size_t a = 0; a < edges.size(); ++a)
    for (std::size_t b = a + 1; b < edges.size(); ++b)
      ASSERT_FALSE(properlyCross(edges[a].first, edges[a].second, edges[b].first, edges[b].second))
          << "place " << place.id << ": edges " << a << " and " << b << " cross";
}

struct Grouped {
  std::vector<Observation<pcl::PointXYZ>> observations;
  Partition partition;
  WeightMatrix W;
  PlaceMap places;
};

Grouped groupAndPlace(const sim::Building& building, std::size_t every = 1) {
  std::vector<sim::Pose2D> route;
  for (std::size_t k = 0; k < building.route.size(); k += every) route.push_back(building.route[k]);
  Grouped out;
  out.observations = test::simulate<pcl::PointXYZ>(building.plan, route, sim::laser360());
  ObservationGrouping<pcl::PointXYZ> grouping;
  grouping.setKeepWorldPoints(true);
  for (const auto& o : out.observations) grouping.addObservation(o.cloud, o.pose);
  out.partition = grouping.compute();
  out.W = grouping.getWeightMatrix();
  const auto overlap = grouping.getSensedSpaceOverlap();
  const ObservationRegions regions = overlap.computeRegions(out.observations, grouping.getWorldPoints());
  std::vector<Eigen::Vector3d> sensors;
  for (const auto& o : out.observations) sensors.push_back(o.pose.translation() - grouping.getWorldPoints().origin);
  std::vector<int> ids;
  for (std::size_t g = 0; g < out.partition.groups.size(); ++g) ids.push_back(int(100 + g));  // not the indices
  out.places = buildPlaceMap(regions, grouping.getWorldPoints(), sensors, out.partition.groups, ids);
  return out;
}

TEST(Places, TheRegionsTheGroupingKeepsAreThoseItWouldComputeAndGiveTheSameGroups) {
  const sim::Building office = sim::makeBuilding("office");
  const auto observations = test::simulate<pcl::PointXYZ>(office.plan, office.route, sim::laser360());
  ObservationGrouping<pcl::PointXYZ> plain, keeping;
  keeping.setKeepRegions(true);
  keeping.setKeepOverlapMatrix(false);
  for (const auto& o : observations) {
    plain.addObservation(o.cloud, o.pose);
    keeping.addObservation(o.cloud, o.pose);
  }
  EXPECT_EQ(plain.compute().groups, keeping.compute().groups);
  EXPECT_EQ(plain.getWeightMatrix().toDense(), keeping.getWeightMatrix().toDense());
  EXPECT_EQ(plain.getRegions().size(), 0);  // not kept unless asked
  // Pi and the pairs are freed once W stands, unless kept (the default); the statistics stay.
  EXPECT_GT(plain.getOverlap().match_ratio.nonZeros(), 0);
  EXPECT_FALSE(plain.getOverlap().pairs.empty());
  EXPECT_EQ(keeping.getOverlap().match_ratio.nonZeros(), 0);
  EXPECT_TRUE(keeping.getOverlap().pairs.empty());
  EXPECT_EQ(keeping.getOverlap().points_per_observation, plain.getOverlap().points_per_observation);
  EXPECT_EQ(keeping.getOverlap().pairs_evaluated, plain.getOverlap().pairs_evaluated);
  const ObservationRegions again =
      keeping.getSensedSpaceOverlap().computeRegions(observations, keeping.getSensedSpaceOverlap().toWorld(observations));
  EXPECT_TRUE(keeping.getRegions() == again);
  EXPECT_GT(again.totalCells(), 0u);
  // The points model has no regions.
  keeping.setParameters(GroupingParameters::paper());
  keeping.compute();
  EXPECT_EQ(keeping.getRegions().size(), 0);
}

TEST(Places, OutlinesAreValidPolygonsAndDoorsJoinNeighbours) {
  const Grouped g = groupAndPlace(sim::makeBuilding("office"));
  const PlaceMap& map = g.places;
  ASSERT_EQ(map.places.size(), g.partition.groups.size());
  const double cell_area = map.grid.resolution * map.grid.resolution;
  std::map<int, const Place*> by_id;
  double total = 0;
  for (const Place& place : map.places) {
    by_id[place.id] = &place;
    expectValidOutline(place, cell_area);
    total += place.area_m2;
    if (place.area_m2 > 0) {
      // The centroid lies in the bounding box, and the label grid agrees with the area.
      EXPECT_TRUE(place.bbox.contains(place.centroid));
      std::size_t cells = 0;
      for (int l : map.labels) cells += l == place.id;
      EXPECT_NEAR(double(cells) * cell_area, place.area_m2, 1e-9);
      // Its name goes on its own floor, never beside it.
      const Eigen::Vector2i cell = map.grid.cellOf(place.label_point);
      ASSERT_TRUE(map.grid.contains(cell.x(), cell.y()));
      EXPECT_EQ(map.labels[map.grid.index(cell.x(), cell.y())], place.id);
    }
  }
  EXPECT_GT(total, 50.0);  // the office's floor, most of it
  for (const Place& place : map.places)
    for (int n : place.neighbours) {
      ASSERT_TRUE(by_id.count(n));
      const auto& back = by_id[n]->neighbours;
      EXPECT_TRUE(std::binary_search(back.begin(), back.end(), place.id)) << place.id << " and " << n;
    }
  ASSERT_FALSE(map.doors.empty());
  for (const Door& d : map.doors) {
    ASSERT_TRUE(by_id.count(d.place_a) && by_id.count(d.place_b));
    EXPECT_LT(d.place_a, d.place_b);
    const auto& n = by_id[d.place_a]->neighbours;
    EXPECT_TRUE(std::binary_search(n.begin(), n.end(), d.place_b));
    EXPECT_GT(d.width_m, 0.0);
    EXPECT_LE(d.width_m, PlaceOptions{}.max_door_width);
    EXPECT_NEAR((d.end_a - d.end_b).norm(), d.width_m, 1e-9);
    EXPECT_TRUE(d.midpoint.isApprox((d.end_a + d.end_b) / 2));
  }
  // No cell is labelled and not free; occupied cells (walls) hold no place.
  for (std::size_t c = 0; c < map.labels.size(); ++c) {
    if (map.labels[c] >= 0) {
      EXPECT_EQ(map.occupancy[c], Occupancy::Free);
    }
  }
}

TEST(Places, AViewThroughADoorAtASlantIsNotTheCorridorsFloor) {
  // A corridor (y 0 to 2) driven end to end, and a room (x 4 to 9, y 2 to 7)
  // it passes through a 1 m door (x 6 to 7) without entering. Rays crossing
  // the door at more than 45 degrees from its normal are not stopped by it
  // (docs/places.md), so the corridor's scans see fans of the room: floor
  // beyond a neck that none of them stood beyond, which its place drops.
  sim::FloorPlan plan;
  plan.addWallX(0.0, 0.0, 12.0);
  plan.addWallX(2.0, 0.0, 12.0, {{6.0, 7.0}});
  plan.addWallY(0.0, 0.0, 2.0);
  plan.addWallY(12.0, 0.0, 2.0);
  plan.addWallY(4.0, 2.0, 7.0);
  plan.addWallY(9.0, 2.0, 7.0);
  plan.addWallX(7.0, 4.0, 9.0);
  sim::Building corridor;
  corridor.plan = plan;
  for (double x = 0.5; x <= 11.5; x += 0.25) corridor.route.push_back({x, 1.0, 0.0});
  const Grouped g = groupAndPlace(corridor);
  const PlaceMap& map = g.places;
  int corridor_cells = 0, room_cells = 0;
  for (int j = 0; j < map.grid.height; ++j)
    for (int i = 0; i < map.grid.width; ++i) {
      if (map.labels[map.grid.index(i, j)] < 0) continue;
      const double y = map.grid.cellCentre(i, j).y();
      if (y < 2.0) ++corridor_cells;
      if (y > 2.6) ++room_cells;  // more than 0.6 m past the door line
    }
  EXPECT_GT(corridor_cells, 350);  // measured: 409
  // Measured: 72 cells (2.9 m2) of the room before the fans were dropped, 0 after.
  EXPECT_LE(room_cells, 10);
  // Every pose still lies in its own place.
  for (std::size_t k = 0; k < g.partition.groups.size(); ++k)
    for (int i : g.partition.groups[k]) {
      const Eigen::Vector3d p = g.observations[std::size_t(i)].pose.translation();
      const Location at = map.locate(p.head<2>(), 0.0);
      ASSERT_TRUE(at.place) << i;
      EXPECT_EQ(*at.place, map.places[k].id) << i;
    }
}

TEST(Places, LocateReturnsTheOwnPlaceOfMostObservations) {
  const Grouped g = groupAndPlace(sim::makeBuilding("office"));
  std::vector<int> id_of_group;
  for (const Place& p : g.places.places) id_of_group.push_back(p.id);
  int own = 0, located = 0;
  for (std::size_t i = 0; i < g.observations.size(); ++i) {
    const Eigen::Vector2d at = g.observations[i].pose.translation().head<2>();
    const Location l = g.places.locate(at, 1.0);
    if (!l.place) continue;
    ++located;
    own += *l.place == id_of_group[g.partition.group_of[i]];
    if (l.distance_m > 0) {
      EXPECT_LE(l.distance_m, 1.0);
    }
  }
  const int n = int(g.observations.size());
  EXPECT_EQ(located, n);  // every pose lies on sensed floor
  // A scan standing in a doorway joins the group its overlap says, while the
  // floor under it goes to the side holding it most: 2 of the 150 land next door.
  EXPECT_GE(own, 0.95 * n) << own << " of " << n;
  // Far from everything: no place; a tolerance as large as one likes finds the nearest.
  EXPECT_FALSE(g.places.locate(Eigen::Vector2d(1e4, 1e4)).place);
  EXPECT_TRUE(g.places.locate(Eigen::Vector2d(1e4, 1e4), 1e12).place);
  EXPECT_FALSE(g.places.locate(Eigen::Vector2d(1e30, -1e30), 1.0).place);
  EXPECT_FALSE(g.places.locate(Eigen::Vector2d(NAN, 0)).place);
}

/// The simulated office at every `every`-th pose of its route, seen by a
/// 360-degree laser or (three_d) a depth camera, grouped with its regions kept.
struct OfficeRun {
  std::vector<Observation<pcl::PointXYZ>> observations;
  ObservationGrouping<pcl::PointXYZ> grouping;
  Partition partition;
};

void groupOffice(bool three_d, std::size_t every, OfficeRun& run) {
  const sim::Building office = sim::makeBuilding("office");
  std::vector<sim::Pose2D> route;
  for (std::size_t k = 0; k < office.route.size(); k += every) route.push_back(office.route[k]);
  run.observations = three_d ? test::simulate3D<pcl::PointXYZ>(office.plan, route, {-0.5f, 0.0f, 0.5f, 1.5f})
                             : test::simulate<pcl::PointXYZ>(office.plan, route, sim::laser360());
  run.grouping.setKeepRegions(true);
  for (const auto& o : run.observations) run.grouping.addObservation(o.cloud, o.pose);
  run.partition = run.grouping.compute();
}

/// The same places whether the points are held (WorldPoints) or asked for
/// one observation at a time (PlacePointSource), in 2D and in 3D (points
/// above the obstacle band too); a source that throws is rethrown.
TEST(Places, PointsAskedForOneObservationAtATimeGiveTheSamePlaces) {
  for (const bool three_d : {false, true}) {
    OfficeRun run;
    groupOffice(three_d, 3, run);
    const auto& observations = run.observations;
    const auto& grouping = run.grouping;
    const Partition& partition = run.partition;
    const auto& sso = grouping.getSensedSpaceOverlap();
    const WorldPoints world = sso.toWorld(observations);
    const Eigen::Vector3d origin = SensedSpaceOverlap<pcl::PointXYZ>::worldOrigin(observations);
    ASSERT_EQ(origin, world.origin);
    std::vector<Eigen::Vector3d> sensors;
    for (const auto& o : observations) sensors.push_back(o.pose.translation() - origin);
    std::vector<int> ids(partition.groups.size());
    std::iota(ids.begin(), ids.end(), 7);
    const PlaceMap held = buildPlaceMap(grouping.getRegions(), world, sensors, partition.groups, ids);
    std::atomic<int> asked{0};
    const PlacePointSource on_demand = [&](int i, std::vector<Eigen::Vector3f>& scratch) {
      ++asked;
      scratch = sso.observationToWorld(observations[std::size_t(i)], origin);
      return std::make_pair(scratch.data(), scratch.data() + scratch.size());
    };
    const PlaceMap made = buildPlaceMap(grouping.getRegions(), origin, on_demand, sensors, partition.groups, ids);
    EXPECT_EQ(asked.load(), int(observations.size()));  // once each
    ASSERT_GT(held.places.size(), 1u);
    EXPECT_EQ(made.labels, held.labels) << "3D: " << three_d;
    EXPECT_EQ(made.occupancy, held.occupancy) << "3D: " << three_d;
    ASSERT_EQ(made.places.size(), held.places.size());
    for (std::size_t k = 0; k < held.places.size(); ++k) {
      EXPECT_EQ(made.places[k].outline, held.places[k].outline);
      EXPECT_EQ(made.places[k].neighbours, held.places[k].neighbours);
    }
    ASSERT_EQ(made.doors.size(), held.doors.size());
    for (std::size_t k = 0; k < held.doors.size(); ++k) EXPECT_EQ(made.doors[k].midpoint, held.doors[k].midpoint);
    EXPECT_GT(std::count(held.occupancy.begin(), held.occupancy.end(), Occupancy::Occupied), 0);
  }
  OfficeRun run;
  groupOffice(false, 3, run);
  const auto& observations = run.observations;
  const auto& grouping = run.grouping;
  const Partition& partition = run.partition;
  std::vector<Eigen::Vector3d> sensors;
  for (const auto& o : observations) sensors.push_back(o.pose.translation() - observations[0].pose.translation());
  const PlacePointSource failing = [](int i, std::vector<Eigen::Vector3f>&)
      -> std::pair<const Eigen::Vector3f*, const Eigen::Vector3f*> {
    if (i == 5) throw std::runtime_error("scan 5 cannot be read");
    return {nullptr, nullptr};
  };
  std::vector<int> ids(partition.groups.size(), 0);
  std::iota(ids.begin(), ids.end(), 0);
  EXPECT_THROW(buildPlaceMap(grouping.getRegions(), observations[0].pose.translation(), failing, sensors,
                             partition.groups, ids),
               std::runtime_error);
}

TEST(Places, TheSamePlacesForAnyThreadCount) {
  // Each thread takes its share of the groups to find each cell's owner; ties
  // (equal shares) go to the lower group whichever thread saw which.
  for (const bool three_d : {false, true}) {
    OfficeRun run;
    groupOffice(three_d, 2, run);
    const auto& observations = run.observations;
    const auto& grouping = run.grouping;
    const Partition& partition = run.partition;
    const WorldPoints world = grouping.getSensedSpaceOverlap().toWorld(observations);
    std::vector<Eigen::Vector3d> sensors;
    for (const auto& o : observations) sensors.push_back(o.pose.translation() - world.origin);
    // The grouping's groups, and one group per observation: every cell that
    // several observations hold is then a tie.
    std::vector<std::vector<int>> singles(observations.size());
    for (std::size_t i = 0; i < singles.size(); ++i) singles[i] = {int(i)};
    for (const auto& groups : {partition.groups, singles}) {
      std::vector<int> ids(groups.size());
      std::iota(ids.begin(), ids.end(), 0);
      std::vector<PlaceMap> maps;
      const int before = omp_get_max_threads();
      for (const int threads : {1, 2, 3, 5}) {
        omp_set_num_threads(threads);
        maps.push_back(buildPlaceMap(grouping.getRegions(), world, sensors, groups, ids));
      }
      omp_set_num_threads(before);
      ASSERT_GT(maps[0].places.size(), 3u);
      for (std::size_t m = 1; m < maps.size(); ++m) {
        EXPECT_EQ(maps[m].labels, maps[0].labels) << "3D: " << three_d << ", map " << m;
        EXPECT_EQ(maps[m].occupancy, maps[0].occupancy) << "3D: " << three_d;
        ASSERT_EQ(maps[m].places.size(), maps[0].places.size());
        for (std::size_t k = 0; k < maps[0].places.size(); ++k)
          EXPECT_EQ(maps[m].places[k].outline, maps[0].places[k].outline);
        ASSERT_EQ(maps[m].doors.size(), maps[0].doors.size());
        for (std::size_t k = 0; k < maps[0].doors.size(); ++k)
          EXPECT_EQ(maps[m].doors[k].midpoint, maps[0].doors[k].midpoint);
      }
    }
  }
}

/// The places' pass over every beam (observeFloor), made from the regions
/// on another thread while the grouping partitions (its regions callback,
/// as `obsgroup partition` does), gives the same places as buildPlaceMap in
/// one go, with one thread or three; evidence of another band or of other
/// regions is refused, and an interrupt stops the pass.
TEST(Places, FloorEvidenceMadeWhileTheGroupingPartitionsGivesTheSamePlaces) {
  for (const bool three_d : {false, true}) {
    const sim::Building office = sim::makeBuilding("office");
    std::vector<sim::Pose2D> route;
    for (std::size_t k = 0; k < office.route.size(); k += 3) route.push_back(office.route[k]);
    const auto observations = three_d ? test::simulate3D<pcl::PointXYZ>(office.plan, route, {-0.5f, 0.0f, 0.5f, 1.5f})
                                      : test::simulate<pcl::PointXYZ>(office.plan, route, sim::laser360());
    ObservationGrouping<pcl::PointXYZ> grouping;
    grouping.setKeepRegions(true);
    for (const auto& o : observations) grouping.addObservation(o.cloud, o.pose);
    const auto sso = grouping.getSensedSpaceOverlap();
    const Eigen::Vector3d origin = SensedSpaceOverlap<pcl::PointXYZ>::worldOrigin(observations);
    std::vector<Eigen::Vector3d> sensors;
    for (const auto& o : observations) sensors.push_back(o.pose.translation() - origin);
    const PlacePointSource points_of = [&](int i, std::vector<Eigen::Vector3f>& scratch) {
      scratch = sso.observationToWorld(observations[std::size_t(i)], origin);
      return std::make_pair(scratch.data(), scratch.data() + scratch.size());
    };
    int calls = 0;
    const ObservationRegions* seen_regions = nullptr;
    std::future<FloorEvidence> pending;
    grouping.setRegionsCallback([&](const ObservationRegions& regions) {
      ++calls;
      seen_regions = &regions;
      pending = std::async(std::launch::async, [&] { return observeFloor(regions, origin, points_of, sensors, {}, 1); });
    });
    const Partition partition = grouping.compute();
    ASSERT_EQ(calls, 1);
    ASSERT_EQ(seen_regions, &grouping.getRegions());  // the regions it keeps, not a copy
    const FloorEvidence floor = pending.get();
    const ObservationRegions& regions = grouping.getRegions();
    std::vector<int> ids(partition.groups.size());
    std::iota(ids.begin(), ids.end(), 3);
    const PlaceMap whole = buildPlaceMap(regions, sso.toWorld(observations), sensors, partition.groups, ids);
    const PlaceMap from_floor = buildPlaceMap(regions, floor, sensors, partition.groups, ids);
    ASSERT_GT(whole.places.size(), 1u);
    EXPECT_EQ(from_floor.grid.origin, whole.grid.origin);
    EXPECT_EQ(from_floor.labels, whole.labels) << "3D: " << three_d;
    EXPECT_EQ(from_floor.occupancy, whole.occupancy) << "3D: " << three_d;
    ASSERT_EQ(from_floor.places.size(), whole.places.size());
    for (std::size_t k = 0; k < whole.places.size(); ++k)
      EXPECT_EQ(from_floor.places[k].outline, whole.places[k].outline);
    ASSERT_EQ(from_floor.doors.size(), whole.doors.size());
    EXPECT_EQ(observeFloor(regions, origin, points_of, sensors, {}, 3).occupancy, floor.occupancy);
    EXPECT_EQ(floor.occupancy, whole.occupancy);

    PlaceOptions other_band;
    other_band.band_high = 1.2;
    EXPECT_THROW(buildPlaceMap(regions, floor, sensors, partition.groups, ids, other_band), std::invalid_argument);
    ObservationRegions fewer;  // the first half of the observations: another grid
    fewer.planar = regions.planar;
    fewer.cell_size = regions.cell_size;
    fewer.phase = regions.phase;
    for (int i = 0; i < regions.size() / 2; ++i) fewer.append(regions.cellsOf(i));
    const std::vector<Eigen::Vector3d> fewer_sensors(sensors.begin(), sensors.begin() + fewer.size());
    std::vector<std::vector<int>> one_group(1);
    for (int i = 0; i < fewer.size(); ++i) one_group[0].push_back(i);
    EXPECT_THROW(buildPlaceMap(fewer, floor, fewer_sensors, one_group, {0}), std::invalid_argument);
    InterruptFlag stop{true};
    EXPECT_THROW(observeFloor(regions, origin, points_of, sensors, {}, 2, &stop), Interrupted);
  }
}

TEST(Places, BadArgumentsAreRefused) {
  ObservationRegions regions;
  WorldPoints world;
  EXPECT_THROW(buildPlaceMap(regions, world, {Eigen::Vector3d::Zero()}, {}, {}), std::invalid_argument);
  EXPECT_THROW(buildPlaceMap(regions, world, {}, {{0}}, {}), std::invalid_argument);
  EXPECT_THROW(buildPlaceMap(regions, world, {}, {{0}}, {7}), std::invalid_argument);  // no observation 0
  const PlaceMap empty = buildPlaceMap(regions, world, {}, {}, {});
  EXPECT_TRUE(empty.places.empty());
  EXPECT_FALSE(empty.locate(Eigen::Vector2d::Zero()).place);
  // An observation with points but no region cell: no floor, no crash.
  WorldPoints one;
  one.appendAll({{Eigen::Vector3f(1, 2, 0), Eigen::Vector3f(-3, 0.5f, 0)}});
  ObservationRegions no_cells;
  no_cells.append({});
  const PlaceMap bare = buildPlaceMap(no_cells, one, {Eigen::Vector3d::Zero()}, {{0}}, {5});
  ASSERT_EQ(bare.places.size(), 1u);
  EXPECT_EQ(bare.places[0].area_m2, 0.0);
  EXPECT_TRUE(bare.places[0].outline.empty());
  PlaceOptions bad;
  bad.min_piece_area = std::nan("");
  EXPECT_THROW(buildPlaceMap(no_cells, one, {Eigen::Vector3d::Zero()}, {{0}}, {5}, bad), std::invalid_argument);
}

}  // namespace
}  // namespace obsgroup

namespace obsgroup {
namespace {

TEST(Places, LocalizeAlignsAScanToItsPlacesLocalMap) {
  const sim::Building office = sim::makeBuilding("office");
  const Grouped g = groupAndPlace(office);
  LocalMapBuilder<pcl::PointXYZ> builder;
  builder.setVoxelLeafSize(0.05);
  const auto maps = builder.build(g.observations, g.partition, g.W);
  std::vector<int> ids;
  for (const Place& p : g.places.places) ids.push_back(p.id);
  // Scan 60 again, its pose 0.2 m and 3 degrees off.
  const std::size_t k = 60;
  const Eigen::Isometry3d truth = g.observations[k].pose;
  const Eigen::Isometry3d off = Eigen::Translation3d(0.15, -0.13, 0) * truth * Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitZ());
  const Localization l = localize(g.places, maps, ids, *g.observations[k].cloud, off);
  ASSERT_TRUE(l.converged);
  ASSERT_TRUE(l.place && l.initial_place);
  EXPECT_EQ(*l.place, ids[g.partition.group_of[k]]);
  EXPECT_LT((l.pose.translation() - truth.translation()).norm(), 0.03);
  EXPECT_LT(Eigen::AngleAxisd(l.pose.rotation().transpose() * truth.rotation()).angle(), 0.01);
  EXPECT_LT(l.fitness_m2, 0.01);
  // Off every place: nothing to align to.
  const Localization nowhere = localize(g.places, maps, ids, *g.observations[k].cloud,
                                        Eigen::Isometry3d(Eigen::Translation3d(1e3, 1e3, 0)));
  EXPECT_FALSE(nowhere.place);
  EXPECT_FALSE(nowhere.converged);
}

namespace {

/// A corridor 2 m wide and 12 m long, cut across at x = 6 m between places
/// 10 (west) and 20 (east), and a room of 4 x 4 m north of it (place 30)
/// behind a door 1.4 m wide: the cut is a passage, the door is not. The
/// grid's lower-left corner lies at `origin`.
PlaceMap corridorCutAndRoom(const Eigen::Vector2d& origin) {
  PlaceMap map;
  map.grid.resolution = 0.2;
  map.grid.origin = origin;
  map.grid.width = 60;
  map.grid.height = 40;
  const std::size_t cells = std::size_t(map.grid.width) * std::size_t(map.grid.height);
  map.occupancy.assign(cells, Occupancy::Unknown);
  map.labels.assign(cells, -1);
  const auto set = [&](int i, int j, Occupancy o, int label) {
    map.occupancy[map.grid.index(i, j)] = o;
    map.labels[map.grid.index(i, j)] = label;
  };
  for (int i = 0; i < 60; ++i) {
    set(i, 4, Occupancy::Occupied, -1);
    for (int j = 5; j <= 14; ++j) set(i, j, Occupancy::Free, i < 30 ? 10 : 20);
    set(i, 15, Occupancy::Occupied, -1);
  }
  for (int i = 19; i <= 40; ++i)
    for (int j = 15; j <= 36; ++j) {
      const bool wall = i == 19 || i == 40 || j == 36 || (j == 15 && !(i >= 33 && i <= 39));
      set(i, j, wall ? Occupancy::Occupied : Occupancy::Free, wall ? -1 : 30);
    }
  for (int id : {10, 20, 30}) {
    Place place;
    place.id = id;
    map.places.push_back(place);
  }
  const auto door = [&](int a, int b, Eigen::Vector2d end_a, Eigen::Vector2d end_b) {
    Door d;
    d.place_a = a;
    d.place_b = b;
    d.end_a = origin + end_a;
    d.end_b = origin + end_b;
    d.midpoint = (d.end_a + d.end_b) / 2;
    d.width_m = (end_b - end_a).norm();
    return d;
  };
  map.doors = {door(10, 20, {6.0, 1.0}, {6.0, 3.0}), door(20, 30, {6.6, 3.0}, {8.0, 3.0})};
  return map;
}

}  // namespace

TEST(Places, ACorridorCutAcrossIsAPassageADoorIsNot) {
  for (const Eigen::Vector2d& origin : {Eigen::Vector2d(0, 0), Eigen::Vector2d(512345.678901, 5123456.789012)}) {
    const PlaceMap map = corridorCutAndRoom(origin);
    const std::vector<Door> passages = passagesOf(map);
    ASSERT_EQ(passages.size(), 1u) << "origin " << origin.transpose();
    EXPECT_EQ(passages[0].place_a, 10);
    EXPECT_EQ(passages[0].place_b, 20);

    Partition p;
    p.groups = {{0, 1, 5}, {2, 3}, {4}};
    p.group_of = {0, 0, 1, 1, 2, 0};
    std::vector<int> ids{10, 20, 30};
    const std::vector<Door> joined = joinThroughPassages(p, ids, map);
    ASSERT_EQ(joined.size(), 1u);
    EXPECT_EQ(p.groups, (std::vector<std::vector<int>>{{0, 1, 2, 3, 5}, {4}}));
    EXPECT_EQ(p.group_of, (std::vector<int>{0, 0, 0, 0, 1, 0}));
    EXPECT_EQ(ids, (std::vector<int>{10, 30}));
  }
  // The room's door almost as wide as the corridor is still a door: the free
  // space widens on both of its sides.
  PlaceMap wide = corridorCutAndRoom(Eigen::Vector2d::Zero());
  for (int i = 31; i <= 39; ++i) wide.occupancy[wide.grid.index(i, 15)] = Occupancy::Free;
  wide.doors[1].end_a = {6.2, 3.0};
  wide.doors[1].midpoint = (wide.doors[1].end_a + wide.doors[1].end_b) / 2;
  wide.doors[1].width_m = 1.8;
  EXPECT_EQ(passagesOf(wide).size(), 1u);
  // A corridor as narrow as a door is a door.
  PlaceMap narrow = corridorCutAndRoom(Eigen::Vector2d::Zero());
  for (int i = 0; i < 60; ++i)
    for (int j = 5; j <= 9; ++j) narrow.occupancy[narrow.grid.index(i, j)] = Occupancy::Occupied;
  EXPECT_TRUE(passagesOf(narrow).empty());
  std::vector<int> wrong{10, 20};
  Partition p;
  p.groups = {{0}, {1}, {2}};
  p.group_of = {0, 1, 2};
  EXPECT_THROW(joinThroughPassages(p, wrong, narrow), std::invalid_argument);
}

TEST(Places, TheCommandsStepJoinsOneGroupPerPassageItReportsAndNothingWhenOff) {
  // The simulated building with a loop: one of its corridor's cuts is a
  // contact of 2 m or less, and joined. (A real corridor cut across, the shipped office log's, is joined in
  // Cli.PassagesJoinACorridorsGroupsAndOffKeepsThem and, through this
  // function, in the Python module's test_grouping.)
  const sim::Building building = sim::makeBuilding("loop");
  const std::vector<Observation<pcl::PointXYZ>> observations =
      test::simulate<pcl::PointXYZ>(building.plan, building.route, sim::laser360());
  ObservationGrouping<pcl::PointXYZ> grouping;
  for (const auto& o : observations) grouping.addObservation(o.cloud, o.pose);
  const Partition before = grouping.compute();
  Partition after = before;
  const std::vector<Door> joined = joinGroupsThroughPassages(observations, grouping.getParameters(), after);
  EXPECT_FALSE(joined.empty());
  EXPECT_EQ(after.groups.size() + joined.size(), before.groups.size());
  for (const Door& passage : joined)
    EXPECT_EQ(after.group_of[std::size_t(before.groups[std::size_t(passage.place_a)][0])],
              after.group_of[std::size_t(before.groups[std::size_t(passage.place_b)][0])]);
  GroupingParameters off = grouping.getParameters();
  off.join_passages = false;
  Partition untouched = before;
  EXPECT_TRUE(joinGroupsThroughPassages(observations, off, untouched).empty());
  EXPECT_EQ(untouched.groups, before.groups);
}

}  // namespace
}  // namespace obsgroup
