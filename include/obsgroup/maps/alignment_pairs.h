#pragma once
/// \file
/// Which members of a local map are aligned with which (LocalMapBuilder's
/// refinement): plain Eigen and W, compiled once in the library rather than
/// per point type.

#include "obsgroup/graph/observation_graph.h"
#include "obsgroup/maps/refinement.h"
#include "obsgroup/maps/topological_map.h"

#include <set>
#include <utility>
#include <vector>

namespace obsgroup::detail {

/// Members of `frame` in the order of a maximum spanning tree of W grown from
/// the reference (Prim), each with its parent's index in `members` (-1 for
/// the reference and for members W does not connect).
std::vector<std::pair<int, int>> maximumSpanningTree(const LocalMapFrame& frame, const WeightMatrix& W);

/// How much the members' points share space at their poses in the map
/// frame, indexed like W by observation: for each pair with points in a
/// common cell of `cell` metres, shared cells / sqrt(cells of each).
WeightMatrix pointOverlap(const LocalMapFrame& frame, const std::vector<MemberPoints>& points, double cell,
                          Eigen::Index size);

/// Adds to `pairs` each member with up to `count` of its strongest partners
/// in `by` (ties by position), pairs already `taken` left out.
void addStrongestPartners(const std::vector<int>& members, const WeightMatrix& by, int count,
                          std::set<std::pair<int, int>>& taken, std::vector<std::pair<int, int>>& pairs);

}  // namespace obsgroup::detail
