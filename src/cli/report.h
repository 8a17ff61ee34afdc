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
  /// What partition.json records of the run (its groups are every frame's,
  /// with keyframes): input, observations, groups, place_ids, stamps,
  /// parameters, statistics, timing_s and warnings.
  nlohmann::json partition;
  /// The places' outlines and doors (io::placeOutlinesJson: places.json
  /// without the members, which the groups hold); null when the places
  /// could not be made.
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
