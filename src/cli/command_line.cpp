// The command line of `obsgroup`: its commands, options and usage errors,
// parsed into the arguments of a run (PartitionArgs). The Python module
// parses its keyword arguments here too, so both check them alike.

#include "command_line.h"

#include <obsgroup/io/errors.h>
#include <obsgroup/io/frame_reading.h>
#include "option_checks.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace {

/// CLI11's help with every description wrapped to fit kHelpWidth columns
/// (CLI11 2.1 writes each on one line, however long).
class WrappingFormatter : public CLI::Formatter {
 public:
  static constexpr std::size_t kHelpWidth = 100;

  std::string make_option(const CLI::Option* option, bool is_positional) const override {
    return layOut("  " + make_option_name(option, is_positional) + make_option_opts(option),
                  make_option_desc(option));
  }
  std::string make_description(const CLI::App* app) const override {
    const std::string description = CLI::Formatter::make_description(app);
    std::string out;
    for (const std::string& line : wrap(description, kHelpWidth)) out += line + "\n";
    return out.empty() ? out : out.substr(0, out.size() - 1) + (description.back() == '\n' ? "\n" : "");
  }

 private:
  /// `name` in the first column, `text` wrapped beside it (below it when the
  /// name is wider than the column).
  std::string layOut(const std::string& name, const std::string& text) const {
    const std::size_t column = get_column_width();
    std::string out = name;
    const std::vector<std::string> lines = wrap(text, kHelpWidth - column);
    if (lines.empty()) return out + "\n";
    if (name.size() >= column) out += "\n" + std::string(column, ' ');
    else out += std::string(column - name.size(), ' ');
    for (std::size_t k = 0; k < lines.size(); ++k) out += (k ? std::string(column, ' ') : "") + lines[k] + "\n";
    return out;
  }

  /// `text` as lines of at most `width` characters, broken at spaces (a
  /// longer word stands alone); its own line breaks are kept.
  static std::vector<std::string> wrap(const std::string& text, std::size_t width) {
    std::vector<std::string> lines;
    std::istringstream paragraphs(text);
    for (std::string paragraph; std::getline(paragraphs, paragraph);) {
      std::istringstream words(paragraph);
      std::string line;
      for (std::string word; words >> word;) {
        if (!line.empty() && line.size() + 1 + word.size() > width) {
          lines.push_back(line);
          line.clear();
        }
        line += (line.empty() ? "" : " ") + word;
      }
      if (!line.empty()) lines.push_back(line);
    }
    return lines;
  }
};

using namespace obsgroup;
using cli::choices;
using cli::finiteNumber;
using cli::number;
using cli::oneOf;
using cli::wholeNumber;

/// INPUT, -o and --format.
void addInputOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args,
                     const std::string& output_help = "folder to write the results to") {
  command.add_option("input", args.input,
                     "CARMEN log (.clf, .log, .gfs.log, gzipped or not; - reads standard input), folder of .pcd files, "
                     "depth images (TUM RGB-D, Redwood), KITTI odometry, ROS 1 bag (.bag) or ROS 2 bag (sqlite3 "
                     "folder)")
      ->required();
  command.add_option("-o,--output", args.output, output_help)->required();
  command.add_option("--format", args.format, "input format (default: from the input)")
      ->check(CLI::IsMember({"auto", "carmen", "pcd", "tum-rgbd", "redwood", "kitti", "ros1", "ros2"}))
      ->option_text("auto|carmen|pcd|tum-rgbd|redwood|kitti|ros1|ros2");
}

/// Options of ROS bags.
void addBagOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args) {
  command.add_option("--topic", args.topic,
                     "bags: the sensor_msgs/LaserScan or PointCloud2 topic (default: the only one)")
      ->group("ROS bags");
  command.add_option("--pose-topic", args.pose_topic,
                     "bags: a nav_msgs/Odometry or geometry_msgs/PoseStamped topic giving the poses (default: /tf)")
      ->group("ROS bags");
  command.add_option("--fixed-frame", args.fixed_frame,
                     "bags: the /tf frame the poses are taken in (default: map, else odom with a warning)")
      ->group("ROS bags");
}

/// Options of CARMEN logs.
void addCarmenOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args) {
  command.add_option("--laser", args.laser, "CARMEN: which laser messages: FLASER, RLASER or ROBOTLASER1 (default: auto, "
                                            "ROBOTLASER1 if any, else FLASER, else RLASER)")
      ->transform(oneOf(io::kLaserSourceNames))
      ->option_text(choices(io::kLaserSourceNames))
      ->group("CARMEN logs");
  command.add_option("--fov", args.field_of_view_deg,
                     "CARMEN: field of view of FLASER/RLASER scans, degrees (default: PARAM, else 180)")
      ->check(finiteNumber(1.0, false, 360.0))
      ->group("CARMEN logs");
  command.add_option("--max-range", args.max_range,
                     "CARMEN: readings at or beyond this are no return, metres (default: the message's, PARAM, "
                     "else 80)")
      ->check(finiteNumber(0.0, true))
      ->group("CARMEN logs");
  command.add_flag("--skip-bad-lines", args.skip_bad_lines,
                   "CARMEN: skip malformed lines (a truncated last line, say), counted in one warning")
      ->group("CARMEN logs");
}

/// Options of PCD sequences and pose files.
void addPcdOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args) {
  command.add_option("--poses", args.poses,
                     "PCD: poses file, one line per cloud, or matched by timestamp when the files are named by one "
                     "(default: each PCD's VIEWPOINT); depth images, KITTI: instead of the folder's; bags: a TUM "
                     "trajectory of the sensor matched by timestamp, instead of /tf")
      ->group("Poses (PCD sequences, depth images, KITTI, bags)");
  command.add_option("--pose-format", args.pose_format, "PCD: format of --poses (default: from the column count, 8 "
                                                        "tum, 12 kitti)")
      ->transform(oneOf(io::kPoseFormatNames))
      ->option_text(choices(io::kPoseFormatNames))
      ->group("Poses (PCD sequences, depth images, KITTI, bags)");
  command.add_option("--max-time-difference", args.max_time_difference,
                     "TUM poses matched by timestamp (depth images, PCD, bags): most seconds between a frame and its pose (default: " +
                         (std::ostringstream() << io::kDefaultMaxTimeDifference).str() + ")")
      ->check(finiteNumber(0.0))
      ->group("Poses (PCD sequences, depth images, KITTI, bags)");
}

/// Options of every folder of files.
void addFolderOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args) {
  command.add_flag("--skip-bad-files", args.skip_bad_files,
                   "PCD sequences, depth images, KITTI: leave out files that cannot be read, named in one warning "
                   "(default: the first one ends the run)")
      ->group("Folders of files (PCD sequences, depth images, KITTI)");
}

/// Options of depth image sequences.
void addDepthOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args) {
  command.add_option("--intrinsics", args.intrinsics, "depth images: pinhole fx,fy,cx,cy in pixels (default: "
                                                      "525,525,319.5,239.5)")
      ->option_text("FX,FY,CX,CY")
      ->group("Depth images");
  command.add_option("--depth-scale", args.depth_scale,
                     "depth images: PNG units per metre (default: 5000 tum-rgbd, 1000 redwood)")
      ->check(finiteNumber(0.0, true))
      ->group("Depth images");
  command.add_option("--depth-max", args.depth_max, "depth images: deeper pixels are no return, metres (default: none)")
      ->check(finiteNumber(0.0, true))
      ->group("Depth images");
  command.add_option("--up", args.up,
                     "depth images: the axis of the trajectory's world that points up, turned onto z (default: z for "
                     "tum-rgbd, auto for redwood: from the cameras' image axes)")
      ->transform(oneOf(io::kUpAxisNames))
      ->option_text(choices(io::kUpAxisNames))
      ->group("Depth images");
  command.add_option("--stride", args.stride, "depth images: every Nth pixel in each direction (default: 1)")
      ->check(wholeNumber(1))
      ->group("Depth images");
}

/// The sensed-space model and the partition (the paper's sec. II-III).
void addMethodOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args) {
  command.add_option("--sso", args.method.model,
                     "sensed-space model: points (eq. 16-18, the paper's), free-space (cells the beams cross) or "
                     "visibility (cells visible from the pose) (default: " + toString(args.method.model) + ")")
      ->transform(oneOf(kSensedSpaceModelNames))
      ->option_text(choices(kSensedSpaceModelNames))
      ->group("Sensed-space model");
  const obsgroup::GroupingParameters paper = obsgroup::GroupingParameters::paper();
  command.add_flag("--paper", args.paper,
                   "the paper's method exactly: --sso " + toString(paper.model) + " --split " + toString(paper.split) +
                       " --ncut-threshold " + number(paper.ncut_threshold) + " --boundary-passes " +
                       std::to_string(paper.boundary_passes) + " --mutual-neighbours " +
                       std::to_string(paper.mutual_neighbours) + " --open-floor-width " +
                       number(paper.open_floor_width) + " --correct-odometry off (delta as given)")
      ->group("Sensed-space model");
  command.add_option("--cell", args.method.regions.cell_size, "free-space, visibility: grid cell (voxel in 3D), metres")
      ->check(finiteNumber(0.0, true))
      ->capture_default_str()
      ->group("Sensed-space model");
  command.add_option("--range", args.method.regions.max_range, "free-space, visibility: how far from the sensor, metres")
      ->check(finiteNumber(0.0, true))
      ->capture_default_str()
      ->group("Sensed-space model");
  command.add_option("--clearance", args.method.regions.clearance,
                     "visibility: occupied cells nearer the pose than this do not block, metres")
      ->check(finiteNumber(0.0))
      ->capture_default_str()
      ->group("Sensed-space model");
  command.add_option("--min-observations", args.method.regions.min_observations,
                     "visibility: a cell is occupied when this many observations have a point in it (and no more "
                     "saw through it)")
      ->check(wholeNumber(1))
      ->capture_default_str()
      ->group("Sensed-space model");
  command.add_option("--door-width", args.method.regions.door_width,
                     "visibility: a view stops past an opening narrower than this (a door), metres; 0: never")
      ->check(finiteNumber(0.0))
      ->capture_default_str()
      ->group("Sensed-space model");
  command.add_option("--door-depth", args.method.regions.door_depth,
                     "visibility: a narrow stretch longer than this is a passage, not a door, metres")
      ->check(finiteNumber(0.0))
      ->capture_default_str()
      ->group("Sensed-space model");
  command.add_option("--band", args.band, "visibility, 3D: heights above the sensor that make the occupancy grid, "
                                          "LOW HIGH metres (default: " + std::to_string(args.method.regions.band_low) + " " +
                                          std::to_string(args.method.regions.band_high) + ")")
      ->expected(2)
      ->check(finiteNumber(-std::numeric_limits<double>::max()))
      ->group("Sensed-space model");
  command.add_option("--delta", args.method.match_distance, "points: match distance of eq. (16), metres")
      ->check(finiteNumber(0.0, true))
      ->capture_default_str()
      ->group("Sensed-space model");
  command.add_option("--voxel", args.voxel,
                     "voxel leaf of every observation, metres, applied as each frame is read (0 = keep every point; "
                     "default: dense frames of " + std::to_string(obsgroup::io::kDenseFramePoints) + "+ points at " +
                         number(obsgroup::io::kDefaultFrameVoxel) + ", others whole)")
      ->check(finiteNumber(0.0))
      ->group("Sensed-space model");
  command.add_option("--ncut-threshold", args.method.ncut_threshold, "accept a bisection while Ncut < this (sec. II-B)")
      ->check(finiteNumber(0.0, false, 2.0))
      ->capture_default_str()
      ->group("Partition");
  command.add_option("--boundary-passes", args.method.boundary_passes,
                     "sweeps after the split tree moving each observation to the group it overlaps most on "
                     "average (0: none, the paper's)")
      ->check(CLI::Range(0, 100))
      ->capture_default_str()
      ->group("Partition");
  command.add_option("--mutual-neighbours", args.method.mutual_neighbours,
                     "partition the graph in which each observation keeps the K it overlaps most that also keep "
                     "it (more on dense maps: --mutual-neighbours-share; 0: every overlap, the paper's)")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str()
      ->group("Partition");
  command.add_option("--mutual-neighbours-share", args.method.mutual_neighbours_share,
                     "... or this share of the median number of observations each overlaps, when more")
      ->check(finiteNumber(0.0, false, 10.0))
      ->capture_default_str()
      ->group("Partition");
  command.add_option("--open-floor-width", args.method.open_floor_width,
                     "join two groups when every step of the route between them passes through enclosed floor at "
                     "least this wide, metres (a hall or a large room no view spans, cut into bands; 0: none, the "
                     "paper's)")
      ->check(finiteNumber(0.0, false, 1000.0))
      ->capture_default_str()
      ->group("Partition");
  command.add_option("--join-passages", args.method.join_passages,
                     "visibility model: join two groups whose places meet through a passage, a corridor cut "
                     "across where it goes on as narrow, not a door (default: on; off with --paper)")
      ->check(CLI::IsMember({"on", "off"}))
      ->option_text("on|off")
      ->group("Partition");
  command.add_option("--split", args.method.split,
                     "how the eigenvector is cut: best (smallest Ncut), mean (the paper's) or sign (default: " +
                         toString(args.method.split) + ")")
      ->transform(oneOf(kSplitCriterionNames))
      ->option_text(choices(kSplitCriterionNames))
      ->group("Partition");
  command.add_option("--min-group-size", args.method.min_group_size, "reject a bisection giving a smaller group")
      ->check(wholeNumber(1))
      ->capture_default_str()
      ->group("Partition");
  command.add_option("--max-depth", args.method.max_depth, "do not bisect deeper than this (default: no limit)")
      ->check(wholeNumber(0))
      ->group("Partition");
}

/// --correct-odometry, for the commands that read poses.
void addOdometryCorrectionOption(CLI::App& command, obsgroup::cli::PartitionArgs& args) {
  command.add_option("--correct-odometry", args.correct_odometry,
                     "scan-match each observation to the one before it and group at the corrected poses: auto (when "
                     "the corrected map is more consistent: drifted odometry), on or off (default: " +
                         toString(args.correct_odometry) + ")")
      ->transform(oneOf(kOdometryCorrectionNames))
      ->option_text(choices(kOdometryCorrectionNames))
      ->group("Partition");
}

/// Threads, refinement, local maps and the outputs.
void addRunOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args) {
  command.add_option("--threads", args.method.threads, "threads (0 = all cores); results do not depend on it")
      ->check(wholeNumber(0))
      ->capture_default_str();
  addOdometryCorrectionOption(command, args);
  command.add_option("--refine", args.refine,
                     "align each local map's observations: none, icp (spanning tree) or lum (Lu & Milios) (default: " +
                         toString(args.refine) + ")")
      ->transform(oneOf(kRefinementNames))
      ->option_text(choices(kRefinementNames))
      ->group("Local maps");
  command.add_option("--map-voxel", args.map_voxel,
                     "voxel leaf of the local maps written, metres (0 = off; default: delta/2)")
      ->check(finiteNumber(0.0))
      ->group("Local maps");
  command.add_flag("--force", args.force, "replace the results already in the output folder")->group("Output");
  command.add_flag("-q,--quiet", args.quiet, "no progress bar, summary or warnings on stderr")->group("Output");
  command.add_flag("--no-pictures", args.no_pictures,
                   "do not draw map.png/.svg, weights.png, fiedler.png, local_maps/group_NNN.png")
      ->group("Output");
}

void addPartitionOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args) {
  addInputOptions(command, args);
  addCarmenOptions(command, args);
  addPcdOptions(command, args);
  addFolderOptions(command, args);
  addDepthOptions(command, args);
  addBagOptions(command, args);
  addMethodOptions(command, args);
  addRunOptions(command, args);
}

/// "DIST,ANGLE": two finite numbers >= 0, metres and degrees.
std::optional<obsgroup::KeyframeOptions> parseKeyframes(const std::string& text) {
  const auto comma = text.find(',');
  if (comma == std::string::npos) return std::nullopt;
  obsgroup::KeyframeOptions options;
  try {
    std::size_t used = 0;
    options.distance = std::stod(text.substr(0, comma), &used);
    if (used != comma) return std::nullopt;
    const std::string angle = text.substr(comma + 1);
    options.angle_deg = std::stod(angle, &used);
    if (used != angle.size()) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (!(std::isfinite(options.distance) && options.distance >= 0 && std::isfinite(options.angle_deg) &&
        options.angle_deg >= 0))
    return std::nullopt;
  return options;
}

/// --keyframes, of `partition` only: the online grouping takes every frame.
void addKeyframeOption(CLI::App& command, obsgroup::cli::PartitionArgs& args) {
  command
      .add_option_function<std::string>(
          "--keyframes", [&args](const std::string& text) { args.keyframes = parseKeyframes(text); },
          "group only the frames that moved DIST metres or turned ANGLE degrees since the last keyframe; each "
          "other frame takes its keyframe's place (default: every frame)")
      ->type_name("DIST,ANGLE")
      ->check(CLI::Validator(
          [](std::string& text) {
            return parseKeyframes(text) ? std::string() : "expected DIST,ANGLE: two finite numbers >= 0 (metres, degrees)";
          },
          "DIST,ANGLE"))
      ->group("Partition");
}

/// `locate PLACES INPUT -o FILE.json`: the places of a run, an input read as
/// partition reads it, and where the locations go.
void addLocateOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args, obsgroup::cli::LocateOptions& locate) {
  command.add_option("places", locate.places,
                     "output folder of `obsgroup partition` or `obsgroup stream` (its places.yaml and places.png)")
      ->required();
  addInputOptions(command, args, "JSON file to write the locations to");
  addCarmenOptions(command, args);
  addPcdOptions(command, args);
  addFolderOptions(command, args);
  addDepthOptions(command, args);
  addBagOptions(command, args);
  command.add_option("--tolerance", locate.tolerance,
                     "a pose on no place takes the nearest place within this, metres (0: none)")
      ->check(finiteNumber(0.0))
      ->capture_default_str();
  addOdometryCorrectionOption(command, args);
  command.add_flag("--align", locate.align,
                   "align each located observation to its place's local map (ICP from its pose) and report the "
                   "aligned pose, its place and the fit");
  command.add_flag("--track,!--no-track", locate.track,
                   "align each observation in turn to its place's local map, from the previous one's aligned pose "
                   "moved by the input's step, and locate it at that pose: a drifted run follows the map (default; "
                   "--no-track: each observation at its own pose)");
  command.add_option("--threads", args.method.threads, "threads (0 = all cores); results do not depend on it")
      ->check(wholeNumber(0))
      ->capture_default_str();
  command.add_flag("--force", args.force, "replace the output file");
  command.add_flag("-q,--quiet", args.quiet, "no summary or warnings on stderr");
}

/// What `stream` adds: how often to update, and the replay's pace.
void addStreamOptions(CLI::App& command, obsgroup::cli::StreamOptions& stream) {
  command.add_option("--update-every", stream.update_every,
                     "update the groups after every N observations inserted, and after the last")
      ->check(wholeNumber(1))
      ->capture_default_str()
      ->group("Stream");
  command.add_option("--exact-every", stream.exact_every,
                     "faster, approximate: between exact updates, re-partition only the groups a change touches "
                     "and their neighbours; exact again after N observations and at the end (1 = always exact)")
      ->check(wholeNumber(1))
      ->capture_default_str()
      ->group("Stream");
  command.add_flag("--verbose", stream.verbose,
                   "print every change of the groups (created, grown, split, merged, ...) instead of one line per "
                   "observation")
      ->group("Stream");
  command.add_flag("--realtime", stream.realtime,
                   "insert each observation at the time of its timestamp, as the robot sensed it (CARMEN logs, "
                   "ROS bags)")
      ->group("Stream");
}

/// The command a user typed, checked before CLI11 parses: it only says "A
/// subcommand is required" or that a misspelt one "was not expected".
std::optional<std::string> commandError(int argc, const char* const* argv, const CLI::App& app) {
  std::string names;
  for (const CLI::App* command : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + command->get_name();
  if (argc < 2) return "a command is required: " + names + " (obsgroup --help for more)";
  const std::string first = argv[1];
  if (first.empty() || first[0] == '-') return std::nullopt;  // --help, --version, or an error CLI11 words
  for (const CLI::App* command : app.get_subcommands({}))
    if (command->get_name() == first) return std::nullopt;
  return "unknown command '" + first + "' (commands: " + names + ")";
}

/// Edit distance (insertions, deletions, substitutions) between two words.
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

/// An option the command does not have, checked before CLI11 parses (it
/// says only that "lum --refin" were not expected): named, with the nearest
/// option the command has when one is close.
std::optional<std::string> unknownOptionError(int argc, const char* const* argv, const CLI::App& app) {
  if (argc < 2) return std::nullopt;
  const CLI::App* command = nullptr;
  for (const CLI::App* c : app.get_subcommands({}))
    if (c->get_name() == argv[1]) command = c;
  if (!command) return std::nullopt;
  std::vector<std::string> names{"--help", "-h"};
  std::map<std::string, int> values;  // option name -> how many values follow it
  for (const CLI::Option* option : command->get_options()) {
    std::vector<std::string> own;
    for (const std::string& l : option->get_lnames()) own.push_back("--" + l);
    for (const std::string& n : option->get_snames()) own.push_back("-" + n);
    for (const std::string& name : own) {
      names.push_back(name);
      values[name] = std::max(0, option->get_items_expected_min());
    }
  }
  for (int a = 2; a < argc; ++a) {
    std::string word = argv[a];
    if (word == "--") break;  // the rest are arguments
    if (word.size() < 2 || word[0] != '-' || std::isdigit(static_cast<unsigned char>(word[1])) || word[1] == '.')
      continue;  // an argument, "-" (standard input) or a negative number
    const std::size_t equals = word.find('=');
    word = word.substr(0, equals);
    if (word[1] != '-' && word.size() > 2 && values.count(word.substr(0, 2)) && values[word.substr(0, 2)] > 0)
      continue;  // a short option with its value attached: -oOUT
    if (const auto known = values.find(word); known != values.end()) {
      if (equals == std::string::npos) a += known->second;  // its values, whatever they look like
      continue;
    }
    if (std::find(names.begin(), names.end(), word) != names.end()) continue;
    std::string nearest;
    std::size_t best = std::string::npos;
    for (const std::string& name : names)
      if (name.size() > 2 && editDistance(word, name) < best) best = editDistance(word, name), nearest = name;
    const std::string hint = best <= std::max<std::size_t>(2, word.size() / 3)
                                 ? "did you mean " + nearest + "?"
                                 : "obsgroup " + command->get_name() + " --help lists the options";
    return "unknown option '" + word + "' (" + hint + ")";
  }
  return std::nullopt;
}

/// --pose-format without a poses file: a mistake whatever the command.
bool poseFormatWithoutPoses(const CLI::App& command, const obsgroup::cli::PartitionArgs& args) {
  return command.count("--pose-format") && !args.poses;
}

/// The options that only make sense together, and the --paper preset.
/// Returns the usage error, if any.
std::optional<std::string> settleOptions(const CLI::App& partition, obsgroup::cli::PartitionArgs& args) {
  using obsgroup::SensedSpaceModel;
  using obsgroup::SplitCriterion;
  if (poseFormatWithoutPoses(partition, args)) return "--pose-format applies to a --poses file (PCD sequences)";
  if (args.paper) {
    const obsgroup::GroupingParameters paper = obsgroup::GroupingParameters::paper();
    if (partition.count("--sso") && args.method.model != paper.model)
      return "--paper uses --sso " + toString(paper.model) + "; drop one of them";
    if (partition.count("--split") && args.method.split != paper.split)
      return "--paper uses --split " + toString(paper.split) + "; drop one of them";
    if (partition.count("--ncut-threshold") && args.method.ncut_threshold != paper.ncut_threshold)
      return "--paper uses --ncut-threshold " + number(paper.ncut_threshold) + "; drop one of them";
    if (partition.count("--boundary-passes") && args.method.boundary_passes != paper.boundary_passes)
      return "--paper uses --boundary-passes " + std::to_string(paper.boundary_passes) + "; drop one of them";
    for (const char* option : {"--mutual-neighbours", "--mutual-neighbours-share"})
      if (partition.count(option))
        return std::string("--paper uses every overlap (--mutual-neighbours 0); drop ") + option;
    if (partition.count("--open-floor-width") && args.method.open_floor_width != 0.0)
      return "--paper joins no groups (--open-floor-width 0); drop one of them";
    if (partition.count("--correct-odometry") && args.correct_odometry != obsgroup::OdometryCorrection::Off)
      return "--paper groups at the input poses (--correct-odometry off); drop one of them";
    if (partition.count("--join-passages") && args.method.join_passages)
      return "--paper joins no groups (--join-passages off); drop one of them";
    args.method.usePaperMethod();
    args.correct_odometry = obsgroup::OdometryCorrection::Off;
  }
  if (partition.count("--mutual-neighbours-share") && args.method.mutual_neighbours == 0)
    return "--mutual-neighbours-share applies when --mutual-neighbours is above 0";
  // Options of one model given with another are a mistake, not a no-op.
  const bool points = args.method.model == SensedSpaceModel::Points;
  for (const char* option : {"--cell", "--range"})
    if (points && partition.count(option))
      return std::string(option) + " applies to --sso free-space or visibility, not points";
  if (!points && partition.count("--delta")) return "--delta applies to --sso points (the region models use --cell)";
  if (args.method.model != SensedSpaceModel::Visibility)
    for (const char* option :
         {"--clearance", "--min-observations", "--band", "--door-width", "--door-depth", "--open-floor-width",
          "--join-passages"})
      if (partition.count(option)) return std::string(option) + " applies to --sso visibility only";
  if (args.voxel) args.method.voxel_leaf = *args.voxel;
  if (!args.band.empty()) {
    if (!(args.band[0] < args.band[1]))
      return "--band: LOW must be below HIGH (got " + std::to_string(args.band[0]) + " " +
             std::to_string(args.band[1]) + ")";
    args.method.regions.band_low = args.band[0];
    args.method.regions.band_high = args.band[1];
  }
  try {
    args.method.check();  // what the options' own checks cannot see, e.g. a range of too many cells
  } catch (const std::invalid_argument& e) {
    return std::string(e.what());
  }
  args.pictures = !args.no_pictures;
  return std::nullopt;
}

}  // namespace

namespace obsgroup::cli {

ParsedCommandLine parseCommandLine(int argc, const char* const* argv) {
  CLI::App app{"obsgroup: group robot observations into consistent local maps and a metric-topological map",
               "obsgroup"};
  app.formatter(std::make_shared<WrappingFormatter>());  // before the subcommands, which copy it
  app.set_version_flag("--version", "obsgroup 0.1.0");
  app.require_subcommand(1, 1);
  PartitionArgs args;
  CLI::App* partition = app.add_subcommand(
      "partition", "group the observations of a laser log, a PCD sequence, depth images, KITTI scans or a ROS bag "
                   "into places: local maps, a topological map, place outlines and pictures");
  addPartitionOptions(*partition, args);
  addKeyframeOption(*partition, args);
  // stream binds the same options (only the command given parses any).
  StreamOptions stream_options;
  CLI::App* stream = app.add_subcommand(
      "stream", "replay the observations one at a time through the online grouping, printing the place each joins "
                "on stdout (-q: not; --verbose: every change); then write what partition writes");
  addPartitionOptions(*stream, args);
  addStreamOptions(*stream, stream_options);
  LocateOptions locate_options;
  CLI::App* locate = app.add_subcommand(
      "locate", "which place each observation of an input is in (poses in the map's frame), from the places of an "
                "earlier partition or stream; written as JSON");
  addLocateOptions(*locate, args, locate_options);

  ParsedCommandLine parsed;
  const auto usage = [&parsed](const std::string& message) {
    parsed.exit_code = 2;
    parsed.error = message;
    return parsed;
  };
  if (const auto error = commandError(argc, argv, app)) return usage(*error);
  if (const auto error = unknownOptionError(argc, argv, app)) return usage(*error);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    parsed.exit_code = app.exit(e);  // --help, --version
    return parsed;
  } catch (const CLI::ParseError& e) {
    parsed.error = e.what();
    std::string path = app.get_name();
    for (const CLI::App* command : app.get_subcommands()) path += " " + command->get_name();
    parsed.help_hint = "Run '" + path + " --help' for the options.";
    parsed.exit_code = 2;
    return parsed;
  }
  const bool streaming = stream->parsed();
  if (locate->parsed()) {
    if (poseFormatWithoutPoses(*locate, args)) return usage("--pose-format applies to a --poses file (PCD sequences)");
    args.locate = locate_options;
  } else if (const auto error = settleOptions(streaming ? *stream : *partition, args)) {
    return usage(*error);
  }
  if (streaming) args.stream = stream_options;
  parsed.args = std::move(args);
  return parsed;
}

}  // namespace obsgroup::cli
