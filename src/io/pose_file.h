#pragma once
// Readers of trajectory files: TUM (timestamp tx ty tz qx qy qz qw) and
// KITTI (12 numbers per line: a 3x4 row-major [R | t]).

#include <obsgroup/common/enum_names.h>

#include <Eigen/Geometry>

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

/// The rotation of a quaternion given as (w, x, y, z), normalised; throws
/// std::invalid_argument when its norm is not within 1% of 1.
Eigen::Quaterniond checkedQuaternion(double w, double x, double y, double z);

}  // namespace obsgroup::io
