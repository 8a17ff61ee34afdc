#pragma once
// How the readers of frame sequences (depth images, KITTI sweeps, PCD files,
// bag clouds) read each frame. Dense frames are reduced as they are read: a
// depth camera records 30 frames of 307,200 points a second, and a minute of
// them held at full resolution is tens of GiB. Each frame is voxel-filtered
// in its sensor frame right after it is decoded, so a reader holds one
// full-resolution frame per thread and the reduced ones of the others.

#include <pcl/PCLPointCloud2.h>
#include <pcl/point_cloud.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace obsgroup::io {

/// The voxel leaf of a dense frame when the user gives none, metres: the
/// local maps' own leaf (delta / 2), so they lose no detail they would
/// have kept, and the rooms found on the simulator's depth and lidar sets are
/// unchanged (docs/performance.md).
inline constexpr double kDefaultFrameVoxel = 0.05;
/// A frame is dense, and reduced by default, when its sensor gives this many
/// points or more (a 160 x 120 depth image or a 2D scan is not; a 320 x 240
/// one, a VLP-16 sweep or a 640 x 480 one is).
inline constexpr std::size_t kDenseFramePoints = 20000;

struct FrameReading {
  /// Voxel leaf, metres; 0 keeps every point.
  double voxel_leaf = 0.0;
  /// Frames whose sensor gives fewer points than this are kept whole.
  std::size_t min_points = 0;
  /// Called with the frames read so far (never fewer than the call before)
  /// and their total, from one thread at a time; may be empty.
  std::function<void(std::size_t, std::size_t)> progress;
  /// Folders of files (PCD, depth images, KITTI): a file that cannot be read
  /// is left out, and named in one warning, instead of ending the read.
  bool skip_bad_files = false;

  /// The settings the command uses when no leaf is given: dense frames at
  /// kDefaultFrameVoxel, the others whole.
  static FrameReading denseDefault() { return {kDefaultFrameVoxel, kDenseFramePoints, {}, false}; }
  /// Whether a frame whose sensor gives `sensor_points` points is reduced.
  bool reduces(std::size_t sensor_points) const { return voxel_leaf > 0.0 && sensor_points >= min_points; }
};

/// A frame left out by FrameReading::skip_bad_files: its index and why.
struct SkippedFrame {
  std::size_t index = 0;
  std::string message;
};

/// Calls read(k) for every frame k < count on every thread, and
/// `reading.progress` (when set) after each. `read` writes frame k's results
/// to slot k, so the result does not depend on the threads. A frame whose
/// read throws InputError is returned (in frame order) with
/// reading.skip_bad_files; otherwise the error of the first failing frame in
/// frame order is thrown once the frames before it are read, and frames after
/// it are not read. Any other exception is thrown.
std::vector<SkippedFrame> readFramesInParallel(std::size_t count, const std::function<void(std::size_t)>& read,
                                               const FrameReading& reading);

/// Removes the skipped frames' slots from `values` (one slot per frame).
template <typename T>
void eraseSkipped(std::vector<T>& values, const std::vector<SkippedFrame>& skipped) {
  std::size_t kept = 0, next = 0;
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (next < skipped.size() && skipped[next].index == k) {
      ++next;
      continue;
    }
    if (kept != k) values[kept] = std::move(values[k]);
    ++kept;
  }
  values.resize(kept);
}

/// One warning naming the skipped files (the first few, and how many more);
/// "" when none. Throws InputError (the first frame's message) when every one
/// of `count` frames was skipped.
std::string skippedWarning(const std::vector<SkippedFrame>& skipped, std::size_t count);

/// Voxel-filters `cloud` in place with pcl::VoxelGrid (each occupied voxel
/// becomes the centroid of its points) when `reduction.reduces(sensor_points)`;
/// returns whether it did. NaN/Inf points are dropped with it. A cloud whose
/// extent holds more voxels than VoxelGrid's 32-bit indices can count (a
/// lidar sweep at a fine leaf) is filtered in parts cut on voxel boundaries,
/// which gives the same voxels. The organised layout (height > 1) is lost.
template <typename PointT>
bool reduceFrame(pcl::PointCloud<PointT>& cloud, std::size_t sensor_points, const FrameReading& reduction);

/// The same for a cloud as a message carries it (a ROS PointCloud2), every
/// field averaged per voxel as pcl::VoxelGrid<pcl::PCLPointCloud2> does, so
/// that a bag reader keeps only the reduced message: its sensor points are
/// width x height. Left as it is (false) when it has no FLOAT32 x, y and z
/// fields or fewer bytes than its points need: the reader reports those.
bool reduceFrame(pcl::PCLPointCloud2& cloud, const FrameReading& reduction);

}  // namespace obsgroup::io
