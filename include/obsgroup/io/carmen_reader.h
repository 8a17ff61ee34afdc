#pragma once
// Reader of CARMEN logs (.clf, .log, GMapping's .gfs.log, each also
// gzipped): FLASER, RLASER and ROBOTLASER1 messages, and the VERTEX2 poses
// of SLAM graph logs.

#include <obsgroup/cloud/observation.h>
#include <obsgroup/common/enum_names.h>

#include <pcl/point_types.h>

#include <limits>
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
  /// A bad line of a read message (laser, PARAM, VERTEX2) is skipped, and
  /// counted in one warning, instead of being an error.
  bool skip_bad_lines = false;
  /// Each scan's timestamp must be a finite number (a replay at the log's
  /// pace needs it): otherwise an error naming file, line and field. Without
  /// it a timestamp that is not a number is NaN, as a grouping does not use it.
  bool require_timestamps = false;
};

/// One scan: ranges and beam geometry in the laser frame (x ahead, y left),
/// and the laser's pose in the world frame.
struct LaserScan {
  std::vector<double> ranges;
  double start_angle = 0.0;  ///< angle of ranges[0], radians, counter-clockwise
  double angle_step = 0.0;   ///< angle between consecutive beams
  double max_range = 0.0;
  Eigen::Isometry3d laser_pose = Eigen::Isometry3d::Identity();
  /// The robot's pose (ROBOTLASER1); FLASER/RLASER: the laser's.
  Eigen::Isometry3d robot_pose = Eigen::Isometry3d::Identity();
  double field_of_view = 0.0;   ///< radians, as the message (or PARAM, option) says
  bool step_disagrees = false;  ///< ROBOTLASER1: fov and resolution disagree; spaced by the resolution
  std::size_t line = 0;  ///< line of the log it came from
  /// When the message was sent, seconds: its ipc_timestamp (the third field
  /// from the end); NaN when that is not a number (see require_timestamps).
  double timestamp = std::numeric_limits<double>::quiet_NaN();
};

struct CarmenLog {
  std::vector<LaserScan> scans;
  LaserSource source = LaserSource::Auto;  ///< the message kind actually used
  std::vector<std::string> warnings;       ///< things the user should know
  double fov_deg = 0.0;     ///< field of view of the first scan, degrees
  std::string fov_source;   ///< where it came from (message, PARAM and the unit assumed, option, default)
  std::size_t skipped_lines = 0;  ///< bad lines skipped (skip_bad_lines)
};

/// Reads a log ("-": standard input), gzipped or not (told by its first
/// bytes), with or without a UTF-8 byte-order mark. Throws InputError naming
/// file, line and field on malformed input (an empty file, a truncated
/// line, a non-numeric field, a count of ranges that does not match the
/// line, or no laser message at all; corrupt or cut gzip data). A VERTEX2
/// (or VERTEX_SE2) id x y theta line gives the robot's pose of the next scan.
CarmenLog readCarmenLog(const std::string& path, const CarmenOptions& options = {});

/// The same from a log's content (gzipped or not) already in memory; `path`
/// names it in errors.
CarmenLog parseCarmenLog(std::string_view content, const std::string& path, const CarmenOptions& options = {});

/// The scan's returns as points in the laser frame (z = 0). Non-finite
/// readings and readings at or beyond max_range give no point.
pcl::PointCloud<pcl::PointXYZ>::Ptr scanToCloud(const LaserScan& scan);

/// cos and sin of every beam's angle for scans of one geometry (start angle,
/// step and beam count): the trigonometry of scanToCloud done once for a log
/// whose scans share it, as most do. The points are the same bit for bit.
class BeamDirections {
 public:
  explicit BeamDirections(const LaserScan& scan);
  /// The scan's cloud, from the table when its geometry is the table's.
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloudOf(const LaserScan& scan) const;

 private:
  double start_angle_, angle_step_;
  std::vector<double> cos_, sin_;
};

}  // namespace obsgroup::io
