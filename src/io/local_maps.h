#pragma once
// local_maps/group_NNN.pcd: each group's clouds merged in the frame of its
// first observation, voxel-filtered, with that observation's pose as VIEWPOINT.

#include "output_folder.h"

#include <obsgroup/observation.h>
#include <obsgroup/partition/recursive_partitioner.h>

#include <string>
#include <vector>

namespace obsgroup::io {

/// Writes one PCD per group; returns the number of points written. A leaf of
/// 0 keeps every point; a leaf too small for a map's extent keeps every point
/// of that map and adds a warning.
template <typename PointT>
std::size_t writeLocalMaps(const OutputFolder& out, const std::vector<Observation<PointT>>& observations,
                           const Partition& partition, double leaf, std::vector<std::string>& warnings);

}  // namespace obsgroup::io
