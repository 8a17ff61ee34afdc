#include "obsgroup/overlap/overlap_matrix.h"

#include <algorithm>
#include <stdexcept>

namespace obsgroup {

OverlapResult assembleOverlap(const MatchCounts& counts, const WorldPoints& world) {
  const int n = world.size();
  if (static_cast<int>(counts.rows.size()) != n)
    throw std::invalid_argument("assembleOverlap: one row of counts per observation expected");
  OverlapResult out;
  out.pairs_evaluated = counts.pairs_evaluated;
  out.point_tests = counts.point_tests;
  out.points_per_observation.resize(n);
  for (int i = 0; i < n; ++i) out.points_per_observation[i] = world.count(i);

  std::vector<Eigen::Triplet<double>> triplets;
  for (int i = 0; i < n; ++i)
    for (const MatchCount& m : counts.rows[i])
      triplets.emplace_back(i, m.j, double(m.count) / double(world.count(i)));  // eq. (17)
  out.match_ratio.resize(n, n);
  out.match_ratio.setFromTriplets(triplets.begin(), triplets.end());

  // Psi = (Pi_ij + Pi_ji) / 2, eq. (18). Taking Pi_ji from the matrix (and 0
  // when absent) keeps this exact whatever the order counts arrived in.
  for (int i = 0; i < n; ++i) {
    for (decltype(out.match_ratio)::InnerIterator it(out.match_ratio, i); it; ++it) {
      const int j = static_cast<int>(it.col());
      const double pi_ji = out.match_ratio.coeff(j, i);
      if (j > i || pi_ji == 0.0) {
        const int a = std::min(i, j), b = std::max(i, j);
        out.pairs.push_back({a, b, 0.5 * (out.match_ratio.coeff(a, b) + out.match_ratio.coeff(b, a))});
      }
    }
  }
  std::sort(out.pairs.begin(), out.pairs.end(),
            [](const WeightedPair& x, const WeightedPair& y) { return x.i < y.i || (x.i == y.i && x.j < y.j); });
  return out;
}

}  // namespace obsgroup
