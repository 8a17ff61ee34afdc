#include "carmen_reader.h"

#include "errors.h"
#include "text_fields.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <sstream>
#include <system_error>
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

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the file");
  const std::streamoff size = in.seekg(0, std::ios::end) ? std::streamoff(in.tellg()) : -1;
  if (size < 0) {  // not seekable (a pipe): stream it
    in.clear();
    std::ostringstream content;
    content << in.rdbuf();
    return content.str();
  }
  std::string content(static_cast<std::size_t>(size), '\0');  // a regular file: one read
  in.seekg(0);
  in.read(content.data(), size);
  content.resize(static_cast<std::size_t>(in.gcount()));
  return content;
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

/// FLASER/RLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp host logger_timestamp
LaserScan parseFrontOrRearLaser(const std::vector<std::string_view>& fields, const LineRef& where) {
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
  return scan;
}

/// ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range accuracy
/// remission_mode n r1..rn num_remissions [remissions] laser_pose_x laser_pose_y laser_pose_theta
/// robot_pose_x robot_pose_y robot_pose_theta laser_tv laser_rv forward_safety_dist
/// side_safety_dist turn_axis timestamp host logger_timestamp
LaserScan parseRobotLaser(const std::vector<std::string_view>& fields, const LineRef& where) {
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
  // Loggers round the resolution; the field of view spans the beams exactly.
  scan.angle_step = n > 1 ? fov / (n - 1) : resolution;
  readRanges(fields, 9, n, where, scan);
  scan.laser_pose = parsePose(fields, tail, where, "laser_pose");
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

void readParam(const std::vector<std::string_view>& fields, const LineRef& where, LaserParams& params) {
  static const char* kKnown[] = {"robot_front_laser_max", "robot_rear_laser_max", "laser_front_laser_resolution",
                                 "laser_rear_laser_resolution", "laser_front_laser_fov", "laser_rear_laser_fov"};
  if (fields.size() < 3) return;
  const std::string name(fields[1]);
  for (const char* known : kKnown)
    if (name == known) params.values[name] = parseFinite(fields[2], where, "PARAM " + name);
}

/// Beam geometry of FLASER/RLASER scans, which the messages do not carry.
void applyGeometry(LaserScan& scan, LaserSource source, const LaserParams& params, const CarmenOptions& options) {
  const std::string side = source == LaserSource::Rear ? "rear" : "front";
  const std::size_t n = scan.ranges.size();
  double fov_deg = kDefaultFieldOfViewDeg;
  if (options.field_of_view_deg) fov_deg = *options.field_of_view_deg;
  else if (auto fov = params.get("laser_" + side + "_laser_fov")) fov_deg = *fov;
  else if (auto resolution = params.get("laser_" + side + "_laser_resolution"); resolution && n > 1)
    fov_deg = *resolution * (n - 1);
  const double fov = fov_deg * kPi / 180.0;
  scan.start_angle = -fov / 2;  // centred ahead, counter-clockwise (right to left)
  scan.angle_step = n > 1 ? fov / (n - 1) : 0.0;
  scan.max_range = params.get("robot_" + side + "_laser_max").value_or(kDefaultMaxRange);
}

/// A reading that gives a point (see scanToCloud).
bool isReturn(double r, double max_range) { return std::isfinite(r) && r > 0.0 && r < max_range; }

bool hasReturn(const LaserScan& scan) {
  for (double r : scan.ranges)
    if (isReturn(r, scan.max_range)) return true;
  return false;
}

/// The first error met, by line number.
struct Failure {
  std::size_t line = 0;
  std::exception_ptr error;
  void keepFirst(std::size_t at, std::exception_ptr e) {
    if (!error || at < line) {
      line = at;
      error = std::move(e);
    }
  }
};

/// What parsing a slice of the log's lines gave: the scans of the chosen
/// message, the PARAM lines (indices into the lines, read later in order),
/// and the first error, after which the slice stops.
struct ParsedSlice {
  std::vector<LaserScan> scans;
  std::vector<std::size_t> param_lines;
  Failure failure;
};

using NumberedLines = std::vector<std::pair<std::size_t, std::string_view>>;  // (line number, text)

void parseSlice(const NumberedLines& lines, std::size_t begin, std::size_t end, const std::string& path,
                LaserSource source, ParsedSlice& out) {
  const std::string_view chosen = messageName(source);
  for (std::size_t k = begin; k < end; ++k) {
    const auto& [line_number, line] = lines[k];
    try {
      const auto fields = splitFields(line);
      if (fields.empty() || fields[0].front() == '#') continue;
      if (fields[0] == "PARAM") {
        out.param_lines.push_back(k);
      } else if (fields[0] == chosen) {
        const LineRef where{path, line_number};
        LaserScan scan = source == LaserSource::RobotLaser ? parseRobotLaser(fields, where)
                                                           : parseFrontOrRearLaser(fields, where);
        scan.line = line_number;
        out.scans.push_back(std::move(scan));
      }
    } catch (...) {
      out.failure.keepFirst(line_number, std::current_exception());
      return;
    }
  }
}

/// Threads worth starting for a log of `bytes`: small logs (and fuzzing
/// inputs) are parsed on the calling thread.
unsigned threadsFor(std::size_t bytes, const CarmenOptions& options) {
  if (bytes < (std::size_t(1) << 20)) return 1;
  const unsigned all = std::max(1u, std::thread::hardware_concurrency());
  return options.threads > 0 ? static_cast<unsigned>(options.threads) : all;
}

/// The lines cut into one slice per thread, parsed in parallel; the slices
/// are in line order, so the result does not depend on the thread count.
std::vector<ParsedSlice> parseSlices(const NumberedLines& lines, const std::string& path, LaserSource source,
                                     unsigned threads) {
  const std::size_t count = std::max<std::size_t>(1, std::min<std::size_t>(threads, lines.size()));
  std::vector<ParsedSlice> slices(count);
  const auto parse = [&](std::size_t t) {
    parseSlice(lines, lines.size() * t / count, lines.size() * (t + 1) / count, path, source, slices[t]);
  };
  std::vector<std::thread> workers;
  std::size_t on_workers = 1;  // slices [1, on_workers) have a thread
  try {
    for (; on_workers < count; ++on_workers) workers.emplace_back(parse, on_workers);
  } catch (const std::system_error&) {
    // No more threads to be had: this thread parses the rest.
  }
  for (std::size_t t = on_workers; t < count; ++t) parse(t);
  parse(0);
  for (auto& worker : workers) worker.join();
  return slices;
}

}  // namespace

CarmenLog readCarmenLog(const std::string& path, const CarmenOptions& options) {
  return parseCarmenLog(readWholeFile(path), path, options);
}

CarmenLog parseCarmenLog(std::string_view content, const std::string& path, const CarmenOptions& options) {
  if (content.find_first_not_of(" \t\r\n") == std::string_view::npos) throw InputError(path + ": the file is empty");

  // First pass: which laser messages the log holds.
  std::map<LaserSource, std::size_t> counts;
  NumberedLines lines;
  std::size_t number = 0;
  for (std::size_t start = 0; start < content.size();) {
    std::size_t end = content.find('\n', start);
    if (end == std::string::npos) end = content.size();
    const std::string_view line(content.data() + start, end - start);
    lines.emplace_back(++number, line);
    for (LaserSource s : {LaserSource::Front, LaserSource::Rear, LaserSource::RobotLaser}) {
      const std::string_view name = messageName(s);
      if (line.substr(0, name.size()) == name && (line.size() == name.size() || line[name.size()] == ' ' ||
                                                  line[name.size()] == '\t'))
        ++counts[s];
    }
    start = end + 1;
  }

  CarmenLog log;
  log.source = options.laser;
  if (log.source == LaserSource::Auto) {
    for (LaserSource s : {LaserSource::RobotLaser, LaserSource::Front, LaserSource::Rear})
      if (counts[s] > 0) {
        log.source = s;
        break;
      }
    if (log.source == LaserSource::Auto)
      throw InputError(path + ": no FLASER, RLASER or ROBOTLASER1 message: is this a CARMEN log?");
  }
  const std::string chosen = messageName(log.source);
  if (counts[log.source] == 0)
    throw InputError(path + ": no " + chosen + " message in this log (--laser " + toString(log.source) + ")");
  std::string others;
  for (LaserSource s : {LaserSource::RobotLaser, LaserSource::Front, LaserSource::Rear})
    if (s != log.source && counts[s] > 0)
      others += (others.empty() ? "" : ", ") + std::to_string(counts[s]) + " " + messageName(s);
  if (!others.empty())
    log.warnings.push_back(path + ": using the " + std::to_string(counts[log.source]) + " " + chosen +
                           " scans; the log also has " + others + " (choose with --laser)");

  // Second pass: parse the chosen messages, slices of lines in parallel,
  // and then the PARAM lines in order.
  std::vector<ParsedSlice> slices = parseSlices(lines, path, log.source, threadsFor(content.size(), options));
  LaserParams params;
  Failure first_failure;
  for (const ParsedSlice& slice : slices) {
    for (std::size_t k : slice.param_lines) {
      const LineRef where{path, lines[k].first};
      try {
        readParam(splitFields(lines[k].second), where, params);
      } catch (...) {
        first_failure.keepFirst(lines[k].first, std::current_exception());
        break;
      }
    }
    if (slice.failure.error) {
      first_failure.keepFirst(slice.failure.line, slice.failure.error);
      break;  // later slices hold later lines
    }
  }
  if (first_failure.error) std::rethrow_exception(first_failure.error);
  for (ParsedSlice& slice : slices)
    log.scans.insert(log.scans.end(), std::make_move_iterator(slice.scans.begin()),
                     std::make_move_iterator(slice.scans.end()));
  for (LaserScan& scan : log.scans) {
    if (log.source != LaserSource::RobotLaser) applyGeometry(scan, log.source, params, options);
    if (options.max_range) scan.max_range = *options.max_range;
    if (!hasReturn(scan))
      log.warnings.push_back(path + ":" + std::to_string(scan.line) +
                             ": the scan has no return; kept as an observation (a group of its own)");
  }
  return log;
}

pcl::PointCloud<pcl::PointXYZ>::Ptr scanToCloud(const LaserScan& scan) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(scan.ranges.size());
  for (std::size_t k = 0; k < scan.ranges.size(); ++k) {
    const double r = scan.ranges[k];
    if (!isReturn(r, scan.max_range)) continue;
    const double angle = scan.start_angle + k * scan.angle_step;
    cloud->push_back(pcl::PointXYZ(float(r * std::cos(angle)), float(r * std::sin(angle)), 0.0f));
  }
  return cloud;
}

}  // namespace obsgroup::io
