#include "result_writers.h"

#include <obsgroup/common/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <sstream>

namespace obsgroup::io {

namespace {

nlohmann::json number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

nlohmann::json splitToJson(const SplitNode& node, std::size_t id) {
  return {{"id", id},
          {"parent", node.parent},
          {"depth", node.depth},
          {"size", node.members.size()},
          {"kind", toString(node.kind)},
          {"outcome", toString(node.outcome)},
          {"accepted", node.accepted},
          {"ncut", number(node.ncut)},
          {"threshold", node.attempted ? number(node.threshold) : nlohmann::json()},
          {"eigenvalue", number(node.eigenvalue)},
          {"solver", node.attempted ? (node.sparse_solver ? "sparse" : "dense") : nlohmann::json()},
          {"solver_fell_back", node.solver_fell_back},
          {"children", node.children},
          {"members", node.members}};
}

nlohmann::json poseToJson(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d t = pose.translation();
  return {{"x", t.x()}, {"y", t.y()}, {"z", t.z()}, {"qw", q.w()}, {"qx", q.x()}, {"qy", q.y()}, {"qz", q.z()}};
}

/// A JSON array with one element per line, indented; element k is item(k).
/// The elements are made on all cores (a big map has tens of thousands) and
/// joined in order.
template <typename Item>
std::string arrayPerLine(std::size_t size, const Item& item) {
  if (size == 0) return "[]";
  std::vector<std::string> lines(size);
  parallelFor(size, 0, 64, [&](std::size_t k) { lines[k] = item(k).dump(); });
  std::size_t length = 4;
  for (const auto& line : lines) length += line.size() + 6;
  std::string out;
  out.reserve(length);
  out += "[\n";
  for (std::size_t k = 0; k < size; ++k) (out += "    ") += lines[k] + (k + 1 < size ? ",\n" : "\n");
  return out + "  ]";
}

nlohmann::json nodeToJson(const LocalMapFrame& node, std::size_t id) {
  std::vector<nlohmann::json> member_poses;
  for (const auto& pose : node.member_poses) member_poses.push_back(poseToJson(pose));
  return {{"id", id}, {"reference", node.reference}, {"pose", poseToJson(node.pose)},
          {"members", node.members}, {"member_poses", member_poses}};
}

nlohmann::json arcToJson(const TopologicalArc& arc) {
  return {{"from", arc.from},
          {"to", arc.to},
          {"transform", poseToJson(arc.transform)},
          {"spread", {{"translation_m", arc.translation_spread}, {"rotation_rad", arc.rotation_spread}}},
          {"weight", arc.weight},
          {"pairs", arc.pairs},
          {"overlapping_pairs", arc.overlapping_pairs},
          {"sequence_pairs", arc.sequence_pairs}};
}

}  // namespace

std::string partitionJson(const Partition& partition, const RunRecord& run) {
  const auto group = [&](std::size_t g) { return nlohmann::json(partition.groups[g]); };
  const auto split = [&](std::size_t s) { return splitToJson(partition.splits[s], s); };
  std::ostringstream out;
  out << "{\n"
      << "  \"observations\": " << partition.group_of.size() << ",\n"
      << "  \"groups\": " << arrayPerLine(partition.groups.size(), group) << ",\n"
      << "  \"place_ids\": " << nlohmann::json(run.place_ids).dump() << ",\n"
      << "  \"sources\": " << nlohmann::json(run.sources).dump() << ",\n"
      << "  \"stamps\": " << (run.stamps.empty() ? nlohmann::json() : nlohmann::json(run.stamps)).dump() << ",\n"
      << "  \"keyframe_of\": "
      << (run.keyframe_of.empty() ? nlohmann::json() : nlohmann::json(run.keyframe_of)).dump() << ",\n"
      << "  \"splits\": " << arrayPerLine(partition.splits.size(), split) << ",\n"
      << "  \"parameters\": " << run.parameters.dump() << ",\n"
      << "  \"statistics\": " << run.statistics.dump() << ",\n"
      << "  \"warnings\": " << nlohmann::json(run.warnings).dump() << ",\n"
      << "  \"input\": " << nlohmann::json(run.input).dump() << ",\n"
      << "  \"timing_s\": " << run.timing_s.dump() << "\n"
      << "}\n";
  return out.str();
}

std::string topologyJson(const TopologicalMap& map) {
  const auto node = [&](std::size_t k) { return nodeToJson(map.nodes[k], k); };
  const auto arc = [&](std::size_t k) { return arcToJson(map.arcs[k]); };
  return "{\n  \"nodes\": " + arrayPerLine(map.nodes.size(), node) + ",\n  \"arcs\": " +
         arrayPerLine(map.arcs.size(), arc) + "\n}\n";
}

std::string localMapPosesTum(const TopologicalMap& map) {
  std::string out = "# obsgroup local maps: group x y z qx qy qz qw (TUM), reference pose of local_maps/group_NNN.pcd\n";
  char line[256];
  for (std::size_t k = 0; k < map.nodes.size(); ++k) {
    const Eigen::Quaterniond q(map.nodes[k].pose.linear());
    const Eigen::Vector3d t = map.nodes[k].pose.translation();
    std::snprintf(line, sizeof line, "%zu %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", k, t.x(), t.y(), t.z(), q.x(),
                  q.y(), q.z(), q.w());
    out += line;
  }
  return out;
}

std::string topologyDot(const TopologicalMap& map) {
  std::ostringstream out;
  out << "graph topology {\n  node [shape=box];\n";
  for (std::size_t k = 0; k < map.nodes.size(); ++k) {
    const std::size_t members = map.nodes[k].members.size();
    out << "  g" << k << " [label=\"group " << k << "\\n" << members << (members == 1 ? " observation" : " observations")
        << "\\nreference " << map.nodes[k].reference << "\"];\n";
  }
  // Labels are for reading: three decimals (a spread of 6.7e-16 m is 0.000);
  // topology.json keeps the full values.
  const auto fixed = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3f", std::abs(v) < 5e-4 ? 0.0 : v);
    return std::string(text);
  };
  for (const auto& arc : map.arcs) {
    const Eigen::Vector3d t = arc.transform.translation();
    out << "  g" << arc.from << " -- g" << arc.to << " [label=\"W " << fixed(arc.weight) << ", " << arc.pairs
        << (arc.pairs == 1 ? " pair" : " pairs") << "\\n" << fixed(t.norm()) << " m +- "
        << fixed(arc.translation_spread) << " m\"";
    if (arc.overlapping_pairs == 0) out << ", style=dashed";  // joined only by the robot's path
    out << "];\n";
  }
  out << "}\n";
  return out.str();
}

}  // namespace obsgroup::io
