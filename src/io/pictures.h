#pragma once
// Pictures of a partition, drawn with cairo: the map from above coloured by
// group (like the paper's Fig. 5), each local map from above, W ordered by
// group (Fig. 3f) and the eigenvectors of the first splits (Fig. 2).

#include "output_folder.h"

#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/maps/topological_map.h>
#include <obsgroup/overlap/sensed_regions.h>
#include <obsgroup/overlap/world_points.h>
#include <obsgroup/partition/recursive_partitioner.h>

#include <vector>

namespace obsgroup::io {

/// The global pose of every observation after refinement: member k of node
/// g is at nodes[g].pose * nodes[g].member_poses[k] (the reference's input
/// pose times the member's refined pose in the reference frame).
std::vector<Eigen::Isometry3d> refinedPoses(const TopologicalMap& topology, std::size_t observations);

/// map.png and map.svg: every point from above coloured by its group, each
/// pose as an arrow, and the topological arcs between group centres. With
/// regions, each cell is first tinted with the colour of the group most of
/// whose observations hold it: the place each group stands for.
/// `world` holds the points at the input `poses` (the frame of `world` before
/// re-centring); each observation is drawn at `drawn[i]` (refinedPoses()),
/// its points moved by drawn[i] * poses[i]^-1. The regions are drawn where
/// they were computed, at the input poses.
void writeMapPictures(const OutputFolder& out, const WorldPoints& world, const std::vector<Eigen::Isometry3d>& poses,
                      const std::vector<Eigen::Isometry3d>& drawn, const Partition& partition,
                      const TopologicalMap& topology, const ObservationRegions* regions = nullptr);

/// local_maps/group_NNN.png, numbered like writeLocalMaps' PCD files: each
/// local map's merged points from above in the map's own frame (x right, y
/// up), its members' poses as arrows, the reference's drawn black in a ring,
/// and a scale bar; 780 px on the long side (820 tall). Written on `threads`
/// threads (<= 0: all); each picture is the same for any number.
template <typename PointT>
void writeLocalMapPictures(const OutputFolder& out, const std::vector<LocalMap<PointT>>& maps, int threads = 0);

/// weights.png: W as an image, rows and columns ordered by group, darker for
/// a larger overlap, each group boxed.
void writeWeightsPicture(const OutputFolder& out, const WeightMatrix& W, const Partition& partition);

/// fiedler.png: the eigenvector components of the first (up to four)
/// bisections, in observation order, with the split threshold drawn.
void writeFiedlerPicture(const OutputFolder& out, const Partition& partition);

}  // namespace obsgroup::io
