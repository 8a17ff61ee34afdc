// Online grouping: after any sequence of inserts, pose updates and removals,
// the groups and W equal a from-scratch ObservationGrouping::compute() on the
// observations present; untouched groups keep their ids.

#include "scenarios.h"
#include "test_support.h"

#include <obsgroup/online_grouping.h>

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace obsgroup {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

/// The simulated office, 360-degree laser, with drifted poses (as a SLAM
/// front end gives them: the visibility model's occupancy then differs
/// between observations, so inserts reach other observations' regions).
std::vector<Observation<pcl::PointXYZ>> driftedOffice(int count = 77) {
  auto obs = test::simulate<pcl::PointXYZ>(sim::office(), sim::officeRoute(count), sim::laser360());
  std::vector<Eigen::Isometry3d> truth;
  for (const auto& o : obs) truth.push_back(o.pose);
  const auto drifted = sim::drift(truth, 7);
  for (std::size_t k = 0; k < obs.size(); ++k) obs[k].pose = drifted[k];
  return obs;
}

ObservationGrouping<pcl::PointXYZ> batchLike(SensedSpaceModel model) {
  ObservationGrouping<pcl::PointXYZ> batch;
  batch.setSensedSpaceModel(model);
  return batch;
}

/// W and the groups of `online` equal a batch run on its observations.
void expectEqualsBatch(const OnlineGrouping<pcl::PointXYZ>& online, ObservationGrouping<pcl::PointXYZ> batch,
                       const std::string& when) {
  SCOPED_TRACE(when);
  batch.clear();
  for (const auto& o : online.getObservations()) batch.addObservation(o.cloud, o.pose);
  const Partition expected = batch.compute();
  const WeightMatrix& W = online.getWeightMatrix();
  const WeightMatrix& B = batch.getWeightMatrix();
  ASSERT_EQ(W.rows(), B.rows());
  ASSERT_EQ(W.nonZeros(), B.nonZeros());
  for (int k = 0; k < W.outerSize(); ++k) {
    WeightMatrix::InnerIterator a(W, k), b(B, k);
    for (; a && b; ++a, ++b) {
      ASSERT_EQ(a.row(), b.row()) << "column " << k;
      ASSERT_EQ(a.value(), b.value()) << "W(" << a.row() << ", " << k << ")";  // bit for bit
    }
  }
  EXPECT_EQ(online.getPartition().groups, expected.groups);
  ASSERT_EQ(online.getPartition().splits.size(), expected.splits.size());
  for (std::size_t s = 0; s < expected.splits.size(); ++s) {
    EXPECT_EQ(online.getPartition().splits[s].members, expected.splits[s].members);
    if (std::isfinite(expected.splits[s].ncut)) {
      EXPECT_EQ(online.getPartition().splits[s].ncut, expected.splits[s].ncut);
    }
  }
  // The id view agrees with the position view.
  const std::vector<int> ids = online.getIds();
  std::size_t members = 0;
  for (const auto& [group, list] : online.getGroups()) {
    members += list.size();
    for (int id : list) EXPECT_EQ(online.getGroupOf(id), group);
  }
  EXPECT_EQ(members, ids.size());
}

class OnlineEqualsBatch : public ::testing::TestWithParam<SensedSpaceModel> {};

TEST_P(OnlineEqualsBatch, AfterEveryInsertInLogOrder) {
  const auto obs = driftedOffice();
  OnlineGrouping<pcl::PointXYZ> online;
  online.setSensedSpaceModel(GetParam());
  for (std::size_t k = 0; k < obs.size(); ++k) {
    EXPECT_EQ(online.insert(obs[k].cloud, obs[k].pose), int(k));
    online.update();
    if (k % 4 == 3 || k + 1 == obs.size()) expectEqualsBatch(online, batchLike(GetParam()), "insert " + std::to_string(k));
  }
}

TEST_P(OnlineEqualsBatch, AfterPoseUpdatesAndRemovals) {
  const auto obs = driftedOffice();
  OnlineGrouping<pcl::PointXYZ> online;
  online.setSensedSpaceModel(GetParam());
  for (const auto& o : obs) online.insert(o.cloud, o.pose);
  online.update();
  expectEqualsBatch(online, batchLike(GetParam()), "all inserted");
  // A loop closure moves a stretch of the route by a few decimetres.
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  correction.translate(Eigen::Vector3d(0.3, -0.2, 0.0));
  correction.rotate(Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitZ()));
  for (int k = 40; k < 60; ++k) online.updatePose(k, correction * obs[k].pose);
  online.update();
  expectEqualsBatch(online, batchLike(GetParam()), "poses updated");
  for (int id : {12, 13, 50, 76}) online.remove(id);
  online.update();
  expectEqualsBatch(online, batchLike(GetParam()), "removed");
  online.remove(0);  // the first observation: the common frame moves to observation 1
  online.updatePose(1, correction * obs[1].pose);
  online.update();
  expectEqualsBatch(online, batchLike(GetParam()), "first removed, new first moved");
  EXPECT_EQ(online.insert(obs[0].cloud, obs[0].pose), 77);  // ids are never reused
  online.update();
  expectEqualsBatch(online, batchLike(GetParam()), "re-inserted");
}

INSTANTIATE_TEST_SUITE_P(Models, OnlineEqualsBatch,
                         ::testing::Values(SensedSpaceModel::Visibility, SensedSpaceModel::FreeSpace,
                                           SensedSpaceModel::Points),
                         [](const auto& info) {
                           std::string name = toString(info.param);
                           name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
                           return name;
                         });

TEST(OnlineGrouping, CloudsIn3DEqualBatch) {
  // 3D clouds (walls at several heights): visibility works in the band about
  // the sensor, free space in voxels. Then a planar scan arrives among them.
  auto obs = test::simulate3D<pcl::PointXYZ>(sim::office(), sim::officeRoute(30), {-0.5f, 0.0f, 0.4f, 1.2f});
  for (SensedSpaceModel model : {SensedSpaceModel::Visibility, SensedSpaceModel::FreeSpace}) {
    OnlineGrouping<pcl::PointXYZ> online;
    online.setSensedSpaceModel(model);
    for (std::size_t k = 0; k < obs.size(); ++k) {
      online.insert(obs[k].cloud, obs[k].pose);
      online.update();
    }
    expectEqualsBatch(online, batchLike(model), "3D " + toString(model));
    online.remove(0);
    online.remove(1);
    online.update();
    expectEqualsBatch(online, batchLike(model), "3D, first two removed " + toString(model));
  }
}

TEST(OnlineGrouping, FromPlanarTo3DAndBack) {
  // 2D scans, then one 3D cloud: the data is no longer planar, every region
  // is recomputed in 3D; removing the cloud makes it planar again.
  const auto flat = driftedOffice(20);
  const auto tall = test::simulate3D<pcl::PointXYZ>(sim::office(), sim::officeRoute(20), {0.0f, 1.0f});
  OnlineGrouping<pcl::PointXYZ> online;
  online.setSensedSpaceModel(SensedSpaceModel::FreeSpace);
  for (const auto& o : flat) online.insert(o.cloud, o.pose);
  online.update();
  const int id = online.insert(tall[7].cloud, tall[7].pose);
  online.update();
  expectEqualsBatch(online, batchLike(SensedSpaceModel::FreeSpace), "one 3D cloud");
  online.remove(id);
  online.update();
  expectEqualsBatch(online, batchLike(SensedSpaceModel::FreeSpace), "planar again");
}

TEST(OnlineGrouping, PaperMethodEqualsBatch) {
  const auto obs = driftedOffice(40);
  OnlineGrouping<pcl::PointXYZ> online;
  online.usePaperMethod();
  ObservationGrouping<pcl::PointXYZ> batch;
  batch.usePaperMethod();
  for (const auto& o : obs) online.insert(o.cloud, o.pose);
  online.update();
  expectEqualsBatch(online, batch, "paper");
}

TEST(OnlineGrouping, FewMutualNeighboursEqualBatchAfterEveryInsert) {
  // With k this small every row of W is cut to its nearest neighbours, and
  // k itself grows with the median as the map does: an insert then moves
  // the thresholds of rows it adds no entry to, whose nodes must be solved
  // again for the groups to stay the batch's.
  GroupingParameters params;
  params.mutual_neighbours = 4;
  params.mutual_neighbours_share = 0.25;
  const auto obs = driftedOffice();
  OnlineGrouping<pcl::PointXYZ> online;
  online.setParameters(params);
  ObservationGrouping<pcl::PointXYZ> batch;
  batch.setParameters(params);
  for (std::size_t k = 0; k < obs.size(); ++k) {
    online.insert(obs[k].cloud, obs[k].pose);
    online.update();
    expectEqualsBatch(online, batch, "insert " + std::to_string(k));
  }
  // The mutual neighbours changed the groups here, so the check above had something to check.
  ObservationGrouping<pcl::PointXYZ> every_overlap;
  params.mutual_neighbours = 0;
  params.mutual_neighbours_share = 0.0;
  every_overlap.setParameters(params);
  for (const auto& o : obs) every_overlap.addObservation(o.cloud, o.pose);
  EXPECT_NE(every_overlap.compute().groups, online.getPartition().groups);
}

TEST(OnlineGrouping, HallBandsJoinedAcrossOpenFloorAsInTheBatch) {
  // The simulated hall is four times the regions' range: its bands are
  // joined across open floor, by the batch and by every exact update.
  const auto obs = test::simulate<pcl::PointXYZ>(sim::hallBuilding(), sim::hallBuildingRoute(160), sim::laser360());
  ObservationGrouping<pcl::PointXYZ> batch;
  for (const auto& o : obs) batch.addObservation(o.cloud, o.pose);
  const Partition joined = batch.compute();
  ASSERT_FALSE(batch.getOpenFloorJoins().empty());
  GroupingParameters unjoined_params;
  unjoined_params.open_floor_width = 0.0;
  ObservationGrouping<pcl::PointXYZ> unjoined;
  unjoined.setParameters(unjoined_params);
  for (const auto& o : obs) unjoined.addObservation(o.cloud, o.pose);
  EXPECT_GT(unjoined.compute().groups.size(), joined.groups.size());
  EXPECT_TRUE(unjoined.getOpenFloorJoins().empty());
  OnlineGrouping<pcl::PointXYZ> online;
  for (std::size_t k = 0; k < obs.size(); ++k) {
    online.insert(obs[k].cloud, obs[k].pose);
    online.update();
    if (k % 20 == 19 || k + 1 == obs.size())
      expectEqualsBatch(online, ObservationGrouping<pcl::PointXYZ>(), "insert " + std::to_string(k));
  }
  EXPECT_EQ(online.getPartition().groups, joined.groups);
  // The same joins, between the same groups of the split tree, as the batch reports.
  ASSERT_EQ(online.getOpenFloorJoins().size(), batch.getOpenFloorJoins().size());
  for (std::size_t j = 0; j < batch.getOpenFloorJoins().size(); ++j) {
    EXPECT_EQ(online.getOpenFloorJoins()[j].first, batch.getOpenFloorJoins()[j].first);
    EXPECT_EQ(online.getOpenFloorJoins()[j].second, batch.getOpenFloorJoins()[j].second);
  }
}

TEST(OnlineGrouping, ReportsChangesAndKeepsIdsOfUntouchedGroups) {
  const auto obs = driftedOffice();
  OnlineGrouping<pcl::PointXYZ> online;
  for (const auto& o : obs) online.insert(o.cloud, o.pose);
  GroupUpdate first = online.update();
  ASSERT_GT(online.getGroups().size(), 2u);
  EXPECT_EQ(first.changes.size(), online.getGroups().size());
  for (const auto& c : first.changes) EXPECT_EQ(c.kind, GroupChange::Kind::Created);
  const auto before = online.getGroups();

  // Nothing changed: nothing is recomputed, nothing reported.
  GroupUpdate idle = online.update();
  EXPECT_TRUE(idle.changes.empty());
  EXPECT_EQ(idle.observations_recomputed, 0u);
  EXPECT_EQ(idle.split_nodes_computed, 0u);
  EXPECT_EQ(online.getGroups(), before);

  // A scan 1 km away overlaps nothing: one group is created, the others keep ids and members.
  Eigen::Isometry3d far = obs[5].pose;
  far.translation().x() += 1000.0;
  const int id = online.insert(obs[5].cloud, far);
  GroupUpdate added = online.update();
  ASSERT_EQ(added.changes.size(), 1u);
  EXPECT_EQ(added.changes[0].kind, GroupChange::Kind::Created);
  EXPECT_EQ(added.changes[0].members, std::vector<int>{id});
  for (const auto& [group, members] : before) EXPECT_EQ(online.getGroups().at(group), members);
  EXPECT_EQ(added.observations_recomputed, 1u);

  // Removing it removes its group.
  online.remove(id);
  GroupUpdate removed = online.update();
  ASSERT_EQ(removed.changes.size(), 1u);
  EXPECT_EQ(removed.changes[0].kind, GroupChange::Kind::Removed);
  EXPECT_EQ(online.getGroups(), before);
}

TEST(OnlineGrouping, ViewsClosedByTheirOwnPointsAreNotRecomputedWhenOthersFlipCells) {
  // Visibility: a 360-degree scan has a point of its own along every ray, so
  // its view reads none of the shared occupancy and an insert that flips
  // cells near it leaves it alone. A forward laser's views read the shared
  // occupancy behind the robot: they are recomputed. Both stay equal to batch.
  std::size_t recomputed[2] = {0, 0};
  const sim::LaserModel lasers[2] = {sim::laser360(), sim::laser180()};
  for (int l = 0; l < 2; ++l) {
    auto obs = test::simulate<pcl::PointXYZ>(sim::office(), sim::officeRoute(60), lasers[l]);
    std::vector<Eigen::Isometry3d> truth;
    for (const auto& o : obs) truth.push_back(o.pose);
    const auto drifted = sim::drift(truth, 7);
    OnlineGrouping<pcl::PointXYZ> online;
    for (std::size_t k = 0; k + 1 < obs.size(); ++k) online.insert(obs[k].cloud, drifted[k]);
    online.update();
    online.insert(obs.back().cloud, drifted.back());
    recomputed[l] = online.update().observations_recomputed;
    expectEqualsBatch(online, batchLike(SensedSpaceModel::Visibility), lasers[l].full_turn ? "360" : "180");
  }
  EXPECT_EQ(recomputed[0], 1u);  // the new scan alone
  EXPECT_GT(recomputed[1], 1u);
}

TEST(OnlineGrouping, ForwardLaserViewsEqualBatchAfterEveryInsert) {
  // A forward laser's views read the shared occupancy behind the robot, and
  // an insert recomputes only those whose rays (and the door-width runs
  // beside them) reach a flipped cell: W stays the batch's, bit for bit.
  auto obs = test::simulate<pcl::PointXYZ>(sim::office(), sim::officeRoute(77), sim::laser180());
  std::vector<Eigen::Isometry3d> truth;
  for (const auto& o : obs) truth.push_back(o.pose);
  const auto drifted = sim::drift(truth, 7);
  OnlineGrouping<pcl::PointXYZ> online;
  std::size_t recomputed_others = 0;
  for (std::size_t k = 0; k < obs.size(); ++k) {
    online.insert(obs[k].cloud, drifted[k]);
    recomputed_others += online.update().observations_recomputed - 1;
    if (k % 4 == 3 || k + 1 == obs.size())
      expectEqualsBatch(online, batchLike(SensedSpaceModel::Visibility), "insert " + std::to_string(k));
  }
  EXPECT_GT(recomputed_others, 0u);  // the views behind the robot were recomputed
}

TEST(OnlineGrouping, LoopClosureRepartitionsOnlyTheGroupsItTouches) {
  // A long building, points model: a row of W changes only for the moved
  // observations and the ones they overlap.
  const auto obs = test::simulate<pcl::PointXYZ>(sim::longBuilding(300.0), sim::longBuildingRoute(300.0, 300),
                                                 sim::fullTurnLaser(180));
  OnlineGrouping<pcl::PointXYZ> online;
  online.setSensedSpaceModel(SensedSpaceModel::Points);
  for (const auto& o : obs) online.insert(o.cloud, o.pose);
  online.update();
  const auto before = online.getGroups();
  const WeightMatrix W_before = online.getWeightMatrix();
  ASSERT_GT(before.size(), 4u);

  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  correction.translate(Eigen::Vector3d(0.05, 0.04, 0.0));
  std::set<int> touched;
  for (int k = 100; k < 150; ++k) {
    online.updatePose(k, correction * obs[k].pose);
    touched.insert(k);
  }
  const GroupUpdate update = online.update();
  // The observations whose row can change: the moved ones and their partners, before or after.
  for (const WeightMatrix* W : {&W_before, &online.getWeightMatrix()})
    for (int k = 100; k < 150; ++k)
      for (WeightMatrix::InnerIterator it(*W, k); it; ++it) touched.insert(int(it.row()));
  std::size_t nodes_touched = 0;
  for (const SplitNode& node : online.getPartition().splits) {
    bool hit = false;
    for (int m : node.members) hit = hit || touched.count(m);
    nodes_touched += hit;
  }
  EXPECT_LE(update.split_nodes_computed, nodes_touched);
  EXPECT_EQ(update.split_nodes_computed + update.split_nodes_reused, online.getPartition().splits.size());
  EXPECT_GT(update.split_nodes_reused, 0u);
  EXPECT_EQ(update.observations_recomputed, 50u);
  // Groups away from the closure keep their ids and members.
  std::size_t kept = 0;
  for (const auto& [group, members] : before) {
    bool away = true;
    for (int m : members) away = away && !touched.count(m);
    if (!away) continue;
    ASSERT_TRUE(online.getGroups().count(group)) << "group " << group;
    EXPECT_EQ(online.getGroups().at(group), members);
    ++kept;
  }
  EXPECT_GT(kept, 0u) << before.size() << " groups, " << touched.size() << " observations touched, "
                      << update.split_nodes_computed << " of " << online.getPartition().splits.size()
                      << " split nodes computed";
  expectEqualsBatch(online, batchLike(SensedSpaceModel::Points), "loop closure");
}

TEST(OnlineGrouping, LocalUpdatesBetweenExactOnes) {
  const auto obs = driftedOffice();
  OnlineGrouping<pcl::PointXYZ> online;
  online.setExactInterval(10);
  int exact = 0;
  for (std::size_t k = 0; k < obs.size(); ++k) {
    online.insert(obs[k].cloud, obs[k].pose);
    const GroupUpdate update = online.update();
    // Every observation in exactly one group, whatever the mode.
    std::vector<int> seen;
    for (const auto& [group, members] : online.getGroups()) seen.insert(seen.end(), members.begin(), members.end());
    std::sort(seen.begin(), seen.end());
    EXPECT_EQ(seen, online.getIds());
    ASSERT_EQ(online.getPartition().group_of.size(), k + 1);
    if (update.exact) {
      ++exact;
      expectEqualsBatch(online, ObservationGrouping<pcl::PointXYZ>(), "exact update " + std::to_string(k));
    } else {
      EXPECT_TRUE(online.getPartition().splits.empty());
    }
  }
  EXPECT_EQ(exact, 1 + 76 / 10);  // the first update, then every 10 inserts
  const GroupUpdate last = online.updateExact();
  EXPECT_TRUE(last.exact);
  expectEqualsBatch(online, ObservationGrouping<pcl::PointXYZ>(), "updateExact");
}

// Local updates around removals and moves: the group an observation left is
// re-partitioned, every observation stays in exactly one group, groups far
// from the change keep their members, and moving the first observation (a
// new common frame) makes the next update exact.
TEST(OnlineGrouping, LocalUpdatesAroundRemovalsAndMoves) {
  const auto obs = driftedOffice();
  OnlineGrouping<pcl::PointXYZ> online;
  online.setExactInterval(1000);
  for (const auto& o : obs) online.insert(o.cloud, o.pose);
  ASSERT_TRUE(online.update().exact);  // the first update is exact
  const auto everyone_once = [&online](const std::string& when) {
    std::vector<int> seen;
    for (const auto& [group, members] : online.getGroups()) seen.insert(seen.end(), members.begin(), members.end());
    std::sort(seen.begin(), seen.end());
    EXPECT_EQ(seen, online.getIds()) << when;
  };

  // Remove one observation: a local update; the groups that do not hold it
  // and do not overlap it keep their members.
  const int removed = 40;
  int home = -1;
  for (const auto& [group, members] : online.getGroups())
    if (std::find(members.begin(), members.end(), removed) != members.end()) home = group;
  ASSERT_GE(home, 0);
  const auto before = online.getGroups();
  const WeightMatrix W = online.getWeightMatrix();
  std::set<int> touching{home};
  for (WeightMatrix::InnerIterator it(W, removed); it; ++it)
    for (const auto& [group, members] : before)
      if (std::find(members.begin(), members.end(), int(it.row())) != members.end()) touching.insert(group);
  online.remove(removed);
  EXPECT_FALSE(online.update().exact);
  everyone_once("after the removal");
  const auto after = online.getGroups();
  for (const auto& [group, members] : before) {
    if (touching.count(group)) continue;
    ASSERT_TRUE(after.count(group)) << "group " << group << " far from the removal lost its id";
    EXPECT_EQ(after.at(group), members) << "group " << group << " far from the removal changed";
  }

  // Move an observation a little: local again.
  Eigen::Isometry3d moved = obs[10].pose;
  moved.translation().x() += 0.05;
  online.updatePose(10, moved);
  EXPECT_FALSE(online.update().exact);
  everyone_once("after a move");

  // Move the first observation: the common frame changes, the update is exact.
  Eigen::Isometry3d first = obs[0].pose;
  first.translation().y() += 0.05;
  online.updatePose(0, first);
  EXPECT_TRUE(online.update().exact);
  expectEqualsBatch(online, ObservationGrouping<pcl::PointXYZ>(), "after moving the first observation");
}

TEST(OnlineGrouping, SameResultWhateverTheThreadCount) {
  const auto obs = driftedOffice(50);
  std::vector<std::map<int, std::vector<int>>> groups;
  std::vector<WeightMatrix> weights;
  for (int threads : {1, 2, 3}) {
    OnlineGrouping<pcl::PointXYZ> online;
    online.setNumberOfThreads(threads);
    for (const auto& o : obs) {
      online.insert(o.cloud, o.pose);
      online.update();
    }
    groups.push_back(online.getGroups());
    weights.push_back(online.getWeightMatrix());
  }
  for (std::size_t k = 1; k < groups.size(); ++k) {
    EXPECT_EQ(groups[k], groups[0]);
    EXPECT_EQ((weights[k] - weights[0]).norm(), 0.0);
  }
}

TEST(OnlineGrouping, BadInputThrowsNamingTheIdAndChangesNothing) {
  const auto obs = driftedOffice(10);
  OnlineGrouping<pcl::PointXYZ> online;
  for (int k = 0; k < 5; ++k) online.insert(obs[k].cloud, obs[k].pose);
  online.update();
  const auto groups = online.getGroups();

  try {
    online.insert(nullptr, obs[5].pose);
    FAIL() << "a null cloud was accepted";
  } catch (const InvalidObservation& e) {
    EXPECT_EQ(e.index(), 5);
    EXPECT_NE(std::string(e.what()).find("observation 5"), std::string::npos);
  }
  Eigen::Isometry3d nan_pose = obs[5].pose;
  nan_pose.translation().x() = std::nan("");
  try {
    online.insert(obs[5].cloud, nan_pose);
    FAIL() << "a NaN pose was accepted";
  } catch (const InvalidObservation& e) {
    EXPECT_EQ(e.index(), 5);
  }
  EXPECT_THROW(online.updatePose(2, nan_pose), InvalidObservation);
  EXPECT_THROW(online.updatePose(0, nan_pose), InvalidObservation);
  EXPECT_THROW(online.updatePose(42, obs[0].pose), std::out_of_range);
  EXPECT_THROW(online.remove(42), std::out_of_range);

  EXPECT_EQ(online.getIds(), (std::vector<int>{0, 1, 2, 3, 4}));
  const GroupUpdate nothing = online.update();
  EXPECT_TRUE(nothing.changes.empty());
  EXPECT_EQ(online.getGroups(), groups);
  EXPECT_EQ(online.insert(obs[5].cloud, obs[5].pose), 5);  // the failed calls took no id
  online.update();
  expectEqualsBatch(online, ObservationGrouping<pcl::PointXYZ>(), "after bad input");
}

}  // namespace
}  // namespace obsgroup

namespace obsgroup {

// The group ids and changes alone, without a point type.
TEST(StableGroupIds, IdsFollowTheLargestShareAndChangesAreReportedInOrder) {
  StableGroupIds ids;
  auto changes = ids.assign({{0, 1, 2}, {3, 4}}, 5);
  ASSERT_EQ(changes.size(), 2u);
  EXPECT_EQ(changes[0].kind, GroupChange::Kind::Created);
  EXPECT_EQ(changes[0].group, 0);
  EXPECT_EQ(changes[1].group, 1);
  EXPECT_EQ(ids.groupOf(4), 1);
  EXPECT_EQ(ids.groupOf(9), -1);  // no such observation yet

  // Group 0 splits: {0, 1} keeps id 0 (its largest share), {2} gets a new id;
  // group 1 grows by the new observation 5.
  changes = ids.assign({{0, 1}, {2}, {3, 4, 5}}, 6);
  ASSERT_EQ(changes.size(), 2u);
  EXPECT_EQ(changes[0].kind, GroupChange::Kind::Split);
  EXPECT_EQ(changes[0].group, 0);
  EXPECT_EQ(changes[0].related, (std::vector<int>{0, 2}));
  EXPECT_EQ(changes[1].kind, GroupChange::Kind::Grown);
  EXPECT_EQ(changes[1].group, 1);
  EXPECT_EQ(changes[1].members, (std::vector<int>{3, 4, 5}));
  EXPECT_EQ(ids.groupOf(2), 2);

  // Groups 0 and 2 merge into 0; group 1 loses observation 3 (removed).
  changes = ids.assign({{0, 1, 2}, {4, 5}}, 6);
  ASSERT_EQ(changes.size(), 2u);
  EXPECT_EQ(changes[0].kind, GroupChange::Kind::Merged);
  EXPECT_EQ(changes[0].group, 0);
  EXPECT_EQ(changes[0].related, (std::vector<int>{0, 2}));
  EXPECT_EQ(changes[1].kind, GroupChange::Kind::Shrunk);
  EXPECT_EQ(changes[1].group, 1);
  EXPECT_EQ(ids.groups().size(), 2u);

  // All of group 1's observations leave.
  changes = ids.assign({{0, 1, 2}}, 6);
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].kind, GroupChange::Kind::Removed);
  EXPECT_EQ(changes[0].group, 1);
  EXPECT_EQ(ids.groupOf(4), -1);
}

TEST(StableGroupIds, TheLocalUpdateRepartitionsOnlyTheGroupsAChangeReaches) {
  // Three cliques of three, the first two joined weakly, the third apart.
  std::vector<WeightedPair> pairs;
  for (int c = 0; c < 3; ++c)
    for (int a = 0; a < 3; ++a)
      for (int b = a + 1; b < 3; ++b) pairs.push_back({3 * c + a, 3 * c + b, 1.0});
  pairs.push_back({2, 3, 0.05});
  const WeightMatrix W = buildWeightMatrix(9, pairs);
  const std::vector<int> ids = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  StableGroupIds current;
  current.assign({{0, 1, 2, 3, 4, 5}, {6, 7, 8}}, 9);  // as if the first two had been one group
  PartitionOptions options;
  options.ncut_threshold = 0.5;
  const Partition p = partitionAroundChanges(W, ids, {0}, current, options);
  // Observation 0's group is cut along the weak edge; the third clique, not
  // next to it in W, is kept as it was.
  EXPECT_EQ(p.groups, (std::vector<std::vector<int>>{{0, 1, 2}, {3, 4, 5}, {6, 7, 8}}));
  EXPECT_TRUE(p.splits.empty());
  EXPECT_EQ(p.group_of[4], 1);
  // A change in the third clique leaves the first group alone even when it
  // would now be cut.
  const Partition q = partitionAroundChanges(W, ids, {7}, current, options);
  EXPECT_EQ(q.groups, (std::vector<std::vector<int>>{{0, 1, 2, 3, 4, 5}, {6, 7, 8}}));
}

}  // namespace obsgroup
