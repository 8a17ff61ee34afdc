#include "obsgroup/overlap/overlap_matrix.h"

#include <algorithm>
#include <stdexcept>

namespace obsgroup {

OverlapResult assembleOverlap(const MatchCounts& counts, const WorldPoints& world) {
  std::vector<std::size_t> sizes(world.size());
  for (int i = 0; i < world.size(); ++i) sizes[i] = world.count(i);
  return assembleOverlap(counts, sizes);
}

OverlapResult assembleOverlap(const MatchCounts& counts, const std::vector<std::size_t>& sizes) {
  const int n = static_cast<int>(sizes.size());
  if (static_cast<int>(counts.rows.size()) != n)
    throw std::invalid_argument("assembleOverlap: one row of counts per observation expected");
  OverlapResult out;
  out.pairs_evaluated = counts.pairs_evaluated;
  out.point_tests = counts.point_tests;
  out.points_per_observation = sizes;

  // Pi row by row, eq. (17): the rows arrive sorted by j, so the compressed
  // storage is filled directly.
  using RowMatrix = decltype(out.match_ratio);
  out.match_ratio.resize(n, n);
  std::size_t entries = 0;
  for (const auto& row : counts.rows) entries += row.size();
  out.match_ratio.reserve(static_cast<Eigen::Index>(entries));
  for (int i = 0; i < n; ++i) {
    out.match_ratio.startVec(i);
    int previous = -1;
    for (const MatchCount& m : counts.rows[i]) {
      if (m.j <= previous || m.j >= n || m.j == i || m.count == 0)
        throw std::invalid_argument("assembleOverlap: each row must list distinct j != i, ascending, with count > 0");
      previous = m.j;
      out.match_ratio.insertBack(i, m.j) = double(m.count) / double(sizes[i]);
    }
  }
  out.match_ratio.finalize();

  // Psi = (Pi_ij + Pi_ji) / 2, eq. (18), for every pair with either ratio
  // non-zero: row i of Pi merged with row i of its transpose (Pi_ji).
  const RowMatrix transposed = out.match_ratio.transpose();
  for (int i = 0; i < n; ++i) {
    RowMatrix::InnerIterator ij(out.match_ratio, i), ji(transposed, i);
    while (ij || ji) {
      const int j = std::min(ij ? int(ij.col()) : n, ji ? int(ji.col()) : n);
      const double pi_ij = ij && ij.col() == j ? ij.value() : 0.0;
      const double pi_ji = ji && ji.col() == j ? ji.value() : 0.0;
      if (j > i) out.pairs.push_back({i, j, 0.5 * (pi_ij + pi_ji)});
      if (ij && ij.col() == j) ++ij;
      if (ji && ji.col() == j) ++ji;
    }
  }
  return out;
}

}  // namespace obsgroup
