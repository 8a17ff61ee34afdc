#pragma once
/// \file
/// The observation graph of paper sec. III: nodes are observations, W_ij the
/// sensed-space overlap Psi(n_i, n_j) of eq. (18). Plain Eigen, no PCL, so
/// that any caller with its own similarity measure can use the rest of the
/// pipeline.

#include <Eigen/SparseCore>

#include <string>
#include <vector>

namespace obsgroup {

/// Symmetric weight matrix W of the observation graph (column-major; W is
/// symmetric, so columns and rows hold the same entries).
using WeightMatrix = Eigen::SparseMatrix<double>;

/// One undirected edge of the observation graph.
struct WeightedPair {
  int i = 0;
  int j = 0;
  double weight = 0.0;
};

/// Default value of W_ii. The paper sets it to 1 (reflexivity of Psi,
/// sec. III), but with a unit diagonal every bisection of a uniform clique
/// has Ncut < 1 and the recursion with threshold 1 splits all groups down to
/// single observations; see docs/method.md for the derivation. MRPT, the
/// authors' own implementation, also uses 0.
inline constexpr double kDefaultDiagonalWeight = 0.0;

/// Builds the n x n symmetric W from undirected pairs (each pair given once,
/// i != j; zero weights are dropped) and a constant diagonal value.
/// Throws std::invalid_argument on out-of-range indices, i == j, negative or
/// non-finite weights, or a pair given twice.
WeightMatrix buildWeightMatrix(int n, const std::vector<WeightedPair>& pairs,
                               double diagonal = kDefaultDiagonalWeight);

/// Degrees d_i = sum_j W_ij (paper sec. II-A), diagonal included.
Eigen::VectorXd degrees(const WeightMatrix& W);

/// The subgraph of W induced by `members` (sorted ascending, unique), in
/// local indices 0..members.size()-1.
WeightMatrix inducedSubgraph(const WeightMatrix& W, const std::vector<int>& members);
/// The same with caller-owned scratch: `local_of` has W.rows() entries, all
/// -1, and is left so; repeated calls then cost O(nnz of the members' columns).
WeightMatrix inducedSubgraph(const WeightMatrix& W, const std::vector<int>& members, std::vector<int>& local_of);

/// Throws std::invalid_argument, its message starting with `who`, unless
/// `members` are nodes of a graph of `n` nodes as every group is: not empty,
/// ascending, distinct, each in [0, n). A caller's bad index is an error,
/// never a read out of bounds.
void checkMembers(const std::string& who, const std::vector<int>& members, Eigen::Index n);

/// Throws std::invalid_argument, its message starting with `who`, unless W
/// is square with `n` rows (one per observation).
void checkWeightMatrixSize(const std::string& who, const WeightMatrix& W, Eigen::Index n);

/// Connected components of W (the diagonal is ignored): each component sorted
/// ascending, components ordered by their smallest node.
std::vector<std::vector<int>> connectedComponents(const WeightMatrix& W);

/// How many neighbours each observation keeps in the mutual-neighbour graph:
/// max(at_least, share x the median number of neighbours of a node, diagonal
/// not counted, rounded). A map sampled twice as densely has twice the
/// neighbours, and through `share` twice the k; `at_least` leaves the
/// observations of sparse maps, which have fewer neighbours, all of theirs.
int mutualNeighbourCount(const WeightMatrix& W, int at_least, double share);

/// Per node, the weight of its k-th strongest edge (the diagonal not
/// counted), or 0 when it has k edges or fewer: the edges at or above it are
/// the node's k nearest neighbours (ties all kept).
std::vector<double> neighbourThresholds(const WeightMatrix& W, int k);
/// The same for the nodes flagged in `rows` only (one flag per node), the
/// others' entries of `thresholds` (one per node) left as they are.
void updateNeighbourThresholds(const WeightMatrix& W, int k, const std::vector<char>& rows,
                               std::vector<double>& thresholds);

/// The mutual k-nearest-neighbour graph of W (von Luxburg, "A tutorial on
/// spectral clustering", 2007, sec. 2.2): W_ij is kept when it is at or
/// above the thresholds of both i and j (neighbourThresholds), otherwise
/// dropped; the diagonal is kept. Symmetric when W is.
WeightMatrix mutualNeighbourGraph(const WeightMatrix& W, const std::vector<double>& thresholds);
/// The same into `kept`, whose storage is reused (`kept` must not be `W`).
void mutualNeighbourGraph(const WeightMatrix& W, const std::vector<double>& thresholds, WeightMatrix& kept);

}  // namespace obsgroup
