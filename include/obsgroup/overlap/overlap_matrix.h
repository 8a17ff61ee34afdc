#pragma once
/// \file
/// From per-pair match counts to Pi (eq. 17) and Psi (eq. 18).

#include "obsgroup/graph/observation_graph.h"
#include "obsgroup/overlap/world_points.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace obsgroup {

/// Number of points of one observation i that have a point of observation j
/// within delta (the sum of eq. 17 before dividing by M).
struct MatchCount {
  int j = 0;
  std::uint32_t count = 0;
};

/// Progress of a long stage: called with the number of observations done and
/// the total, from one thread at a time, the last call with done == total.
using ProgressCallback = std::function<void(std::size_t done, std::size_t total)>;

/// Output of a neighbour back-end: for each observation i, the observations it
/// matched (ascending j, count > 0), plus work statistics.
struct MatchCounts {
  std::vector<std::vector<MatchCount>> rows;
  std::uint64_t pairs_evaluated = 0;  ///< Ordered pairs (i, j) whose points were compared.
  std::uint64_t point_tests = 0;      ///< Point-to-observation tests: one per point of i and observation j with points near it.
};

/// The sensed-space overlap of a set of observations.
struct OverlapResult {
  /// Pi(n_i, n_j, delta), eq. (17): row i, column j; not symmetric (Fig. 4).
  Eigen::SparseMatrix<double, Eigen::RowMajor> match_ratio;
  /// Psi(n_i, n_j) = (Pi_ij + Pi_ji) / 2, eq. (18), for each pair i < j with Psi > 0.
  std::vector<WeightedPair> pairs;
  std::vector<std::size_t> points_per_observation;  ///< Points of each observation, after filtering (M of eq. 17 for points).
  /// Cells of each observation's region (M of Pi for the region models;
  /// empty for points).
  std::vector<std::size_t> region_cells;
  /// Visibility: the plane cells occupied in the evidence of all
  /// observations, as the views were cast against (keys ascending;
  /// planeCellReader reads them). Empty for the other models.
  std::vector<std::uint64_t> occupied_cells;
  std::uint64_t pairs_evaluated = 0;
  std::uint64_t point_tests = 0;
};

/// Divides the counts by M (eq. 17) and symmetrises them (eq. 18).
/// An observation without points matches nothing: its Pi row is 0.
OverlapResult assembleOverlap(const MatchCounts& counts, const WorldPoints& world);
/// The same with M of eq. (17) given per observation: its points, or its
/// cells for the region models (sensed_regions.h). points_per_observation
/// is set to `sizes`.
OverlapResult assembleOverlap(const MatchCounts& counts, const std::vector<std::size_t>& sizes);

}  // namespace obsgroup
