#pragma once

#include "obsgroup/common/invalid_observation.h"
#include "obsgroup/common/parallel_for.h"
#include "obsgroup/online_grouping.h"
#include "obsgroup/overlap/impl/sensed_space_overlap.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace obsgroup {

template <typename PointT>
void OnlineGrouping<PointT>::setParameters(const GroupingParameters& params) {
  params.check();
  GroupingParameters same_but_threads = params;
  same_but_threads.threads = params_.threads;
  const bool changed = same_but_threads != params_;
  params_ = params;
  if (changed) reconfigure();
}

template <typename PointT>
PartitionOptions OnlineGrouping<PointT>::getPartitionOptions() const {
  PartitionOptions options = params_.partitionOptions();
  options.interrupt = interrupt_;
  return options;
}

template <typename PointT>
int OnlineGrouping<PointT>::firstPresent() const {
  for (int i = 0; i < int(slots_.size()); ++i)
    if (slots_[i].present) return i;
  return -1;
}

template <typename PointT>
std::vector<Eigen::Vector3f> OnlineGrouping<PointT>::worldPointsOf(int id, const Observation<PointT>& observation,
                                                                   const Eigen::Vector3d& origin) const {
  if (!observation.cloud) throw InvalidObservation(id, "null cloud");
  if (!observation.pose.matrix().allFinite()) throw InvalidObservation(id, "pose is not finite");
  try {
    return sensedSpaceOverlapOf<PointT>(params_).observationToWorld(observation, origin);
  } catch (const InvalidObservation&) {
    throw;
  } catch (const std::exception& e) {
    throw InvalidObservation(id, e.what());
  }
}

template <typename PointT>
int OnlineGrouping<PointT>::insert(const PointCloudConstPtr& cloud, const Eigen::Isometry3d& pose) {
  const int id = static_cast<int>(slots_.size());
  const Observation<PointT> observation{cloud, pose};
  if (!overlap_ || reconfigure_) recentreAll();  // so that the new observation is checked now
  // The common frame is re-centred on the first observation present, as
  // SensedSpaceOverlap::toWorld does (the same points, to the bit).
  const bool first = firstPresent() < 0;
  const Eigen::Vector3d origin = first && pose.translation().allFinite() ? Eigen::Vector3d(pose.translation()) : origin_;
  std::vector<Eigen::Vector3f> points = worldPointsOf(id, observation, origin);
  try {
    overlap_->check(id, points, pose.translation() - origin);
  } catch (const std::invalid_argument& e) {
    throw InvalidObservation(id, e.what());
  }
  slots_.push_back({true, observation});
  ++changes_since_exact_;
  moved_.push_back(id);
  origin_ = origin;
  overlap_->set(id, std::move(points), pose.translation() - origin);
  return id;
}

template <typename PointT>
void OnlineGrouping<PointT>::updatePose(int id, const Eigen::Isometry3d& pose) {
  if (!contains(id)) throw std::out_of_range("updatePose: no observation " + std::to_string(id));
  if (!pose.matrix().allFinite()) throw InvalidObservation(id, "pose is not finite");
  Observation<PointT> moved = slots_[id].observation;
  moved.pose = pose;
  ++changes_since_exact_;
  if (id == firstPresent()) {
    // The common frame moves with it: every observation is re-centred.
    const Observation<PointT> kept = slots_[id].observation;
    slots_[id].observation = moved;
    try {
      recentreAll();
    } catch (...) {
      slots_[id].observation = kept;
      recentreAll();
      throw;
    }
    moved_.push_back(id);
    return;
  }
  if (!overlap_ || reconfigure_) recentreAll();
  std::vector<Eigen::Vector3f> points = worldPointsOf(id, moved, origin_);
  try {
    overlap_->check(id, points, pose.translation() - origin_);
  } catch (const std::invalid_argument& e) {
    throw InvalidObservation(id, e.what());
  }
  overlap_->set(id, std::move(points), pose.translation() - origin_);
  slots_[id].observation = moved;
  moved_.push_back(id);
}

template <typename PointT>
void OnlineGrouping<PointT>::remove(int id) {
  if (!contains(id)) throw std::out_of_range("remove: no observation " + std::to_string(id));
  if (!overlap_ || reconfigure_) recentreAll();
  const bool was_first = id == firstPresent();
  slots_[id].present = false;
  if (!was_first) {
    overlap_->erase(id);
  } else {
    // The common frame moves to the next observation: every one is re-centred.
    try {
      recentreAll();
    } catch (...) {
      slots_[id].present = true;
      recentreAll();
      throw;
    }
  }
  ++changes_since_exact_;
  moved_.push_back(id);
  slots_[id].observation = Observation<PointT>{};
}

template <typename PointT>
void OnlineGrouping<PointT>::recentreAll() {
  // A new common frame moves the cell grid under every region: all of W may
  // change, so the next update is exact, not local.
  exact_once_ = false;
  const int first = firstPresent();
  const Eigen::Vector3d origin =
      first >= 0 ? Eigen::Vector3d(slots_[first].observation.pose.translation()) : Eigen::Vector3d::Zero();
  params_.check();
  auto fresh = std::make_unique<IncrementalOverlap>(params_.model, params_.match_distance, params_.regions);
  std::vector<std::vector<Eigen::Vector3f>> points(slots_.size());
  parallelFor(slots_.size(), params_.threads, 4, [&](std::size_t i) {
    if (slots_[i].present) points[i] = worldPointsOf(int(i), slots_[i].observation, origin);
  });
  for (int i = 0; i < int(slots_.size()); ++i) {
    if (!slots_[i].present) continue;
    const Eigen::Vector3d sensor = slots_[i].observation.pose.translation() - origin;
    try {
      fresh->check(i, points[i], sensor);
    } catch (const std::invalid_argument& e) {
      throw InvalidObservation(i, e.what());
    }
    fresh->set(i, std::move(points[i]), sensor);
  }
  overlap_ = std::move(fresh);
  origin_ = origin;
  reconfigure_ = false;
}

template <typename PointT>
GroupUpdate OnlineGrouping<PointT>::update() {
  return run(false);
}

template <typename PointT>
GroupUpdate OnlineGrouping<PointT>::updateExact() {
  return run(true);
}

template <typename PointT>
GroupUpdate OnlineGrouping<PointT>::run(bool force_exact) {
  if (reconfigure_ || !overlap_) recentreAll();
  GroupUpdate out;
  const std::vector<int> changed_slots = overlap_->update(params_.threads, interrupt_);
  out.observations_recomputed = overlap_->recomputedLastUpdate();
  const std::vector<int> ids = overlap_->slots();
  // Into the matrix of the update before last, whose storage is reused; the
  // unchanged columns copied from the last one.
  overlap_->weightMatrix(params_.diagonal_weight, &W_, spare_W_);
  W_.swap(spare_W_);
  pending_.resize(slots_.size(), 0);
  for (int slot : changed_slots) pending_[slot] = 1;
  pending_sources_.resize(slots_.size(), 0);
  for (int slot : overlap_->sourcesOfLastUpdate()) pending_sources_[slot] = 1;
  out.exact = force_exact || !exact_once_ || exact_interval_ <= 1 || changes_since_exact_ >= exact_interval_;
  std::vector<std::vector<int>> groups;
  if (out.exact) {
    groups = partitionExactly(ids, out);
  } else {
    partition_ = partitionAroundChanges(W_, ids, moved_, group_ids_, getPartitionOptions());
    joinAcrossOpenFloor(ids);
    for (const auto& group : partition_.groups) {
      std::vector<int> members;
      for (int k : group) members.push_back(ids[k]);
      groups.push_back(std::move(members));
    }
  }

  warnings_.clear();
  for (int id : ids)
    if (overlap_->pointCount(id) == 0)
      warnings_.push_back("observation " + std::to_string(id) +
                          " has no finite point: it overlaps nothing and forms a group of its own");
  warnings_.insert(warnings_.end(), partition_.warnings.begin(), partition_.warnings.end());
  out.changes = group_ids_.assign(groups, slots_.size());
  moved_.clear();
  return out;
}

/// The exact partition, reusing the split-tree nodes no changed row reaches.
template <typename PointT>
std::vector<std::vector<int>> OnlineGrouping<PointT>::partitionExactly(const std::vector<int>& ids, GroupUpdate& out) {
  std::vector<char> changed(ids.size(), 0);
  std::vector<char> sources(ids.size(), 0);
  for (std::size_t k = 0; k < ids.size(); ++k) changed[k] = pending_[ids[k]], sources[k] = pending_sources_[ids[k]];
  // Only the nodes holding a source are solved again: a new observation
  // changes its neighbours' rows, not the blocks of the nodes without it.
  partition_ = recursivePartition(W_, getPartitionOptions(), ids, changed, sources, cache_);
  joinAcrossOpenFloor(ids);
  out.split_nodes_reused = cache_.reusedNodes();
  out.split_nodes_computed = cache_.computedNodes();
  out.split_nodes_ahead = cache_.aheadNodes();
  std::fill(pending_.begin(), pending_.end(), 0);
  std::fill(pending_sources_.begin(), pending_sources_.end(), 0);
  changes_since_exact_ = 0;
  exact_once_ = true;
  std::vector<std::vector<int>> groups;
  for (const auto& group : partition_.groups) {
    std::vector<int> members;
    for (int k : group) members.push_back(ids[k]);
    groups.push_back(std::move(members));
  }
  return groups;
}

template <typename PointT>
void OnlineGrouping<PointT>::joinAcrossOpenFloor(const std::vector<int>& ids) {
  open_floor_joins_.clear();
  if (params_.model != SensedSpaceModel::Visibility || !(params_.open_floor_width > 0.0) || ids.empty()) return;
  // In the re-centred frame the regions are cast in, as the batch's.
  std::vector<Eigen::Vector2d> positions(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const Eigen::Vector3d& at = slots_[std::size_t(ids[k])].observation.pose.translation();
    positions[k] = overlap_->pointCount(ids[k]) == 0
                       ? Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN())  // overlaps nothing
                       : Eigen::Vector2d((at - origin_).template head<2>());
  }
  open_floor_joins_ =
      obsgroup::joinAcrossOpenFloor(partition_, positions, params_.open_floor_width, params_.regions.cell_size,
                                    overlap_->planeCellReader(), params_.regions.max_range);
}

template <typename PointT>
std::vector<int> OnlineGrouping<PointT>::getIds() const {
  std::vector<int> ids;
  for (int i = 0; i < int(slots_.size()); ++i)
    if (slots_[i].present) ids.push_back(i);
  return ids;
}

template <typename PointT>
const Observation<PointT>& OnlineGrouping<PointT>::getObservation(int id) const {
  if (!contains(id)) throw std::out_of_range("getObservation: no observation " + std::to_string(id));
  return slots_[id].observation;
}

template <typename PointT>
std::vector<Observation<PointT>> OnlineGrouping<PointT>::getObservations() const {
  std::vector<Observation<PointT>> out;
  for (const Slot& s : slots_)
    if (s.present) out.push_back(s.observation);
  return out;
}

}  // namespace obsgroup

#define PCL_INSTANTIATE_OnlineGrouping(T) template class obsgroup::OnlineGrouping<T>;
