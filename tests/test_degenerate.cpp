// Degenerate inputs of the core: what a real robot log can hold (no scan,
// one scan, scans that overlap nothing, a scan with no return, a bad pose)
// and graphs the eigen solver cannot handle. Each has one clear outcome.
#include <obsgroup/observation_grouping.h>
#include <obsgroup/partition/recursive_partitioner.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace obsgroup;

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

/// Points on a circle of `radius` around the sensor: a round room.
Cloud::Ptr roundRoom(int points = 180, float radius = 2.0f) {
  Cloud::Ptr cloud(new Cloud);
  for (int k = 0; k < points; ++k) {
    const float a = float(2.0 * M_PI * k / points);
    cloud->push_back(pcl::PointXYZ(radius * std::cos(a), radius * std::sin(a), 0.0f));
  }
  return cloud;
}

ObservationGrouping<pcl::PointXYZ> groupingOf(const std::vector<std::pair<Cloud::Ptr, Eigen::Isometry3d>>& input) {
  ObservationGrouping<pcl::PointXYZ> g;
  for (const auto& [cloud, pose] : input) g.addObservation(cloud, pose);
  return g;
}

bool anyAttempted(const Partition& p) {
  for (const SplitNode& node : p.splits)
    if (node.attempted) return true;
  return false;
}

/// A path graph 0 - 1 - ... - (n-1) with slowly varying weights.
WeightMatrix pathGraph(int n) {
  std::vector<WeightedPair> pairs;
  for (int i = 0; i + 1 < n; ++i) pairs.push_back({i, i + 1, 0.5 + 0.4 * std::sin(0.1 * i)});
  return buildWeightMatrix(n, pairs);
}

/// Lanczos asked for a zero tolerance within three restarts: it reports
/// non-convergence on any graph it cannot solve exactly, as it would on a
/// hard real one, but deterministically.
PartitionOptions starvedLanczos() {
  PartitionOptions options;
  options.eigen.solver = EigenSolver::Sparse;
  options.eigen.max_iterations = 3;
  options.eigen.tolerance = 0.0;
  options.keep_eigenvectors = false;
  return options;
}

}  // namespace

TEST(Degenerate, NoObservationGivesNoGroup) {
  ObservationGrouping<pcl::PointXYZ> g;
  const Partition p = g.compute();
  EXPECT_TRUE(p.groups.empty());
  EXPECT_TRUE(p.splits.empty());
  EXPECT_TRUE(g.getWarnings().empty());
  EXPECT_EQ(g.getWeightMatrix().rows(), 0);
}

TEST(Degenerate, OneObservationIsOneGroupWithoutEigenSolve) {
  auto g = groupingOf({{roundRoom(), Eigen::Isometry3d::Identity()}});
  const Partition p = g.compute();
  ASSERT_EQ(p.groups.size(), 1u);
  EXPECT_EQ(p.groups[0], std::vector<int>({0}));
  EXPECT_FALSE(anyAttempted(p));
}

TEST(Degenerate, TwoObservations) {
  // Overlapping: Ncut of the only split is 1 + 1 = 2 (zero diagonal), so they stay together.
  auto together = groupingOf({{roundRoom(), Eigen::Isometry3d::Identity()}, {roundRoom(), pose2D(0.01, 0, 0)}});
  Partition p = together.compute();
  ASSERT_EQ(p.groups.size(), 1u);
  EXPECT_EQ(p.groups[0], std::vector<int>({0, 1}));
  EXPECT_NEAR(p.splits[0].ncut, 2.0, 1e-12);
  // Apart: two components, no eigen solve.
  auto apart = groupingOf({{roundRoom(), Eigen::Isometry3d::Identity()}, {roundRoom(), pose2D(100, 0, 0)}});
  p = apart.compute();
  ASSERT_EQ(p.groups.size(), 2u);
  EXPECT_FALSE(anyAttempted(p));
}

TEST(Degenerate, IdenticalObservationsStayOneGroup) {
  std::vector<std::pair<Cloud::Ptr, Eigen::Isometry3d>> input(20, {roundRoom(), pose2D(3, 4, 0.5)});
  auto g = groupingOf(input);
  const Partition p = g.compute();
  ASSERT_EQ(p.groups.size(), 1u);
  EXPECT_EQ(p.groups[0].size(), 20u);
  const WeightMatrix& W = g.getWeightMatrix();
  EXPECT_EQ(W.nonZeros(), 20 * 19);
  EXPECT_DOUBLE_EQ(W.coeff(3, 7), 1.0);
  // A clique of k equal weights: any bisection has Ncut k / (k - 1) > 1 (docs/method.md).
  EXPECT_TRUE(p.splits[0].attempted);
  EXPECT_GE(p.splits[0].ncut, 1.0);
}

TEST(Degenerate, NoTwoOverlappingGivesSingletonsWithoutEigenSolve) {
  std::vector<std::pair<Cloud::Ptr, Eigen::Isometry3d>> input;
  for (int i = 0; i < 12; ++i) input.push_back({roundRoom(), pose2D(10.0 * i, 0, 0)});
  auto g = groupingOf(input);
  const Partition p = g.compute();
  EXPECT_EQ(p.groups.size(), 12u);
  EXPECT_FALSE(anyAttempted(p));
  EXPECT_EQ(g.getOverlap().pairs_evaluated, 0u);
  EXPECT_EQ(g.getWeightMatrix().nonZeros(), 0);
}

TEST(Degenerate, ObservationWithoutPointsIsItsOwnGroupWithAWarning) {
  Cloud::Ptr nan_only(new Cloud);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  nan_only->push_back(pcl::PointXYZ(nan, 0, 0));
  nan_only->is_dense = true;  // a lie some drivers tell: every point is checked anyway
  auto g = groupingOf({{roundRoom(), Eigen::Isometry3d::Identity()},
                       {Cloud::Ptr(new Cloud), Eigen::Isometry3d::Identity()},
                       {roundRoom(), pose2D(0.05, 0, 0)},
                       {nan_only, Eigen::Isometry3d::Identity()}});
  const Partition p = g.compute();
  EXPECT_EQ(p.groups, (std::vector<std::vector<int>>{{0, 2}, {1}, {3}}));
  ASSERT_EQ(g.getWarnings().size(), 2u);
  EXPECT_NE(g.getWarnings()[0].find("observation 1 has no finite point"), std::string::npos);
  EXPECT_NE(g.getWarnings()[1].find("observation 3 has no finite point"), std::string::npos);
}

TEST(Degenerate, ExplicitZeroWeightsDoNotConnect) {
  // Stored zeros, as a user-built W may hold: 0 -(0)- 1 -(0.5)- 2, and 3 alone.
  WeightMatrix W(4, 4);
  std::vector<Eigen::Triplet<double>> t{{0, 1, 0.0}, {1, 0, 0.0}, {1, 2, 0.5}, {2, 1, 0.5}, {3, 3, 0.0}};
  W.setFromTriplets(t.begin(), t.end());
  ASSERT_EQ(W.nonZeros(), 5);
  const Partition p = recursivePartition(W);
  EXPECT_EQ(p.groups, (std::vector<std::vector<int>>{{0}, {1, 2}, {3}}));
  EXPECT_EQ(p.splits[0].kind, SplitNode::Kind::Components);
}

TEST(Degenerate, WeightsThatAreNotOverlapsAreRefused) {
  const auto refused = [](double w01, double w10) {
    WeightMatrix W(2, 2);
    std::vector<Eigen::Triplet<double>> t{{0, 1, w01}, {1, 0, w10}};
    W.setFromTriplets(t.begin(), t.end());
    EXPECT_THROW(recursivePartition(W), std::invalid_argument) << w01 << " " << w10;
  };
  refused(std::numeric_limits<double>::quiet_NaN(), 0.5);
  refused(-0.5, -0.5);
  refused(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
  refused(0.5, 0.25);  // not symmetric
  WeightMatrix one_sided(2, 2);
  one_sided.insert(0, 1) = 0.5;
  EXPECT_THROW(recursivePartition(one_sided), std::invalid_argument);
}

// The online overload checks only the rows flagged changed once its cache
// holds a checked run, yet refuses a bad weight in such a row, and after a
// refusal checks every row again: the caller need not flag the bad row twice.
TEST(Degenerate, TheCachedPartitionRefusesBadWeightsInTheRowsThatChanged) {
  const auto graph = [](double w23, double w32) {
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j)
        if (i != j) t.emplace_back(i, j, (i < 3) == (j < 3) ? 1.0 : 0.01);
    WeightMatrix W(6, 6);
    W.setFromTriplets(t.begin(), t.end());
    W.coeffRef(2, 3) = w23;
    W.coeffRef(3, 2) = w32;
    return W;
  };
  const std::vector<int> ids{0, 1, 2, 3, 4, 5};
  const std::vector<char> none(6, 0), rows_2_3{0, 0, 1, 1, 0, 0};
  PartitionOptions options;
  options.min_group_size = 1;
  SplitCache cache;
  EXPECT_THROW(recursivePartition(graph(0.01, 0.5), options, ids, none, cache), std::invalid_argument)
      << "a cold cache checks every row";
  const Partition good = recursivePartition(graph(0.01, 0.01), options, ids, none, cache);
  EXPECT_EQ(good.groups, (std::vector<std::vector<int>>{{0, 1, 2}, {3, 4, 5}}));
  EXPECT_THROW(recursivePartition(graph(-0.01, -0.01), options, ids, rows_2_3, cache), std::invalid_argument);
  EXPECT_THROW(recursivePartition(graph(0.01, 0.5), options, ids, none, cache), std::invalid_argument)
      << "after a refusal the next run checks every row";
  EXPECT_EQ(recursivePartition(graph(0.01, 0.01), options, ids, none, cache).groups, good.groups);
}

TEST(Degenerate, LanczosFailureFallsBackToTheDenseSolverWithAWarning) {
  const WeightMatrix W = pathGraph(400);
  FiedlerOptions no_fallback = starvedLanczos().eigen;
  no_fallback.dense_fallback_max_size = 0;
  ASSERT_THROW(fiedlerVector(W, no_fallback), EigenSolverError)
      << "the starved Lanczos run must fail on its own for this test to mean anything";
  PartitionOptions options = starvedLanczos();
  options.eigen.dense_fallback_max_size = 400;
  options.max_depth = 1;
  const Partition fell_back = recursivePartition(W, options);
  ASSERT_FALSE(fell_back.warnings.empty());
  EXPECT_NE(fell_back.warnings[0].find("the dense solver was used"), std::string::npos);
  EXPECT_TRUE(fell_back.splits[0].solver_fell_back);
  EXPECT_FALSE(fell_back.splits[0].sparse_solver);

  PartitionOptions dense;
  dense.eigen.solver = EigenSolver::Dense;
  dense.max_depth = 1;
  const Partition reference = recursivePartition(W, dense);
  EXPECT_EQ(fell_back.groups, reference.groups);
  EXPECT_TRUE(reference.warnings.empty());
}

TEST(Degenerate, EigenSolverFailureKeepsTheGroupWholeWithAWarning) {
  const WeightMatrix W = pathGraph(400);
  PartitionOptions options = starvedLanczos();
  options.eigen.dense_fallback_max_size = 100;  // too small to take over
  const Partition p = recursivePartition(W, options);
  ASSERT_EQ(p.groups.size(), 1u);
  EXPECT_EQ(p.groups[0].size(), 400u);
  EXPECT_EQ(p.splits[0].outcome, SplitNode::Outcome::EigenSolverFailed);
  EXPECT_FALSE(p.splits[0].accepted);
  ASSERT_EQ(p.warnings.size(), 1u);
  EXPECT_NE(p.warnings[0].find("kept whole"), std::string::npos);
}

TEST(Degenerate, NonFinitePosesAreRefusedNamingTheObservation) {
  Eigen::Isometry3d nan_pose = Eigen::Isometry3d::Identity();
  nan_pose.translation().x() = std::numeric_limits<double>::quiet_NaN();
  auto g = groupingOf({{roundRoom(), Eigen::Isometry3d::Identity()}, {roundRoom(), nan_pose}});
  try {
    g.compute();
    FAIL() << "a NaN pose was accepted";
  } catch (const InvalidObservation& e) {
    EXPECT_EQ(e.index(), 1);
    EXPECT_NE(std::string(e.what()).find("observation 1: observation pose is not finite"), std::string::npos)
        << e.what();
  }
  // A NaN VIEWPOINT read from a PCD file, through the cloud's sensor origin.
  Cloud::Ptr cloud = roundRoom();
  cloud->sensor_orientation_ = Eigen::Quaternionf(std::nanf(""), 0, 0, 0);
  ObservationGrouping<pcl::PointXYZ> from_viewpoint;
  from_viewpoint.addObservation(cloud);
  EXPECT_THROW(from_viewpoint.compute(), std::invalid_argument);
}

TEST(Degenerate, MapsTooWideForTheGridAreRefusedClearly) {
  // 1e12 m apart at delta 0.1: cell indices beyond 32 bits. Never a wrapped index.
  auto g = groupingOf({{roundRoom(), Eigen::Isometry3d::Identity()}, {roundRoom(), pose2D(1e12, 0, 0)}});
  try {
    g.compute();
    FAIL() << "a map 1e12 m wide was accepted";
  } catch (const InvalidObservation& e) {
    EXPECT_EQ(e.index(), 1) << e.what();
    EXPECT_NE(std::string(e.what()).find("too far"), std::string::npos) << e.what();
  }
}

TEST(Degenerate, AnInterruptStopsEveryStage) {
  std::vector<std::pair<Cloud::Ptr, Eigen::Isometry3d>> input;
  for (int i = 0; i < 8; ++i) input.push_back({roundRoom(), pose2D(0.5 * i, 0, 0)});
  auto g = groupingOf(input);
  InterruptFlag flag{true};
  g.setInterruptFlag(&flag);
  EXPECT_THROW(g.compute(), Interrupted);
  flag = false;
  EXPECT_NO_THROW(g.compute());

  PartitionOptions options;
  options.interrupt = &flag;
  flag = true;
  EXPECT_THROW(recursivePartition(pathGraph(10), options), Interrupted);
}
