#pragma once
/// \file
/// Sensed-space models other than points: the space an observation sensed as
/// a set of grid cells (its region), and Pi (eq. 17) as the share of one
/// region's cells that another region holds. Plain Eigen, no PCL.
///
/// The paper's node is "the space sensed in each observation"; eq. (16)-(17)
/// implement it with the end points of a laser scan. Two other readings of
/// the same words are given here (docs/method.md measures all three):
///  - free space: the cells the observation's beams or rays pass through,
///    from the sensor to each point (2D: cells of a plane grid; 3D: voxels);
///  - visibility: the cells visible from the observation's position, all
///    around it: where its own beams looked, what they saw; elsewhere, what
///    the occupancy grid of every observation's points lets through (3D: the
///    points in a horizontal band about the sensor's height). It does not
///    depend on the heading, so a forward laser or a camera that looks the
///    other way in the same room still overlaps.
/// With either, Pi(i, j) = |R_i and R_j| / |R_i| and Psi is eq. (18) as before.

#include "obsgroup/common/enum_names.h"
#include "obsgroup/common/interrupt.h"
#include "obsgroup/overlap/overlap_matrix.h"
#include "obsgroup/overlap/world_points.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace obsgroup {

/// How the sensed space of an observation is modelled.
enum class SensedSpaceModel {
  Points,     ///< End points matched within delta, eq. (16)-(17): the paper's.
  FreeSpace,  ///< Cells crossed by the beams / rays.
  Visibility  ///< Cells visible all around the pose (own beams, then the shared occupancy grid).
};

/// Points model: how the points of one observation find a point of another
/// within delta. Both give the same W (SensedSpaceOverlap).
enum class NeighbourSearch {
  SharedGrid,  ///< One grid over all observations' points (the default; see shared_grid_matcher.h).
  PclSearch    ///< One pcl::search::Search per observation (kd-tree by default).
};

inline constexpr EnumName<SensedSpaceModel> kSensedSpaceModelNames[] = {
    {SensedSpaceModel::Points, "points"},
    {SensedSpaceModel::FreeSpace, "free-space"},
    {SensedSpaceModel::Visibility, "visibility"}};

inline std::string toString(SensedSpaceModel model) { return nameOf(kSensedSpaceModelNames, model); }
/// Parses "points", "free-space" or "visibility"; throws std::invalid_argument otherwise.
inline SensedSpaceModel sensedSpaceModelFromString(const std::string& name) {
  return valueNamed(kSensedSpaceModelNames, name, "sensed-space model");
}

/// Parameters of the region models (free space, visibility). The defaults
/// measured best across 2D lasers and depth cameras, exact and drifted poses
/// (docs/grouping.md).
struct RegionParameters {
  /// Edge of a grid cell (2D) or voxel (3D), metres.
  double cell_size = 0.2;
  /// Beams are followed, and visibility is cast, this far from the sensor,
  /// metres: about a room's size, so that a long corridor is cut into
  /// stretches and a view through a door reaches only the near part of the
  /// next room.
  double max_range = 6.0;
  /// Visibility: occupied cells closer than this to the pose do not block
  /// (a drifted pose next to a wall, or inside its cell, still sees), metres.
  double clearance = 0.3;
  /// Visibility: a cell is occupied when at least this many observations
  /// have a point in it, and no fewer than have a beam through it: a drifted
  /// copy of a wall across a door, which the beams of everyone who looked
  /// through the door cross, does not close it; a wall seen once stands.
  int min_observations = 1;
  /// Visibility in 3D: the points whose height above the sensor lies in
  /// [band_low, band_high] make the occupancy grid (a depth camera at 1 m
  /// over the floor: 0.3 to 1.8 m above the floor), metres.
  double band_low = -0.7;
  double band_high = 0.8;
  /// Visibility: a ray stops once it has come through a door, an opening
  /// narrower than this between wider free space, so that an observation's
  /// region is the place it stands in and not the rooms it looks into,
  /// metres; 0: doors do not stop the view.
  double door_width = 1.2;
  /// Visibility: a narrow stretch longer than this along the ray is a
  /// passage (a narrow corridor), not a door, and does not stop it, metres.
  double door_depth = 1.0;
};

/// Throws std::invalid_argument naming the first parameter out of range.
void checkRegionParameters(const RegionParameters& params);

/// Whether every point and sensor lies at one height (within a quarter of
/// `cell_size`): 2D scans, which the region models treat in the plane (the
/// visibility model's regions are plane cells in 3D too, from a height band).
bool isPlanarData(const WorldPoints& world, const std::vector<Eigen::Vector3d>& sensor_origins, double cell_size);

inline bool operator==(const RegionParameters& a, const RegionParameters& b) {
  return a.cell_size == b.cell_size && a.max_range == b.max_range && a.clearance == b.clearance &&
         a.min_observations == b.min_observations && a.band_low == b.band_low && a.band_high == b.band_high &&
         a.door_width == b.door_width && a.door_depth == b.door_depth;
}
inline bool operator!=(const RegionParameters& a, const RegionParameters& b) { return !(a == b); }

/// The cells of every observation's region. A region is kept as runs of
/// consecutive keys (a column of plane cells, a stack of voxels): a 6 m
/// visibility region of 0.2 m cells is about 950 cells in about 60 runs,
/// 10 bytes a run where a list of keys takes 8 a cell (docs/performance.md).
class ObservationRegions {
 public:
  bool planar = true;  ///< 2D cells (x, y) or 3D voxels
  double cell_size = 1.0;
  /// Where the cells lie: a cell's corner is at (k - phase) * cell_size in
  /// the re-centred frame of the WorldPoints (the first sensor at a centre).
  Eigen::Vector3d phase = Eigen::Vector3d::Constant(0.5);
  /// Visibility: the plane cells occupied in the evidence of all
  /// observations (keys ascending; planeCellReader reads them); empty for
  /// free space.
  std::vector<std::uint64_t> occupied;

  /// Adds the next observation's region: keys ascending and distinct (else
  /// std::invalid_argument, naming the observation).
  void append(const std::uint64_t* begin, const std::uint64_t* end);
  void append(const std::vector<std::uint64_t>& keys) { append(keys.data(), keys.data() + keys.size()); }
  /// Adds the next observation's region as runs, as forEachRun gives them:
  /// starts ascending, each run at least one key long and ending before the
  /// next begins (a run of 65,535 keys may be followed at once).
  void appendRuns(const std::uint64_t* starts, const std::uint16_t* lengths, std::size_t runs);

  int size() const { return static_cast<int>(cell_offsets_.size()) - 1; }
  /// Cells of observation i's region.
  std::size_t count(int i) const { return cell_offsets_[i + 1] - cell_offsets_[i]; }
  /// Cells of all regions (a cell in two regions counts twice).
  std::size_t totalCells() const { return cell_offsets_.back(); }
  bool empty() const { return cell_offsets_.back() == 0; }
  /// Runs of all regions; the bytes they and their offsets take.
  std::size_t runCount() const { return run_start_.size(); }
  std::size_t bytes() const;

  /// f(key) for each cell of observation i's region, ascending.
  template <typename F>
  void forEachCell(int i, F&& f) const {
    for (std::size_t r = run_offsets_[i]; r < run_offsets_[i + 1]; ++r)
      for (std::uint64_t key = run_start_[r], end = key + run_length_[r]; key != end; ++key) f(key);
  }
  /// f(first key, length) for each run of observation i's region, ascending.
  template <typename F>
  void forEachRun(int i, F&& f) const {
    for (std::size_t r = run_offsets_[i]; r < run_offsets_[i + 1]; ++r) f(run_start_[r], std::size_t(run_length_[r]));
  }
  /// Observation i's cells as a list of keys, ascending.
  std::vector<std::uint64_t> cellsOf(int i) const;
  /// The lowest key of the first region that has a cell (0 when none has).
  std::uint64_t firstKey() const;

  /// The centre of a cell in the re-centred frame of the WorldPoints the
  /// regions were computed from (for plane cells, z is the grid's 0).
  Eigen::Vector3d cellCentre(std::uint64_t key) const;
  /// The centres of the lowest and the highest cell along x and along y over
  /// all regions (z: the first cell's), as cellCentre gives them; found from
  /// the keys' integer coordinates, without a centre per cell. False when
  /// there is no cell.
  bool planeBounds(Eigen::Vector3d& lowest, Eigen::Vector3d& highest) const;

  /// The same cells in the same regions, on the same grid.
  bool operator==(const ObservationRegions& other) const;
  bool operator!=(const ObservationRegions& other) const { return !(*this == other); }

 private:
  std::vector<std::uint64_t> run_start_;
  std::vector<std::uint16_t> run_length_;
  std::vector<std::size_t> run_offsets_{0};   ///< observation i's runs: [run_offsets_[i], run_offsets_[i+1])
  std::vector<std::size_t> cell_offsets_{0};  ///< and its cells, counted the same way
};

/// The regions of `world`'s observations under `model` (FreeSpace or
/// Visibility), the sensor of observation i at sensor_origins[i] (re-centred
/// on world.origin like the points). Data whose points and origins all share
/// one height is planar (2D cells); otherwise free space traverses voxels and
/// visibility works in the band. Throws std::invalid_argument on bad
/// parameters, Interrupted when `interrupt` is set. The result does not depend
/// on `threads`.
ObservationRegions computeRegions(SensedSpaceModel model, const WorldPoints& world,
                                  const std::vector<Eigen::Vector3d>& sensor_origins, const RegionParameters& params,
                                  int threads = 0, const InterruptFlag* interrupt = nullptr);

/// Pi and Psi of the regions of `model`, as regionOverlap(computeRegions(...))
/// but without ever holding the regions twice (what SensedSpaceOverlap uses).
OverlapResult computeRegionOverlap(SensedSpaceModel model, const WorldPoints& world,
                                   const std::vector<Eigen::Vector3d>& sensor_origins, const RegionParameters& params,
                                   int threads = 0, const InterruptFlag* interrupt = nullptr);

/// Whether the plane cell of `cell_size` metres holding p (x and y in the
/// re-centred frame of the world points) is one of `occupied` (plane cell
/// keys, as ObservationRegions::occupied and OverlapResult::occupied_cells
/// hold them), as a function over a bitmap of the cells made once, which
/// remembers the tile it read last: for many reads by one caller.
std::function<bool(const Eigen::Vector2d&)> planeCellReader(const std::vector<std::uint64_t>& occupied,
                                                            double cell_size);

/// For every observation i and every j != i, the number of cells of i's
/// region that j's region holds (the numerator of Pi).
MatchCounts countSharedCells(const ObservationRegions& regions, int threads = 0,
                             const InterruptFlag* interrupt = nullptr);

/// Pi (eq. 17 with cells for points) and Psi (eq. 18) of the regions;
/// points_per_observation holds each region's cells (SensedSpaceOverlap moves
/// them to region_cells and puts the points there).
OverlapResult regionOverlap(const ObservationRegions& regions, int threads = 0,
                            const InterruptFlag* interrupt = nullptr);

}  // namespace obsgroup
