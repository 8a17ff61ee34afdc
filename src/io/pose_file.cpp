#include <obsgroup/io/pose_file.h>

#include <obsgroup/io/errors.h>
#include <obsgroup/io/input_file.h>
#include "text_fields.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace obsgroup::io {

Eigen::Quaterniond checkedQuaternion(double w, double x, double y, double z) {
  const Eigen::Quaterniond q(w, x, y, z);
  const double norm = q.norm();
  if (!(std::abs(norm - 1.0) <= 0.01))
    throw std::invalid_argument("the quaternion (qw qx qy qz) = (" + std::to_string(w) + " " + std::to_string(x) +
                                " " + std::to_string(y) + " " + std::to_string(z) + ") has norm " +
                                std::to_string(norm) + ", not 1");
  return q.normalized();
}

namespace {

Eigen::Isometry3d parseTum(const std::vector<std::string_view>& f, const LineRef& where) {
  static const char* kNames[] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  double v[8];
  for (int k = 0; k < 8; ++k) v[k] = parseFinite(f[k], where, kNames[k]);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() << v[1], v[2], v[3];
  try {
    pose.linear() = checkedQuaternion(v[7], v[4], v[5], v[6]).toRotationMatrix();
  } catch (const std::invalid_argument& e) {
    throw inputError(where.file, where.line, std::string("fields 'qx qy qz qw': ") + e.what());
  }
  return pose;
}

Eigen::Isometry3d parseKitti(const std::vector<std::string_view>& f, const LineRef& where) {
  Eigen::Matrix<double, 3, 4> m;
  for (int k = 0; k < 12; ++k)
    m(k / 4, k % 4) = parseFinite(f[k], where, "r" + std::to_string(k / 4 + 1) + std::to_string(k % 4 + 1));
  const Eigen::Matrix3d R = m.leftCols<3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-2 || R.determinant() < 0)
    throw inputError(where.file, where.line, "fields 1-3, 5-7, 9-11: the 3x3 part is not a rotation matrix");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();  // re-orthonormalised
  pose.translation() = m.col(3);
  return pose;
}

/// A line with the other format's number of values: say so.
std::string otherFormatHint(std::size_t values, PoseFormat format) {
  if (format == PoseFormat::Tum && values == 12) return "; 12 values are a KITTI line: --pose-format kitti?";
  if (format == PoseFormat::Kitti && values == 8) return "; 8 values are a TUM line: --pose-format tum?";
  return "";
}

}  // namespace

std::vector<Eigen::Isometry3d> readPoses(const std::string& path, PoseFormat format) {
  return parsePoses(readInputBytes(path, "poses file"), inputName(path), format);
}

namespace {

/// Every pose line of `content` (gzip inflated, BOM dropped): `add` receives
/// its fields and where it is.
template <typename Add>
void forEachPoseLine(std::string_view content, const std::string& path, PoseFormat format, Add&& add) {
  const std::size_t expected = format == PoseFormat::Tum ? 8 : 12;
  const std::string layout = format == PoseFormat::Tum ? "TUM: timestamp tx ty tz qx qy qz qw"
                                                       : "KITTI: 12 values of a 3x4 [R|t] matrix";
  std::size_t count = 0;
  for (TextLines lines(content); lines.nextData();) {
    const auto& fields = lines.fields();
    const std::size_t number = lines.number();
    const LineRef where{path, number};
    if (fields.size() != expected)
      throw inputError(path, number,
                       "a pose line has " + std::to_string(fields.size()) + " values, expected " +
                           std::to_string(expected) + " (" + layout + ")" + otherFormatHint(fields.size(), format));
    add(fields, where);
    ++count;
  }
  if (count == 0) throw InputError(path + ": the poses file holds no pose");
}

}  // namespace

std::vector<Eigen::Isometry3d> parsePoses(std::string_view content, const std::string& path, PoseFormat format) {
  if (isGzip(content)) return parsePoses(gunzip(content, path), path, format);
  content = withoutByteOrderMark(content);
  std::vector<Eigen::Isometry3d> poses;
  forEachPoseLine(content, path, format, [&](const std::vector<std::string_view>& fields, const LineRef& where) {
    poses.push_back(format == PoseFormat::Tum ? parseTum(fields, where) : parseKitti(fields, where));
  });
  return poses;
}

std::vector<StampedPose> readStampedPoses(const std::string& path) {
  return parseStampedPoses(readInputBytes(path, "poses file"), inputName(path));
}

std::vector<StampedPose> parseStampedPoses(std::string_view content, const std::string& path) {
  if (isGzip(content)) return parseStampedPoses(gunzip(content, path), path);
  content = withoutByteOrderMark(content);
  std::vector<StampedPose> poses;
  forEachPoseLine(content, path, PoseFormat::Tum, [&](const std::vector<std::string_view>& fields, const LineRef& where) {
    poses.push_back({parseFinite(fields[0], where, "timestamp"), parseTum(fields, where)});
  });
  return poses;
}

PoseFormat detectPoseFormat(std::string_view content, const std::string& path) {
  if (isGzip(content)) return detectPoseFormat(gunzip(content, path), path);
  content = withoutByteOrderMark(content);
  for (TextLines lines(content); lines.nextData();) {
    const auto& fields = lines.fields();
    const std::size_t number = lines.number();
    if (fields.size() == 8) return PoseFormat::Tum;
    if (fields.size() == 12) return PoseFormat::Kitti;
    throw inputError(path, number,
                     "a pose line has " + std::to_string(fields.size()) +
                         " values: neither TUM (8: timestamp tx ty tz qx qy qz qw) nor KITTI (12: a 3x4 [R|t]); "
                         "--pose-format tells which");
  }
  throw InputError(path + ": the poses file holds no pose");
}

std::optional<std::size_t> nearestStamp(const std::vector<StampedPose>& poses, double stamp, double tolerance) {
  const auto after = std::lower_bound(poses.begin(), poses.end(), stamp,
                                      [](const StampedPose& p, double t) { return p.stamp < t; });
  std::optional<std::size_t> best;
  double best_gap = tolerance;
  const auto consider = [&](std::vector<StampedPose>::const_iterator it) {
    const double gap = std::abs(it->stamp - stamp);
    if (gap <= best_gap) {
      best_gap = gap;
      best = std::size_t(it - poses.begin());
    }
  };
  if (after != poses.end()) consider(after);
  if (after != poses.begin()) consider(after - 1);
  return best;
}

StampedPoseIndex::StampedPoseIndex(std::vector<StampedPose> poses, double tolerance)
    : poses_(std::move(poses)), tolerance_(tolerance) {
  std::stable_sort(poses_.begin(), poses_.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
}

std::optional<Eigen::Isometry3d> StampedPoseIndex::at(double stamp) const {
  const auto match = nearestStamp(poses_, stamp, tolerance_);
  if (!match) return std::nullopt;
  return poses_[*match].pose;
}

}  // namespace obsgroup::io
