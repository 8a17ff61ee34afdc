// Groups joined across open floor: the free space across a step, whether it
// is enclosed by walls the route came near, and the joins themselves.

#include <obsgroup/partition/open_floor.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace obsgroup {
namespace {

constexpr double kCell = 0.2;

/// Walls drawn as segments on cells of kCell.
class Walls {
 public:
  Walls& segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const int steps = int(std::ceil((b - a).norm() / 0.02));
    for (int s = 0; s <= steps; ++s) {
      const Eigen::Vector2d p = a + (double(s) / double(std::max(steps, 1))) * (b - a);
      cells_.insert(cellOf(p));
    }
    return *this;
  }
  /// The outline of the box [x0, x1] x [y0, y1].
  Walls& box(double x0, double y0, double x1, double y1) {
    return segment({x0, y0}, {x1, y0})
        .segment({x1, y0}, {x1, y1})
        .segment({x1, y1}, {x0, y1})
        .segment({x0, y1}, {x0, y0});
  }
  OccupiedAt occupied() const {
    return [this](const Eigen::Vector2d& p) { return cells_.count(cellOf(p)) > 0; };
  }

 private:
  static std::pair<long, long> cellOf(const Eigen::Vector2d& p) {
    return {long(std::floor(p.x() / kCell)), long(std::floor(p.y() / kCell))};
  }
  std::set<std::pair<long, long>> cells_;
};

/// A hall of 16 x 10 m and, through a 1 m door in its east wall, a room of
/// 6 x 10 m.
Walls hallAndRoom() {
  Walls walls;
  walls.box(0, 0, 22, 10);
  walls.segment({16, 0}, {16, 4.5}).segment({16, 5.5}, {16, 10});
  return walls;
}

/// The route along the middle, x = 1 ... 21 every metre, and a partition
/// of it in three: two bands of the hall (x < 8, x < 16) and the room.
struct Route {
  std::vector<Eigen::Vector2d> positions;
  Partition partition;
};
Route alongTheMiddle() {
  Route r;
  std::vector<std::vector<int>> groups(3);
  for (int k = 0; k <= 20; ++k) {
    const double x = 1.0 + k;
    r.positions.emplace_back(x, 5.0);
    const int g = x < 8 ? 0 : x < 16 ? 1 : 2;
    groups[std::size_t(g)].push_back(k);
    r.partition.group_of.push_back(g);
  }
  r.partition.groups = groups;
  return r;
}

TEST(OpenFloor, TheNarrowestChordIsTheFreeSpaceAcross) {
  Walls corridor;
  corridor.box(0, 0, 20, 2);
  const OccupiedAt in_corridor = corridor.occupied();
  // 2 m across, to within a cell at each wall.
  const double across = narrowestChord({5, 1}, {6, 1}, kCell, 10.0, in_corridor);
  EXPECT_NEAR(across, 2.0, 2 * kCell);
  Walls room;
  room.box(0, 0, 10, 10);
  EXPECT_NEAR(narrowestChord({5, 5}, {5, 5}, kCell, 20.0, room.occupied()), 10.0, 2 * kCell);
  // Each side counts up to the cap.
  EXPECT_NEAR(narrowestChord({5, 5}, {5, 5}, kCell, 3.0, room.occupied()), 6.0, 1e-9);
  // A step that passes a door is as narrow as the door.
  const double door = narrowestChord({15, 5}, {17, 5}, kCell, 10.0, hallAndRoom().occupied());
  EXPECT_LT(door, 1.0 + 2 * kCell);
  // A point in a wall has none.
  EXPECT_EQ(narrowestChord({0.05, 5}, {0.05, 5}, kCell, 10.0, room.occupied()), 0.0);
}

TEST(OpenFloor, EnclosedByWallsTheRouteCameNear) {
  const Walls walls = hallAndRoom();
  const SeenAt near_route = [](const Eigen::Vector2d& p) {
    return p.x() >= -7 && p.x() <= 29 && std::abs(p.y() - 5) <= 8;
  };
  EXPECT_TRUE(enclosedAlong({7, 5}, {8, 5}, kCell, 30.0, walls.occupied(), near_route));
  // Walls farther than the reach do not enclose (all 5 m or more away
  // here), nor walls no view came near.
  EXPECT_FALSE(enclosedAlong({7, 5}, {8, 5}, kCell, 4.0, walls.occupied(), near_route));
  EXPECT_FALSE(enclosedAlong({7, 5}, {8, 5}, kCell, 30.0, walls.occupied(),
                             [](const Eigen::Vector2d& p) { return std::abs(p.y() - 5) <= 3; }));
  // Open country: nothing to meet.
  const Walls none;
  EXPECT_FALSE(enclosedAlong({7, 5}, {8, 5}, kCell, 30.0, none.occupied(), near_route));
}

TEST(OpenFloor, AGapInTheWallsNoViewLookedAtLetsAtMostTwoRaysOut) {
  // A forward camera leaves stretches of a hall's walls unseen: a ray that
  // slips out through such a gap meets nothing. A 3 m gap in the south wall
  // lets one or two of the sixteen rays out along the step, and the hall is
  // still enclosed; a 10 m gap lets three or more out, and it is not.
  const SeenAt seen = [](const Eigen::Vector2d&) { return true; };
  const auto hallWithGap = [](double x0, double x1) {
    Walls walls;
    walls.segment({0, 10}, {16, 10}).segment({0, 0}, {0, 10}).segment({16, 0}, {16, 10});
    walls.segment({0, 0}, {x0, 0}).segment({x1, 0}, {16, 0});
    return walls;
  };
  const Walls narrow_gap = hallWithGap(5.5, 8.5), wide_gap = hallWithGap(2.0, 12.0);
  EXPECT_TRUE(enclosedAlong({7, 5}, {8, 5}, kCell, 30.0, narrow_gap.occupied(), seen));
  EXPECT_FALSE(enclosedAlong({7, 5}, {8, 5}, kCell, 30.0, wide_gap.occupied(), seen));
  // A wall beyond the gap that no view came near is not open floor either.
  Walls beyond = hallWithGap(5.5, 8.5);
  beyond.segment({-20, -15}, {36, -15});
  EXPECT_TRUE(enclosedAlong({7, 5}, {8, 5}, kCell, 30.0, beyond.occupied(), seen));
  EXPECT_FALSE(enclosedAlong({7, 5}, {8, 5}, kCell, 30.0, beyond.occupied(),
                             [](const Eigen::Vector2d& p) { return p.y() > -1; }));
}

TEST(OpenFloor, BandsOfAHallAreJoinedAndTheRoomBehindItsDoorIsNot) {
  const Walls walls = hallAndRoom();
  Route r = alongTheMiddle();
  const std::vector<OpenFloorJoin> joins =
      joinAcrossOpenFloor(r.partition, r.positions, 4.5, kCell, walls.occupied(), 6.0);
  ASSERT_EQ(joins.size(), 1u);
  EXPECT_EQ(joins[0].first, 0);
  EXPECT_EQ(joins[0].second, 1);
  EXPECT_GE(joins[0].narrowest, 4.5);
  ASSERT_EQ(r.partition.groups.size(), 2u);
  std::vector<int> hall, room;
  for (int k = 0; k <= 14; ++k) hall.push_back(k);
  for (int k = 15; k <= 20; ++k) room.push_back(k);
  EXPECT_EQ(r.partition.groups[0], hall);
  EXPECT_EQ(r.partition.groups[1], room);
  for (int k = 0; k <= 20; ++k) EXPECT_EQ(r.partition.group_of[std::size_t(k)], k <= 14 ? 0 : 1);
  // Wider than the hall: nothing is joined, the partition stays as it was.
  Route wide = alongTheMiddle();
  EXPECT_TRUE(joinAcrossOpenFloor(wide.partition, wide.positions, 12.0, kCell, walls.occupied(), 6.0).empty());
  EXPECT_EQ(wide.partition.groups.size(), 3u);
}

TEST(OpenFloor, PillarsBetweenTheBandsDoNotNarrowTheFloorAWallDoes) {
  // Two pillars of 0.6 m, 3 m apart, where the route crosses from the first
  // band to the second (x = 8): across the route they leave less than 3 m
  // of free space, but the floor flows round them, and the bands are
  // joined. Two stretches of wall of 1.6 m there instead keep them apart.
  Walls pillars = hallAndRoom();
  pillars.box(7.7, 2.9, 8.3, 3.5).box(7.7, 6.5, 8.3, 7.1);
  EXPECT_LT(narrowestChord({7.5, 5}, {8.5, 5}, kCell, 4.5, pillars.occupied()), 3.0);
  Route r = alongTheMiddle();
  const std::vector<OpenFloorJoin> joins = joinAcrossOpenFloor(r.partition, r.positions, 4.5, kCell, pillars.occupied(), 6.0);
  ASSERT_EQ(joins.size(), 1u);
  EXPECT_EQ(joins[0].first, 0);
  EXPECT_EQ(joins[0].second, 1);
  EXPECT_EQ(r.partition.groups.size(), 2u);

  Walls wall_ends = hallAndRoom();
  wall_ends.segment({8, 1.9}, {8, 3.5}).segment({8, 6.5}, {8, 8.1});
  Route blocked = alongTheMiddle();
  EXPECT_TRUE(joinAcrossOpenFloor(blocked.partition, blocked.positions, 4.5, kCell, wall_ends.occupied(), 6.0).empty());
  EXPECT_EQ(blocked.partition.groups.size(), 3u);
}

TEST(OpenFloor, NothingIsJoinedInOpenCountryOrThroughAnObservationWithoutPosition) {
  const Walls none;
  Route open = alongTheMiddle();
  EXPECT_TRUE(joinAcrossOpenFloor(open.partition, open.positions, 4.5, kCell, none.occupied(), 6.0).empty());
  // The same hall 18 m beyond the route on each side: walls within reach,
  // but no view came near them (4/3 of a 6 m range).
  Walls far;
  far.box(-10, -13, 25, 23);
  Route unseen = alongTheMiddle();
  EXPECT_TRUE(joinAcrossOpenFloor(unseen.partition, unseen.positions, 4.5, kCell, far.occupied(), 6.0).empty());
  // The step between the bands starts at an observation with no point.
  Route gap = alongTheMiddle();
  gap.positions[6] = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  EXPECT_TRUE(joinAcrossOpenFloor(gap.partition, gap.positions, 4.5, kCell, hallAndRoom().occupied(), 6.0).empty());
}

TEST(OpenFloor, BadArgumentsAreRefused) {
  Route r = alongTheMiddle();
  const OccupiedAt occupied = hallAndRoom().occupied();
  std::vector<Eigen::Vector2d> short_list(r.positions.begin(), r.positions.end() - 1);
  EXPECT_THROW(joinAcrossOpenFloor(r.partition, short_list, 4.5, kCell, occupied, 6.0), std::invalid_argument);
  for (double bad : {0.0, -1.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_THROW(joinAcrossOpenFloor(r.partition, r.positions, bad, kCell, occupied, 6.0), std::invalid_argument);
    EXPECT_THROW(joinAcrossOpenFloor(r.partition, r.positions, 4.5, bad, occupied, 6.0), std::invalid_argument);
    EXPECT_THROW(joinAcrossOpenFloor(r.partition, r.positions, 4.5, kCell, occupied, bad), std::invalid_argument);
  }
  EXPECT_EQ(r.partition.groups.size(), 3u);
}

TEST(OpenFloor, JoinGroupsKeepsTheGroupsOrderedAndSaysWhereEachCameFrom) {
  Partition p;
  p.groups = {{0, 4}, {1, 2}, {3, 6}, {5}};
  p.group_of = {0, 1, 1, 2, 0, 3, 2};
  p.warnings = {"kept"};
  const std::vector<int> first_of = joinGroups(p, {{3, 1}, {1, 3}});
  EXPECT_EQ(p.groups, (std::vector<std::vector<int>>{{0, 4}, {1, 2, 5}, {3, 6}}));
  EXPECT_EQ(p.group_of, (std::vector<int>{0, 1, 1, 2, 0, 1, 2}));
  EXPECT_EQ(first_of, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(p.warnings, std::vector<std::string>{"kept"});
  // Through a chain: the set takes the place of its first group.
  EXPECT_EQ(joinGroups(p, {{2, 1}, {0, 2}}), std::vector<int>{0});
  EXPECT_EQ(p.groups, (std::vector<std::vector<int>>{{0, 1, 2, 3, 4, 5, 6}}));
  EXPECT_EQ(p.group_of, std::vector<int>(7, 0));
  EXPECT_THROW(joinGroups(p, {{0, 1}}), std::invalid_argument);
  EXPECT_THROW(joinGroups(p, {{-1, 0}}), std::invalid_argument);
  EXPECT_EQ(joinGroups(p, {}), std::vector<int>{0});
}

}  // namespace
}  // namespace obsgroup
