#pragma once
// report.html: one page per run to click through, self-contained (no
// network, no external script): the places drawn from their outlines, and
// for the place under the pointer or clicked its number, size, members, time
// span, neighbours, doors and local-map picture; a table of the places; the
// parameters, statistics, warnings and timings.

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace obsgroup::cli {

struct ReportInput {
  /// partition.json as written (its groups are every frame's, with keyframes).
  nlohmann::json partition;
  /// places.json as written; null when the places could not be made.
  nlohmann::json places;
  /// Each grouped observation: x, y of its pose and its group (group order).
  struct Position {
    double x, y;
    int group;
  };
  std::vector<Position> positions;
  std::vector<std::string> colours;  ///< per group, "#rrggbb", as map.png colours it
  /// Per group: its local-map picture as a data: URI, a path relative to the
  /// page, or empty (no picture).
  std::vector<std::string> pictures;
};

/// The page.
std::string reportHtml(const ReportInput& input);

/// "data:image/png;base64,..." of the bytes.
std::string pngDataUri(const std::string& bytes);

}  // namespace obsgroup::cli
