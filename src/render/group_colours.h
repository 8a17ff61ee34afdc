#pragma once
// Which colour each group gets in the pictures, and which arcs map.png
// shows: pure functions of the topological map, drawn by pictures.h.

#include <obsgroup/maps/topological_map.h>

#include <cstddef>
#include <vector>

namespace obsgroup::render {

/// Well separated colours of the pictures' palette; beyond them colours repeat, paler.
inline constexpr int kDistinctColours = 12;

/// Palette index of each group in the pictures (map.png and the local maps):
/// a greedy (DSATUR) colouring of the groups joined by an arc of the topology
/// or among each other's two nearest group centres, so that such neighbours
/// never share a colour. When that needs more than the palette's 12 well
/// separated colours (a dense topology: a real log's 163 groups with 5,087
/// arcs need 44; the 382 arcs shown, 5), only the arcs map.png shows
/// (shownArcs(), 3 per group) and the nearest centres count.
std::vector<int> groupColours(const TopologicalMap& topology);

/// Neighbours of each node, ascending: joined by one of `arcs` (indices into
/// topology.arcs), or among each other's two nearest centres (the mean of
/// the members' global poses; ties: the lower index), the pairs groupColours
/// keeps apart.
std::vector<std::vector<int>> groupNeighbours(const TopologicalMap& topology, const std::vector<std::size_t>& arcs);

/// The arcs map.png draws, indices into topology.arcs, ascending: each node's
/// `per_node` strongest (by weight, then overlapping and sequence pairs).
/// topology.json keeps all of them.
std::vector<std::size_t> shownArcs(const TopologicalMap& topology, int per_node = 3);

}  // namespace obsgroup::render
