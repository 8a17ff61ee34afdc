// The PCL-style facade: parameters, poses from VIEWPOINT, results.
#include "test_support.h"

#include <obsgroup/observation_grouping.h>
#include <obsgroup/online_grouping.h>

#include <gtest/gtest.h>

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

TEST(ObservationGrouping, PartitionOptionsSetLaterKeepTheThreadsAndTheInterruptFlag) {
  ObservationGrouping<pcl::PointXYZ> g;
  InterruptFlag flag{false};
  g.setNumberOfThreads(1);
  g.setInterruptFlag(&flag);
  PartitionOptions options;
  options.ncut_threshold = 0.5;
  options.threads = 7;  // stored once, by setNumberOfThreads: ignored here
  g.setPartitionOptions(options);
  EXPECT_EQ(g.getPartitionOptions().threads, 1);
  EXPECT_EQ(g.getPartitionOptions().interrupt, &flag);
  EXPECT_EQ(g.getNumberOfThreads(), 1);
  EXPECT_EQ(g.getNcutThreshold(), 0.5);
  // Set after the options, the threads reach both stages.
  g.setNumberOfThreads(2);
  EXPECT_EQ(g.getPartitionOptions().threads, 2);
  EXPECT_EQ(g.getSensedSpaceOverlap().getNumberOfThreads(), 2);
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
  EXPECT_EQ(online.getNcutThreshold(), 0.4);
  EXPECT_EQ(online.getSplitCriterion(), SplitCriterion::Mean);
  EXPECT_EQ(online.getMinGroupSize(), 3);
  EXPECT_EQ(online.getMaxDepth(), 5);
  EXPECT_EQ(online.getInterruptFlag(), &flag);
}
