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

TEST(ObservationGraph, MutualNeighboursKeepAnEdgeOnlyWhenBothEndsRankItAmongTheirStrongest) {
  // Node 0 overlaps 1 and 2 most; node 3 overlaps 0 weakly, but for 0 it
  // is its third: with k = 2 the edge 0-3 goes, whatever 3 thinks of it.
  const WeightMatrix W =
      buildWeightMatrix(5, {{0, 1, 0.9}, {0, 2, 0.8}, {0, 3, 0.3}, {1, 2, 0.7}, {3, 4, 0.6}}, 1.0);
  const std::vector<double> thresholds = neighbourThresholds(W, 2);
  EXPECT_DOUBLE_EQ(thresholds[0], 0.8);  // its 2nd strongest edge; the diagonal not counted
  EXPECT_DOUBLE_EQ(thresholds[1], 0.0);  // two edges: all kept
  EXPECT_DOUBLE_EQ(thresholds[4], 0.0);
  const WeightMatrix M = mutualNeighbourGraph(W, thresholds);
  EXPECT_DOUBLE_EQ(M.coeff(0, 1), 0.9);
  EXPECT_DOUBLE_EQ(M.coeff(2, 0), 0.8);
  EXPECT_DOUBLE_EQ(M.coeff(0, 3), 0.0);
  EXPECT_DOUBLE_EQ(M.coeff(3, 0), 0.0);
  EXPECT_DOUBLE_EQ(M.coeff(3, 4), 0.6);
  for (int i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(M.coeff(i, i), 1.0);  // the diagonal stays
  EXPECT_EQ(M.nonZeros(), 2 * 4 + 5);
  // Ties at the threshold are all kept.
  const WeightMatrix T = buildWeightMatrix(4, {{0, 1, 0.5}, {0, 2, 0.5}, {0, 3, 0.5}});
  EXPECT_EQ(mutualNeighbourGraph(T, neighbourThresholds(T, 1)).nonZeros(), 6);
  EXPECT_THROW(mutualNeighbourGraph(W, {0.0}), std::invalid_argument);
  // No nodes: an empty graph.
  const WeightMatrix none(0, 0);
  EXPECT_EQ(mutualNeighbourGraph(none, neighbourThresholds(none, 3)).rows(), 0);
}

TEST(ObservationGraph, MutualNeighboursIntoAReusedMatrixAreTheSameGraph) {
  const WeightMatrix W =
      buildWeightMatrix(5, {{0, 1, 0.9}, {0, 2, 0.8}, {0, 3, 0.3}, {1, 2, 0.7}, {3, 4, 0.6}}, 1.0);
  const WeightMatrix small = buildWeightMatrix(2, {{0, 1, 0.5}});
  WeightMatrix kept;
  // A buffer that held a larger graph, then a smaller one: each time the
  // entries W pruned by the rule keeps, written independently with Eigen's prune.
  for (const WeightMatrix* g : {&W, &small, &W}) {
    const std::vector<double> thresholds = neighbourThresholds(*g, 2);
    mutualNeighbourGraph(*g, thresholds, kept);
    WeightMatrix pruned = *g;
    pruned.prune([&thresholds](const Eigen::Index& i, const Eigen::Index& j, const double& w) {
      return i == j || (w >= thresholds[std::size_t(i)] && w >= thresholds[std::size_t(j)]);
    });
    ASSERT_EQ(kept.rows(), pruned.rows());
    ASSERT_EQ(kept.nonZeros(), pruned.nonZeros());
    EXPECT_TRUE(kept.isCompressed());
    for (Eigen::Index k = 0; k < pruned.outerSize(); ++k) {
      WeightMatrix::InnerIterator a(kept, k), b(pruned, k);
      for (; a && b; ++a, ++b) {
        EXPECT_EQ(a.row(), b.row());
        EXPECT_EQ(a.value(), b.value());
      }
      EXPECT_FALSE(a || b) << "column " << k;
    }
    EXPECT_EQ(mutualNeighbourGraph(*g, thresholds).nonZeros(), pruned.nonZeros());
  }
  EXPECT_THROW(mutualNeighbourGraph(kept, neighbourThresholds(kept, 2), kept), std::invalid_argument);
}

TEST(ObservationGraph, MutualNeighbourCountGrowsWithTheMedianNumberOfNeighbours) {
  // A path of 9 nodes: 2 neighbours each but the ends (median 2).
  std::vector<WeightedPair> path;
  for (int i = 0; i + 1 < 9; ++i) path.push_back({i, i + 1, 1.0});
  const WeightMatrix W = buildWeightMatrix(9, path, 1.0);
  EXPECT_EQ(mutualNeighbourCount(W, 1, 0.0), 1);
  EXPECT_EQ(mutualNeighbourCount(W, 1, 2.0), 4);  // 2.0 x 2
  EXPECT_EQ(mutualNeighbourCount(W, 5, 2.0), 5);
  EXPECT_EQ(mutualNeighbourCount(WeightMatrix(0, 0), 3, 1.0), 3);
}
