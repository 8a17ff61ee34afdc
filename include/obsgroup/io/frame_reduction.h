#pragma once
// Dense inputs (depth images, lidar scans, large clouds) reduced frame by
// frame as they are read: a depth camera records 30 frames of 307,200 points
// a second, and a minute of them held at full resolution is tens of GiB.
// Each frame is voxel-filtered in its sensor frame right after it is decoded,
// so a reader holds one full-resolution frame per thread and the reduced
// ones of the others.

#include <pcl/PCLPointCloud2.h>
#include <pcl/point_cloud.h>

#include <cstddef>
#include <cstdint>
#include <functional>

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

struct FrameReduction {
  /// Voxel leaf, metres; 0 keeps every point.
  double voxel_leaf = 0.0;
  /// Frames whose sensor gives fewer points than this are kept whole.
  std::size_t min_points = 0;
  /// Called with the frames read so far (never fewer than the call before)
  /// and their total, from one thread at a time; may be empty.
  std::function<void(std::size_t, std::size_t)> progress;

  /// The settings the command uses when no leaf is given: dense frames at
  /// kDefaultFrameVoxel, the others whole.
  static FrameReduction denseDefault() { return {kDefaultFrameVoxel, kDenseFramePoints, {}}; }
  /// Whether a frame whose sensor gives `sensor_points` points is reduced.
  bool reduces(std::size_t sensor_points) const { return voxel_leaf > 0.0 && sensor_points >= min_points; }
};

/// Voxel-filters `cloud` in place with pcl::VoxelGrid (each occupied voxel
/// becomes the centroid of its points) when `reduction.reduces(sensor_points)`;
/// returns whether it did. NaN/Inf points are dropped with it. A cloud whose
/// extent holds more voxels than VoxelGrid's 32-bit indices can count (a
/// lidar sweep at a fine leaf) is filtered in parts cut on voxel boundaries,
/// which gives the same voxels. The organised layout (height > 1) is lost.
/// Calls read(k) for every frame k < count on every thread, and `progress`
/// (when set) after each. The error of the first failing frame in frame
/// order is thrown once the frames before it are read; frames after a failed
/// one are not read. `read` writes frame k's results to slot k, so the
/// result does not depend on the threads.
void readFramesInParallel(std::size_t count, const std::function<void(std::size_t)>& read,
                          const std::function<void(std::size_t, std::size_t)>& progress);

template <typename PointT>
bool reduceFrame(pcl::PointCloud<PointT>& cloud, std::size_t sensor_points, const FrameReduction& reduction);

/// The same for a cloud as a message carries it (a ROS PointCloud2), every
/// field averaged per voxel as pcl::VoxelGrid<pcl::PCLPointCloud2> does, so
/// that a bag reader keeps only the reduced message: its sensor points are
/// width x height. Left as it is (false) when it has no FLOAT32 x, y and z
/// fields or fewer bytes than its points need: the reader reports those.
bool reduceFrame(pcl::PCLPointCloud2& cloud, const FrameReduction& reduction);

}  // namespace obsgroup::io
