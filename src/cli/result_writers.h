#pragma once
// partition.json, topology.json and topology.dot: the documented, stable
// text outputs of `obsgroup partition`.

#include <obsgroup/maps/topological_map.h>
#include <obsgroup/partition/recursive_partitioner.h>

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace obsgroup::io {

/// What a run was given and did, echoed into partition.json.
struct RunRecord {
  std::string input;
  nlohmann::json parameters;  ///< every parameter actually used
  nlohmann::json statistics;  ///< points, pairs evaluated, edges of W
  nlohmann::json timing_s;    ///< seconds per stage (the only part that varies between runs)
  std::vector<std::string> warnings;  ///< what the user was warned about, in order
  /// The place id of each group, in group order (places.json's ids): the
  /// group's index for `partition`, the online grouping's stable id for `stream`.
  std::vector<int> place_ids;
  /// Where each observation came from (a log's file and line, a PCD or image
  /// file, a bag's message), and when it was sensed (empty: the format has
  /// no stamps), in observation order.
  std::vector<std::string> sources;
  std::vector<double> stamps;
  /// With keyframes: each observation's keyframe (its own index for a
  /// keyframe); empty: every observation was grouped.
  std::vector<int> keyframe_of;
};

/// {"observations": N, "groups": [[...]], "place_ids": [...], "sources": [...],
///  "stamps": [...] or null, "keyframe_of": [...] or null, "splits": [...], "parameters": {...},
///  "statistics": {...}, "warnings": [...], "input": "...", "timing_s": {...}}, keys in this order,
/// one group and one split per line.
std::string partitionJson(const Partition& partition, const RunRecord& run);

/// {"nodes": [{"id", "reference", "pose", "members", "member_poses"}], "arcs":
/// [{"from", "to", "transform", "spread", "weight", "pairs", "overlapping_pairs",
/// "sequence_pairs"}]}; poses and transforms as x y z qw qx qy qz at full
/// double precision.
std::string topologyJson(const TopologicalMap& map);

/// The reference pose of each local map, one TUM line per group in group
/// order ("g x y z qx qy qz qw", the group number as timestamp), at full
/// double precision: PCD VIEWPOINTs keep only 6 significant digits, which
/// loses metres at UTM coordinates. local_maps/ with this file is a PCD
/// sequence that `obsgroup partition --poses` reads back.
std::string localMapPosesTum(const TopologicalMap& map);

/// The same graph in GraphViz DOT.
std::string topologyDot(const TopologicalMap& map);

}  // namespace obsgroup::io
