#pragma once
/// \file
/// The shared-grid neighbour back-end: one grid over every
/// observation's world points, so the whole overlap matrix comes from one
/// pass over the cells and one over the observations.

#include "obsgroup/common/interrupt.h"
#include "obsgroup/overlap/overlap_matrix.h"

namespace obsgroup {

/// Counts, for every observation i and every other observation j, the points
/// of i with a point of j within delta (eq. 16-17).
///
/// The grid's cells are a hair larger than delta, so two points within delta
/// always fall in the same or adjacent cells whatever the rounding of the
/// cell index; the match itself is decided by MatchDistance. Two passes:
/// cell by cell, the 3x3 (flat data) or 3x3x3 neighbourhood is grouped by
/// observation once and every point of the cell, whatever its observation, is
/// tested against each other observation of it, giving one bit per (point,
/// nearby observation); then observation by observation, the bits of its
/// points are added up. Integer counts in fixed places: the result is the
/// same for any number of threads. Progress is reported in observations
/// (the two passes scaled to n). Throws Interrupted when `interrupt` is set.
MatchCounts countMatchesSharedGrid(const WorldPoints& world, double delta, int threads = 0,
                                   const ProgressCallback& progress = {},
                                   const InterruptFlag* interrupt = nullptr);

}  // namespace obsgroup
