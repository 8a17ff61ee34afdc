#pragma once
// `obsgroup partition INPUT -o OUTDIR`: read a log or a PCD sequence, group
// its observations and write the results. `obsgroup stream` does the same
// through the online grouping, one observation at a time.

#include <obsgroup/io/carmen_reader.h>
#include <obsgroup/io/depth_sequence.h>
#include <obsgroup/io/pose_file.h>

#include <obsgroup/grouping_parameters.h>
#include <obsgroup/partition/keyframes.h>
#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/maps/odometry_correction.h>
#include "progress_bar.h"

#include <nlohmann/json.hpp>
#include <pcl/point_types.h>

#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace obsgroup::cli {

/// What `obsgroup stream` adds to partition's options.
struct StreamOptions {
  int update_every = 1;   ///< update the groups after every N inserts (and after the last)
  /// Local updates in between, exact once N observations came since the
  /// last exact one (OnlineGrouping::setExactInterval); 1: always exact.
  int exact_every = 1;
  bool realtime = false;  ///< insert each observation at its stamp's time (logs and bags)
  /// Print every change of the groups (created, grown, split, ...) instead of
  /// one line per observation saying its place.
  bool verbose = false;
};

/// What `obsgroup locate` adds: the places the observations are located in.
struct LocateOptions {
  std::string places;      ///< the output folder of `partition` or `stream`
  double tolerance = 1.0;  ///< metres: a pose off every place takes the nearest within this
  /// Align each located observation to its place's local map (PCL's ICP)
  /// and report the aligned pose, its place and the fit.
  bool align = false;
  /// Align each observation in turn from the previous one's aligned pose
  /// moved by the input's step, and locate it at its aligned pose: a drifted
  /// run follows the map. Off (--no-track): each at its own pose.
  bool track = true;
  /// --track: an alignment is followed when its fit (mean squared distance
  /// of the matched points) is below this, m^2.
  double track_fit_m2 = 0.01;
};

struct PartitionArgs {
  std::string input;
  std::string output;
  std::string format = "auto";  ///< auto, carmen, pcd, tum-rgbd, redwood, kitti, ros1 or ros2
  // CARMEN logs
  io::LaserSource laser = io::LaserSource::Auto;
  std::optional<double> field_of_view_deg;
  std::optional<double> max_range;
  bool skip_bad_lines = false;  ///< a bad line is a warning (counted), not an error
  /// Folders of PCD files, depth images or KITTI sweeps: an unreadable file
  /// is left out with a warning, not an error.
  bool skip_bad_files = false;
  // PCD sequences
  std::optional<std::string> poses;
  std::optional<io::PoseFormat> pose_format;  ///< default: from the column count (8 tum, 12 kitti)
  std::optional<double> max_time_difference;  ///< seconds; default 0.02 (TUM poses matched by timestamp)
  // depth image sequences
  std::optional<std::string> intrinsics;  ///< "fx,fy,cx,cy"
  std::optional<double> depth_scale;      ///< units per metre; default from the layout
  std::optional<double> depth_max;        ///< metres
  std::optional<int> stride;              ///< every Nth pixel in u and v
  std::optional<io::UpAxis> up;           ///< the trajectory world's up axis
  // ROS bags
  std::optional<std::string> topic;        ///< LaserScan or PointCloud2 topic
  std::optional<std::string> pose_topic;   ///< Odometry or PoseStamped topic
  std::optional<std::string> fixed_frame;  ///< /tf frame of the poses
  // the method
  /// The defaults are GroupingParameters' (the settings that measured best
  /// across lasers and depth cameras with drifted poses, docs/grouping.md);
  /// `--paper` gives the paper's.
  GroupingParameters method;
  /// --voxel as given: every frame's leaf (in the readers and the grouping);
  /// none: dense frames at io::kDefaultFrameVoxel as they are read.
  std::optional<double> voxel;
  std::optional<double> map_voxel;  ///< local-map voxel leaf; default delta / 2
  /// --keyframes DIST,ANGLE: only frames that moved this far or turned this
  /// much since the last keyframe are grouped; the others join their keyframe.
  std::optional<KeyframeOptions> keyframes;
  Refinement refine = Refinement::None;
  /// Scan matching of the input poses before grouping; --paper: off.
  OdometryCorrection correct_odometry = OdometryCorrection::Auto;
  bool paper = false;         ///< --paper: the preset, applied by the command line
  std::vector<double> band;  ///< --band LOW HIGH as given (then in `method.regions`)
  // the run
  bool force = false;
  bool quiet = false;
  bool no_pictures = false;  ///< --no-pictures as given
  bool pictures = true;
  /// Set (by a SIGINT/SIGTERM handler) to stop the run; the output folder is
  /// then left as it was.
  const InterruptFlag* interrupt = nullptr;
  /// Told each step of each stage (the progress bars' steps), from the
  /// thread doing the work.
  ProgressObserver progress;
  /// Set: `obsgroup stream` (the online grouping), not `partition`.
  std::optional<StreamOptions> stream;
  /// Set: `obsgroup locate`: `output` is the JSON file written, the method's
  /// options are not used.
  std::optional<LocateOptions> locate;
};

/// What reading the input gave, besides the observations.
struct InputRecord {
  std::string format;          ///< "carmen", "pcd", "tum-rgbd", "redwood", "kitti", "ros1" or "ros2"
  nlohmann::json parameters;   ///< reader settings actually used
  std::vector<std::string> labels;  ///< where each observation came from, for messages
  std::vector<std::string> warnings;
  /// When each observation was sensed, seconds (logs and bags; empty: the
  /// format has none), for `stream --realtime`.
  std::vector<double> stamps;
  double load_s = 0.0;
};

/// The observations of an input, in the point type its files carry.
template <typename PointT>
struct InputObservations {
  std::vector<Observation<PointT>> observations;
  InputRecord input;
};
using AnyInput = std::variant<InputObservations<pcl::PointXYZ>, InputObservations<pcl::PointXYZI>,
                              InputObservations<pcl::PointXYZRGB>>;

/// Reads args.input as the command does (the format detected or given, the
/// reader options, dense frames reduced as they are read), writing nothing.
/// Throws io::UsageError for options that do not fit the input and
/// io::InputError for input that cannot be read.
AnyInput readInput(const PartitionArgs& args);

/// Runs the command; returns the exit code. Throws io::UsageError (exit 2),
/// io::InputError (exit 3) and Interrupted.
/// With args.stream, `obsgroup stream`: the same outputs, from the online
/// grouping, and each change of the groups on stdout. With args.locate,
/// `obsgroup locate`: the place of each observation, as JSON.
int runPartition(const PartitionArgs& args);

}  // namespace obsgroup::cli
