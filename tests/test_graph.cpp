#include <obsgroup/graph/observation_graph.h>

#include <gtest/gtest.h>

#include <stdexcept>

using namespace obsgroup;

TEST(ObservationGraph, BuildsSymmetricMatrixWithConfiguredDiagonal) {
  const WeightMatrix W = buildWeightMatrix(3, {{0, 1, 0.5}, {2, 1, 0.25}}, 0.0);
  EXPECT_EQ(W.nonZeros(), 4);
  EXPECT_DOUBLE_EQ(W.coeff(0, 1), 0.5);
  EXPECT_DOUBLE_EQ(W.coeff(1, 0), 0.5);
  EXPECT_DOUBLE_EQ(W.coeff(1, 2), 0.25);
  EXPECT_DOUBLE_EQ(W.coeff(0, 0), 0.0);

  const WeightMatrix U = buildWeightMatrix(3, {{0, 1, 0.5}}, 1.0);
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(U.coeff(i, i), 1.0);
  const Eigen::VectorXd d = degrees(U);
  EXPECT_DOUBLE_EQ(d[0], 1.5);
  EXPECT_DOUBLE_EQ(d[1], 1.5);
  EXPECT_DOUBLE_EQ(d[2], 1.0);
}

TEST(ObservationGraph, RejectsBadPairs) {
  EXPECT_THROW(buildWeightMatrix(2, {{0, 2, 0.5}}), std::invalid_argument);
  EXPECT_THROW(buildWeightMatrix(2, {{1, 1, 0.5}}), std::invalid_argument);
  EXPECT_THROW(buildWeightMatrix(2, {{0, 1, -0.5}}), std::invalid_argument);
  EXPECT_THROW(buildWeightMatrix(2, {{0, 1, std::nan("")}}), std::invalid_argument);
  EXPECT_THROW(buildWeightMatrix(2, {{0, 1, 0.5}, {1, 0, 0.5}}), std::invalid_argument);
  EXPECT_THROW(buildWeightMatrix(2, {}, -1.0), std::invalid_argument);
}

TEST(ObservationGraph, ConnectedComponentsOrderedBySmallestNode) {
  // 0-3, 1-4-2, 5 alone; the diagonal must not connect anything.
  const WeightMatrix W = buildWeightMatrix(6, {{0, 3, 1.0}, {4, 1, 0.2}, {2, 4, 0.3}}, 1.0);
  const auto components = connectedComponents(W);
  ASSERT_EQ(components.size(), 3u);
  EXPECT_EQ(components[0], (std::vector<int>{0, 3}));
  EXPECT_EQ(components[1], (std::vector<int>{1, 2, 4}));
  EXPECT_EQ(components[2], (std::vector<int>{5}));
}

TEST(ObservationGraph, InducedSubgraphKeepsInternalEdgesOnly) {
  const WeightMatrix W = buildWeightMatrix(5, {{0, 1, 0.1}, {1, 3, 0.2}, {3, 4, 0.3}, {0, 4, 0.4}}, 0.0);
  const WeightMatrix S = inducedSubgraph(W, {1, 3, 4});
  ASSERT_EQ(S.rows(), 3);
  EXPECT_EQ(S.nonZeros(), 4);
  EXPECT_DOUBLE_EQ(S.coeff(0, 1), 0.2);
  EXPECT_DOUBLE_EQ(S.coeff(1, 2), 0.3);
  EXPECT_DOUBLE_EQ(S.coeff(2, 1), 0.3);
  EXPECT_DOUBLE_EQ(S.coeff(0, 2), 0.0);
}
