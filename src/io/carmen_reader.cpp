#include <obsgroup/io/carmen_reader.h>

#include <obsgroup/io/errors.h>
#include <obsgroup/io/input_file.h>
#include "text_fields.h"

#include <obsgroup/common/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <thread>

namespace obsgroup::io {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDefaultFieldOfViewDeg = 180.0;
constexpr double kDefaultMaxRange = 80.0;  // SICK scanners report ~81.9 m for "no return"
constexpr long kMaxReadings = 1000000;

const char* messageName(LaserSource source) {
  switch (source) {
    case LaserSource::Front: return "FLASER";
    case LaserSource::Rear: return "RLASER";
    case LaserSource::RobotLaser: return "ROBOTLASER1";
    case LaserSource::Auto: break;
  }
  return "";
}

/// Checks that a message line has exactly `expected` fields; otherwise names
/// the first missing field, or says the counts do not match.
void requireFieldCount(const std::vector<std::string_view>& fields, std::size_t expected, const LineRef& where,
                       const std::string& counts, const std::function<std::string(std::size_t)>& field_name) {
  const std::string message(fields[0]);
  if (fields.size() < expected)
    throw inputError(where.file, where.line,
                     message + " line is truncated: it has " + std::to_string(fields.size()) +
                         " fields and ends before field '" + field_name(fields.size()) + "' (" + counts +
                         " make " + std::to_string(expected) + " fields)");
  if (fields.size() > expected)
    throw inputError(where.file, where.line,
                     message + " line has " + std::to_string(fields.size()) + " fields, but " + counts + " make " +
                         std::to_string(expected) + ": the number of ranges does not match");
}

void readRanges(const std::vector<std::string_view>& fields, std::size_t first, long n, const LineRef& where,
                LaserScan& scan) {
  scan.ranges.resize(n);
  for (long k = 0; k < n; ++k) {  // nan/inf: no return
    const std::optional<double> range = toDouble(fields[first + k]);
    if (!range) throwNotANumber(fields[first + k], where, "range " + std::to_string(k + 1));
    scan.ranges[k] = *range;
  }
}

Eigen::Isometry3d parsePose(const std::vector<std::string_view>& fields, std::size_t first, const LineRef& where,
                            const std::string& prefix) {
  const double x = parseFinite(fields[first], where, prefix + "_x");
  const double y = parseFinite(fields[first + 1], where, prefix + "_y");
  const double theta = parseFinite(fields[first + 2], where, prefix + "_theta");
  return pose2D(x, y, theta);
}

/// The message's ipc_timestamp (named `name` in errors): a finite number
/// when `required`, else NaN when it is not a number.
double readTimestamp(std::string_view field, const LineRef& where, const std::string& name, bool required) {
  if (required) return parseFinite(field, where, name);
  return toDouble(field).value_or(std::numeric_limits<double>::quiet_NaN());
}

/// FLASER/RLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp host logger_timestamp
LaserScan parseFrontOrRearLaser(const std::vector<std::string_view>& fields, const LineRef& where,
                                bool require_timestamp) {
  static const char* kTail[] = {"x", "y", "theta", "odom_x", "odom_y", "odom_theta",
                                "ipc_timestamp", "ipc_hostname", "logger_timestamp"};
  if (fields.size() < 2)
    throw inputError(where.file, where.line, std::string(fields[0]) + " line ends before field 'num_readings'");
  const long n = parseCount(fields[1], where, "num_readings", kMaxReadings);
  requireFieldCount(fields, 2 + n + 9, where, "num_readings = " + std::to_string(n), [n](std::size_t k) {
    return k < std::size_t(2 + n) ? "range " + std::to_string(k - 1) : std::string(kTail[k - 2 - n]);
  });
  LaserScan scan;
  readRanges(fields, 2, n, where, scan);
  scan.laser_pose = parsePose(fields, 2 + n, where, "laser_pose");  // x y theta: the laser's pose
  scan.timestamp = readTimestamp(fields[2 + n + 6], where, "ipc_timestamp", require_timestamp);
  return scan;
}

/// The angle between the beams of a ROBOTLASER1 scan, from the fields that
/// agree: a sensor that includes both ends of its field of view has
/// resolution * (n - 1) = fov; a full turn (fov = 2 pi) has resolution * n =
/// fov (beam n would be beam 0 again). Loggers round the resolution, so
/// within half a beam the field of view gives the exact step. When neither
/// agrees, the resolution is used and `*disagrees` is set.
double robotLaserStep(double fov, double resolution, long n, bool* disagrees) {
  *disagrees = false;
  if (n < 2) return resolution;
  const double tolerance = 0.5 * std::abs(resolution);
  if (std::abs(resolution * (n - 1) - fov) < tolerance) return fov / (n - 1);
  if (std::abs(std::abs(fov) - 2 * kPi) < std::max(tolerance, 1e-3) && std::abs(resolution * n - fov) < tolerance)
    return fov / n;
  *disagrees = true;
  return resolution;
}

/// ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range accuracy
/// remission_mode n r1..rn num_remissions [remissions] laser_pose_x laser_pose_y laser_pose_theta
/// robot_pose_x robot_pose_y robot_pose_theta laser_tv laser_rv forward_safety_dist
/// side_safety_dist turn_axis timestamp host logger_timestamp
LaserScan parseRobotLaser(const std::vector<std::string_view>& fields, const LineRef& where, bool require_timestamp) {
  static const char* kHead[] = {"ROBOTLASER1",        "laser_type",   "start_angle",   "field_of_view",
                                "angular_resolution", "maximum_range", "accuracy",     "remission_mode",
                                "num_readings"};
  static const char* kTail[] = {"laser_pose_x", "laser_pose_y", "laser_pose_theta", "robot_pose_x",
                                "robot_pose_y", "robot_pose_theta", "laser_tv", "laser_rv",
                                "forward_safety_dist", "side_safety_dist", "turn_axis", "timestamp",
                                "host", "logger_timestamp"};
  if (fields.size() < 9)
    throw inputError(where.file, where.line, "ROBOTLASER1 line is truncated: it ends before field '" +
                                                 std::string(kHead[fields.size()]) + "'");
  const long n = parseCount(fields[8], where, "num_readings", kMaxReadings);
  if (fields.size() < std::size_t(10 + n))
    throw inputError(where.file, where.line,
                     "ROBOTLASER1 line is truncated: it has " + std::to_string(fields.size()) +
                         " fields and ends before field '" +
                         (fields.size() < std::size_t(9 + n) ? "range " + std::to_string(fields.size() - 8)
                                                             : std::string("num_remissions")) +
                         "' (num_readings = " + std::to_string(n) + ")");
  long remissions = 0;
  try {
    remissions = parseCount(fields[9 + n], where, "num_remissions", kMaxReadings);
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + "; does num_readings = " + std::to_string(n) +
                     " match the number of ranges?");
  }
  const std::size_t tail = 10 + n + remissions;
  requireFieldCount(fields, tail + 14, where,
                    "num_readings = " + std::to_string(n) + " and num_remissions = " + std::to_string(remissions),
                    [&](std::size_t k) {
                      return k < tail ? "remission " + std::to_string(k - 9 - n) : std::string(kTail[k - tail]);
                    });
  LaserScan scan;
  scan.start_angle = parseFinite(fields[2], where, "start_angle");
  const double fov = parseFinite(fields[3], where, "field_of_view");
  const double resolution = parseFinite(fields[4], where, "angular_resolution");
  scan.max_range = parseFinite(fields[5], where, "maximum_range");
  scan.field_of_view = fov;
  scan.angle_step = robotLaserStep(fov, resolution, n, &scan.step_disagrees);
  readRanges(fields, 9, n, where, scan);
  scan.laser_pose = parsePose(fields, tail, where, "laser_pose");
  scan.robot_pose = parsePose(fields, tail + 3, where, "robot_pose");
  scan.timestamp = readTimestamp(fields[tail + 11], where, "timestamp", require_timestamp);
  return scan;
}

/// Numeric PARAM values that set the geometry of FLASER/RLASER scans.
struct LaserParams {
  std::map<std::string, double> values;
  std::optional<double> get(const std::string& name) const {
    const auto it = values.find(name);
    return it == values.end() ? std::nullopt : std::optional<double>(it->second);
  }
};

using ParamValue = std::pair<std::string, double>;

std::optional<ParamValue> readParam(const std::vector<std::string_view>& fields, const LineRef& where) {
  static const char* kKnown[] = {"robot_front_laser_max", "robot_rear_laser_max", "laser_front_laser_resolution",
                                 "laser_rear_laser_resolution", "laser_front_laser_fov", "laser_rear_laser_fov"};
  if (fields.size() < 3) return std::nullopt;
  const std::string name(fields[1]);
  for (const char* known : kKnown)
    if (name == known) return ParamValue{name, parseFinite(fields[2], where, "PARAM " + name)};
  return std::nullopt;
}

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

/// The field of view of FLASER/RLASER scans of n beams, in degrees, and
/// where it came from. CARMEN's PARAM laser_*_laser_fov is in degrees, but
/// some loggers wrote radians (MIT CSAIL: 3.14159 with a 0.5 degree
/// resolution and 361 beams): the unit that agrees with resolution * (n - 1)
/// is taken, or without a resolution, radians for a value up to 2 pi.
struct FieldOfView {
  double deg = kDefaultFieldOfViewDeg;
  std::string source = "default";
  bool radians_assumed = false;
};

FieldOfView frontOrRearFieldOfView(const LaserParams& params, const std::string& side, std::size_t n,
                                   const CarmenOptions& options) {
  if (options.field_of_view_deg) return {*options.field_of_view_deg, "--fov"};
  const std::string fov_name = "laser_" + side + "_laser_fov", resolution_name = "laser_" + side + "_laser_resolution";
  const std::optional<double> fov = params.get(fov_name), resolution = params.get(resolution_name);
  if (fov) {
    const double as_radians = *fov * 180.0 / kPi;
    bool radians = false;
    std::string why;
    if (resolution && *resolution > 0 && n > 1 && *fov > 0) {
      const double expected = *resolution * (n - 1);
      radians = std::abs(std::log(as_radians / expected)) < std::abs(std::log(*fov / expected));
      why = "the resolution " + number(*resolution) + " degrees x " + std::to_string(n - 1) + " beam steps make " +
            number(expected) + " degrees";
    } else {
      radians = *fov > 0 && *fov <= 2 * kPi + 1e-3;
      why = "no scanner covers only " + number(*fov) + " degrees";
    }
    if (radians)
      return {as_radians, "PARAM " + fov_name + " " + number(*fov) + " read as radians (" + why + ")", true};
    return {*fov, "PARAM " + fov_name + " (degrees)"};
  }
  if (resolution && n > 1)
    return {*resolution * (n - 1), "PARAM " + resolution_name + " x (" + std::to_string(n) + " - 1) beams"};
  return {kDefaultFieldOfViewDeg, "default (180 degrees)"};
}

/// A reading that gives a point (see scanToCloud).
bool isReturn(double r, double max_range) { return std::isfinite(r) && r > 0.0 && r < max_range; }

bool hasReturn(const LaserScan& scan) {
  for (double r : scan.ranges)
    if (isReturn(r, scan.max_range)) return true;
  return false;
}

using NumberedLines = std::vector<std::pair<std::size_t, std::string_view>>;  // (line number, text)

/// The log cut into numbered lines, and how many messages of each laser kind it holds.
struct LogLines {
  NumberedLines lines;
  std::map<LaserSource, std::size_t> counts;
};

bool startsWithMessage(std::string_view line, std::string_view name) {
  return line.substr(0, name.size()) == name &&
         (line.size() == name.size() || line[name.size()] == ' ' || line[name.size()] == '\t');
}

LogLines splitLines(std::string_view content) {
  LogLines log;
  for (TextLines lines(content); lines.next();) {
    log.lines.emplace_back(lines.number(), lines.line());
    for (LaserSource s : {LaserSource::Front, LaserSource::Rear, LaserSource::RobotLaser})
      if (startsWithMessage(lines.line(), messageName(s))) ++log.counts[s];
  }
  return log;
}

/// The laser messages to read: the option's, or ROBOTLASER1, else FLASER,
/// else RLASER; warns when the log holds others too.
LaserSource chooseSource(std::map<LaserSource, std::size_t>& counts, const CarmenOptions& options,
                         const std::string& path, std::vector<std::string>& warnings) {
  LaserSource source = options.laser;
  if (source == LaserSource::Auto) {
    for (LaserSource s : {LaserSource::RobotLaser, LaserSource::Front, LaserSource::Rear})
      if (counts[s] > 0) {
        source = s;
        break;
      }
    if (source == LaserSource::Auto)
      throw InputError(path + ": no FLASER, RLASER or ROBOTLASER1 message: is this a CARMEN log?");
  }
  const std::string chosen = messageName(source);
  if (counts[source] == 0)
    throw InputError(path + ": no " + chosen + " message in this log (--laser " + toString(source) + ")");
  std::string others;
  for (LaserSource s : {LaserSource::RobotLaser, LaserSource::Front, LaserSource::Rear})
    if (s != source && counts[s] > 0)
      others += (others.empty() ? "" : ", ") + std::to_string(counts[s]) + " " + messageName(s);
  if (!others.empty())
    warnings.push_back(path + ": using the " + std::to_string(counts[source]) + " " + chosen +
                       " scans; the log also has " + others + " (choose with --laser)");
  return source;
}

/// A pose of a SLAM graph (VERTEX2 id x y theta, or g2o's VERTEX_SE2): the
/// corrected pose of the scan that follows it.
struct Vertex {
  std::size_t line = 0;
  Eigen::Isometry3d pose;
};

/// What parsing a slice of the log's lines gave, in line order: the scans of
/// the chosen message, the PARAM values, the graph vertices and, with
/// skip_bad_lines, the errors of the lines skipped.
struct ParsedSlice {
  std::vector<LaserScan> scans;
  std::vector<ParamValue> params;
  std::vector<Vertex> vertices;
  std::vector<std::string> bad_lines;
};

bool isVertex(std::string_view message) { return message == "VERTEX2" || message == "VERTEX_SE2"; }

/// `fields`: the caller's scratch, reused from line to line.
void parseLine(std::string_view line, std::size_t line_number, const std::string& path, LaserSource source,
               bool require_timestamps, ParsedSlice& out, std::vector<std::string_view>& fields) {
  splitFields(line, fields);
  if (fields.empty() || fields[0].front() == '#') return;
  const LineRef where{path, line_number};
  if (fields[0] == "PARAM") {
    if (auto value = readParam(fields, where)) out.params.push_back(std::move(*value));
  } else if (isVertex(fields[0])) {
    if (fields.size() < 5)
      throw inputError(path, line_number,
                       std::string(fields[0]) + " line is truncated: expected id x y theta after " +
                           std::string(fields[0]));
    out.vertices.push_back({line_number, parsePose(fields, 2, where, "vertex")});
  } else if (fields[0] == messageName(source)) {
    LaserScan scan = source == LaserSource::RobotLaser ? parseRobotLaser(fields, where, require_timestamps)
                                                       : parseFrontOrRearLaser(fields, where, require_timestamps);
    if (source != LaserSource::RobotLaser) scan.robot_pose = scan.laser_pose;
    scan.line = line_number;
    out.scans.push_back(std::move(scan));
  }
}

/// Parses lines [begin, end); throws the first bad line's error, or records
/// it and goes on when `skip_bad_lines`.
void parseSlice(const NumberedLines& lines, std::size_t begin, std::size_t end, const std::string& path,
                LaserSource source, const CarmenOptions& options, ParsedSlice& out) {
  std::vector<std::string_view> fields;
  for (std::size_t k = begin; k < end; ++k) {
    try {
      parseLine(lines[k].second, lines[k].first, path, source, options.require_timestamps, out, fields);
    } catch (const InputError& e) {
      if (!options.skip_bad_lines) throw;
      out.bad_lines.push_back(e.what());
    }
  }
}

/// Threads worth starting for a log of `bytes`: small logs (and fuzzing
/// inputs) are parsed on the calling thread.
int threadsFor(std::size_t bytes, const CarmenOptions& options) {
  if (bytes < (std::size_t(1) << 20)) return 1;
  const int all = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return options.threads > 0 ? options.threads : all;
}

/// The lines cut into one slice per thread, parsed in parallel; the slices
/// are in line order, so the result (and the error of the first bad line)
/// does not depend on the thread count.
std::vector<ParsedSlice> parseSlices(const NumberedLines& lines, const std::string& path, LaserSource source,
                                     const CarmenOptions& options, int threads) {
  const std::size_t count = std::max<std::size_t>(1, std::min<std::size_t>(threads, lines.size()));
  std::vector<ParsedSlice> slices(count);
  parallelFor(count, threads, [&](std::size_t t) {
    parseSlice(lines, lines.size() * t / count, lines.size() * (t + 1) / count, path, source, options, slices[t]);
  });
  return slices;
}

/// Each vertex's pose replaces the pose of the scan that follows it (before
/// the next vertex); the laser keeps its mounting on the robot.
void applyVertices(std::vector<LaserScan>& scans, const std::vector<Vertex>& vertices, const std::string& path,
                   std::vector<std::string>& warnings) {
  if (vertices.empty()) return;
  std::size_t v = 0, used = 0;
  std::optional<Eigen::Isometry3d> pending;
  for (LaserScan& scan : scans) {
    while (v < vertices.size() && vertices[v].line < scan.line) pending = vertices[v++].pose;
    if (!pending) continue;
    scan.laser_pose = *pending * (scan.robot_pose.inverse() * scan.laser_pose);
    scan.robot_pose = *pending;
    pending.reset();
    ++used;
  }
  warnings.push_back(path + ": a SLAM graph log: the poses of " + std::to_string(used) + " of " +
                     std::to_string(vertices.size()) + " VERTEX2 lines replace those of the scans that follow them (" +
                     std::to_string(scans.size() - used) + " scans keep their own); EDGE2 lines are ignored");
}

/// Beam geometry of FLASER/RLASER scans, which the messages do not carry.
void applyGeometry(LaserScan& scan, const FieldOfView& fov, double max_range) {
  const std::size_t n = scan.ranges.size();
  const double fov_rad = fov.deg * kPi / 180.0;
  scan.field_of_view = fov_rad;
  scan.start_angle = -fov_rad / 2;  // centred ahead, counter-clockwise (right to left)
  scan.angle_step = n > 1 ? fov_rad / (n - 1) : 0.0;
  scan.max_range = max_range;
}

/// The scans, PARAM values and vertices of all slices, in line order; the
/// bad lines skipped are counted in one warning.
void mergeSlices(std::vector<ParsedSlice>& slices, const std::string& path, CarmenLog& log, LaserParams& params,
                 std::vector<Vertex>& vertices) {
  std::string first_bad;
  for (ParsedSlice& slice : slices) {
    for (ParamValue& value : slice.params) params.values[value.first] = value.second;  // the last one holds
    vertices.insert(vertices.end(), slice.vertices.begin(), slice.vertices.end());
    log.scans.insert(log.scans.end(), std::make_move_iterator(slice.scans.begin()),
                     std::make_move_iterator(slice.scans.end()));
    if (!slice.bad_lines.empty() && first_bad.empty()) first_bad = slice.bad_lines.front();
    log.skipped_lines += slice.bad_lines.size();
    slice = {};
  }
  if (log.skipped_lines > 0)
    log.warnings.push_back("skipped " + std::to_string(log.skipped_lines) + " bad line" +
                           (log.skipped_lines == 1 ? "" : "s") + " (first: " + first_bad + ")");
  if (log.scans.empty())
    throw InputError(path + ": no " + std::string(messageName(log.source)) + " scan left after skipping " +
                     std::to_string(log.skipped_lines) + " bad lines");
}

/// Geometry and maximum range of every scan, the field of view used, and
/// the warnings about them (once each).
void finishScans(CarmenLog& log, const LaserParams& params, const CarmenOptions& options, const std::string& path) {
  const std::string side = log.source == LaserSource::Rear ? "rear" : "front";
  const double max_range = params.get("robot_" + side + "_laser_max").value_or(kDefaultMaxRange);
  std::map<std::size_t, FieldOfView> by_beams;  // FLASER/RLASER: per number of beams
  const LaserScan* disagreeing = nullptr;
  std::size_t disagreeing_count = 0;
  for (LaserScan& scan : log.scans) {
    if (log.source != LaserSource::RobotLaser) {
      auto it = by_beams.find(scan.ranges.size());
      if (it == by_beams.end())
        it = by_beams.emplace(scan.ranges.size(), frontOrRearFieldOfView(params, side, scan.ranges.size(), options))
                 .first;
      applyGeometry(scan, it->second, max_range);
    } else if (scan.step_disagrees && disagreeing_count++ == 0) {
      disagreeing = &scan;
    }
    if (options.max_range) scan.max_range = *options.max_range;
    if (!hasReturn(scan))
      log.warnings.push_back(path + ":" + std::to_string(scan.line) +
                             ": the scan has no return; kept as an observation (a group of its own)");
  }
  const LaserScan& first = log.scans.front();
  log.fov_deg = first.field_of_view * 180.0 / kPi;
  if (log.source == LaserSource::RobotLaser) {
    log.fov_source = "ROBOTLASER1 field_of_view";
  } else {
    const FieldOfView& fov = by_beams.at(first.ranges.size());
    log.fov_source = fov.source;
    if (fov.radians_assumed) log.warnings.push_back(path + ": " + fov.source);
  }
  if (disagreeing)
    log.warnings.push_back(path + ":" + std::to_string(disagreeing->line) + ": ROBOTLASER1 field_of_view " +
                           number(disagreeing->field_of_view) + " is neither angular_resolution x (n - 1) nor x n (n = " +
                           std::to_string(disagreeing->ranges.size()) + "): the beams are spaced by the resolution, " +
                           number(disagreeing->angle_step) + " rad (" + std::to_string(disagreeing_count) +
                           " scans like this)");
}

CarmenLog parseText(std::string_view content, const std::string& path, const CarmenOptions& options) {
  content = withoutByteOrderMark(content);
  if (content.find_first_not_of(" \t\r\n") == std::string_view::npos) throw InputError(path + ": the file is empty");
  LogLines lines = splitLines(content);  // first pass: which laser messages the log holds
  CarmenLog log;
  log.source = chooseSource(lines.counts, options, path, log.warnings);
  // Second pass: the lines in slices, in parallel.
  std::vector<ParsedSlice> slices =
      parseSlices(lines.lines, path, log.source, options, threadsFor(content.size(), options));
  lines = {};
  LaserParams params;
  std::vector<Vertex> vertices;
  mergeSlices(slices, path, log, params, vertices);
  applyVertices(log.scans, vertices, path, log.warnings);
  finishScans(log, params, options, path);
  return log;
}

}  // namespace

CarmenLog readCarmenLog(const std::string& path, const CarmenOptions& options) {
  return parseCarmenLog(readInputBytes(path), inputName(path), options);
}

CarmenLog parseCarmenLog(std::string_view content, const std::string& path, const CarmenOptions& options) {
  if (isGzip(content)) {
    // With --skip-bad-lines a cut gzip log keeps every complete line read
    // (its cut last line is skipped with the other bad lines).
    std::string cut_short;
    CarmenLog log = parseText(gunzip(content, path, options.skip_bad_lines ? &cut_short : nullptr), path, options);
    if (!cut_short.empty()) log.warnings.push_back(cut_short + ": kept the " + std::to_string(log.scans.size()) +
                                                   " scans read before the cut");
    return log;
  }
  return parseText(content, path, options);
}

namespace {
double beamAngle(const LaserScan& scan, std::size_t k) { return scan.start_angle + k * scan.angle_step; }
}  // namespace

pcl::PointCloud<pcl::PointXYZ>::Ptr scanToCloud(const LaserScan& scan) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(scan.ranges.size());
  for (std::size_t k = 0; k < scan.ranges.size(); ++k) {
    const double r = scan.ranges[k];
    if (!isReturn(r, scan.max_range)) continue;
    const double angle = beamAngle(scan, k);
    cloud->push_back(pcl::PointXYZ(float(r * std::cos(angle)), float(r * std::sin(angle)), 0.0f));
  }
  return cloud;
}

BeamDirections::BeamDirections(const LaserScan& scan)
    : start_angle_(scan.start_angle), angle_step_(scan.angle_step) {
  cos_.reserve(scan.ranges.size());
  sin_.reserve(scan.ranges.size());
  for (std::size_t k = 0; k < scan.ranges.size(); ++k) {
    const double angle = beamAngle(scan, k);
    cos_.push_back(std::cos(angle));
    sin_.push_back(std::sin(angle));
  }
}

pcl::PointCloud<pcl::PointXYZ>::Ptr BeamDirections::cloudOf(const LaserScan& scan) const {
  if (scan.start_angle != start_angle_ || scan.angle_step != angle_step_ || scan.ranges.size() != cos_.size())
    return scanToCloud(scan);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  std::size_t returns = 0;
  for (double r : scan.ranges) returns += isReturn(r, scan.max_range);
  cloud->resize(returns);
  std::size_t n = 0;
  for (std::size_t k = 0; k < scan.ranges.size(); ++k) {
    const double r = scan.ranges[k];
    if (!isReturn(r, scan.max_range)) continue;
    (*cloud)[n++] = pcl::PointXYZ(float(r * cos_[k]), float(r * sin_[k]), 0.0f);
  }
  return cloud;
}

}  // namespace obsgroup::io
