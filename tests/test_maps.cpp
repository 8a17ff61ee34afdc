// Local maps (paper sec. IV-A, step 3) and the topological map (step 4).
#include "test_support.h"

#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/maps/pose_average.h>
#include <obsgroup/maps/topological_map.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

using namespace obsgroup;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

double yawOf(const Eigen::Isometry3d& pose) { return std::atan2(pose.linear()(1, 0), pose.linear()(0, 0)); }

double angleBetween(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

}  // namespace

TEST(PoseAverage, KnownAnswers) {
  // Translations average; rotations +-10 degrees average to none, with a 10 degree spread.
  PoseAverage a = averagePoses({pose2D(0, 0, 10 * kDeg), pose2D(2, 0, -10 * kDeg)}, {1.0, 1.0});
  EXPECT_NEAR(a.mean.translation().x(), 1.0, 1e-12);
  EXPECT_NEAR(yawOf(a.mean), 0.0, 1e-12);
  EXPECT_NEAR(a.translation_spread, 1.0, 1e-12);
  EXPECT_NEAR(a.rotation_spread, 10 * kDeg, 1e-12);

  // Weights 3 : 1 on yaw 0 and 90 degrees: the chordal mean is atan2(1, 3).
  a = averagePoses({pose2D(0, 0, 0), pose2D(4, 0, 90 * kDeg)}, {3.0, 1.0});
  EXPECT_NEAR(yawOf(a.mean), std::atan2(1.0, 3.0), 1e-12);
  EXPECT_NEAR(a.mean.translation().x(), 1.0, 1e-12);

  // Across +-180 degrees: 179 and -179 average to 180, not to 0 as Euler angles would.
  a = averagePoses({pose2D(0, 0, 179 * kDeg), pose2D(0, 0, -179 * kDeg)}, {1.0, 1.0});
  EXPECT_NEAR(std::abs(yawOf(a.mean)), 180 * kDeg, 1e-12);
  EXPECT_NEAR(a.rotation_spread, 1 * kDeg, 1e-12);

  // A 3D rotation averaged with itself is itself.
  Eigen::Isometry3d r = Eigen::Isometry3d::Identity();
  r.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  a = averagePoses({r, r, r}, {0.2, 0.3, 0.5});
  EXPECT_TRUE(a.mean.isApprox(r, 1e-12));
  EXPECT_NEAR(a.rotation_spread, 0.0, 1e-7);

  EXPECT_THROW(averagePoses({}, {}), std::invalid_argument);
  EXPECT_THROW(averagePoses({r}, {0.0}), std::invalid_argument);
  EXPECT_THROW(averagePoses({r}, {-1.0}), std::invalid_argument);
}

TEST(TopologicalMap, ArcsJoinOverlappingOrConsecutiveGroupsOnly) {
  // Groups {0,1}, {2,3}, {4,5}, {6}; overlap across groups only between 1 and 2;
  // 3-4 and 5-6 follow each other in the sequence; 0-1-2 groups and {6} share nothing else.
  const WeightMatrix W = buildWeightMatrix(7, {{0, 1, 0.5}, {2, 3, 0.5}, {4, 5, 0.5}, {1, 2, 0.2}, {0, 2, 0.1}});
  Partition p;
  p.groups = {{0, 1}, {2, 3}, {4, 5}, {6}};
  p.group_of = {0, 0, 1, 1, 2, 2, 3};
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 7; ++i) poses.push_back(pose2D(i, 0.5 * i, 0.1 * i));
  const TopologicalMap map = buildTopologicalMap(initialFrames(p, W, poses), W, poses);
  ASSERT_EQ(map.arcs.size(), 3u);
  EXPECT_EQ(std::make_pair(map.arcs[0].from, map.arcs[0].to), std::make_pair(0, 1));
  EXPECT_EQ(map.arcs[0].overlapping_pairs, 2);  // (1,2) and (0,2)
  EXPECT_EQ(map.arcs[0].sequence_pairs, 1);     // (1,2)
  EXPECT_EQ(map.arcs[0].pairs, 2);
  EXPECT_NEAR(map.arcs[0].weight, 0.3, 1e-12);
  EXPECT_EQ(std::make_pair(map.arcs[1].from, map.arcs[1].to), std::make_pair(1, 2));
  EXPECT_EQ(map.arcs[1].overlapping_pairs, 0);
  EXPECT_EQ(map.arcs[1].sequence_pairs, 1);
  EXPECT_EQ(std::make_pair(map.arcs[2].from, map.arcs[2].to), std::make_pair(2, 3));
  // Unrefined local maps: every pair gives the exact transform between the references.
  for (const auto& arc : map.arcs) {
    const Eigen::Isometry3d exact = map.nodes[arc.from].pose.inverse() * map.nodes[arc.to].pose;
    EXPECT_TRUE(arc.transform.isApprox(exact, 1e-12));
    EXPECT_NEAR(arc.translation_spread, 0.0, 1e-9);
    EXPECT_NEAR(arc.rotation_spread, 0.0, 1e-7);
  }
}

TEST(TopologicalMap, ReferenceIsTheMostStronglyConnectedMember) {
  const WeightMatrix W = buildWeightMatrix(4, {{0, 1, 0.2}, {1, 2, 0.5}, {2, 3, 0.4}, {0, 3, 0.9}});
  EXPECT_EQ(strongestMember({0, 1, 2, 3}, W), 3);  // 0.4 + 0.9
  EXPECT_EQ(strongestMember({0, 1, 2}, W), 1);     // 0.2 + 0.5
  EXPECT_EQ(strongestMember({1, 2}, W), 1);        // tie: the smaller index
}

TEST(TopologicalMap, RefinedMemberPosesEnterTheArcAverage) {
  const WeightMatrix W = buildWeightMatrix(4, {{0, 1, 0.5}, {2, 3, 0.5}, {0, 2, 0.3}, {1, 3, 0.1}});
  Partition p;
  p.groups = {{0, 1}, {2, 3}};
  p.group_of = {0, 0, 1, 1};
  const std::vector<Eigen::Isometry3d> poses{pose2D(0, 0, 0), pose2D(1, 0, 0), pose2D(0, 3, 0), pose2D(1, 3, 0)};
  auto frames = initialFrames(p, W, poses);
  frames[0].member_poses[1] = pose2D(1.1, 0, 0);  // refinement moved observation 1 by 10 cm
  const TopologicalMap map = buildTopologicalMap(frames, W, poses);
  ASSERT_EQ(map.arcs.size(), 1u);
  // Pairs (0,2) weight 0.3 says y = 3; (1,3) weight 0.1 says the same plus 0.1 m in x,
  // and the sequence pair (1,2) with a tiny weight says x + 0.1 too.
  const double w_shift = 0.1 + kSequencePairWeight;
  EXPECT_NEAR(map.arcs[0].transform.translation().x(), 0.1 * w_shift / (0.3 + w_shift), 1e-12);
  EXPECT_NEAR(map.arcs[0].transform.translation().y(), 3.0, 1e-12);
  EXPECT_GT(map.arcs[0].translation_spread, 0.0);
}

namespace {

/// Five noise-free 360-degree scans (half a degree apart) in the west room of the three-room plan.
std::vector<Observation<pcl::PointXYZ>> westRoom(std::vector<Eigen::Isometry3d>* truth = nullptr) {
  sim::LaserModel laser;
  laser.field_of_view = 2 * 3.14159265358979;
  laser.beams = 720;
  auto obs = test::simulate<pcl::PointXYZ>(sim::threeRooms(), sim::threeRoomsPoses(5), laser);
  obs.resize(5);
  if (truth)
    for (const auto& o : obs) truth->push_back(o.pose);
  return obs;
}

WeightMatrix chain(int n) {
  std::vector<WeightedPair> pairs;
  for (int i = 0; i + 1 < n; ++i) pairs.push_back({i, i + 1, 0.8});
  pairs.push_back({0, 2, 0.9});
  return buildWeightMatrix(n, pairs);
}

}  // namespace

TEST(LocalMapBuilder, PerfectMapIsLeftUnchangedByRefinement) {
  std::vector<Eigen::Isometry3d> truth;
  const auto obs = westRoom(&truth);
  const WeightMatrix W = chain(5);
  for (Refinement r : {Refinement::None, Refinement::Icp, Refinement::Lum}) {
    LocalMapBuilder<pcl::PointXYZ> builder;
    builder.setRefinement(r);
    const LocalMap<pcl::PointXYZ> map = builder.build(obs, {0, 1, 2, 3, 4}, W);
    EXPECT_EQ(map.frame.reference, strongestMember({0, 1, 2, 3, 4}, W)) << toString(r);
    // Noise-free scans at exact poses: no change makes the map more
    // consistent, so every member keeps its input pose exactly.
    EXPECT_EQ(map.refinement.moved, 0) << toString(r);
    for (int i = 0; i < 5; ++i) {
      const Eigen::Isometry3d expected = truth[map.frame.reference].inverse() * truth[i];
      EXPECT_LT((map.frame.memberPose(i).translation() - expected.translation()).norm(), 1e-9) << toString(r) << i;
      EXPECT_LT(angleBetween(map.frame.memberPose(i), expected), 1e-9) << toString(r) << i;
    }
    EXPECT_GT(map.cloud->size(), 100u);
    EXPECT_TRUE(map.filtered);
  }
}

TEST(LocalMapBuilder, RefinementRepairsADriftedGroup) {
  std::vector<Eigen::Isometry3d> truth;
  auto obs = westRoom(&truth);
  // Drift: each pose off by a few centimetres and about a degree.
  for (int i = 1; i < 5; ++i) obs[i].pose = obs[i].pose * pose2D(0.04 * i, -0.03 * i, 0.6 * kDeg * i);
  const WeightMatrix W = chain(5);
  for (Refinement r : {Refinement::Icp, Refinement::Lum}) {
    LocalMapBuilder<pcl::PointXYZ> builder;
    builder.setRefinement(r);
    const LocalMap<pcl::PointXYZ> map = builder.build(obs, {0, 1, 2, 3, 4}, W);
    const int ref = map.frame.reference;
    double before = 0.0, after = 0.0;
    for (int i = 0; i < 5; ++i) {
      const Eigen::Isometry3d expected = truth[ref].inverse() * truth[i];
      before += ((obs[ref].pose.inverse() * obs[i].pose).translation() - expected.translation()).norm();
      after += (map.frame.memberPose(i).translation() - expected.translation()).norm();
    }
    EXPECT_LT(after, 0.25 * before) << toString(r) << ": " << before << " -> " << after;
  }
}

TEST(LocalMapBuilder, MergedCloudIsInTheReferenceFrameWithItsPose) {
  const auto obs = westRoom();
  LocalMapBuilder<pcl::PointXYZ> builder;
  builder.setVoxelLeafSize(0.0);
  const auto map = builder.build(obs, {0, 1, 2, 3, 4}, chain(5));
  std::size_t total = 0;
  for (const auto& o : obs) total += o.cloud->size();
  EXPECT_EQ(map.cloud->size(), total);
  const Eigen::Vector3f origin = map.cloud->sensor_origin_.head<3>();
  EXPECT_TRUE(origin.isApprox(obs[map.frame.reference].pose.translation().cast<float>(), 1e-6f));
  // Members are merged in order: the reference's points are unmoved, the
  // others moved by their pose in the reference frame.
  std::size_t offset = 0;
  for (int i = 0; i < 5; ++i) {
    const Eigen::Isometry3d pose = map.frame.memberPose(i);
    if (i == map.frame.reference) {
      EXPECT_TRUE(pose.isApprox(Eigen::Isometry3d::Identity()));
    }
    for (std::size_t k = 0; k < obs[i].cloud->size(); k += 37) {
      const auto& p = (*obs[i].cloud)[k];
      const Eigen::Vector3f expected = (pose * Eigen::Vector3d(p.x, p.y, p.z)).cast<float>();
      EXPECT_LT(((*map.cloud)[offset + k].getVector3fMap() - expected).norm(), 1e-5f) << i << " " << k;
    }
    offset += obs[i].cloud->size();
  }
  builder.setVoxelLeafSize(0.2);
  EXPECT_LT(builder.build(obs, {0, 1, 2, 3, 4}, chain(5)).cloud->size(), total / 2);
  EXPECT_EQ(refinementFromString("lum"), Refinement::Lum);
  EXPECT_THROW(refinementFromString("slam"), std::invalid_argument);
}

// The parallel overload builds every group as the one-group call does, for
// any thread count, and in the partition's order.
TEST(LocalMapBuilder, AllGroupsAtOnceEqualOneByOneOnAnyThreadCount) {
  std::vector<Eigen::Isometry3d> truth;
  auto obs = westRoom(&truth);
  for (int i = 1; i < 5; ++i) obs[i].pose = obs[i].pose * pose2D(0.03 * i, -0.02 * i, 0.5 * kDeg * i);
  const WeightMatrix W = chain(5);
  Partition partition;
  partition.groups = {{0, 1, 2}, {3, 4}};
  for (int threads : {1, 2, 3}) {
    LocalMapBuilder<pcl::PointXYZ> builder;
    builder.setRefinement(Refinement::Lum);
    builder.setNumberOfThreads(threads);
    const auto maps = builder.build(obs, partition, W);
    ASSERT_EQ(maps.size(), 2u);
    for (std::size_t g = 0; g < maps.size(); ++g) {
      const auto one = builder.build(obs, partition.groups[g], W);
      EXPECT_EQ(maps[g].frame.members, partition.groups[g]);
      EXPECT_EQ(maps[g].frame.reference, one.frame.reference);
      for (std::size_t k = 0; k < partition.groups[g].size(); ++k)
        EXPECT_TRUE(maps[g].frame.member_poses[k].isApprox(one.frame.member_poses[k], 0.0)) << threads << " " << g;
      ASSERT_EQ(maps[g].cloud->size(), one.cloud->size());
      for (std::size_t p = 0; p < one.cloud->size(); ++p)
        ASSERT_EQ((*maps[g].cloud)[p].getVector3fMap(), (*one.cloud)[p].getVector3fMap()) << threads << " " << g;
    }
  }
}

// A group spanning more voxels than the filter's 32-bit indices hold is kept
// unfiltered (and says so) rather than silently wrong.
TEST(LocalMapBuilder, TooManyVoxelsKeepsTheMapUnfilteredAndSaysSo) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (int k = 0; k < 10; ++k) cloud->push_back({0.1f * k, 0.0f, 0.0f});
  std::vector<Observation<pcl::PointXYZ>> obs{{cloud, pose2D(0, 0, 0)}, {cloud, pose2D(3000, 3000, 0)}};
  LocalMapBuilder<pcl::PointXYZ> builder;
  builder.setVoxelLeafSize(0.01);  // (3000 m / 1 cm)^2 cells > 2^31
  const WeightMatrix W = buildWeightMatrix(2, {{0, 1, 0.5}});
  const auto map = builder.build(obs, {0, 1}, W);
  EXPECT_FALSE(map.filtered);
  EXPECT_EQ(map.cloud->size(), 20u);
  builder.setVoxelLeafSize(0.5);
  EXPECT_TRUE(builder.build(obs, {0, 1}, W).filtered);
}

namespace {

/// The message of the std::invalid_argument `f` throws, or "" (and a failure) when it throws none.
template <typename F>
std::string invalidArgumentOf(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no std::invalid_argument";
  return "";
}

}  // namespace

// A caller's bad group, W or cloud is an std::invalid_argument naming what is
// wrong, never a read out of bounds.
TEST(LocalMapBuilder, BadArgumentsAreRefusedByName) {
  auto obs = westRoom();
  const WeightMatrix W = chain(5);
  LocalMapBuilder<pcl::PointXYZ> builder;
  builder.setRefinement(Refinement::Lum);
  EXPECT_NE(invalidArgumentOf([&] { builder.build(obs, {0, 1, 7}, W); }).find("index 7 at position 2"),
            std::string::npos);
  EXPECT_NE(invalidArgumentOf([&] { builder.build(obs, {0, -1}, W); }).find("index -1"), std::string::npos);
  EXPECT_NE(invalidArgumentOf([&] { builder.build(obs, {2, 1}, W); }).find("ascend"), std::string::npos);
  EXPECT_NE(invalidArgumentOf([&] { builder.build(obs, {1, 1}, W); }).find("ascend"), std::string::npos);
  EXPECT_NE(invalidArgumentOf([&] { builder.build(obs, pcl::Indices{}, W); }).find("empty group"), std::string::npos);
  EXPECT_NE(invalidArgumentOf([&] { builder.build(obs, {0, 1}, chain(3)); }).find("W is 3 x 3 for 5 observations"),
            std::string::npos);
  Partition partition;
  partition.groups = {{0, 1}, {2, 3, 9}};
  EXPECT_NE(invalidArgumentOf([&] { builder.build(obs, partition, W); }).find("local map 1: "), std::string::npos);
  EXPECT_NE(invalidArgumentOf([&] { builder.build(obs, partition, chain(4)); }).find("W is 4 x 4"), std::string::npos);
  auto nan_pose = obs;
  nan_pose[1].pose.translation().y() = std::nan("");
  EXPECT_NE(invalidArgumentOf([&] { builder.build(nan_pose, {0, 1}, W); }).find("observation 1 is not finite"),
            std::string::npos);
  obs[2].cloud.reset();
  EXPECT_NE(invalidArgumentOf([&] { builder.build(obs, {0, 2}, W); }).find("observation 2 has no cloud"),
            std::string::npos);
  EXPECT_NO_THROW(builder.build(obs, {0, 1}, W));  // the null cloud is not a member
}

TEST(TopologicalMap, BadFramesAreRefusedByName) {
  const WeightMatrix W = chain(4);
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 4; ++i) poses.push_back(pose2D(i, 0, 0));
  EXPECT_NE(invalidArgumentOf([&] { initialFrame({0, 4}, W, poses); }).find("index 4"), std::string::npos);
  EXPECT_NE(invalidArgumentOf([&] { initialFrame({0, 1}, chain(3), poses); }).find("W is 3 x 3 for 4"),
            std::string::npos);
  EXPECT_NE(invalidArgumentOf([&] { strongestMember({3, 0}, W); }).find("ascend"), std::string::npos);
  Partition partition;
  partition.groups = {{0, 1}, {2, 3}};
  std::vector<LocalMapFrame> frames = initialFrames(partition, W, poses);
  EXPECT_NO_THROW(buildTopologicalMap(frames, W, poses));
  EXPECT_NE(invalidArgumentOf([&] { buildTopologicalMap(frames, chain(3), poses); }).find("W is 3 x 3"),
            std::string::npos);
  auto twice = frames;
  twice[1] = initialFrame({1, 2, 3}, W, poses);
  EXPECT_NE(invalidArgumentOf([&] { buildTopologicalMap(twice, W, poses); }).find("observation 1 is also in local map 0"),
            std::string::npos);
  auto missing = frames;
  missing[1] = initialFrame({2}, W, poses);
  EXPECT_NE(invalidArgumentOf([&] { buildTopologicalMap(missing, W, poses); }).find("observation 3 is in no local map"),
            std::string::npos);
  auto short_poses = frames;
  short_poses[0].member_poses.pop_back();
  EXPECT_NE(invalidArgumentOf([&] { buildTopologicalMap(short_poses, W, poses); }).find("1 member poses for 2"),
            std::string::npos);
  auto far = poses;
  far[3].translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_NE(invalidArgumentOf([&] { buildTopologicalMap(frames, W, far); }).find("observation 3 is not finite"),
            std::string::npos);
  partition.groups = {{0, 1}, {2, 5}};
  EXPECT_NE(invalidArgumentOf([&] { initialFrames(partition, W, poses); }).find("group 1: initialFrame: index 5"),
            std::string::npos);
  // Refinement's own entry point: pairs and the reference are checked too.
  LocalMapFrame frame = initialFrame({0, 1}, W, poses);
  const std::vector<MemberPoints> points(2, MemberPoints{Eigen::Vector3f(1, 0, 0)});
  EXPECT_NE(invalidArgumentOf([&] { refineMemberPoses(Refinement::Lum, points, {{0, 2}}, true, {}, frame); })
                .find("pair (0, 2)"),
            std::string::npos);
  frame.reference = 3;
  EXPECT_NE(invalidArgumentOf([&] { refineMemberPoses(Refinement::Lum, points, {{0, 1}}, true, {}, frame); })
                .find("reference 3 is not a member"),
            std::string::npos);
}

TEST(TopologicalMap, GlobalPosesPlaceEachMemberByItsMap) {
  const WeightMatrix W = chain(4);
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 4; ++i) poses.push_back(pose2D(i, 0.5 * i, 0.1 * i));
  Partition partition;
  partition.groups = {{0, 1}, {2, 3}};
  TopologicalMap topology = buildTopologicalMap(initialFrames(partition, W, poses), W, poses);
  // Unrefined maps give back the input poses...
  std::vector<Eigen::Isometry3d> global = globalPoses(topology, 4);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(global[i].isApprox(poses[i], 1e-12)) << i;
  // ...and a member moved in its map's frame moves in the world by the same.
  const int other = topology.nodes[1].members[0] == topology.nodes[1].reference ? 1 : 0;
  topology.nodes[1].member_poses[other] = topology.nodes[1].member_poses[other] * pose2D(0.2, 0, 0);
  global = globalPoses(topology, 4);
  const int moved = topology.nodes[1].members[other];
  EXPECT_TRUE(global[moved].isApprox(poses[moved] * pose2D(0.2, 0, 0), 1e-12));
  EXPECT_THROW(globalPoses(topology, 3), std::invalid_argument);
}
