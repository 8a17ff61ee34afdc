#pragma once
// KITTI odometry: velodyne/*.bin (float32 x y z reflectance per point),
// poses.txt (camera 0, 3x4 row-major per line) and calib.txt (Tr: the
// velodyne-to-camera transform). The lidar's pose is Tr^-1 * pose_cam * Tr:
// the world is the first velodyne frame (x ahead, y left, z up), not camera
// 0's (z ahead, y down), so that z is up as obsgroup assumes.

#include "obsgroup/io/frame_reading.h"

#include <obsgroup/cloud/observation.h>

#include <pcl/point_types.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace obsgroup::io {

/// True when the folder holds velodyne/ and poses.txt.
bool isKittiFolder(const std::string& folder);

/// The points of a .bin scan held in memory. Throws InputError naming
/// `name` when its size is not a multiple of 16 bytes (truncated).
pcl::PointCloud<pcl::PointXYZI>::Ptr decodeKittiScan(std::string_view bytes, const std::string& name);

/// The "Tr:" line of a calib.txt as a 4x4 transform. Throws InputError
/// naming the file, the line and the field.
Eigen::Isometry3d parseKittiCalibration(std::string_view content, const std::string& path);

struct KittiSequence {
  std::vector<Observation<pcl::PointXYZI>> observations;
  std::vector<std::string> labels;  ///< the .bin of each observation
  std::vector<std::string> warnings;
  std::string poses_file;
  std::string calib_file;
  std::size_t reduced = 0;  ///< scans voxel-filtered as they were read
};

/// Reads the folder; `poses` replaces its poses.txt. One pose per scan in
/// name order: a different count is an error. Scans are decoded on every
/// thread, each reduced as `reduction` says (its sensor points: the scan's)
/// before the next is read.
KittiSequence loadKittiSequence(const std::string& folder, const std::optional<std::string>& poses,
                                const FrameReading& reduction = {});

}  // namespace obsgroup::io
