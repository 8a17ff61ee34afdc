#include "obsgroup/spectral/fiedler_vector.h"

#include <Eigen/Dense>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Spectra/SymEigsSolver.h>

#include <algorithm>
#include <numeric>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace obsgroup {
namespace {

/// Normalized Laplacian of eq. (11): I - D^-1/2 W D^-1/2, written as
/// D^-1/2 (D - W) D^-1/2 so that a non-zero diagonal of W is honoured; into
/// L's storage.
void normalizedLaplacian(const WeightMatrix& W, const Eigen::VectorXd& inv_sqrt_d, WeightMatrix& L) {
  // D^-1/2 (D - W) D^-1/2 in one pass over W's columns, each written straight
  // into L's compressed arrays with its diagonal entry in row order (W's
  // pattern plus the diagonal: the size is known up front). The arithmetic is
  // that of the matrix expression, (s_i * ([i == j] d_i - w_ij)) * s_j, so the
  // results are the same bits. At the sizes of an online update's nodes the
  // element-wise insertion this replaces was a twentieth of the stream.
  const Eigen::Index n = W.outerSize();
  const Eigen::VectorXd diagonal = inv_sqrt_d.cwiseInverse().cwiseAbs2();
  Eigen::Index entries = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    bool has_diagonal = false;
    for (WeightMatrix::InnerIterator it(W, j); it; ++it) {
      ++entries;
      has_diagonal = has_diagonal || it.row() == j;
    }
    if (!has_diagonal) ++entries;
  }
  L.resize(n, n);
  L.resizeNonZeros(entries);
  int* outer = L.outerIndexPtr();
  int* inner = L.innerIndexPtr();
  double* value = L.valuePtr();
  Eigen::Index k = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    outer[j] = static_cast<int>(k);
    const double s_j = inv_sqrt_d[j];
    bool diagonal_done = false;
    const auto put = [&](Eigen::Index i, double minus_w) {
      const double x = i == j ? minus_w + diagonal[j] : minus_w;
      inner[k] = static_cast<int>(i);
      value[k] = (inv_sqrt_d[i] * x) * s_j;
      ++k;
    };
    for (WeightMatrix::InnerIterator it(W, j); it; ++it) {
      if (!diagonal_done && it.row() > j) {
        put(j, 0.0);
        diagonal_done = true;
      }
      if (it.row() == j) diagonal_done = true;
      put(it.row(), -it.value());
    }
    if (!diagonal_done) put(j, 0.0);
  }
  outer[n] = static_cast<int>(k);
}

using Permutation = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;

/// A symmetric sparse matrix without its last row and column, copied
/// straight into B's compressed arrays, sized exactly (a block assignment
/// grows its storage as it goes, a copy and fresh pages at each step).
void withoutLastNode(const WeightMatrix& A, WeightMatrix& B) {
  const Eigen::Index m = A.rows() - 1;
  Eigen::Index entries = 0;
  for (Eigen::Index j = 0; j < m; ++j)
    for (WeightMatrix::InnerIterator it(A, j); it && it.row() < m; ++it) ++entries;
  B.resize(m, m);
  B.resizeNonZeros(entries);
  int* outer = B.outerIndexPtr();
  int* inner = B.innerIndexPtr();
  double* value = B.valuePtr();
  Eigen::Index k = 0;
  for (Eigen::Index j = 0; j < m; ++j) {
    outer[j] = static_cast<int>(k);
    for (WeightMatrix::InnerIterator it(A, j); it && it.row() < m; ++it, ++k) {
      inner[k] = static_cast<int>(it.row());
      value[k] = it.value();
    }
  }
  outer[m] = static_cast<int>(k);
}

/// AMD's order of a compressed matrix whose pattern is symmetric, the same
/// as Eigen::AMDOrdering gives. That first forms the pattern of A + A^T from
/// two copies of A (a transpose and a sum); for a symmetric pattern it is
/// A's own, so one copy of A's indices, with the elbow room the ordering
/// asks for reserved up front, is enough. At 10,000 scans those two copies
/// and their fresh pages took a third of an online update's eigen solves.
Permutation amdOrder(const WeightMatrix& A, Eigen::SparseMatrix<double, Eigen::ColMajor, int>& pattern) {
  Permutation order;
  if (!A.isCompressed()) {
    Eigen::AMDOrdering<int>()(A, order);
    return order;
  }
  const Eigen::Index n = A.cols(), entries = A.nonZeros();
  pattern.resize(n, n);
  pattern.reserve(entries + entries / 5 + 2 * n);  // minimum_degree_ordering's elbow room
  pattern.resizeNonZeros(entries);                 // the values are never read
  std::copy(A.outerIndexPtr(), A.outerIndexPtr() + n + 1, pattern.outerIndexPtr());
  std::copy(A.innerIndexPtr(), A.innerIndexPtr() + entries, pattern.innerIndexPtr());
  Eigen::internal::minimum_degree_ordering(pattern, order);
  return order;
}

Permutation maximumCardinalityPermutation(const WeightMatrix& A) {
  Permutation order;
  const std::vector<int> eliminated = maximumCardinalityOrder(A);
  order.resize(Eigen::Index(eliminated.size()));
  std::copy(eliminated.begin(), eliminated.end(), order.indices().data());
  return order;
}

/// The fill-reducing elimination order of a symmetric matrix, as Eigen's
/// orderings give it (entry k: the node eliminated k-th): the nodes by
/// increasing rank when ranks are given (rank[k] for node k; extra entries
/// are ignored), else AMD's.
Permutation eliminationOrder(const WeightMatrix& A, const std::vector<int>& rank,
                             Eigen::SparseMatrix<double, Eigen::ColMajor, int>& pattern) {
  if (rank.empty()) return amdOrder(A, pattern);
  Permutation order;
  order.resize(A.rows());
  std::iota(order.indices().data(), order.indices().data() + A.rows(), 0);
  std::stable_sort(order.indices().data(), order.indices().data() + A.rows(),
                   [&rank](int a, int b) { return rank[a] < rank[b]; });
  return order;
}

/// Eigen's SimplicialLDLT of a matrix already in elimination order (its
/// upper triangle). Its compute() asks whether the ordering is
/// NaturalOrdering<Index>; with int indices it is NaturalOrdering<int>, so
/// Eigen 3.4 copies the matrix twice (a full symmetric copy for an ordering
/// that returns none, then the upper triangle again) before it factorises.
/// The two steps compute() runs after its ordering are called directly, on
/// the matrix itself: the same factor, without the copies.
class PreorderedLDLT : public Eigen::SimplicialLDLT<WeightMatrix, Eigen::Upper, Eigen::NaturalOrdering<int>> {
 public:
  void analyzeInOrder(const WeightMatrix& upper) { analyzePattern_preordered(upper, true); }
  /// Entries of the analysed factor below its diagonal (the symbolic
  /// analysis's count; LDL^T keeps no diagonal in it).
  Eigen::Index factorEntries() const { return m_matrix.nonZeros(); }
  void factorizeInOrder(const WeightMatrix& upper) { factorize_preordered<true>(upper); }
  std::size_t factorBytes() const {
    return std::size_t(m_matrix.data().allocatedSize()) * (sizeof(double) + sizeof(int));
  }
};

}  // namespace

struct FiedlerWorkspace::Buffers {
  WeightMatrix laplacian, grounded, permuted;
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> pattern;
  PreorderedLDLT ldlt;

  static std::size_t bytesOf(const WeightMatrix& m) {
    return std::size_t(m.data().allocatedSize()) * (sizeof(double) + sizeof(int)) +
           std::size_t(m.outerSize() + 1) * sizeof(int);
  }
  std::size_t bytes() const {
    return bytesOf(laplacian) + bytesOf(grounded) + bytesOf(permuted) + bytesOf(pattern) + ldlt.factorBytes();
  }
};

FiedlerWorkspace::FiedlerWorkspace() : buffers_(std::make_unique<Buffers>()) {}
FiedlerWorkspace::~FiedlerWorkspace() = default;
FiedlerWorkspace::FiedlerWorkspace(FiedlerWorkspace&&) noexcept = default;
FiedlerWorkspace& FiedlerWorkspace::operator=(FiedlerWorkspace&&) noexcept = default;
std::size_t FiedlerWorkspace::heldBytes() const { return buffers_ ? buffers_->bytes() : 0; }
FiedlerWorkspace::Buffers& FiedlerWorkspace::buffers() {
  if (!buffers_) buffers_ = std::make_unique<Buffers>();
  return *buffers_;
}

namespace {

using Buffers = FiedlerWorkspace::Buffers;

/// The order of maximum cardinality search is kept while the factor holds at
/// most this many times the entries of the matrix below its diagonal, else
/// the node is ordered by AMD. On the 1,001-scan stream's blocks the search
/// filled in 0.5% (AMD 1.2%); on the sparse solves of six real logs 2-55%
/// (AMD 2-43%); on a grid of loops far more (a test).
constexpr double kMaxSearchFill = 1.5;

/// Spectra operator for P L^+ P, where P projects out z0 = D^1/2 1 (the known
/// null vector of eq. (11)). Its largest eigenvalue is 1/lambda_1, so Lanczos
/// converges at the rate lambda_1/lambda_2 with no shift to tune. L^+ is
/// applied exactly by grounding: for b orthogonal to z0, L x = b has a solution
/// with x_last = 0, found with a Cholesky factor of L without its last row and
/// column (positive definite for a connected graph), factorised in the order
/// of the given ranks, else of maximum cardinality search, or of AMD where
/// that fills in (kMaxSearchFill).
class DeflatedLaplacianInverse {
 public:
  using Scalar = double;

  DeflatedLaplacianInverse(const WeightMatrix& L, Eigen::VectorXd z0, const std::vector<int>& rank, Buffers& buffers)
      : n_(L.rows()), z0_(std::move(z0)), ldlt_(buffers.ldlt) {
    const WeightMatrix& grounded = buffers.grounded;
    withoutLastNode(L, buffers.grounded);
    WeightMatrix& permuted = buffers.permuted;  // upper triangle, in elimination order
    const auto permuteBy = [&](Permutation order) {
      order_ = std::move(order);
      to_eliminated_ = order_.inverse();
      permuted.selfadjointView<Eigen::Upper>() = grounded.selfadjointView<Eigen::Lower>().twistedBy(to_eliminated_);
    };
    if (!rank.empty()) {
      permuteBy(eliminationOrder(grounded, rank, buffers.pattern));
      ldlt_.analyzeInOrder(permuted);
    } else {
      // A node's own order, from its block alone. The blocks of route-like
      // graphs are nearly chordal, where maximum cardinality search orders
      // in linear time with as little fill as AMD or less; AMD where it
      // fills in (a graph of loops).
      const Eigen::Index below_diagonal = (grounded.nonZeros() - grounded.rows()) / 2;
      // The fill is the factor's own symbolic analysis, made once: a count
      // of its own before it took about 4% of the stream's CPU time.
      permuteBy(maximumCardinalityPermutation(grounded));
      ldlt_.analyzeInOrder(permuted);
      if (ldlt_.factorEntries() > Eigen::Index(kMaxSearchFill * double(below_diagonal))) {
        permuteBy(amdOrder(grounded, buffers.pattern));
        ldlt_.analyzeInOrder(permuted);
      }
    }
    ldlt_.factorizeInOrder(permuted);
    if (ldlt_.info() != Eigen::Success)
      throw EigenSolverError("Fiedler vector: the grounded Laplacian could not be factorised");
  }
  Eigen::Index rows() const { return n_; }
  Eigen::Index cols() const { return n_; }

  void perform_op(const double* x_in, double* y_out) const {
    Eigen::Map<const Eigen::VectorXd> x(x_in, n_);
    Eigen::Map<Eigen::VectorXd> y(y_out, n_);
    // Into buffers kept over the solve's applications (about fifteen each,
    // thousands of solves in a stream) rather than three fresh vectors each:
    // the same operations, the same bits.
    b_ = x - z0_ * z0_.dot(x);
    permuted_b_ = to_eliminated_ * b_.head(n_ - 1);
    solved_ = ldlt_.solve(permuted_b_);
    y.head(n_ - 1) = order_ * solved_;
    y[n_ - 1] = 0.0;
    y -= z0_ * z0_.dot(y);
  }

 private:
  Eigen::Index n_;
  Eigen::VectorXd z0_;
  Permutation order_, to_eliminated_;
  PreorderedLDLT& ldlt_;
  mutable Eigen::VectorXd b_, permuted_b_, solved_;
};

/// Spectra operator for P (I - L) P = P D^-1/2 W D^-1/2 P: its largest
/// eigenvalue is 1 - lambda_1. Only matrix-vector products, no factorisation:
/// the better choice on dense graphs (heavily overlapping observations),
/// where a Cholesky factor fills in, and spectral gaps are wide.
class DeflatedNormalizedAdjacency {
 public:
  using Scalar = double;
  DeflatedNormalizedAdjacency(const WeightMatrix& L, Eigen::VectorXd z0, const std::vector<int>& /*rank*/,
                              Buffers& /*buffers*/)
      : L_(L), z0_(std::move(z0)) {}
  Eigen::Index rows() const { return L_.rows(); }
  Eigen::Index cols() const { return L_.cols(); }
  void perform_op(const double* x_in, double* y_out) const {
    Eigen::Map<const Eigen::VectorXd> x(x_in, L_.rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, L_.rows());
    const Eigen::VectorXd b = x - z0_ * z0_.dot(x);
    y = b - L_ * b;
    y -= z0_ * z0_.dot(y);
  }

 private:
  const WeightMatrix& L_;
  Eigen::VectorXd z0_;
};

/// A graph is dense, and the adjacency form tried first, when each node links
/// to at least this share of the others (and to at least 48 of them): then
/// a Cholesky factor would fill in, and the spectral gap is wide. Long
/// route-like graphs have tiny gaps, where plain Lanczos stalls.
constexpr double kDenseGraphShare = 0.125;
constexpr double kDenseGraphDegree = 48.0;

/// Lanczos vectors of each solve (Spectra's ncv). Through the Laplacian's
/// inverse the Fiedler pair has converged after about a dozen steps, and
/// Spectra tests convergence only once its basis is full: a basis of 20 took
/// 21 applications of the operator (each two triangular solves) in every
/// solve of the 1,001-scan stream, a basis of 12 takes 15.0 on average (the
/// extra ones in a restart), the same groups on every dataset measured
/// (docs/performance.md). The product form converges more slowly and keeps a
/// wider basis; the wide one is the retry when a solve did not converge.
constexpr int kInverseLanczosVectors = 12;
constexpr int kProductLanczosVectors = 20;
constexpr int kWideLanczosVectors = 80;

/// The Rayleigh quotient z'Lz of eq. (8) (the eigenvalue, for an
/// eigenvector) and the residual ||L z - (z'Lz) z|| of a unit z: one product.
struct EigenCheck {
  double eigenvalue = 0.0;
  double residual = 0.0;
};

EigenCheck check(const WeightMatrix& L, const Eigen::VectorXd& z) {
  const Eigen::VectorXd Lz = L * z;
  const double lambda = z.dot(Lz);
  return {lambda, (Lz - lambda * z).norm()};
}

/// A computed eigenvector is accepted when its residual is below this. The
/// eigenvalues of L lie in [0, 2], and the Lanczos tolerance (1e-10) leaves
/// residuals around 1e-9 and below on the graphs of the test suite.
constexpr double kMaxResidual = 1e-6;

template <typename Operator>
bool solveSparse(const WeightMatrix& L, const Eigen::VectorXd& z0, const FiedlerOptions& options,
                 Buffers& buffers, int ncv, Eigen::VectorXd& z, EigenCheck& checked) {
  std::optional<Operator> op;
  try {
    op.emplace(L, z0, options.elimination_rank, buffers);
  } catch (const EigenSolverError&) {
    return false;  // e.g. a factorisation that failed: the next solver takes over
  }
  Spectra::SymEigsSolver<Operator> solver(*op, 1, ncv);
  // A fixed start vector, orthogonal to z0, keeps the result deterministic.
  Eigen::VectorXd start = Eigen::VectorXd::LinSpaced(L.rows(), 1.0, 2.0);
  start -= z0 * z0.dot(start);
  solver.init(start.data());
  solver.compute(Spectra::SortRule::LargestAlge, options.max_iterations, options.tolerance);
  if (solver.info() != Spectra::CompInfo::Successful) return false;
  z = solver.eigenvectors().col(0);
  // Spectra's own test is on the operator; the result must also be an
  // eigenvector of L itself, orthogonal to the trivial one.
  if (!z.allFinite() || !(z.norm() > 0.5)) return false;
  z.normalize();
  checked = check(L, z);
  return checked.residual <= kMaxResidual && std::abs(z.dot(z0)) <= kMaxResidual;
}

Eigen::VectorXd solveDense(const WeightMatrix& L) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(Eigen::MatrixXd(L), Eigen::ComputeEigenvectors);
  if (solver.info() != Eigen::Success)
    throw EigenSolverError("Fiedler vector: the dense eigen solver did not converge");
  return solver.eigenvectors().col(1);  // eigenvalues ascend: column 1 is the second smallest
}

/// Fixes the arbitrary sign of an eigenvector: the first component that is
/// clearly non-zero becomes positive, so that every solver returns the same y.
void fixSign(Eigen::VectorXd& y) {
  const double scale = y.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    if (std::abs(y[i]) > 1e-6 * scale) {
      if (y[i] < 0) y = -y;
      return;
    }
  }
}

/// Buffers above this are given back after the solve that needed them: the
/// root of a run of a million scans would otherwise hold gigabytes while the
/// rest of the split tree, whose nodes are smaller, is solved.
constexpr std::size_t kMaxKeptBytes = std::size_t(256) << 20;

}  // namespace

/// Tarjan and Yannakakis (1984): unnumbered nodes wait in buckets by their
/// count of numbered neighbours. O(nodes + entries). A count only grows, so
/// a node enters each bucket at most once: the buckets are stacks in one
/// pool, and a node whose count has grown past a bucket, or that is
/// numbered, is dropped from it when met. The node taken is the last one to
/// enter the fullest bucket (the first among equal counts at the start, the
/// lowest index), as with doubly linked lists, without unlinking.
std::vector<int> maximumCardinalityOrder(const WeightMatrix& A) {
  const int n = int(A.cols());
  const auto size = std::size_t(n);
  std::vector<int> count(size, 0), head(size + 1, -1);
  std::vector<int> pool_node, pool_next;  // the stacks' entries
  pool_node.reserve(size + std::size_t(A.nonZeros()));
  pool_next.reserve(size + std::size_t(A.nonZeros()));
  const auto push = [&](int c, int v) {
    pool_node.push_back(v);
    pool_next.push_back(head[std::size_t(c)]);
    head[std::size_t(c)] = int(pool_node.size()) - 1;
  };
  std::vector<char> numbered(size, 0);
  for (int v = n - 1; v >= 0; --v) push(0, v);
  int most = 0;
  std::vector<int> eliminated(size);
  for (int k = n - 1; k >= 0; --k) {
    int v = -1;
    while (v < 0) {
      const int top = head[std::size_t(most)];
      if (top < 0) {
        --most;
        continue;
      }
      head[std::size_t(most)] = pool_next[std::size_t(top)];
      const int candidate = pool_node[std::size_t(top)];
      if (!numbered[std::size_t(candidate)] && count[std::size_t(candidate)] == most) v = candidate;
    }
    numbered[std::size_t(v)] = 1;
    eliminated[std::size_t(k)] = v;
    for (WeightMatrix::InnerIterator it(A, v); it; ++it) {
      const int u = int(it.row());
      if (numbered[std::size_t(u)]) continue;
      push(++count[std::size_t(u)], u);
      most = std::max(most, count[std::size_t(u)]);
    }
  }
  return eliminated;
}

FiedlerResult fiedlerVector(const WeightMatrix& W, const FiedlerOptions& options) {
  FiedlerWorkspace workspace;
  return fiedlerVector(W, options, workspace);
}

FiedlerResult fiedlerVector(const WeightMatrix& W, const FiedlerOptions& options, FiedlerWorkspace& workspace) {
  struct GiveBackLarge {
    FiedlerWorkspace& w;
    ~GiveBackLarge() {
      if (w.heldBytes() > kMaxKeptBytes) w = FiedlerWorkspace();
    }
  } give_back{workspace};
  Buffers& buffers = workspace.buffers();
  const Eigen::Index n = W.rows();
  if (n < 2) throw std::invalid_argument("Fiedler vector: the graph needs at least two nodes");
  if (!options.elimination_rank.empty() && Eigen::Index(options.elimination_rank.size()) != n)
    throw std::invalid_argument("Fiedler vector: elimination_rank needs one rank per node");
  const Eigen::VectorXd d = degrees(W);
  if (d.minCoeff() <= 0.0)
    throw std::invalid_argument("Fiedler vector: a node has zero degree (split components first)");

  const Eigen::VectorXd inv_sqrt_d = d.cwiseSqrt().cwiseInverse();
  WeightMatrix& L = buffers.laplacian;
  normalizedLaplacian(W, inv_sqrt_d, L);
  const Eigen::VectorXd z0 = d.cwiseSqrt().normalized();  // eq. (11): z0 = D^1/2 1

  FiedlerResult result;
  Eigen::VectorXd z;
  EigenCheck checked;
  const bool want_sparse = options.solver == EigenSolver::Sparse ||
                           (options.solver == EigenSolver::Auto && n > options.dense_max_size);
  if (want_sparse && n > 2) {
    const auto basis = [n](int vectors) { return static_cast<int>(std::min<Eigen::Index>(n, vectors)); };
    const double degree = double(W.nonZeros()) / double(n);
    const bool dense_graph = degree >= kDenseGraphDegree && degree >= kDenseGraphShare * double(n);
    result.sparse = (dense_graph && solveSparse<DeflatedNormalizedAdjacency>(L, z0, options, buffers,
                                                                             basis(kProductLanczosVectors), z, checked)) ||
                    solveSparse<DeflatedLaplacianInverse>(L, z0, options, buffers, basis(kInverseLanczosVectors), z,
                                                          checked) ||
                    solveSparse<DeflatedLaplacianInverse>(L, z0, options, buffers, basis(kWideLanczosVectors), z,
                                                          checked);
    result.fell_back = !result.sparse;
  }
  if (!result.sparse) {
    if (result.fell_back && n > options.dense_fallback_max_size)
      throw EigenSolverError("Fiedler vector: Lanczos did not converge on a graph of " + std::to_string(n) +
                             " nodes, above the dense fallback limit of " +
                             std::to_string(options.dense_fallback_max_size));
    z = solveDense(L).normalized();
    checked = check(L, z);
  }
  result.residual = checked.residual;
  if (!(result.residual <= kMaxResidual))
    throw EigenSolverError("Fiedler vector: the eigenvector found has residual " + std::to_string(result.residual) +
                           " on a graph of " + std::to_string(n) + " nodes");
  result.eigenvalue = checked.eigenvalue;
  result.y = inv_sqrt_d.cwiseProduct(z);  // y = D^-1/2 z, eq. (11)
  fixSign(result.y);
  return result;
}

}  // namespace obsgroup
