// The Fiedler vector of eq. (10)-(11) and the split criteria of sec. II-A.
#include <obsgroup/spectral/fiedler_vector.h>
#include <obsgroup/partition/recursive_partitioner.h>
#include <obsgroup/spectral/spectral_bisection.h>

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <random>

using namespace obsgroup;

namespace {

/// A route-like graph: nodes along a path, each linked to its next `reach`
/// nodes with random weights, and four weak spots where the route passes
/// doors (what a robot's log gives).
WeightMatrix routeGraph(int n, int reach, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> weight(0.2, 1.0);
  std::vector<WeightedPair> pairs;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j <= std::min(n - 1, i + reach); ++j) {
      double w = weight(rng) / (j - i);
      if ((i * 5) / n != (j * 5) / n) w *= 0.05;  // a door between five "rooms"
      pairs.push_back({i, j, w});
    }
  return buildWeightMatrix(n, pairs);
}

double residual(const WeightMatrix& W, const FiedlerResult& f) {
  // || (D - W) y - lambda D y || / || D y ||, eq. (10)
  const Eigen::VectorXd d = degrees(W);
  const Eigen::VectorXd Dy = d.cwiseProduct(f.y);
  return (Dy - W * f.y - f.eigenvalue * Dy).norm() / Dy.norm();
}

FiedlerOptions withSolver(EigenSolver solver) {
  FiedlerOptions options;
  options.solver = solver;
  return options;
}

/// The dense and Spectra solvers give the same eigenpair of eq. (10).
void expectSolversAgree(const WeightMatrix& W) {
  const FiedlerResult dense = fiedlerVector(W, withSolver(EigenSolver::Dense));
  const FiedlerResult sparse = fiedlerVector(W, withSolver(EigenSolver::Sparse));
  EXPECT_FALSE(dense.sparse);
  EXPECT_TRUE(sparse.sparse);
  EXPECT_LT(residual(W, dense), 1e-8);
  EXPECT_LT(residual(W, sparse), 1e-8);
  EXPECT_NEAR(dense.eigenvalue, sparse.eigenvalue, 1e-10);
  // Same vector: the sign is fixed by both, so no "up to sign" is needed.
  EXPECT_LT((dense.y - sparse.y).cwiseAbs().maxCoeff(), 1e-6 * dense.y.cwiseAbs().maxCoeff());
}

}  // namespace

TEST(Fiedler, DenseAndSparseAgreeOnAThousandNodes) {
  const WeightMatrix W = routeGraph(1000, 8, 7);
  expectSolversAgree(W);
  const FiedlerOptions dense_options = withSolver(EigenSolver::Dense);
  const FiedlerOptions sparse_options = withSolver(EigenSolver::Sparse);
  for (SplitCriterion c : {SplitCriterion::Mean, SplitCriterion::Sign, SplitCriterion::BestNcut}) {
    const Bisection a = spectralBisection(W, c, dense_options);
    const Bisection b = spectralBisection(W, c, sparse_options);
    EXPECT_EQ(a.in_a, b.in_a) << toString(c);
    EXPECT_NEAR(a.cut.ncut, b.cut.ncut, 1e-12) << toString(c);
  }
}

TEST(Fiedler, DenseAndSparseAgreeOnADenseGraph) {
  // Heavily overlapping observations give dense graphs: every pair linked,
  // three clusters. Spectra then works on the normalized adjacency (no
  // factorisation); it must agree with the dense solver all the same.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> weight(0.5, 1.0);
  std::vector<WeightedPair> pairs;
  const int n = 300;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) pairs.push_back({i, j, weight(rng) * ((i * 3) / n == (j * 3) / n ? 1.0 : 0.05)});
  const WeightMatrix W = buildWeightMatrix(n, pairs);
  expectSolversAgree(W);
  EXPECT_EQ(spectralBisection(W, SplitCriterion::Mean, withSolver(EigenSolver::Dense)).in_a,
            spectralBisection(W, SplitCriterion::Mean, withSolver(EigenSolver::Sparse)).in_a);
}

TEST(Fiedler, IsTheSecondSmallestGeneralizedEigenvector) {
  const WeightMatrix W = routeGraph(60, 4, 3);
  const FiedlerResult f = fiedlerVector(W, {EigenSolver::Dense});
  // Reference: the generalized problem (D - W) y = lambda D y solved directly.
  const Eigen::MatrixXd Wd(W);
  const Eigen::MatrixXd D = degrees(W).asDiagonal();
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ref(D - Wd, D);
  EXPECT_NEAR(f.eigenvalue, ref.eigenvalues()[1], 1e-12);
  EXPECT_NEAR(ref.eigenvalues()[0], 0.0, 1e-12);
  Eigen::VectorXd y = ref.eigenvectors().col(1);
  y *= f.y.norm() / y.norm();
  if (y.dot(f.y) < 0) y = -y;
  EXPECT_LT((y - f.y).norm(), 1e-8 * y.norm());
  // y is D-orthogonal to y_0 = 1 (sec. II-A).
  EXPECT_NEAR(degrees(W).dot(f.y), 0.0, 1e-10);
}

TEST(Fiedler, RejectsGraphsItCannotSolve) {
  EXPECT_THROW(fiedlerVector(buildWeightMatrix(1, {})), std::invalid_argument);
  EXPECT_THROW(fiedlerVector(buildWeightMatrix(3, {{0, 1, 1.0}})), std::invalid_argument);
}

TEST(Fiedler, AutoUsesSparseAboveTheThreshold) {
  const WeightMatrix W = routeGraph(300, 5, 11);
  FiedlerOptions options;
  options.dense_max_size = 299;
  EXPECT_TRUE(fiedlerVector(W, options).sparse);
  options.dense_max_size = 300;
  EXPECT_FALSE(fiedlerVector(W, options).sparse);
}

TEST(SpectralBisection, BestNcutIsTheMinimumOverAllThresholds) {
  const WeightMatrix W = routeGraph(200, 6, 5);
  const Bisection best = spectralBisection(W, SplitCriterion::BestNcut);
  // Brute force: every threshold between consecutive sorted values of y.
  std::vector<double> values(best.fiedler.y.data(), best.fiedler.y.data() + best.fiedler.y.size());
  std::sort(values.begin(), values.end());
  double minimum = 2.0;
  for (std::size_t k = 0; k + 1 < values.size(); ++k) {
    std::vector<bool> in_a(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) in_a[i] = best.fiedler.y[i] > values[k];
    minimum = std::min(minimum, normalizedCut(W, in_a).ncut);
  }
  EXPECT_NEAR(best.cut.ncut, minimum, 1e-12);
  EXPECT_LE(best.cut.ncut, spectralBisection(W, SplitCriterion::Mean).cut.ncut + 1e-15);
  EXPECT_LE(best.cut.ncut, spectralBisection(W, SplitCriterion::Sign).cut.ncut + 1e-15);
}

TEST(SpectralBisection, CriteriaUseTheirThresholds) {
  const WeightMatrix W = routeGraph(100, 4, 9);
  const Bisection mean = spectralBisection(W, SplitCriterion::Mean);
  const Bisection sign = spectralBisection(W, SplitCriterion::Sign);
  EXPECT_DOUBLE_EQ(mean.threshold, mean.fiedler.y.mean());
  EXPECT_EQ(sign.threshold, 0.0);
  for (Eigen::Index i = 0; i < W.rows(); ++i) {
    EXPECT_EQ(mean.in_a[i], mean.fiedler.y[i] > mean.threshold);
    EXPECT_EQ(sign.in_a[i], sign.fiedler.y[i] > 0.0);
  }
  EXPECT_EQ(splitCriterionFromString("best"), SplitCriterion::BestNcut);
  EXPECT_THROW(splitCriterionFromString("median"), std::invalid_argument);
}

TEST(SpectralBisection, BestNcutHonoursTheMinimumSide) {
  const WeightMatrix W = routeGraph(100, 4, 9);
  const Bisection b = spectralBisection(W, SplitCriterion::BestNcut, {}, 45);
  const auto size_a = std::count(b.in_a.begin(), b.in_a.end(), true);
  EXPECT_GE(size_a, 45);
  EXPECT_LE(size_a, 55);
}

TEST(Fiedler, AnyEliminationOrderGivesTheSameVector) {
  // The elimination order only changes the fill of the factor (the speed),
  // never the eigenvector: AMD's, the natural one, a reversed and a shuffled one.
  const WeightMatrix W = routeGraph(1000, 8, 11);
  const FiedlerResult amd = fiedlerVector(W, withSolver(EigenSolver::Sparse));
  std::vector<int> natural(1000), reversed(1000), shuffled(1000);
  for (int i = 0; i < 1000; ++i) natural[i] = shuffled[i] = i, reversed[i] = 999 - i;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(5));
  for (const auto& rank : {natural, reversed, shuffled}) {
    FiedlerOptions options = withSolver(EigenSolver::Sparse);
    options.elimination_rank = rank;
    const FiedlerResult ranked = fiedlerVector(W, options);
    EXPECT_TRUE(ranked.sparse);
    EXPECT_NEAR(ranked.eigenvalue, amd.eigenvalue, 1e-12);
    EXPECT_LT((ranked.y - amd.y).cwiseAbs().maxCoeff(), 1e-8 * amd.y.cwiseAbs().maxCoeff());
  }
  FiedlerOptions wrong = withSolver(EigenSolver::Sparse);
  wrong.elimination_rank = {0, 1, 2};
  EXPECT_THROW(fiedlerVector(W, wrong), std::invalid_argument);
}

/// The grounded Laplacian's pattern (all nodes but the last), and the
/// elimination ranks that hand fiedlerVector an order of it.
WeightMatrix groundedPattern(const WeightMatrix& W) {
  const int n = int(W.rows());
  WeightMatrix identity(n, n);
  identity.setIdentity();
  return WeightMatrix(W + identity).topLeftCorner(n - 1, n - 1);
}
std::vector<int> ranksOf(const int* eliminated, int n) {
  std::vector<int> rank(std::size_t(n), n - 1);
  for (int k = 0; k + 1 < n; ++k) rank[std::size_t(eliminated[k])] = k;
  return rank;
}
/// Entries of the factor below the diagonal, over those of the matrix, in
/// the order `eliminated`.
double factorFill(const WeightMatrix& pattern, const std::vector<int>& eliminated) {
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> order(Eigen::Index(eliminated.size()));
  std::copy(eliminated.begin(), eliminated.end(), order.indices().data());
  WeightMatrix spd = pattern;
  for (int k = 0; k < spd.outerSize(); ++k)
    for (WeightMatrix::InnerIterator it(spd, k); it; ++it) it.valueRef() = it.row() == it.col() ? 1e3 : -1.0;
  WeightMatrix permuted;
  permuted.selfadjointView<Eigen::Upper>() = spd.selfadjointView<Eigen::Lower>().twistedBy(order.inverse());
  Eigen::SimplicialLDLT<WeightMatrix, Eigen::Upper, Eigen::NaturalOrdering<int>> ldlt(permuted);
  return double(ldlt.matrixL().nestedExpression().nonZeros()) / double((pattern.nonZeros() - pattern.rows()) / 2);
}

TEST(Fiedler, ItsOwnOrderingIsMaximumCardinalitySearchWhereThatDoesNotFillIn) {
  // A route's overlaps reach a few scans ahead: a chordal graph, whose factor
  // in the search's order has no fill. fiedlerVector orders its grounded
  // Laplacian so, from the pattern alone: handing it the same order as ranks
  // gives the very same factor, hence the same bits.
  for (const WeightMatrix& W : {routeGraph(700, 8, 17), routeGraph(400, 20, 19)}) {
    const int n = int(W.rows());
    const WeightMatrix pattern = groundedPattern(W);
    const std::vector<int> search = maximumCardinalityOrder(pattern);
    ASSERT_EQ(int(search.size()), n - 1);
    std::vector<int> sorted = search;
    std::sort(sorted.begin(), sorted.end());
    for (int k = 0; k + 1 < n; ++k) ASSERT_EQ(sorted[std::size_t(k)], k);  // a permutation
    EXPECT_EQ(factorFill(pattern, search), 1.0);
    FiedlerOptions options = withSolver(EigenSolver::Sparse);
    options.elimination_rank = ranksOf(search.data(), n);
    const FiedlerResult own = fiedlerVector(W, withSolver(EigenSolver::Sparse));
    const FiedlerResult given = fiedlerVector(W, options);
    ASSERT_TRUE(own.sparse && given.sparse);
    EXPECT_EQ(own.eigenvalue, given.eigenvalue);
    EXPECT_EQ(own.y, given.y);
  }
}

/// Maximum cardinality search by its definition, in O(n^2): each step
/// numbers (from the last position down) the unnumbered node with the most
/// numbered neighbours, among those the one whose count rose last, at the
/// start the lowest index.
std::vector<int> searchByDefinition(const WeightMatrix& A) {
  const int n = int(A.cols());
  const auto size = std::size_t(n);
  std::vector<int> count(size, 0), rose(size), eliminated(size);
  std::vector<char> numbered(std::size_t(n), 0);
  for (int v = 0; v < n; ++v) rose[std::size_t(v)] = -v;
  int clock = 0;
  for (int k = n - 1; k >= 0; --k) {
    int v = -1;
    for (int u = 0; u < n; ++u)
      if (!numbered[std::size_t(u)] &&
          (v < 0 || count[std::size_t(u)] > count[std::size_t(v)] ||
           (count[std::size_t(u)] == count[std::size_t(v)] && rose[std::size_t(u)] > rose[std::size_t(v)])))
        v = u;
    numbered[std::size_t(v)] = 1;
    eliminated[std::size_t(k)] = v;
    for (WeightMatrix::InnerIterator it(A, v); it; ++it)
      if (!numbered[std::size_t(it.row())]) ++count[std::size_t(it.row())], rose[std::size_t(it.row())] = ++clock;
  }
  return eliminated;
}

TEST(Fiedler, MaximumCardinalitySearchBreaksTiesAsItsDefinition) {
  // The order decides the factor's bits: it must not depend on how the
  // buckets are kept. Route graphs, and random graphs with many ties.
  std::mt19937 rng(5);
  std::vector<WeightMatrix> graphs = {routeGraph(300, 8, 3), routeGraph(200, 20, 4)};
  for (int n : {1, 2, 30, 120}) {
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < n; ++i) entries.emplace_back(i, i, 1.0);
    std::uniform_int_distribution<int> node(0, n - 1);
    for (int e = 0; e < 3 * n; ++e) {
      const int a = node(rng), b = node(rng);
      if (a != b) entries.emplace_back(a, b, 1.0), entries.emplace_back(b, a, 1.0);
    }
    WeightMatrix g(n, n);
    g.setFromTriplets(entries.begin(), entries.end(), [](double a, double) { return a; });
    graphs.push_back(g);
  }
  for (const WeightMatrix& g : graphs) EXPECT_EQ(maximumCardinalityOrder(g), searchByDefinition(g));
}

TEST(Fiedler, ItsOwnOrderingIsEigensAMDOrderingWhereTheSearchFillsIn) {
  // A grid of 24 x 24 nodes is all loops: the search's order fills in more
  // than the 1.5 times the matrix's entries it is allowed, and fiedlerVector
  // orders by AMD instead, computed without Eigen's AMDOrdering's copies.
  // Handing it Eigen's AMDOrdering of the same pattern as ranks must give the
  // very same factor, hence the same bits.
  const int side = 24;
  std::vector<WeightedPair> pairs;
  for (int x = 0; x < side; ++x)
    for (int y = 0; y < side; ++y) {
      const int i = x * side + y;
      if (x + 1 < side) pairs.push_back({i, i + side, 0.5 + 0.01 * ((i * 7) % 11)});
      if (y + 1 < side) pairs.push_back({i, i + 1, 0.5 + 0.01 * ((i * 3) % 13)});
    }
  const WeightMatrix W = buildWeightMatrix(side * side, pairs);
  const int n = int(W.rows());
  const WeightMatrix pattern = groundedPattern(W);
  ASSERT_GT(factorFill(pattern, maximumCardinalityOrder(pattern)), 1.5);
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> amd;
  Eigen::AMDOrdering<int>()(pattern, amd);
  FiedlerOptions options = withSolver(EigenSolver::Sparse);
  options.elimination_rank = ranksOf(amd.indices().data(), n);
  const FiedlerResult own = fiedlerVector(W, withSolver(EigenSolver::Sparse));
  const FiedlerResult eigens = fiedlerVector(W, options);
  ASSERT_TRUE(own.sparse && eigens.sparse);
  EXPECT_EQ(own.eigenvalue, eigens.eigenvalue);
  EXPECT_EQ(own.y, eigens.y);
}

TEST(Fiedler, AWorkspaceReusedAcrossSizesGivesTheBitsOfAFreshSolve) {
  // One workspace through solves of a large, a small, a dense and again a
  // large graph (its buffers keep the largest's storage and the last
  // factor): each result must be the bits of a solve with none.
  FiedlerWorkspace workspace;
  const FiedlerOptions sparse = withSolver(EigenSolver::Sparse);
  for (const WeightMatrix& W : {routeGraph(1200, 8, 23), routeGraph(150, 4, 29), routeGraph(300, 60, 31),
                                routeGraph(900, 10, 37)}) {
    const FiedlerResult fresh = fiedlerVector(W, sparse);
    const FiedlerResult reused = fiedlerVector(W, sparse, workspace);
    EXPECT_GT(workspace.heldBytes(), 0u);
    EXPECT_EQ(reused.sparse, fresh.sparse);
    EXPECT_EQ(reused.eigenvalue, fresh.eigenvalue);
    EXPECT_EQ(reused.y, fresh.y);
    const Bisection b = spectralBisection(W, SplitCriterion::BestNcut, sparse, 1, workspace);
    EXPECT_EQ(b.fiedler.y, fresh.y);
  }
}

TEST(Fiedler, AUsersEliminationOrderGivesThePartitionOfTheSharedOne) {
  // recursivePartition orders the whole graph once and hands each subgraph its
  // members' ranks; a user's order of the whole graph is used the same way and
  // must give the same partition (the order changes the speed only), and one
  // of the wrong length is refused.
  const WeightMatrix W = routeGraph(1500, 8, 13);
  PartitionOptions options;
  options.eigen.solver = EigenSolver::Sparse;
  const Partition shared = recursivePartition(W, options);
  options.eigen.elimination_rank.resize(1500);
  for (int i = 0; i < 1500; ++i) options.eigen.elimination_rank[i] = 1499 - i;
  const Partition users = recursivePartition(W, options);
  EXPECT_GE(shared.groups.size(), 5u);  // the five rooms at least
  EXPECT_EQ(shared.groups, users.groups);
  ASSERT_EQ(shared.splits.size(), users.splits.size());
  for (std::size_t s = 0; s < shared.splits.size(); ++s) EXPECT_NEAR(shared.splits[s].ncut, users.splits[s].ncut, 1e-9);
  options.eigen.elimination_rank = {1, 2, 3};
  EXPECT_THROW(recursivePartition(W, options), std::invalid_argument);
}

// What FiedlerResult promises when lambda_1 is repeated: on a cycle every
// vector of a two-dimensional eigenspace is a Fiedler vector. Both solvers
// find lambda_1 with a small residual, each repeats itself exactly, and the
// vectors are allowed to differ (they do here).
TEST(Fiedler, RepeatedEigenvalueGuaranteesTheEigenvalueNotTheVector) {
  const int n = 100;
  std::vector<WeightedPair> pairs;
  for (int i = 0; i < n; ++i) pairs.push_back({i, (i + 1) % n, 1.0});
  const WeightMatrix W = buildWeightMatrix(n, pairs);
  const double lambda1 = 1.0 - std::cos(2.0 * M_PI / n);  // eigenvalues of the normalized cycle Laplacian
  for (EigenSolver solver : {EigenSolver::Dense, EigenSolver::Sparse}) {
    const FiedlerResult first = fiedlerVector(W, withSolver(solver));
    EXPECT_NEAR(first.eigenvalue, lambda1, 1e-9);
    EXPECT_LT(residual(W, first), 1e-8);
    EXPECT_EQ(fiedlerVector(W, withSolver(solver)).y, first.y);
  }
}
