#pragma once
/// \file
/// The normalized cut of Shi and Malik, paper eq. (1)-(3), computed exactly.

#include "obsgroup/graph/observation_graph.h"

#include <vector>

namespace obsgroup {

/// The terms of eq. (1) for one bisection {A, B} of a graph.
struct CutValues {
  double cut = 0.0;     ///< cut(A,B), eq. (2): sum of W_uv, u in A, v in B.
  double assoc_a = 0.0; ///< assoc(A,V), eq. (3): sum of W_uv, u in A, v in V (ordered pairs, diagonal included).
  double assoc_b = 0.0; ///< assoc(B,V).
  double ncut = 0.0;    ///< Ncut(A,B), eq. (1), in [0, 2].
};

/// Ncut(A,B) of eq. (1) over W as given (its diagonal included in assoc).
/// `in_a[u]` tells whether node u belongs to A. A side whose assoc is zero
/// (it has no edge at all) contributes 0, since its cut is 0 too.
CutValues normalizedCut(const WeightMatrix& W, const std::vector<bool>& in_a);

}  // namespace obsgroup
