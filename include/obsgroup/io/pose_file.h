#pragma once
// Readers of trajectory files: TUM (timestamp tx ty tz qx qy qz qw) and
// KITTI (12 numbers per line: a 3x4 row-major [R | t]).

#include <obsgroup/common/enum_names.h>

#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace obsgroup::io {

enum class PoseFormat { Tum, Kitti };

inline constexpr EnumName<PoseFormat> kPoseFormatNames[] = {{PoseFormat::Tum, "tum"}, {PoseFormat::Kitti, "kitti"}};
inline std::string toString(PoseFormat format) { return nameOf(kPoseFormatNames, format); }

/// Reads one pose per non-empty, non-comment ('#') line of a file ("-":
/// standard input), gzipped or not (told by its first bytes). Throws InputError
/// naming the file, the line and the field on a wrong number of values, a
/// non-numeric or non-finite value, a zero or far-from-unit quaternion or a
/// rotation matrix that is not one. Small deviations (|q| within 1% of 1, a
/// matrix within 1e-2 of orthonormal) are normalised silently.
std::vector<Eigen::Isometry3d> readPoses(const std::string& path, PoseFormat format);

/// The same from a file's content (gzipped or not) already in memory; `path` names it in errors.
std::vector<Eigen::Isometry3d> parsePoses(std::string_view content, const std::string& path, PoseFormat format);

/// A pose and the time it was taken at (a TUM line's timestamp).
struct StampedPose {
  double stamp = 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

/// The TUM poses of a file with their timestamps, in file order.
std::vector<StampedPose> readStampedPoses(const std::string& path);
std::vector<StampedPose> parseStampedPoses(std::string_view content, const std::string& path);

/// The format told by the number of values on the first pose line: 8 TUM,
/// 12 KITTI. Throws InputError naming the file and the line otherwise.
PoseFormat detectPoseFormat(std::string_view content, const std::string& path);

/// The index of the pose nearest `stamp` within `tolerance` seconds, or
/// nothing. `poses` sorted by stamp.
std::optional<std::size_t> nearestStamp(const std::vector<StampedPose>& poses, double stamp, double tolerance);

/// How far apart, in seconds, a frame's time and its pose's stamp may be by
/// default: a TUM RGB-D ground truth at 100 Hz puts one within 5 ms of every
/// frame; a few missed poses are still matched.
inline constexpr double kDefaultMaxTimeDifference = 0.02;

/// Poses by time: TUM poses sorted by stamp, each looked up at the stamp
/// nearest a time within a tolerance. PCD files named by their time, TUM
/// RGB-D depth frames and bag messages given a poses file are all matched
/// to their poses this way.
class StampedPoseIndex {
 public:
  /// `poses` in any order (sorted here, stably: of equal stamps the first
  /// in the file is found); `tolerance` in seconds.
  StampedPoseIndex(std::vector<StampedPose> poses, double tolerance);
  /// The pose whose stamp is nearest `stamp`, if within the tolerance.
  std::optional<Eigen::Isometry3d> at(double stamp) const;
  double tolerance() const { return tolerance_; }

 private:
  std::vector<StampedPose> poses_;
  double tolerance_;
};

/// The rotation of a quaternion given as (w, x, y, z), normalised; throws
/// std::invalid_argument when its norm is not within 1% of 1.
Eigen::Quaterniond checkedQuaternion(double w, double x, double y, double z);

}  // namespace obsgroup::io
