#pragma once

#include "obsgroup/common/invalid_observation.h"
#include "obsgroup/observation_grouping.h"

#include <chrono>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace obsgroup {

template <typename PointT>
void ObservationGrouping<PointT>::addObservation(const PointCloudConstPtr& cloud, const Eigen::Isometry3d& pose) {
  if (!cloud) throw InvalidObservation(static_cast<int>(observations_.size()), "null cloud");
  observations_.push_back({cloud, pose});
}

template <typename PointT>
void ObservationGrouping<PointT>::addObservation(const PointCloudConstPtr& cloud) {
  if (!cloud) throw InvalidObservation(static_cast<int>(observations_.size()), "null cloud");
  addObservation(cloud, poseFromSensorOrigin(*cloud));
}

template <typename PointT>
void ObservationGrouping<PointT>::clear() {
  observations_.clear();
  overlap_result_ = OverlapResult{};
  W_ = WeightMatrix{};
  world_ = WorldPoints{};
  warnings_.clear();
  open_floor_joins_.clear();
}

template <typename PointT>
SensedSpaceOverlap<PointT> ObservationGrouping<PointT>::getSensedSpaceOverlap() const {
  SensedSpaceOverlap<PointT> overlap = sensedSpaceOverlapOf<PointT>(params_);
  if (search_ && params_.neighbour_search == NeighbourSearch::PclSearch) overlap.setSearchMethod(search_);
  overlap.setProgressCallback(progress_);
  overlap.setInterruptFlag(interrupt_);
  return overlap;
}

template <typename PointT>
Partition ObservationGrouping<PointT>::compute() {
  params_.check();
  if (search_ && params_.neighbour_search == NeighbourSearch::PclSearch && params_.model != SensedSpaceModel::Points)
    throw std::invalid_argument("grouping parameters: a search method applies to the points model, not " +
                                toString(params_.model));
  using Clock = std::chrono::steady_clock;
  const auto seconds_since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  auto start = Clock::now();
  const SensedSpaceOverlap<PointT> overlap = getSensedSpaceOverlap();
  world_ = WorldPoints{};
  regions_ = ObservationRegions{};
  if (keep_world_points_) {
    world_ = overlap.toWorld(observations_);
    overlap_result_ = overlap.compute(observations_, world_, keep_regions_ ? &regions_ : nullptr);
  } else if (keep_regions_) {
    overlap_result_ = overlap.compute(observations_, overlap.toWorld(observations_), &regions_);
  } else {
    overlap_result_ = overlap.compute(observations_);
  }
  timings_.overlap_s = seconds_since(start);
  if (keep_regions_ && regions_callback_) regions_callback_(regions_);
  start = Clock::now();
  W_ = buildWeightMatrix(static_cast<int>(observations_.size()), overlap_result_.pairs, params_.diagonal_weight);
  if (!keep_overlap_matrix_) {
    overlap_result_.match_ratio = decltype(overlap_result_.match_ratio)();
    overlap_result_.pairs = {};
  }
  timings_.graph_s = seconds_since(start);
  start = Clock::now();
  Partition partition = recursivePartition(W_, getPartitionOptions());
  open_floor_joins_.clear();
  if (params_.model == SensedSpaceModel::Visibility && params_.open_floor_width > 0.0 && !observations_.empty()) {
    // In the re-centred frame the regions were cast in (SensedSpaceOverlap::compute).
    const Eigen::Vector3d origin = SensedSpaceOverlap<PointT>::worldOrigin(observations_);
    std::vector<Eigen::Vector2d> positions(observations_.size());
    for (std::size_t i = 0; i < observations_.size(); ++i)
      positions[i] = overlap_result_.points_per_observation[i] == 0
                         ? Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN())  // overlaps nothing
                         : Eigen::Vector2d((observations_[i].pose.translation() - origin).template head<2>());
    const double cell = params_.regions.cell_size;
    open_floor_joins_ = joinAcrossOpenFloor(partition, positions, params_.open_floor_width, cell,
                                            planeCellReader(overlap_result_.occupied_cells, cell),
                                            params_.regions.max_range);
  }
  std::vector<std::uint64_t>().swap(overlap_result_.occupied_cells);  // read by the joins alone
  timings_.partition_s = seconds_since(start);

  warnings_.clear();
  const auto& points = overlap_result_.points_per_observation;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i] == 0)
      warnings_.push_back("observation " + std::to_string(i) +
                          " has no finite point: it overlaps nothing and forms a group of its own");
  warnings_.insert(warnings_.end(), partition.warnings.begin(), partition.warnings.end());
  return partition;
}

template <typename PointT>
std::vector<Door> joinGroupsThroughPassages(const std::vector<Observation<PointT>>& observations,
                                            const GroupingParameters& params, Partition& partition) {
  if (params.model != SensedSpaceModel::Visibility || !params.join_passages || observations.empty()) return {};
  const SensedSpaceOverlap<PointT> overlap = sensedSpaceOverlapOf<PointT>(params);
  const WorldPoints world = overlap.toWorld(observations);
  const ObservationRegions regions = overlap.computeRegions(observations, world);
  std::vector<Eigen::Vector3d> sensors;
  sensors.reserve(observations.size());
  for (const auto& o : observations) sensors.push_back(o.pose.translation() - world.origin);
  PlaceOptions options;
  options.band_low = params.regions.band_low;
  options.band_high = params.regions.band_high;
  std::vector<int> place_ids(partition.groups.size());
  std::iota(place_ids.begin(), place_ids.end(), 0);
  return joinThroughPassages(partition, place_ids,
                             buildPlaceMap(regions, world, sensors, partition.groups, place_ids, options));
}

}  // namespace obsgroup

#define PCL_INSTANTIATE_ObservationGrouping(T)                                                              \
  template class obsgroup::ObservationGrouping<T>;                                                           \
  template std::vector<obsgroup::Door> obsgroup::joinGroupsThroughPassages<T>(                               \
      const std::vector<obsgroup::Observation<T>>&, const obsgroup::GroupingParameters&, obsgroup::Partition&);
