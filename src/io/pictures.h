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

/// World (re-centred) metres to picture pixels, y up.
struct PictureView {
  double scale = 1.0, min_x = 0.0, max_y = 0.0, margin = 40.0;
  int width = 0, height = 0;
  double px(double x) const { return margin + (x - min_x) * scale; }
  double py(double y) const { return margin + (max_y - y) * scale; }
};

/// Palette index of each group in the pictures (map.png and the local maps):
/// a greedy (DSATUR) colouring of the groups joined by an arc of the topology
/// or among each other's two nearest group centres, so that such neighbours
/// never share a colour. When that needs more than the palette's 12 well
/// separated colours (a dense topology: a real log's 163 groups with 5,087
/// arcs need 44; the 382 arcs shown, 5), only the arcs map.png shows
/// (shownArcs()) and the nearest centres count.
std::vector<int> groupColours(const TopologicalMap& topology);

/// The arcs map.png draws, indices into topology.arcs, ascending: each node's
/// `per_node` strongest (by weight, then overlapping and sequence pairs).
/// topology.json keeps all of them.
std::vector<std::size_t> shownArcs(const TopologicalMap& topology, int per_node = 3);

/// Where map.png puts things.
struct MapLayout {
  /// The drawing: cropped to the bulk of the observations (every pose and
  /// the points between the 2.5th and 97.5th percentile on each axis) plus a
  /// margin, so that a few far returns do not shrink the building.
  PictureView view;
  int legend_top = 0;                    ///< The legend: rows [legend_top, view.height).
  std::vector<Eigen::Vector2d> centres;  ///< Each group's mean position, in pixels.
  std::vector<int> colours;              ///< groupColours()
  std::vector<std::size_t> shown_arcs;   ///< shownArcs()
  /// Whether each group's mark is a numbered circle of `label_radius` pixels
  /// (no two overlap) or a dot: numbers where they fit, the larger groups first.
  std::vector<char> numbered;
  double label_radius = 11;
  std::size_t points_outside = 0;        ///< Points beyond the crop (not drawn).
};

/// The layout writeMapPictures() uses for these arguments.
MapLayout mapLayout(const WorldPoints& world, const std::vector<Eigen::Isometry3d>& poses,
                    const std::vector<Eigen::Isometry3d>& drawn, const Partition& partition,
                    const TopologicalMap& topology);

/// map.png and map.svg: the points from above coloured by group (colours:
/// groupColours()), each pose as an arrow (thinned where they would overlap),
/// each group as a numbered circle at its observations' mean (a dot where
/// numbers would overlap), the strongest arcs (shownArcs(), thicker for a
/// larger cut weight), a legend saying so and a scale bar; see mapLayout().
/// Marker sizes and line widths follow the spacing of the groups in the
/// picture, which grows with their number. With regions, each cell is first
/// tinted with the colour of the group most of whose observations hold it.
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
/// and a scale bar, cropped to the bulk of its points (all but the 0.5% at
/// either end on each axis: fewer are far returns than in map.png); about
/// 780 px on the long side. Group g is drawn in colour `colours[g]`
/// (groupColours(), as in map.png; empty: g). Written on `threads` threads
/// (<= 0: all); each picture is the same for any number.
template <typename PointT>
void writeLocalMapPictures(const OutputFolder& out, const std::vector<LocalMap<PointT>>& maps, int threads = 0,
                           const std::vector<int>& colours = {});

/// weights.png: W as an image, rows and columns ordered by group, darker for
/// a larger overlap, each group boxed.
void writeWeightsPicture(const OutputFolder& out, const WeightMatrix& W, const Partition& partition);

/// fiedler.png: the eigenvector components of the first (up to four)
/// bisections, in observation order, with the split threshold drawn.
void writeFiedlerPicture(const OutputFolder& out, const Partition& partition);

}  // namespace obsgroup::io
