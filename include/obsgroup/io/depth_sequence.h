#pragma once
// Depth image sequences (16-bit PNG) as clouds in the camera body frame: the TUM
// RGB-D layout (depth.txt, depth/, groundtruth.txt matched by timestamp) and
// the Redwood/Open3D layout (depth/*.png, trajectory.log).
//
// Camera (optical) frame: z forward (the optical axis), x right, y down.
// Pixel (u, v) with depth d metres is the point ((u - cx) d / fx,
// (v - cy) d / fy, d) there (backProject). The observations of a sequence are
// in the camera's body frame instead (x forward, y left, z up, as ROS's REP
// 103 has a camera_link beside its optical frame), posed accordingly: the
// same points in the world, and the local maps and pose arrows then read as
// from above.

#include "obsgroup/io/frame_reading.h"
#include "obsgroup/io/pose_file.h"

#include <obsgroup/cloud/observation.h>
#include <obsgroup/common/enum_names.h>

#include <pcl/point_types.h>

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace obsgroup::io {

enum class DepthLayout { TumRgbd, Redwood };

inline constexpr EnumName<DepthLayout> kDepthLayoutNames[] = {{DepthLayout::TumRgbd, "tum-rgbd"},
                                                              {DepthLayout::Redwood, "redwood"}};
inline std::string toString(DepthLayout layout) { return nameOf(kDepthLayoutNames, layout); }

/// Units of the PNG per metre when --depth-scale is not given.
double defaultDepthScale(DepthLayout layout);  // 5000 TUM, 1000 Redwood

/// The optical frame's axes in the body frame: body = kOpticalInBody * optical.
inline const Eigen::Matrix3d kOpticalInBody = (Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished();

struct PinholeIntrinsics {
  double fx = 525.0, fy = 525.0, cx = 319.5, cy = 239.5;  // PrimeSense, as both datasets document
};

/// "fx,fy,cx,cy" with fx, fy > 0, all finite; throws UsageError otherwise.
PinholeIntrinsics parseIntrinsics(const std::string& text);

/// A 16-bit single-channel image, row-major, values as stored (host order).
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> values;
};

/// Decodes a PNG held in memory. Throws InputError naming `name` when the
/// data are not a PNG, are corrupt or cut short, or the image is not 16-bit
/// grey (bit depth and colour type are named).
DepthImage decodeDepthPng(std::string_view bytes, const std::string& name);
DepthImage readDepthPng(const std::string& path);

/// Which axis of a trajectory's world points up: obsgroup's world has z up
/// (the height band of the sensed regions, the 2D/3D decision, the pictures
/// from above), and the reader turns the world so. Auto: the coordinate axis
/// nearest the cameras' mean up direction (the opposite of the image's y
/// axis, which points down in an upright camera), for worlds no convention
/// fixes (Redwood/Open3D reconstructions put y or -y up).
enum class UpAxis { Auto, PlusX, MinusX, PlusY, MinusY, PlusZ, MinusZ };

inline constexpr EnumName<UpAxis> kUpAxisNames[] = {{UpAxis::Auto, "auto"}, {UpAxis::PlusX, "x"},
                                                    {UpAxis::MinusX, "-x"}, {UpAxis::PlusY, "y"},
                                                    {UpAxis::MinusY, "-y"}, {UpAxis::PlusZ, "z"},
                                                    {UpAxis::MinusZ, "-z"}};
inline std::string toString(UpAxis axis) { return nameOf(kUpAxisNames, axis); }

/// The rotation taking `axis` (not Auto) to +z: a quarter or half turn about
/// a coordinate axis, the identity for z.
Eigen::Matrix3d upToZ(UpAxis axis);

/// The coordinate axis nearest the mean of -R_k * (0, 1, 0) over the optical
/// poses (the cameras' up); z when there are none.
UpAxis camerasUpAxis(const std::vector<Eigen::Isometry3d>& optical_poses);

struct DepthOptions {
  PinholeIntrinsics intrinsics;
  std::optional<double> depth_scale;  ///< units per metre; default from the layout
  std::optional<double> max_depth;    ///< metres; deeper pixels are no return
  int stride = 1;                     ///< every stride-th pixel in u and v
  double max_time_difference = kDefaultMaxTimeDifference;  ///< TUM: seconds between a frame and its pose
  std::optional<std::string> poses;   ///< TUM: instead of groundtruth.txt
  /// The world's up axis; default: z for TUM (its motion-capture world has
  /// z up), Auto for Redwood.
  std::optional<UpAxis> up;
  /// Each frame's reduction as it is read (a frame's sensor points: the
  /// image's pixels / stride^2), and the progress of the read.
  FrameReading reduction;
};

/// The points of an image; value 0 is no return, as is a depth beyond
/// `max_depth`.
pcl::PointCloud<pcl::PointXYZ>::Ptr backProject(const DepthImage& image, const PinholeIntrinsics& intrinsics,
                                                double depth_scale, std::optional<double> max_depth, int stride);

/// TUM when the folder holds depth.txt and depth/, Redwood when it holds
/// trajectory.log and depth/, else nothing.
std::optional<DepthLayout> detectDepthLayout(const std::string& folder);

/// Redwood/Open3D trajectory.log: per frame a line "i i i+1" and four lines
/// of a 4x4 camera-to-world matrix. Throws InputError naming the file, the
/// line and the field of a malformed block.
std::vector<Eigen::Isometry3d> parseTrajectoryLog(std::string_view content, const std::string& path);

struct DepthSequence {
  DepthLayout layout = DepthLayout::TumRgbd;
  double depth_scale = 0.0;
  std::vector<Observation<pcl::PointXYZ>> observations;
  std::vector<std::string> labels;  ///< the PNG of each observation
  std::vector<std::string> warnings;
  std::size_t skipped = 0;  ///< TUM frames without a pose within the tolerance
  std::size_t reduced = 0;  ///< frames voxel-filtered as they were read
  UpAxis up = UpAxis::PlusZ;  ///< the trajectory's up axis (the world was turned to put it on z)
};

/// Reads the folder in `layout`. TUM: frames without a groundtruth pose
/// within the tolerance are skipped (one warning with the count). Redwood:
/// fewer trajectory entries than images is an error. Frames are decoded on
/// every thread, each reduced as options.reduction says before the next is
/// read, so that peak memory grows with the reduced frames.
DepthSequence loadDepthSequence(const std::string& folder, DepthLayout layout, const DepthOptions& options);

}  // namespace obsgroup::io
