#include "obsgroup/graph/observation_graph.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

namespace obsgroup {

WeightMatrix buildWeightMatrix(int n, const std::vector<WeightedPair>& pairs, double diagonal) {
  if (n < 0) throw std::invalid_argument("buildWeightMatrix: negative size");
  if (!std::isfinite(diagonal) || diagonal < 0.0)
    throw std::invalid_argument("buildWeightMatrix: diagonal weight must be finite and >= 0");
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(2 * pairs.size() + (diagonal != 0.0 ? n : 0));
  for (const auto& p : pairs) {
    if (p.i < 0 || p.j < 0 || p.i >= n || p.j >= n || p.i == p.j)
      throw std::invalid_argument("buildWeightMatrix: bad pair (" + std::to_string(p.i) + ", " +
                                  std::to_string(p.j) + ") for " + std::to_string(n) + " nodes");
    if (!std::isfinite(p.weight) || p.weight < 0.0)
      throw std::invalid_argument("buildWeightMatrix: weight of pair (" + std::to_string(p.i) +
                                  ", " + std::to_string(p.j) + ") is not finite and >= 0");
    if (p.weight == 0.0) continue;
    triplets.emplace_back(p.i, p.j, p.weight);
    triplets.emplace_back(p.j, p.i, p.weight);
  }
  if (diagonal != 0.0)
    for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, diagonal);
  WeightMatrix W(n, n);
  // A duplicated pair must not be summed silently into a weight above 1.
  bool duplicate = false;
  W.setFromTriplets(triplets.begin(), triplets.end(), [&duplicate](double a, double) {
    duplicate = true;
    return a;
  });
  if (duplicate) throw std::invalid_argument("buildWeightMatrix: a pair is given twice");
  W.makeCompressed();
  return W;
}

void checkMembers(const std::string& who, const std::vector<int>& members, Eigen::Index n) {
  if (members.empty()) throw std::invalid_argument(who + ": empty group");
  for (std::size_t k = 0; k < members.size(); ++k) {
    if (members[k] < 0 || members[k] >= n)
      throw std::invalid_argument(who + ": index " + std::to_string(members[k]) + " at position " +
                                  std::to_string(k) + " of the group is out of range (" + std::to_string(n) +
                                  " observations)");
    if (k > 0 && members[k] <= members[k - 1])
      throw std::invalid_argument(who + ": the group's indices must ascend without repeats (" +
                                  std::to_string(members[k - 1]) + " then " + std::to_string(members[k]) +
                                  " at position " + std::to_string(k) + ")");
  }
}

void checkWeightMatrixSize(const std::string& who, const WeightMatrix& W, Eigen::Index n) {
  if (W.rows() != n || W.cols() != n)
    throw std::invalid_argument(who + ": W is " + std::to_string(W.rows()) + " x " + std::to_string(W.cols()) +
                                " for " + std::to_string(n) + " observations");
}

Eigen::VectorXd degrees(const WeightMatrix& W) {
  Eigen::VectorXd d = Eigen::VectorXd::Zero(W.outerSize());
  for (int k = 0; k < W.outerSize(); ++k)
    for (WeightMatrix::InnerIterator it(W, k); it; ++it) d[k] += it.value();
  return d;
}

WeightMatrix inducedSubgraph(const WeightMatrix& W, const std::vector<int>& members, std::vector<int>& local_of) {
  const int m = static_cast<int>(members.size());
  if (W.rows() != W.cols()) throw std::invalid_argument("inducedSubgraph: W must be square");
  if (Eigen::Index(local_of.size()) != W.rows())
    throw std::invalid_argument("inducedSubgraph: the scratch needs one entry per node of W");
  if (m > 0) checkMembers("inducedSubgraph", members, W.rows());
  for (int k = 0; k < m; ++k) local_of[members[k]] = k;
  // Members ascend, so local indices ascend with W's row indices: each column
  // is written in order straight into the compressed arrays, sized for every
  // entry of the members' columns and cut to those kept (an entry-by-entry
  // insertion cost a twentieth of an online update's partition).
  WeightMatrix sub(m, m);
  std::size_t entries = 0;
  for (int i : members)
    entries += static_cast<std::size_t>(W.isCompressed() ? W.outerIndexPtr()[i + 1] - W.outerIndexPtr()[i]
                                                         : W.innerNonZeroPtr()[i]);
  sub.resizeNonZeros(static_cast<Eigen::Index>(entries));
  int* outer = sub.outerIndexPtr();
  int* inner = sub.innerIndexPtr();
  double* value = sub.valuePtr();
  int k = 0;
  for (int local_col = 0; local_col < m; ++local_col) {
    outer[local_col] = k;
    for (WeightMatrix::InnerIterator it(W, members[local_col]); it; ++it) {
      const int local_row = local_of[it.row()];
      if (local_row < 0) continue;
      inner[k] = local_row;
      value[k] = it.value();
      ++k;
    }
  }
  outer[m] = k;
  sub.resizeNonZeros(k);
  for (int i : members) local_of[i] = -1;
  return sub;
}

WeightMatrix inducedSubgraph(const WeightMatrix& W, const std::vector<int>& members) {
  std::vector<int> local_of(W.rows(), -1);
  return inducedSubgraph(W, members, local_of);
}

std::vector<std::vector<int>> connectedComponents(const WeightMatrix& W) {
  const int n = static_cast<int>(W.outerSize());
  std::vector<int> label(n, -1), sizes;
  std::vector<int> stack;
  // Seeds are visited in ascending order, so components come out ordered by
  // their smallest node.
  for (int seed = 0; seed < n; ++seed) {
    if (label[seed] >= 0) continue;
    const int c = static_cast<int>(sizes.size());
    sizes.push_back(0);
    label[seed] = c;
    stack.push_back(seed);
    while (!stack.empty()) {
      const int u = stack.back();
      stack.pop_back();
      ++sizes[c];
      for (WeightMatrix::InnerIterator it(W, u); it; ++it) {
        const int v = static_cast<int>(it.row());
        if (v == u || it.value() == 0.0 || label[v] >= 0) continue;
        label[v] = c;
        stack.push_back(v);
      }
    }
  }
  // Each component's nodes ascending, by one pass over the labels rather
  // than a sort of each (a connected graph, the common case, is one list).
  std::vector<std::vector<int>> components(sizes.size());
  for (std::size_t c = 0; c < sizes.size(); ++c) components[c].reserve(std::size_t(sizes[c]));
  for (int u = 0; u < n; ++u) components[std::size_t(label[u])].push_back(u);
  return components;
}

int mutualNeighbourCount(const WeightMatrix& W, int at_least, double share) {
  std::vector<Eigen::Index> counts(std::size_t(W.outerSize()));
  for (Eigen::Index j = 0; j < W.outerSize(); ++j) {
    Eigen::Index c = 0;
    for (WeightMatrix::InnerIterator it(W, j); it; ++it)
      if (it.index() != j) ++c;
    counts[std::size_t(j)] = c;
  }
  if (counts.empty()) return std::max(at_least, 0);
  const auto middle = counts.begin() + std::ptrdiff_t(counts.size() / 2);
  std::nth_element(counts.begin(), middle, counts.end());
  const double from_median = std::round(share * double(*middle));
  return std::max(at_least, int(std::min(from_median, double(std::numeric_limits<int>::max()))));
}

namespace {

/// The k-th largest weight of node j's edges (the diagonal not counted), or
/// 0 when it has k or fewer: the edges at or above it are the k strongest.
double neighbourThreshold(const WeightMatrix& W, Eigen::Index j, int k, std::vector<double>& row) {
  row.clear();
  for (WeightMatrix::InnerIterator it(W, j); it; ++it)
    if (it.index() != j) row.push_back(it.value());
  if (k <= 0 || Eigen::Index(row.size()) <= k) return 0.0;
  std::nth_element(row.begin(), row.begin() + (k - 1), row.end(), std::greater<>());
  return row[std::size_t(k - 1)];
}

}  // namespace

std::vector<double> neighbourThresholds(const WeightMatrix& W, int k) {
  std::vector<double> thresholds(std::size_t(W.outerSize()), 0.0);
  updateNeighbourThresholds(W, k, std::vector<char>(thresholds.size(), 1), thresholds);
  return thresholds;
}

void updateNeighbourThresholds(const WeightMatrix& W, int k, const std::vector<char>& rows,
                               std::vector<double>& thresholds) {
  if (Eigen::Index(rows.size()) != W.outerSize() || Eigen::Index(thresholds.size()) != W.outerSize())
    throw std::invalid_argument("updateNeighbourThresholds: one flag and one threshold per node expected");
  std::vector<double> row;
  for (Eigen::Index j = 0; j < W.outerSize(); ++j)
    if (rows[std::size_t(j)]) thresholds[std::size_t(j)] = neighbourThreshold(W, j, k, row);
}

namespace {

/// mutualNeighbourGraph into `kept`, its storage grown (when it must) with
/// `spare` of W's entries to spare.
void keepMutual(const WeightMatrix& W, const std::vector<double>& thresholds, WeightMatrix& kept, double spare) {
  if (Eigen::Index(thresholds.size()) != W.outerSize())
    throw std::invalid_argument("mutualNeighbourGraph: one threshold per node expected");
  if (&kept == &W) throw std::invalid_argument("mutualNeighbourGraph: the output cannot be W");
  // The kept entries, in W's order, written straight into kept's compressed
  // arrays: its storage, sized for all of W's entries, is reused from one
  // online update to the next (a copy of W pruned took a twentieth of one).
  const Eigen::Index n = W.outerSize();
  kept.resize(W.rows(), W.cols());
  kept.data().resize(W.nonZeros(), spare);
  int* outer = kept.outerIndexPtr();
  int* inner = kept.innerIndexPtr();
  double* value = kept.valuePtr();
  Eigen::Index at = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    outer[j] = int(at);
    const double t_j = thresholds[std::size_t(j)];
    for (WeightMatrix::InnerIterator it(W, j); it; ++it) {
      const Eigen::Index i = it.index();
      const double w = it.value();
      if (i == j || (w >= thresholds[std::size_t(i)] && w >= t_j)) {
        inner[at] = int(i);
        value[at] = w;
        ++at;
      }
    }
  }
  outer[n] = int(at);
  kept.data().resize(at);  // the capacity stays
}

}  // namespace

WeightMatrix mutualNeighbourGraph(const WeightMatrix& W, const std::vector<double>& thresholds) {
  WeightMatrix kept;
  keepMutual(W, thresholds, kept, 0.0);
  kept.data().squeeze();  // the dropped entries' storage back
  return kept;
}

void mutualNeighbourGraph(const WeightMatrix& W, const std::vector<double>& thresholds, WeightMatrix& kept) {
  keepMutual(W, thresholds, kept, 0.1);  // online, W grows a little at every update
}

}  // namespace obsgroup
