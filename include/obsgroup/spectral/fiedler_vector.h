#pragma once
/// \file
/// Second smallest eigenvector of the generalized problem (D - W) y = lambda D y,
/// paper eq. (10), through the normalized form of eq. (11).

#include "obsgroup/graph/observation_graph.h"

#include <Eigen/Core>

#include <cstddef>
#include <memory>
#include <stdexcept>
#include <vector>

namespace obsgroup {

/// Which eigen solver computes the Fiedler vector.
enum class EigenSolver {
  Auto,   ///< Dense below FiedlerOptions::dense_max_size nodes, sparse above.
  Dense,  ///< Eigen::SelfAdjointEigenSolver on the dense normalized Laplacian.
  /// Spectra's Lanczos (SymEigsSolver) on the deflated pseudo-inverse of the
  /// normalized Laplacian (the largest eigenvalue is 1/lambda_1, so no shift
  /// is tuned), or on the deflated normalized adjacency for dense graphs.
  Sparse
};

struct FiedlerOptions {
  EigenSolver solver = EigenSolver::Auto;
  /// Largest graph solved densely by EigenSolver::Auto. Measured with
  /// bench/bench_core on route-like graphs: Spectra is already faster at 50
  /// nodes (0.13 ms vs 0.38 ms) and the dense cost grows as N^3 (2.1 s at
  /// 1,000); below 64 nodes the dense solve takes under a millisecond and is
  /// kept as the exact reference.
  int dense_max_size = 64;
  /// Relative tolerance of the Lanczos iteration.
  double tolerance = 1e-10;
  /// Maximum number of restarts of the Lanczos iteration.
  int max_iterations = 1000;
  /// Largest graph the dense solver takes over when Lanczos fails (its
  /// memory grows as N^2: 200 MB at 5,000 nodes).
  int dense_fallback_max_size = 5000;
  /// Optional elimination order for the sparse factorisation: one rank per
  /// node, eliminated in increasing rank (ties by index). Empty (the
  /// default): an AMD ordering of this graph is computed. recursivePartition
  /// leaves it empty, so each node of the split tree is ordered from its own
  /// block of W alone and decided the same whatever the rest of the graph
  /// (what lets online grouping reuse decisions, see SplitCache); given for
  /// the whole graph, each node gets its members' ranks instead. Only speed
  /// depends on it, and the last bits of the eigenvector.
  std::vector<int> elimination_rank{};
};

/// No solver found the Fiedler vector to the required accuracy.
class EigenSolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct FiedlerResult {
  /// y_1 of eq. (10), y = D^-1/2 z with ||z|| = 1, sign fixed so that the
  /// first clearly non-zero component is positive. Guaranteed: lambda_1 and
  /// the residual below, whatever the solver, and the same y for the same
  /// input and solver. When lambda_1 is simple the dense and sparse solvers
  /// return the same y up to their tolerance; when it is repeated (symmetric
  /// graphs: on a cycle of 100 nodes the two put 96 nodes on different
  /// sides) any unit vector of its eigenspace is a Fiedler vector, and each
  /// solver may return a different one.
  Eigen::VectorXd y;
  double eigenvalue = 0.0;  ///< lambda_1 of eq. (10)/(11).
  bool sparse = false;      ///< true when Spectra computed it.
  bool fell_back = false;   ///< true when Spectra failed and the dense solver was used.
  /// ||L z - lambda z|| of the returned vector (z = D^1/2 y, unit norm): every
  /// result is checked, whatever the solver reported.
  double residual = 0.0;
};

/// The buffers of the sparse eigen solve (the normalized Laplacian, the
/// pattern its fill-reducing order is computed from, the matrix in that order
/// and its Cholesky factor), kept from one solve to the next. A run of
/// solves, such as the split tree's nodes or an online update after every
/// insert, then reuses memory instead of asking the system for fresh pages
/// at each solve. The result does not depend on it. One per thread: two
/// solves at once must not share one. Buffers above 256 MB are given back
/// after the solve that needed them.
class FiedlerWorkspace {
 public:
  FiedlerWorkspace();
  ~FiedlerWorkspace();
  FiedlerWorkspace(FiedlerWorkspace&&) noexcept;
  FiedlerWorkspace& operator=(FiedlerWorkspace&&) noexcept;
  /// Bytes the buffers hold now.
  std::size_t heldBytes() const;

  struct Buffers;  ///< opaque
  Buffers& buffers();

 private:
  std::unique_ptr<Buffers> buffers_;
};

/// Fiedler vector of a connected graph with positive degrees (the recursive
/// partitioner splits off connected components first, so the zero eigenvalue
/// is simple). Throws std::invalid_argument on a graph with fewer than two
/// nodes or a node of zero degree, EigenSolverError if no solver converges
/// (Lanczos failing on a graph above dense_fallback_max_size).
FiedlerResult fiedlerVector(const WeightMatrix& W, const FiedlerOptions& options = {});

/// The same, reusing `workspace`'s buffers (the same result to the bit).
FiedlerResult fiedlerVector(const WeightMatrix& W, const FiedlerOptions& options, FiedlerWorkspace& workspace);

/// The elimination order of maximum cardinality search on the pattern of a
/// symmetric matrix (entry k: the node eliminated k-th): each node is
/// numbered from the last to the first, the unnumbered one with the most
/// numbered neighbours next (ties: the one whose count rose last; at the
/// start the lowest index). Eliminated in this
/// order, a chordal graph's factor has no fill. Without elimination ranks,
/// fiedlerVector orders its grounded Laplacian so, or by AMD where this
/// order's factor would hold more than 1.5 times the matrix's entries below
/// its diagonal.
std::vector<int> maximumCardinalityOrder(const WeightMatrix& A);

}  // namespace obsgroup
