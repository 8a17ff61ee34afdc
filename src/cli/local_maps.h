#pragma once
// local_maps/group_NNN.pcd: each local map's merged cloud, in the frame of its
// reference observation, with that observation's pose as VIEWPOINT.

#include "output_folder.h"

#include <obsgroup/maps/local_map_builder.h>

#include <vector>

namespace obsgroup::io {

/// Writes one PCD per local map, on `threads` threads (<= 0: all); returns
/// the points written. A failure reports the lowest group that failed.
template <typename PointT>
std::size_t writeLocalMaps(const OutputFolder& out, const std::vector<LocalMap<PointT>>& maps, int threads = 0);

/// map_labelled.pcd: every local map's points at its reference's pose in
/// the world frame, each labelled with its place id (`place_ids`, in map
/// order): pcl::PointXYZL, or PointXYZRGBL for coloured input. Each map is
/// voxel-filtered already; returns the points written.
template <typename PointT>
std::size_t writeLabelledMap(const OutputFolder& out, const std::vector<LocalMap<PointT>>& maps,
                             const std::vector<int>& place_ids);

}  // namespace obsgroup::io
