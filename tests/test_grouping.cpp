// The PCL-style facade: parameters, poses from VIEWPOINT, results.
#include "test_support.h"

#include <obsgroup/observation_grouping.h>
#include <obsgroup/online_grouping.h>

#include <gtest/gtest.h>
#include <pcl/search/kdtree.h>

#include <cmath>
#include <string>

using namespace obsgroup;

TEST(ObservationGrouping, ParametersRoundTrip) {
  ObservationGrouping<pcl::PointXYZI> g;
  EXPECT_DOUBLE_EQ(g.getMatchDistance(), 0.1);
  EXPECT_DOUBLE_EQ(g.getVoxelLeafSize(), 0.0);
  EXPECT_DOUBLE_EQ(g.getNcutThreshold(), 0.7);
  EXPECT_DOUBLE_EQ(g.getDiagonalWeight(), 0.0);
  // The measured defaults (docs/grouping.md), and the paper's on request.
  EXPECT_EQ(g.getSensedSpaceModel(), SensedSpaceModel::Visibility);
  EXPECT_EQ(g.getSplitCriterion(), SplitCriterion::BestNcut);
  g.usePaperMethod();
  EXPECT_EQ(g.getSensedSpaceModel(), SensedSpaceModel::Points);
  EXPECT_EQ(g.getSplitCriterion(), SplitCriterion::Mean);
  EXPECT_DOUBLE_EQ(g.getNcutThreshold(), 1.0);
  EXPECT_EQ(g.getMinGroupSize(), 1);
  EXPECT_EQ(g.getNeighbourSearch(), NeighbourSearch::SharedGrid);
  g.setMatchDistance(0.2);
  g.setVoxelLeafSize(0.05);
  g.setNcutThreshold(0.9);
  g.setDiagonalWeight(1.0);
  g.setSplitCriterion(SplitCriterion::BestNcut);
  g.setMinGroupSize(3);
  g.setMaxDepth(4);
  g.setNumberOfThreads(1);
  EXPECT_DOUBLE_EQ(g.getMatchDistance(), 0.2);
  EXPECT_DOUBLE_EQ(g.getVoxelLeafSize(), 0.05);
  EXPECT_DOUBLE_EQ(g.getNcutThreshold(), 0.9);
  EXPECT_DOUBLE_EQ(g.getDiagonalWeight(), 1.0);
  EXPECT_EQ(g.getSplitCriterion(), SplitCriterion::BestNcut);
  EXPECT_EQ(g.getMinGroupSize(), 3);
  EXPECT_EQ(g.getMaxDepth(), 4);
  EXPECT_EQ(g.getNumberOfThreads(), 1);
}

TEST(ObservationGrouping, PoseFromViewpointOfAPcdFile) {
  const auto obs = test::realLog(4);
  ASSERT_EQ(obs.size(), 4u);
  // 000003.pcd: VIEWPOINT 0.264964193 -0.233036101 0 0.985235729645 0 0 -0.171203262323
  const Eigen::Isometry3d& pose = obs[3].pose;
  EXPECT_NEAR(pose.translation().x(), 0.264964193, 1e-6);
  EXPECT_NEAR(pose.translation().y(), -0.233036101, 1e-6);
  const Eigen::Quaterniond q(pose.linear());
  EXPECT_NEAR(std::abs(q.w()), 0.985235729645, 1e-6);
  EXPECT_NEAR(std::atan2(pose.linear()(1, 0), pose.linear()(0, 0)), 2 * std::atan2(-0.171203262323, 0.985235729645),
              1e-6);

  ObservationGrouping<pcl::PointXYZ> g;
  g.addObservation(obs[3].cloud);  // pose taken from the cloud itself
  EXPECT_TRUE(g.getObservations()[0].pose.isApprox(pose, 1e-12));
}

TEST(ObservationGrouping, WeightMatrixHasTheConfiguredDiagonal) {
  const auto obs = test::simulate<pcl::PointXYZ>(sim::threeRooms(), sim::threeRoomsPoses(2));
  ObservationGrouping<pcl::PointXYZ> g;
  g.usePaperMethod();  // the diagonal is the paper's question (sec. III), asked of its method
  for (const auto& o : obs) g.addObservation(o.cloud, o.pose);
  g.compute();
  const WeightMatrix& W = g.getWeightMatrix();
  ASSERT_EQ(W.rows(), 6);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(W.coeff(i, i), 0.0);
  EXPECT_EQ(W.nonZeros(), 2 * static_cast<Eigen::Index>(g.getOverlap().pairs.size()));
  EXPECT_TRUE(W.isApprox(WeightMatrix(W.transpose())));

  g.setDiagonalWeight(1.0);  // the paper's reflexive Psi, sec. III
  const Partition p = g.compute();
  for (int i = 0; i < 6; ++i) EXPECT_EQ(g.getWeightMatrix().coeff(i, i), 1.0);
  EXPECT_EQ(p.groups.size(), 6u);  // with a unit diagonal every group falls apart

  g.clear();
  EXPECT_TRUE(g.getObservations().empty());
  EXPECT_TRUE(g.compute().groups.empty());
}

TEST(ObservationGrouping, RejectsNullCloudsNamingTheirIndex) {
  ObservationGrouping<pcl::PointXYZ> g;
  g.addObservation(pcl::PointCloud<pcl::PointXYZ>::ConstPtr(new pcl::PointCloud<pcl::PointXYZ>),
                   Eigen::Isometry3d::Identity());
  for (int overload = 0; overload < 2; ++overload) {
    try {
      if (overload == 0) g.addObservation(nullptr);
      else g.addObservation(nullptr, Eigen::Isometry3d::Identity());
      FAIL() << "a null cloud was accepted";
    } catch (const InvalidObservation& e) {
      EXPECT_EQ(e.index(), 1);  // the position it would have had
      EXPECT_NE(std::string(e.what()).find("null cloud"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(g.getObservations().size(), 1u);
}

TEST(GroupingParameters, TheDefaultsAndThePaperPresetAreWrittenOnceAndUsedByEveryLayer) {
  const GroupingParameters defaults;
  EXPECT_EQ(defaults.model, SensedSpaceModel::Visibility);
  EXPECT_EQ(defaults.split, SplitCriterion::BestNcut);
  EXPECT_DOUBLE_EQ(defaults.ncut_threshold, 0.7);
  EXPECT_EQ(defaults.boundary_passes, 3);
  EXPECT_NO_THROW(defaults.check());
  EXPECT_TRUE(ObservationGrouping<pcl::PointXYZ>().getParameters() == defaults);
  EXPECT_TRUE(OnlineGrouping<pcl::PointXYZ>().getParameters() == defaults);

  // The paper's: the points model and PartitionOptions' defaults (sec. II).
  const GroupingParameters paper = GroupingParameters::paper();
  const PartitionOptions papers_partition;
  EXPECT_EQ(paper.model, SensedSpaceModel::Points);
  EXPECT_EQ(paper.split, SplitCriterion::Mean);
  EXPECT_EQ(paper.ncut_threshold, 1.0);
  EXPECT_EQ(paper.boundary_passes, 0);
  EXPECT_EQ(paper.partitionOptions().split, papers_partition.split);
  EXPECT_EQ(paper.partitionOptions().ncut_threshold, papers_partition.ncut_threshold);
  EXPECT_EQ(paper.partitionOptions().boundary_passes, papers_partition.boundary_passes);
  EXPECT_NO_THROW(paper.check());
  ObservationGrouping<pcl::PointXYZ> batch;
  batch.setMatchDistance(0.3);  // usePaperMethod keeps delta, as the command's --paper does
  batch.usePaperMethod();
  GroupingParameters paper_with_delta = paper;
  paper_with_delta.match_distance = 0.3;
  EXPECT_TRUE(batch.getParameters() == paper_with_delta);
  OnlineGrouping<pcl::PointXYZ> online;
  online.usePaperMethod();
  EXPECT_TRUE(online.getParameters() == paper);
}

TEST(GroupingParameters, ASettingTheModelDoesNotUseIsRefusedNamingIt) {
  const auto refused = [](const GroupingParameters& params, const std::string& words) {
    try {
      params.check();
      ADD_FAILURE() << "accepted; expected: " << words;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
    ObservationGrouping<pcl::PointXYZ> grouping;
    EXPECT_THROW(grouping.setParameters(params), std::invalid_argument);
    EXPECT_TRUE(grouping.getParameters() == GroupingParameters{});  // nothing changed
    OnlineGrouping<pcl::PointXYZ> online;
    EXPECT_THROW(online.setParameters(params), std::invalid_argument);
  };
  GroupingParameters p;
  p.match_distance = 0.2;  // delta under the visibility model
  refused(p, "match_distance (delta) applies to the points model, not visibility");
  p = GroupingParameters{};
  p.neighbour_search = NeighbourSearch::PclSearch;
  refused(p, "neighbour_search applies to the points model");
  p = GroupingParameters::paper();
  p.regions.cell_size = 0.1;
  refused(p, "regions.cell_size applies to the free-space and visibility models, not points");
  p = GroupingParameters{};
  p.model = SensedSpaceModel::FreeSpace;
  p.regions.clearance = 0.5;
  refused(p, "regions.clearance applies to the visibility model only");
  // ...and out of range.
  p = GroupingParameters{};
  p.regions.cell_size = 0.0;
  refused(p, "cell size must be finite and > 0");
  p = GroupingParameters::paper();
  p.match_distance = -1;
  refused(p, "match_distance (delta) must be finite and > 0");
  p = GroupingParameters{};
  p.ncut_threshold = std::nan("");
  refused(p, "ncut_threshold must be finite");
  p = GroupingParameters{};
  p.min_group_size = 0;
  refused(p, "min_group_size must be >= 1");
  p = GroupingParameters{};
  p.boundary_passes = -1;
  refused(p, "boundary_passes must be >= 0");
  p = GroupingParameters{};
  p.threads = -2;
  refused(p, "threads must be >= 0");
}

TEST(GroupingParameters, OneSetterAtATimeIsCheckedWhenTheGroupingRuns) {
  const auto obs = test::simulate<pcl::PointXYZ>(sim::threeRooms(), sim::threeRoomsPoses(2));
  ObservationGrouping<pcl::PointXYZ> batch;
  for (const auto& o : obs) batch.addObservation(o.cloud, o.pose);
  batch.setMatchDistance(0.2);  // silently ignored before: the default model has no delta
  EXPECT_THROW(batch.compute(), std::invalid_argument);
  batch.setSensedSpaceModel(SensedSpaceModel::Points);  // in any order: now delta applies
  EXPECT_NO_THROW(batch.compute());
  batch.setSensedSpaceModel(SensedSpaceModel::Visibility);
  batch.setMatchDistance(GroupingParameters{}.match_distance);
  batch.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
  EXPECT_THROW(batch.compute(), std::invalid_argument);  // a search object is the points model's

  OnlineGrouping<pcl::PointXYZ> online;
  online.setMatchDistance(0.2);
  EXPECT_THROW(online.insert(obs[0].cloud, obs[0].pose), std::invalid_argument);
  EXPECT_TRUE(online.getIds().empty());
  online.setSensedSpaceModel(SensedSpaceModel::Points);
  EXPECT_EQ(online.insert(obs[0].cloud, obs[0].pose), 0);
}

TEST(GroupingParameters, TheThreadsAndTheInterruptFlagReachEveryStage) {
  ObservationGrouping<pcl::PointXYZ> g;
  InterruptFlag flag{false};
  g.setInterruptFlag(&flag);
  GroupingParameters params;
  params.threads = 2;
  params.ncut_threshold = 0.5;
  g.setParameters(params);
  EXPECT_EQ(g.getPartitionOptions().threads, 2);
  EXPECT_EQ(g.getPartitionOptions().interrupt, &flag);
  EXPECT_EQ(g.getPartitionOptions().ncut_threshold, 0.5);
  EXPECT_EQ(g.getSensedSpaceOverlap().getNumberOfThreads(), 2);
  EXPECT_EQ(g.getSensedSpaceOverlap().getInterruptFlag(), &flag);
  g.setNumberOfThreads(1);
  EXPECT_EQ(g.getPartitionOptions().threads, 1);
  EXPECT_EQ(g.getParameters().threads, 1);
  OnlineGrouping<pcl::PointXYZ> online;
  online.setInterruptFlag(&flag);
  online.setParameters(params);
  EXPECT_EQ(online.getPartitionOptions().threads, 2);
  EXPECT_EQ(online.getPartitionOptions().interrupt, &flag);
  EXPECT_TRUE(online.getPartitionOptions().eigen.elimination_rank.empty());
}

TEST(GroupingParameters, TheOnlineGroupingGivesTheBatchsGroupsForTheSameParameters) {
  const auto obs = test::simulate<pcl::PointXYZ>(sim::threeRooms(), sim::threeRoomsPoses(3));
  GroupingParameters params;
  params.regions.cell_size = 0.1;
  params.ncut_threshold = 0.8;
  params.boundary_passes = 1;
  ObservationGrouping<pcl::PointXYZ> batch;
  batch.setParameters(params);
  OnlineGrouping<pcl::PointXYZ> online;
  online.setParameters(params);
  for (const auto& o : obs) {
    batch.addObservation(o.cloud, o.pose);
    online.insert(o.cloud, o.pose);
  }
  const Partition expected = batch.compute();
  online.update();
  EXPECT_EQ(online.getPartition().groups, expected.groups);
  EXPECT_GT(expected.groups.size(), 1u);
}

// Every setting reads back as it was set.
TEST(ObservationGrouping, EverySetterHasItsGetter) {
  ObservationGrouping<pcl::PointXYZ> g;
  InterruptFlag flag{false};
  g.setInterruptFlag(&flag);
  EXPECT_EQ(g.getInterruptFlag(), &flag);
  g.setProgressCallback([](std::size_t, std::size_t) {});
  EXPECT_TRUE(bool(g.getProgressCallback()));
  OnlineGrouping<pcl::PointXYZ> online;
  online.setNcutThreshold(0.4);
  online.setSplitCriterion(SplitCriterion::Mean);
  online.setMinGroupSize(3);
  online.setMaxDepth(5);
  online.setInterruptFlag(&flag);
  online.setEigenSolver(EigenSolver::Dense);
  online.setDiagonalWeight(0.5);
  online.setVoxelLeafSize(0.05);
  EXPECT_EQ(online.getEigenSolver(), EigenSolver::Dense);
  EXPECT_EQ(online.getDiagonalWeight(), 0.5);
  EXPECT_EQ(online.getVoxelLeafSize(), 0.05);
  EXPECT_EQ(online.getNcutThreshold(), 0.4);
  EXPECT_EQ(online.getSplitCriterion(), SplitCriterion::Mean);
  EXPECT_EQ(online.getMinGroupSize(), 3);
  EXPECT_EQ(online.getMaxDepth(), 5);
  EXPECT_EQ(online.getInterruptFlag(), &flag);
}
