#pragma once
// Pictures of a partition, drawn with cairo: the map from above coloured by
// group (like the paper's Fig. 5), each local map from above, W ordered by
// group (Fig. 3f) and the eigenvectors of the first splits (Fig. 2). The
// drawing alone: where a picture is written is the caller's (PictureWriter).

#include "group_colours.h"

#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/maps/topological_map.h>
#include <obsgroup/overlap/sensed_regions.h>
#include <obsgroup/overlap/world_points.h>
#include <obsgroup/places/place_map.h>
#include <obsgroup/partition/recursive_partitioner.h>

#include <functional>
#include <string>
#include <vector>

namespace obsgroup::render {

/// Where a picture goes: called with its name among the results ("map.png",
/// "local_maps/group_003.png") and a function that writes it to a path. The
/// command stages its results in its output folder; folderWriter() writes
/// straight into a folder.
using PictureWriter =
    std::function<void(const std::string& name, const std::function<void(const std::string& path)>& write)>;
/// Writes each picture to `folder`/name, creating the folders it needs.
PictureWriter folderWriter(const std::string& folder);

/// Colour `index` of the pictures' palette (groupColours() gives each group
/// its index) as "#rrggbb", for pages that show the groups as the pictures do.
std::string paletteHex(int index);

/// World (re-centred) metres to picture pixels, y up.
struct PictureView {
  double scale = 1.0, min_x = 0.0, max_y = 0.0, margin = 40.0;
  int width = 0, height = 0;
  double px(double x) const { return margin + (x - min_x) * scale; }
  double py(double y) const { return margin + (max_y - y) * scale; }
};

/// Where map.png puts things.
struct MapLayout {
  /// The drawing: cropped to the bulk of the observations (every pose and
  /// the points between the 2.5th and 97.5th percentile on each axis) plus a
  /// margin, so that a few far returns do not shrink the building.
  PictureView view;
  int legend_top = 0;                    ///< The legend: rows [legend_top, view.height).
  /// Where each group's mark is, in pixels: on its place's floor (Place::label_point)
  /// when the map has places and the place has floor, else at its observations' mean.
  std::vector<Eigen::Vector2d> centres;
  std::vector<int> colours;              ///< groupColours()
  std::vector<std::size_t> shown_arcs;   ///< shownArcs()
  /// Whether each group's mark is a numbered circle of `label_radius` pixels
  /// (no two overlap) or a dot: numbers where they fit, the larger groups first.
  std::vector<char> numbered;
  double label_radius = 11;
  std::size_t points_outside = 0;        ///< Points beyond the crop (not drawn).
  /// The level of detail. A map of 1,000 groups or more whose marks would
  /// lie less than 4 pixels apart (the median distance to the nearest other;
  /// tens of thousands of groups on one canvas) is drawn coarse:
  /// the observations as a density on blocks of `block` pixels, each in the
  /// colour of the group with most observations there; the points in grey;
  /// the arcs summed between blocks of `arc_block` pixels (`coarse_arcs`);
  /// numbered groups where they fit and no dots, pose arrows, outlines or
  /// doors, which would be smaller than a pixel.
  bool coarse = false;
  double spacing = 0;                    ///< median pixels from a group's mark to the nearest other
  int block = 4, arc_block = 24;
  struct BlockArc {
    Eigen::Vector2d from, to;            ///< pixels: the mean mark of the groups of each block
    double weight = 0;                   ///< the sum of the cut weights of the arcs between them
    std::size_t arcs = 0;                ///< how many arcs of the topology it sums
  };
  std::vector<BlockArc> coarse_arcs;
};

/// 3D input seen from above: only the points whose height above their
/// sensor lies in [low, high] (the visibility model's band, which leaves the
/// floor and the ceiling out) are drawn, and where several fall on one
/// pixel the highest is shown, shaded from pale (low) to full colour (high),
/// so that walls, furniture and doors read as on a floor plan.
struct HeightBand {
  double low = 0.0, high = 0.0;
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
/// picture, which grows with their number; groups too close together for
/// their own marks are drawn at a coarser level of detail (MapLayout::coarse). With regions, each cell is first
/// tinted with the colour of the group most of whose observations hold it.
/// `world` holds the points at the input `poses` (the frame of `world` before
/// re-centring); each observation is drawn at `drawn[i]` (globalPoses()),
/// its points moved by drawn[i] * poses[i]^-1. The regions are drawn where
/// they were computed, at the input poses. With places (place k of group k),
/// each place's outline is drawn in its group's colour and each door as a
/// short black bar, where they were computed (at the input poses). With a
/// height band (3D input), only the points within it are drawn and framed.
void writeMapPictures(const PictureWriter& out, const WorldPoints& world, const std::vector<Eigen::Isometry3d>& poses,
                      const std::vector<Eigen::Isometry3d>& drawn, const Partition& partition,
                      const TopologicalMap& topology, const ObservationRegions* regions = nullptr,
                      const PlaceMap* places = nullptr, const HeightBand* band = nullptr);

/// local_maps/group_NNN.png, numbered like writeLocalMaps' PCD files: each
/// local map's merged points from above in the map's own frame (x right, y
/// up), its members' poses as arrows, the reference's drawn black in a ring,
/// and a scale bar, framing the place: the points within 6 m of its
/// members' positions (all but the 0.5% of them at either end on each axis);
/// returns beyond (through a door, a window) are ticks on the picture's edge
/// in the direction they lie, counted in the caption. About 780 px on the
/// long side. Group g is drawn in colour `colours[g]`
/// (groupColours(), as in map.png; empty: g). Written on `threads` threads
/// (<= 0: all); each picture is the same for any number. With a height band
/// (3D input), heights are taken above the map's reference sensor.
template <typename PointT>
void writeLocalMapPictures(const PictureWriter& out, const std::vector<LocalMap<PointT>>& maps, int threads = 0,
                           const std::vector<int>& colours = {}, const HeightBand* band = nullptr);

/// weights.png: W as an image, rows and columns ordered by group, darker for
/// a larger overlap, each group boxed.
void writeWeightsPicture(const PictureWriter& out, const WeightMatrix& W, const Partition& partition);

/// fiedler.png: the eigenvector components of the first (up to four)
/// bisections, in observation order, with the split threshold drawn.
void writeFiedlerPicture(const PictureWriter& out, const Partition& partition);

}  // namespace obsgroup::render
