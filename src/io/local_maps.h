#pragma once
// local_maps/group_NNN.pcd: each local map's merged cloud, in the frame of its
// reference observation, with that observation's pose as VIEWPOINT.

#include "output_folder.h"

#include <obsgroup/maps/local_map_builder.h>

#include <vector>

namespace obsgroup::io {

/// Writes one PCD per local map, in group order; returns the points written.
template <typename PointT>
std::size_t writeLocalMaps(const OutputFolder& out, const std::vector<LocalMap<PointT>>& maps);

}  // namespace obsgroup::io
