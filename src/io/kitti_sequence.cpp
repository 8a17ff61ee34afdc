#include <obsgroup/io/kitti_sequence.h>

#include <obsgroup/io/errors.h>
#include <obsgroup/io/input_file.h>
#include <obsgroup/io/pcd_sequence.h>
#include <obsgroup/io/pose_file.h>
#include "text_fields.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>

namespace obsgroup::io {

namespace fs = std::filesystem;

bool isKittiFolder(const std::string& folder) {
  std::error_code ec;
  return fs::is_directory(fs::path(folder) / "velodyne", ec) && fs::is_regular_file(fs::path(folder) / "poses.txt", ec);
}

pcl::PointCloud<pcl::PointXYZI>::Ptr decodeKittiScan(std::string_view bytes, const std::string& name) {
  if (bytes.size() % 16 != 0)
    throw InputError(name + ": " + std::to_string(bytes.size()) +
                     " bytes, not a multiple of 16 (float32 x y z reflectance per point): truncated");
  pcl::PointCloud<pcl::PointXYZI>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZI>);
  const std::size_t n = bytes.size() / 16;
  cloud->reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    float v[4];
    std::memcpy(v, bytes.data() + 16 * k, 16);
    pcl::PointXYZI p;
    p.x = v[0];
    p.y = v[1];
    p.z = v[2];
    p.intensity = v[3];
    cloud->push_back(p);
  }
  return cloud;
}

Eigen::Isometry3d parseKittiCalibration(std::string_view content, const std::string& path) {
  content = withoutByteOrderMark(content);
  for (TextLines lines(content); lines.nextData();) {
    const auto& fields = lines.fields();
    const std::size_t number = lines.number();
    if (fields[0] != "Tr:" && fields[0] != "Tr_velo_to_cam:") continue;
    if (fields.size() != 13)
      throw inputError(path, number,
                       "field 'Tr': " + std::to_string(fields.size() - 1) + " values, expected 12 (a 3x4 [R|t])");
    const LineRef where{path, number};
    Eigen::Matrix<double, 3, 4> m;
    for (int k = 0; k < 12; ++k)
      m(k / 4, k % 4) = parseFinite(fields[1 + k], where, "Tr " + std::to_string(k / 4 + 1) + std::to_string(k % 4 + 1));
    const Eigen::Matrix3d R = m.leftCols<3>();
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-2 || R.determinant() < 0)
      throw inputError(path, number, "field 'Tr': the 3x3 part is not a rotation matrix");
    Eigen::Isometry3d tr = Eigen::Isometry3d::Identity();
    tr.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
    tr.translation() = m.col(3);
    return tr;
  }
  throw InputError(path + ": no 'Tr:' line (the velodyne-to-camera calibration)");
}

KittiSequence loadKittiSequence(const std::string& folder, const std::optional<std::string>& poses_path,
                                const FrameReading& reduction) {
  const fs::path dir(folder);
  KittiSequence out;
  std::error_code ec;
  const fs::path velodyne = dir / "velodyne";
  if (!fs::is_directory(velodyne, ec)) throw InputError(velodyne.string() + ": no such folder (KITTI: velodyne/*.bin)");
  const std::vector<std::string> scans = filesWithExtension(velodyne.string(), ".bin");
  if (scans.empty()) throw InputError(velodyne.string() + ": the folder holds no .bin file");

  out.poses_file = poses_path.value_or((dir / "poses.txt").string());
  out.calib_file = (dir / "calib.txt").string();
  const std::vector<Eigen::Isometry3d> camera = readPoses(out.poses_file, PoseFormat::Kitti);
  if (camera.size() != scans.size())
    throw InputError(out.poses_file + ": " + std::to_string(camera.size()) + " poses for " +
                     std::to_string(scans.size()) + " velodyne scans (one pose per scan, in name order)");
  if (!fs::is_regular_file(out.calib_file, ec))
    throw InputError(out.calib_file + ": no such file (KITTI poses are the camera's: the Tr velodyne-to-camera "
                     "line of calib.txt makes them the lidar's)");
  const Eigen::Isometry3d tr = parseKittiCalibration(readInputBytes(out.calib_file, "calibration"), out.calib_file);
  out.observations.resize(scans.size());
  std::vector<std::string> warnings(scans.size());
  std::vector<char> reduced(scans.size(), 0);
  const auto read = [&](std::size_t k) {
    const std::string& file = scans[k];
    auto cloud = decodeKittiScan(readInputBytes(file, "velodyne scan"), file);
    if (cloud->empty()) warnings[k] = file + ": the scan has no point; kept as an observation (a group of its own)";
    reduced[k] = reduceFrame(*cloud, cloud->size(), reduction);
    // KITTI's world is camera 0 at the start: y down, z ahead. Expressed in
    // the first velodyne frame instead (Tr^-1 P Tr, as lidar odometry
    // evaluates KITTI), z is up, which the height band of the sensed regions,
    // the 2D/3D decision and the pictures from above take it to be.
    const Eigen::Isometry3d pose = tr.inverse() * camera[k] * tr;
    cloud->sensor_origin_ << pose.translation().cast<float>(), 0.0f;
    cloud->sensor_orientation_ = Eigen::Quaternionf(pose.linear().cast<float>());
    out.observations[k] = {cloud, pose};
  };
  const std::vector<SkippedFrame> skipped = readFramesInParallel(scans.size(), read, reduction);
  const std::string skipped_warning = skippedWarning(skipped, scans.size());
  if (!skipped_warning.empty()) out.warnings.push_back(skipped_warning);
  out.labels = scans;
  for (std::size_t k = 0; k < scans.size(); ++k) {
    if (!warnings[k].empty()) out.warnings.push_back(std::move(warnings[k]));
    out.reduced += reduced[k];
  }
  eraseSkipped(out.observations, skipped);
  eraseSkipped(out.labels, skipped);
  return out;
}

}  // namespace obsgroup::io
