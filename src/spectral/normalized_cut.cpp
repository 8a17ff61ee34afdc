#include "obsgroup/spectral/normalized_cut.h"

#include <stdexcept>

namespace obsgroup {

CutValues normalizedCut(const WeightMatrix& W, const std::vector<bool>& in_a) {
  if (static_cast<Eigen::Index>(in_a.size()) != W.outerSize())
    throw std::invalid_argument("normalizedCut: membership size does not match the graph");
  CutValues v;
  for (int u = 0; u < W.outerSize(); ++u) {
    for (WeightMatrix::InnerIterator it(W, u); it; ++it) {
      // Column u holds W_vu = W_uv: each ordered pair (u, v) is visited once.
      const bool same_side = in_a[it.row()] == in_a[u];
      (in_a[u] ? v.assoc_a : v.assoc_b) += it.value();  // eq. (3)
      if (in_a[u] && !same_side) v.cut += it.value();    // eq. (2)
    }
  }
  // eq. (1); a side without any edge has cut 0 too and contributes nothing.
  v.ncut = (v.assoc_a > 0.0 ? v.cut / v.assoc_a : 0.0) + (v.assoc_b > 0.0 ? v.cut / v.assoc_b : 0.0);
  return v;
}

}  // namespace obsgroup
