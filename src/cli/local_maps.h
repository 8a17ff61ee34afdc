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

}  // namespace obsgroup::io
