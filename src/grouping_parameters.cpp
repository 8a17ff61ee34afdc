#include "obsgroup/grouping_parameters.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace obsgroup {

namespace {

std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("grouping parameters: " + message);
}

/// The region settings the free-space model does not use.
bool visibilityOnlyChanged(const RegionParameters& r, const RegionParameters& d) {
  return r.clearance != d.clearance || r.min_observations != d.min_observations || r.band_low != d.band_low ||
         r.band_high != d.band_high || r.door_width != d.door_width || r.door_depth != d.door_depth;
}

/// The first region setting that differs from its default, by name.
std::string firstChangedRegionSetting(const RegionParameters& r, const RegionParameters& d) {
  if (r.cell_size != d.cell_size) return "regions.cell_size";
  if (r.max_range != d.max_range) return "regions.max_range";
  if (r.clearance != d.clearance) return "regions.clearance";
  if (r.min_observations != d.min_observations) return "regions.min_observations";
  if (r.door_width != d.door_width) return "regions.door_width";
  if (r.door_depth != d.door_depth) return "regions.door_depth";
  return "regions.band_low/band_high";
}

}  // namespace

GroupingParameters GroupingParameters::paper() {
  GroupingParameters params;
  params.usePaperMethod();
  return params;
}

void GroupingParameters::usePaperMethod() {
  // PartitionOptions' defaults are the paper's RecursivePart (sec. II): the
  // preset is written there, once.
  const PartitionOptions papers;
  model = SensedSpaceModel::Points;
  split = papers.split;
  ncut_threshold = papers.ncut_threshold;
  boundary_passes = papers.boundary_passes;
  mutual_neighbours = papers.mutual_neighbours;
  mutual_neighbours_share = papers.mutual_neighbours_share;
  open_floor_width = 0.0;
  join_passages = false;
}

void GroupingParameters::check() const {
  const GroupingParameters defaults;
  const std::string model_name = toString(model);
  if (model == SensedSpaceModel::Points) {
    require(regions == defaults.regions, firstChangedRegionSetting(regions, defaults.regions) +
                                             " applies to the free-space and visibility models, not points");
    require(std::isfinite(match_distance) && match_distance > 0,
            "match_distance (delta) must be finite and > 0 (got " + number(match_distance) + ")");
  } else {
    require(match_distance == defaults.match_distance,
            "match_distance (delta) applies to the points model, not " + model_name + " (it uses regions.cell_size)");
    require(neighbour_search == defaults.neighbour_search,
            "neighbour_search applies to the points model, not " + model_name);
    if (model == SensedSpaceModel::FreeSpace)
      require(!visibilityOnlyChanged(regions, defaults.regions),
              firstChangedRegionSetting(regions, defaults.regions) + " applies to the visibility model only");
    try {
      checkRegionParameters(regions);
    } catch (const std::invalid_argument& e) {
      require(false, e.what());
    }
  }
  require(std::isfinite(voxel_leaf) && voxel_leaf >= 0,
          "voxel_leaf must be finite and >= 0 (got " + number(voxel_leaf) + ")");
  require(std::isfinite(diagonal_weight) && diagonal_weight >= 0,
          "diagonal_weight must be finite and >= 0 (got " + number(diagonal_weight) + ")");
  require(std::isfinite(ncut_threshold) && ncut_threshold >= 0,
          "ncut_threshold must be finite and >= 0 (got " + number(ncut_threshold) + ")");
  require(boundary_passes >= 0, "boundary_passes must be >= 0 (got " + std::to_string(boundary_passes) + ")");
  require(mutual_neighbours >= 0, "mutual_neighbours must be >= 0 (got " + std::to_string(mutual_neighbours) + ")");
  require(std::isfinite(mutual_neighbours_share) && mutual_neighbours_share >= 0,
          "mutual_neighbours_share must be finite and >= 0 (got " + number(mutual_neighbours_share) + ")");
  require(mutual_neighbours > 0 || mutual_neighbours_share == 0 ||
              mutual_neighbours_share == defaults.mutual_neighbours_share,
          "mutual_neighbours_share applies when mutual_neighbours is above 0");
  require(std::isfinite(open_floor_width) && open_floor_width >= 0,
          "open_floor_width must be finite and >= 0 (got " + number(open_floor_width) + ")");
  require(model == SensedSpaceModel::Visibility || open_floor_width == 0 ||
              open_floor_width == defaults.open_floor_width,
          "open_floor_width applies to the visibility model, not " + model_name);
  require(min_group_size >= 1, "min_group_size must be >= 1 (got " + std::to_string(min_group_size) + ")");
  require(max_depth >= 0, "max_depth must be >= 0 (got " + std::to_string(max_depth) + ")");
  require(threads >= 0, "threads must be >= 0 (got " + std::to_string(threads) + ")");
}

PartitionOptions GroupingParameters::partitionOptions() const {
  PartitionOptions options;
  options.ncut_threshold = ncut_threshold;
  options.split = split;
  options.min_group_size = min_group_size;
  options.max_depth = max_depth;
  options.boundary_passes = boundary_passes;
  options.mutual_neighbours = mutual_neighbours;
  options.mutual_neighbours_share = mutual_neighbours_share;
  options.eigen.solver = eigen_solver;
  options.threads = threads;
  return options;
}

bool operator==(const GroupingParameters& a, const GroupingParameters& b) {
  return a.model == b.model && a.regions == b.regions && a.match_distance == b.match_distance &&
         a.neighbour_search == b.neighbour_search && a.voxel_leaf == b.voxel_leaf &&
         a.diagonal_weight == b.diagonal_weight && a.split == b.split && a.ncut_threshold == b.ncut_threshold &&
         a.boundary_passes == b.boundary_passes && a.mutual_neighbours == b.mutual_neighbours &&
         a.mutual_neighbours_share == b.mutual_neighbours_share && a.open_floor_width == b.open_floor_width &&
         a.join_passages == b.join_passages && a.min_group_size == b.min_group_size &&
         a.max_depth == b.max_depth && a.eigen_solver == b.eigen_solver && a.threads == b.threads;
}

}  // namespace obsgroup
