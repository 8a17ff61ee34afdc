// Ncut of eq. (1)-(3) and the recursive partition of sec. II-B on small
// graphs whose answers are computed by hand.
#include <obsgroup/partition/recursive_partitioner.h>
#include <obsgroup/spectral/normalized_cut.h>
#include <obsgroup/spectral/spectral_bisection.h>

#include <gtest/gtest.h>

using namespace obsgroup;

namespace {

std::vector<bool> sideA(int n, std::vector<int> a) {
  std::vector<bool> in_a(n, false);
  for (int i : a) in_a[i] = true;
  return in_a;
}

/// Two triangles {0,1,2} and {3,4,5} with unit edges, joined by 2-3 of weight 0.1.
WeightMatrix twoCliques() {
  return buildWeightMatrix(6, {{0, 1, 1}, {0, 2, 1}, {1, 2, 1}, {3, 4, 1}, {3, 5, 1}, {4, 5, 1}, {2, 3, 0.1}});
}

WeightMatrix uniformClique(int k, double w, double diagonal) {
  std::vector<WeightedPair> pairs;
  for (int i = 0; i < k; ++i)
    for (int j = i + 1; j < k; ++j) pairs.push_back({i, j, w});
  return buildWeightMatrix(k, pairs, diagonal);
}

}  // namespace

TEST(NormalizedCut, TwoCliquesJoinedByAWeakEdge) {
  // cut = 0.1; assoc(A,V) = 2 + 2 + 2.1 = 6.1 = assoc(B,V); Ncut = 0.2 / 6.1.
  const CutValues v = normalizedCut(twoCliques(), sideA(6, {0, 1, 2}));
  EXPECT_DOUBLE_EQ(v.cut, 0.1);
  EXPECT_DOUBLE_EQ(v.assoc_a, 6.1);
  EXPECT_DOUBLE_EQ(v.assoc_b, 6.1);
  EXPECT_NEAR(v.ncut, 0.2 / 6.1, 1e-15);

  // A worse split: {0} against the rest. cut = 2, assoc(A) = 2, assoc(B) = 12.2 - 2.
  EXPECT_NEAR(normalizedCut(twoCliques(), sideA(6, {0})).ncut, 2.0 / 2.0 + 2.0 / 10.2, 1e-15);
}

TEST(NormalizedCut, SpectralBisectionFindsTheWeakEdge) {
  for (SplitCriterion c : {SplitCriterion::Mean, SplitCriterion::Sign, SplitCriterion::BestNcut}) {
    const Bisection b = spectralBisection(twoCliques(), c);
    ASSERT_TRUE(b.valid) << toString(c);
    EXPECT_EQ(b.in_a, (std::vector<bool>{true, true, true, false, false, false})) << toString(c);
    EXPECT_NEAR(b.cut.ncut, 0.2 / 6.1, 1e-12) << toString(c);
  }
}

TEST(NormalizedCut, PartitionOfTwoCliquesStopsAtTheCliques) {
  const Partition p = recursivePartition(twoCliques());
  ASSERT_EQ(p.groups.size(), 2u);
  EXPECT_EQ(p.groups[0], (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(p.groups[1], (std::vector<int>{3, 4, 5}));
  EXPECT_NEAR(p.splits[0].ncut, 0.2 / 6.1, 1e-12);
  EXPECT_EQ(p.splits[0].kind, SplitNode::Kind::Bisection);
  // A triangle's best split {u} | {v, w}: cut 2, assoc 2 and 4, Ncut 1.5 >= 1.
  for (int child : p.splits[0].children) {
    EXPECT_FALSE(p.splits[child].accepted);
    EXPECT_NEAR(p.splits[child].ncut, 1.5, 1e-9);
    EXPECT_EQ(p.splits[child].outcome, SplitNode::Outcome::NcutAboveThreshold);
  }
}

TEST(NormalizedCut, PathGraph) {
  // 0-1-2-3 with unit weights: {0,1}|{2,3} has cut 1 and assoc 3 on each side.
  const WeightMatrix W = buildWeightMatrix(4, {{0, 1, 1}, {1, 2, 1}, {2, 3, 1}});
  EXPECT_NEAR(normalizedCut(W, sideA(4, {0, 1})).ncut, 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(normalizedCut(W, sideA(4, {0})).ncut, 1.0 / 1.0 + 1.0 / 5.0, 1e-15);
  const Bisection b = spectralBisection(W, SplitCriterion::Mean);
  EXPECT_EQ(b.in_a, (std::vector<bool>{true, true, false, false}));
  EXPECT_NEAR(b.cut.ncut, 2.0 / 3.0, 1e-12);
  // Each half is a single edge: {0}|{1} inside it has Ncut 1/1 + 1/1 = 2, so it stays.
  const Partition p = recursivePartition(W);
  ASSERT_EQ(p.groups.size(), 2u);
  EXPECT_EQ(p.groups[0], (std::vector<int>{0, 1}));
  EXPECT_EQ(p.groups[1], (std::vector<int>{2, 3}));
}

TEST(NormalizedCut, IsolatedNode) {
  // A triangle and node 3 with no edge: Ncut({3}, rest) = 0 (its assoc is 0).
  const WeightMatrix W = buildWeightMatrix(4, {{0, 1, 1}, {0, 2, 1}, {1, 2, 1}});
  const CutValues v = normalizedCut(W, sideA(4, {3}));
  EXPECT_EQ(v.cut, 0.0);
  EXPECT_EQ(v.assoc_a, 0.0);
  EXPECT_EQ(v.ncut, 0.0);
  const Partition p = recursivePartition(W);
  ASSERT_EQ(p.groups.size(), 2u);
  EXPECT_EQ(p.groups[0], (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(p.groups[1], (std::vector<int>{3}));
  EXPECT_EQ(p.splits[0].kind, SplitNode::Kind::Components);
  EXPECT_EQ(p.splits[0].ncut, 0.0);
}

TEST(NormalizedCut, ThreeDisconnectedComponents) {
  const WeightMatrix W = buildWeightMatrix(7, {{0, 4, 0.5}, {1, 2, 0.3}, {2, 6, 0.9}, {3, 5, 0.2}});
  const Partition p = recursivePartition(W);
  ASSERT_EQ(p.groups.size(), 3u);
  EXPECT_EQ(p.groups[0], (std::vector<int>{0, 4}));
  EXPECT_EQ(p.groups[1], (std::vector<int>{1, 2, 6}));
  EXPECT_EQ(p.groups[2], (std::vector<int>{3, 5}));
  EXPECT_EQ(p.splits[0].kind, SplitNode::Kind::Components);
  EXPECT_EQ(p.splits[0].children.size(), 3u);
  EXPECT_EQ(p.group_of, (std::vector<int>{0, 1, 1, 2, 0, 2, 1}));
}

TEST(NormalizedCut, UnitDiagonalSplitsACliqueToSingletonsZeroDiagonalKeepsIt) {
  // Bisecting a uniform clique of k nodes and weight w, any sizes a + b = k:
  // unit diagonal: Ncut = k w / (1 + (k-1) w) < 1; zero diagonal: k / (k-1) > 1.
  const int k = 5;
  const double w = 0.5;
  const auto split = sideA(k, {0, 1});
  EXPECT_NEAR(normalizedCut(uniformClique(k, w, 1.0), split).ncut, k * w / (1 + (k - 1) * w), 1e-14);
  EXPECT_NEAR(normalizedCut(uniformClique(k, w, 0.0), split).ncut, double(k) / (k - 1), 1e-14);

  EXPECT_EQ(recursivePartition(uniformClique(k, w, 1.0)).groups.size(), std::size_t(k));
  EXPECT_EQ(recursivePartition(uniformClique(k, w, 0.0)).groups.size(), 1u);
}

TEST(NormalizedCut, MinGroupSizeAndMaxDepth) {
  // A pair {0,1} hangs on a dense four {2,3,4,5} by a weak edge: the split
  // has a low Ncut, but gives a group of two.
  const WeightMatrix W = buildWeightMatrix(
      6, {{0, 1, 1.0}, {1, 2, 0.05}, {2, 3, 1.0}, {3, 4, 1.0}, {4, 5, 1.0}, {2, 4, 1.0}, {3, 5, 1.0}});
  Partition p = recursivePartition(W);
  ASSERT_EQ(p.groups.size(), 2u);
  EXPECT_EQ(p.groups[0], (std::vector<int>{0, 1}));
  PartitionOptions options;
  options.min_group_size = 3;
  p = recursivePartition(W, options);
  ASSERT_EQ(p.groups.size(), 1u);
  EXPECT_TRUE(p.splits[0].attempted);
  EXPECT_LT(p.splits[0].ncut, 1.0);
  EXPECT_EQ(p.splits[0].outcome, SplitNode::Outcome::GroupTooSmall);
  options.min_group_size = 4;  // 6 nodes cannot make two groups of 4: not even tried
  p = recursivePartition(W, options);
  ASSERT_EQ(p.groups.size(), 1u);
  EXPECT_FALSE(p.splits[0].attempted);
  EXPECT_EQ(p.splits[0].outcome, SplitNode::Outcome::TooFewNodes);

  options = {};
  options.max_depth = 0;
  p = recursivePartition(twoCliques(), options);
  ASSERT_EQ(p.groups.size(), 1u);
  EXPECT_EQ(p.splits[0].outcome, SplitNode::Outcome::MaxDepth);

  options = {};
  options.ncut_threshold = 0.01;  // below the cliques' 0.0328
  EXPECT_EQ(recursivePartition(twoCliques(), options).groups.size(), 1u);
}

TEST(NormalizedCut, EmptyAndSingleNodeGraphs) {
  EXPECT_TRUE(recursivePartition(WeightMatrix(0, 0)).groups.empty());
  const Partition one = recursivePartition(buildWeightMatrix(1, {}));
  ASSERT_EQ(one.groups.size(), 1u);
  EXPECT_EQ(one.groups[0], std::vector<int>{0});
}
