#pragma once
/// \file
/// Spectral bisection of a graph by minimum normalized cut (paper sec. II-A).

#include "obsgroup/common/enum_names.h"
#include "obsgroup/spectral/fiedler_vector.h"
#include "obsgroup/spectral/normalized_cut.h"

#include <string>
#include <vector>

namespace obsgroup {

/// How the real-valued Fiedler vector is turned into two groups.
enum class SplitCriterion {
  Mean,    ///< y_i > mean(y): the paper's choice (sec. II-A), PartitionOptions' default.
  Sign,    ///< y_i > 0.
  BestNcut ///< sweep every threshold along the sorted y and keep the smallest Ncut.
};

inline constexpr EnumName<SplitCriterion> kSplitCriterionNames[] = {
    {SplitCriterion::Mean, "mean"}, {SplitCriterion::Sign, "sign"}, {SplitCriterion::BestNcut, "best"}};

inline std::string toString(SplitCriterion criterion) { return nameOf(kSplitCriterionNames, criterion); }
/// Parses "mean", "sign" or "best"; throws std::invalid_argument otherwise.
inline SplitCriterion splitCriterionFromString(const std::string& name) {
  return valueNamed(kSplitCriterionNames, name, "split criterion");
}

struct Bisection {
  FiedlerResult fiedler;    ///< The eigenvector the split was read from.
  double threshold = 0.0;   ///< Nodes with y_i > threshold go to A.
  std::vector<bool> in_a;   ///< Membership of each node in A.
  CutValues cut;            ///< Exact Ncut of this split, eq. (1).
  /// False when every node fell on one side (no split exists, e.g. all y equal).
  bool valid = false;
};

/// Bisects a connected graph (positive degrees, at least 2 nodes). For
/// BestNcut, only thresholds leaving at least `min_side` nodes on each side
/// are considered.
Bisection spectralBisection(const WeightMatrix& W, SplitCriterion criterion,
                            const FiedlerOptions& options = {}, int min_side = 1);

/// The same, the eigen solve reusing `workspace`'s buffers (the same result).
Bisection spectralBisection(const WeightMatrix& W, SplitCriterion criterion, const FiedlerOptions& options,
                            int min_side, FiedlerWorkspace& workspace);

}  // namespace obsgroup
