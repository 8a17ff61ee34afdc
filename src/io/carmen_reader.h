#pragma once
// Reader of CARMEN logs (.clf, .log, GMapping's .gfs.log): FLASER, RLASER
// and ROBOTLASER1 messages.

#include <obsgroup/cloud/observation.h>
#include <obsgroup/common/enum_names.h>

#include <pcl/point_types.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace obsgroup::io {

/// Which laser messages of a log become observations.
enum class LaserSource {
  Auto,       ///< ROBOTLASER1 if present, else FLASER, else RLASER.
  Front,      ///< FLASER
  Rear,       ///< RLASER
  RobotLaser  ///< ROBOTLASER1
};

inline constexpr EnumName<LaserSource> kLaserSourceNames[] = {{LaserSource::Auto, "auto"},
                                                              {LaserSource::Front, "front"},
                                                              {LaserSource::Rear, "rear"},
                                                              {LaserSource::RobotLaser, "robotlaser"}};
inline std::string toString(LaserSource source) { return nameOf(kLaserSourceNames, source); }

struct CarmenOptions {
  LaserSource laser = LaserSource::Auto;
  /// Field of view of FLASER/RLASER scans in degrees; default: the log's
  /// PARAM lines, else 180.
  std::optional<double> field_of_view_deg;
  /// Readings at or beyond this range are "no return"; default: the
  /// message's own (ROBOTLASER1), the log's PARAM, else 80 m.
  std::optional<double> max_range;
  /// Threads parsing a large log (0 = all cores); the result is the same for any number.
  int threads = 0;
};

/// One scan: ranges and beam geometry in the laser frame (x ahead, y left),
/// and the laser's pose in the world frame.
struct LaserScan {
  std::vector<double> ranges;
  double start_angle = 0.0;  ///< angle of ranges[0], radians, counter-clockwise
  double angle_step = 0.0;   ///< angle between consecutive beams
  double max_range = 0.0;
  Eigen::Isometry3d laser_pose = Eigen::Isometry3d::Identity();
  std::size_t line = 0;  ///< line of the log it came from
};

struct CarmenLog {
  std::vector<LaserScan> scans;
  LaserSource source = LaserSource::Auto;  ///< the message kind actually used
  std::vector<std::string> warnings;       ///< things the user should know
};

/// Reads a log. Throws InputError naming file, line and field on malformed
/// input (an empty file, a truncated line, a non-numeric field, a count of
/// ranges that does not match the line, or no laser message at all).
CarmenLog readCarmenLog(const std::string& path, const CarmenOptions& options = {});

/// The same from a log's content already in memory; `path` names it in errors.
CarmenLog parseCarmenLog(std::string_view content, const std::string& path, const CarmenOptions& options = {});

/// The scan's returns as points in the laser frame (z = 0). Non-finite
/// readings and readings at or beyond max_range give no point.
pcl::PointCloud<pcl::PointXYZ>::Ptr scanToCloud(const LaserScan& scan);

}  // namespace obsgroup::io
