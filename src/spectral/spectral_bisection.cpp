#include "obsgroup/spectral/spectral_bisection.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace obsgroup {

namespace {

/// Sweeps every threshold between distinct values of y (largest first into A)
/// and returns the one with the smallest Ncut. cut(A,B) and assoc are updated
/// incrementally in O(deg u) per moved node; the chosen split's Ncut is then
/// recomputed exactly by the caller.
double bestNcutThreshold(const WeightMatrix& W, const Eigen::VectorXd& y, int min_side) {
  const int n = static_cast<int>(y.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  // Largest first, ties in index order: the order a stable sort gives,
  // without its buffer.
  std::sort(order.begin(), order.end(), [&y](int a, int b) { return y[a] > y[b] || (y[a] == y[b] && a < b); });
  const Eigen::VectorXd d = degrees(W);

  std::vector<char> in_a(std::size_t(n), 0);
  double cut = 0.0, assoc_a = 0.0, assoc_b = d.sum();
  double best = std::numeric_limits<double>::infinity();
  double best_threshold = y.minCoeff() - 1.0;  // no valid cut: everything in A
  for (int k = 0; k + 1 < n; ++k) {
    const int u = order[k];
    for (WeightMatrix::InnerIterator it(W, u); it; ++it) {
      if (it.row() == u) continue;
      cut += in_a[it.row()] ? -it.value() : it.value();
    }
    in_a[u] = true;
    assoc_a += d[u];
    assoc_b -= d[u];
    const int size_a = k + 1;
    if (y[order[k + 1]] == y[u] || size_a < min_side || n - size_a < min_side) continue;
    const double ncut = (assoc_a > 0 ? cut / assoc_a : 0.0) + (assoc_b > 0 ? cut / assoc_b : 0.0);
    if (ncut < best) {
      best = ncut;
      best_threshold = y[order[k + 1]];
    }
  }
  return best_threshold;
}

}  // namespace

Bisection spectralBisection(const WeightMatrix& W, SplitCriterion criterion,
                            const FiedlerOptions& options, int min_side) {
  FiedlerWorkspace workspace;
  return spectralBisection(W, criterion, options, min_side, workspace);
}

Bisection spectralBisection(const WeightMatrix& W, SplitCriterion criterion, const FiedlerOptions& options,
                            int min_side, FiedlerWorkspace& workspace) {
  Bisection b;
  b.fiedler = fiedlerVector(W, options, workspace);
  const Eigen::VectorXd& y = b.fiedler.y;
  switch (criterion) {
    case SplitCriterion::Mean: b.threshold = y.mean(); break;  // the paper's rule, sec. II-A
    case SplitCriterion::Sign: b.threshold = 0.0; break;
    case SplitCriterion::BestNcut: b.threshold = bestNcutThreshold(W, y, std::max(1, min_side)); break;
  }
  b.in_a.resize(y.size());
  Eigen::Index size_a = 0;
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    b.in_a[i] = y[i] > b.threshold;
    size_a += b.in_a[i];
  }
  b.valid = size_a > 0 && size_a < y.size();
  b.cut = normalizedCut(W, b.in_a);
  return b;
}

}  // namespace obsgroup
