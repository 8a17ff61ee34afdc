// The scan simulator that the evaluations measure with: its buildings'
// routes are drivable and reach every room, and the room scores count as
// their definitions say.
#include "scenarios.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

using namespace obsgroup::sim;

TEST(Simulator, EveryRouteKeepsClearOfWallsAndReachesEveryRoom) {
  for (const std::string& key : buildingKeys()) {
    const Building building = makeBuilding(key);
    ASSERT_FALSE(building.route.empty()) << key;
    std::set<int> reached;
    for (std::size_t k = 0; k < building.route.size(); ++k) {
      const Pose2D& pose = building.route[k];
      // A robot is wider than a quarter metre: a pose nearer a wall, or
      // inside furniture, would scan nothing but that wall.
      EXPECT_GE(building.plan.clearanceAt(pose.x, pose.y, 0.25), 0.25) << key << " pose " << k << " at " << pose.x
                                                                        << ", " << pose.y;
      const int room = building.plan.roomAt(pose.x, pose.y);
      EXPECT_GE(room, 0) << key << " pose " << k << " is in no room";
      reached.insert(room);
    }
    for (std::size_t r = 0; r < building.plan.rooms().size(); ++r)
      EXPECT_TRUE(reached.count(int(r))) << key << ": " << building.plan.roomNames()[r] << " is never reached";
  }
}

TEST(Simulator, SmallRoomsAreLookedIntoFromTheDoorOnly) {
  const Building building = makeBuilding("smallrooms");
  // No pose is more than 1.6 m past a room's door wall: rooms are looked
  // into, not walked round, as in the Intel lab's log.
  for (const Pose2D& pose : building.route) {
    const int room = building.plan.roomAt(pose.x, pose.y);
    const std::string& name = building.plan.roomNames()[room];
    if (name.find("corridor") != std::string::npos) continue;
    const FloorPlan::Room& box = building.plan.rooms()[room];
    const double to_door_wall = std::min({pose.y - box.y0, box.y1 - pose.y});
    EXPECT_LE(to_door_wall, 1.6) << name;
  }
}

TEST(Simulator, RoomScoresFollowTheirDefinitions) {
  // Places 0 and 1 are rooms, 2 a corridor; -1 has no label.
  const std::vector<bool> is_room{true, true, false};
  // Room 0 whole in group 0 with corridor scans: pure and found. Room 1
  // split 9 : 1 over groups 1 and 2: found (90%), not pure.
  std::vector<int> place{0, 0, 0, 2, 2, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, -1};
  std::vector<int> group{0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2, 2};
  RoomScores s = scoreRooms(place, is_room, group);
  EXPECT_EQ(s.rooms, 2);
  EXPECT_EQ(s.found, 2);
  EXPECT_EQ(s.pure, 1);
  EXPECT_EQ(s.whole, 1);
  // Both rooms in one group: whole, neither pure; room 1 (10 of 13 room
  // scans) is not found, room 0 (3 of 13) neither.
  group.assign(place.size(), 0);
  s = scoreRooms(place, is_room, group);
  EXPECT_EQ(s.whole, 2);
  EXPECT_EQ(s.pure, 0);
  EXPECT_EQ(s.found, 0);
  EXPECT_THROW(scoreRooms(place, is_room, {0, 1}), std::invalid_argument);
}
