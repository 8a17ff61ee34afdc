#pragma once
// Pictures of a partition, drawn with cairo: the map from above coloured by
// group (like the paper's Fig. 5), W ordered by group (Fig. 3f) and the
// eigenvectors of the first splits (Fig. 2).

#include "output_folder.h"

#include <obsgroup/maps/topological_map.h>
#include <obsgroup/overlap/sensed_regions.h>
#include <obsgroup/overlap/world_points.h>
#include <obsgroup/partition/recursive_partitioner.h>

#include <vector>

namespace obsgroup::io {

/// map.png and map.svg: every point from above coloured by its group, each
/// pose as an arrow, and the topological arcs between group centres. With
/// regions, each cell is first tinted with the colour of the group most of
/// whose observations hold it: the place each group stands for.
/// `poses` are in the same frame as `world` before re-centring.
void writeMapPictures(const OutputFolder& out, const WorldPoints& world, const std::vector<Eigen::Isometry3d>& poses,
                      const Partition& partition, const TopologicalMap& topology,
                      const ObservationRegions* regions = nullptr);

/// weights.png: W as an image, rows and columns ordered by group, darker for
/// a larger overlap, each group boxed.
void writeWeightsPicture(const OutputFolder& out, const WeightMatrix& W, const Partition& partition);

/// fiedler.png: the eigenvector components of the first (up to four)
/// bisections, in observation order, with the split threshold drawn.
void writeFiedlerPicture(const OutputFolder& out, const Partition& partition);

}  // namespace obsgroup::io
