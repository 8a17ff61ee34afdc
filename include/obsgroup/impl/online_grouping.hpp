#pragma once

#include "obsgroup/common/invalid_observation.h"
#include "obsgroup/common/parallel_for.h"
#include "obsgroup/online_grouping.h"
#include "obsgroup/overlap/impl/sensed_space_overlap.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>
#include <string>

namespace obsgroup {

template <typename PointT>
OnlineGrouping<PointT>::OnlineGrouping() {
  const ObservationGrouping<PointT> defaults;
  setParametersFrom(defaults);
}

template <typename PointT>
void OnlineGrouping<PointT>::usePaperMethod() {
  ObservationGrouping<PointT> paper;
  paper.usePaperMethod();
  setParametersFrom(paper);
}

template <typename PointT>
void OnlineGrouping<PointT>::setParametersFrom(const ObservationGrouping<PointT>& grouping) {
  const int threads = config_.getNumberOfThreads();
  const InterruptFlag* interrupt = config_.getInterruptFlag();
  config_.setSensedSpaceModel(grouping.getSensedSpaceModel());
  config_.setRegionParameters(grouping.getRegionParameters());
  config_.setMatchDistance(grouping.getMatchDistance());
  config_.setVoxelLeafSize(grouping.getVoxelLeafSize());
  config_.setNumberOfThreads(threads);
  config_.setInterruptFlag(interrupt);
  diagonal_ = grouping.getDiagonalWeight();
  options_ = grouping.getPartitionOptions();
  reconfigure();
}

template <typename PointT>
PartitionOptions OnlineGrouping<PointT>::getPartitionOptions() const {
  PartitionOptions options = options_;
  options.threads = config_.getNumberOfThreads();
  options.interrupt = config_.getInterruptFlag();
  options.eigen.elimination_rank.clear();  // each node orders itself (SplitCache)
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
    return config_.observationToWorld(observation, origin);
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
  group_of_.push_back(-1);
  ++changes_since_exact_;
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
  slots_[id].observation = Observation<PointT>{};
}

template <typename PointT>
void OnlineGrouping<PointT>::recentreAll() {
  const int first = firstPresent();
  const Eigen::Vector3d origin =
      first >= 0 ? Eigen::Vector3d(slots_[first].observation.pose.translation()) : Eigen::Vector3d::Zero();
  auto fresh = std::make_unique<IncrementalOverlap>(config_.getSensedSpaceModel(), config_.getMatchDistance(),
                                                    config_.getRegionParameters());
  std::vector<std::vector<Eigen::Vector3f>> points(slots_.size());
  parallelFor(slots_.size(), config_.getNumberOfThreads(), 4, [&](std::size_t i) {
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
  const std::vector<int> changed_slots = overlap_->update(config_.getNumberOfThreads(), config_.getInterruptFlag());
  out.observations_recomputed = overlap_->recomputedLastUpdate();
  const std::vector<int> ids = overlap_->slots();
  W_ = overlap_->weightMatrix(diagonal_);
  pending_.resize(slots_.size(), 0);
  for (int slot : changed_slots) pending_[slot] = 1;
  out.exact = force_exact || !exact_once_ || exact_interval_ <= 1 || changes_since_exact_ >= exact_interval_;
  const std::vector<std::vector<int>> groups =
      out.exact ? partitionExactly(ids, out) : partitionLocally(ids, changed_slots);

  warnings_.clear();
  for (int id : ids)
    if (overlap_->pointCount(id) == 0)
      warnings_.push_back("observation " + std::to_string(id) +
                          " has no finite point: it overlaps nothing and forms a group of its own");
  warnings_.insert(warnings_.end(), partition_.warnings.begin(), partition_.warnings.end());
  assignGroupIds(groups, out);
  return out;
}

/// The exact partition, reusing the split-tree nodes no changed row reaches.
template <typename PointT>
std::vector<std::vector<int>> OnlineGrouping<PointT>::partitionExactly(const std::vector<int>& ids, GroupUpdate& out) {
  std::vector<char> changed(ids.size(), 0);
  for (std::size_t k = 0; k < ids.size(); ++k) changed[k] = pending_[ids[k]];
  partition_ = recursivePartition(W_, getPartitionOptions(), ids, changed, cache_);
  out.split_nodes_reused = cache_.reusedNodes();
  out.split_nodes_computed = cache_.computedNodes();
  std::fill(pending_.begin(), pending_.end(), 0);
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

/// The groups holding a changed observation, the new observations and the
/// groups next to them in W, re-partitioned on their own; the other groups
/// kept (setExactInterval).
template <typename PointT>
std::vector<std::vector<int>> OnlineGrouping<PointT>::partitionLocally(const std::vector<int>& ids,
                                                                       const std::vector<int>& changed_slots) {
  const auto position = [&ids](int id) { return int(std::lower_bound(ids.begin(), ids.end(), id) - ids.begin()); };
  std::vector<char> in_region(ids.size(), 0);
  std::set<int> region_groups;
  for (int id : changed_slots)
    if (group_of_[id] >= 0) region_groups.insert(group_of_[id]);
  for (std::size_t k = 0; k < ids.size(); ++k)
    if (group_of_[ids[k]] < 0) in_region[k] = 1;
  for (int g : region_groups)
    for (int id : groups_.at(g))
      if (contains(id)) in_region[position(id)] = 1;
  // ...and the groups next to them.
  std::set<int> next_to;
  for (std::size_t k = 0; k < ids.size(); ++k)
    if (in_region[k])
      for (WeightMatrix::InnerIterator it(W_, Eigen::Index(k)); it; ++it)
        if (!in_region[it.row()] && group_of_[ids[it.row()]] >= 0) next_to.insert(group_of_[ids[it.row()]]);
  for (int g : next_to)
    for (int id : groups_.at(g))
      if (contains(id)) in_region[position(id)] = 1;

  std::vector<int> region;
  for (std::size_t k = 0; k < ids.size(); ++k)
    if (in_region[k]) region.push_back(int(k));
  std::vector<std::vector<int>> groups;  // by position
  if (!region.empty()) {
    PartitionOptions options = getPartitionOptions();
    options.keep_eigenvectors = false;
    Partition local = recursivePartition(inducedSubgraph(W_, region), options);
    for (auto& group : local.groups) {
      for (int& k : group) k = region[k];
      groups.push_back(std::move(group));
    }
    partition_.warnings = std::move(local.warnings);
  } else {
    partition_.warnings.clear();
  }
  for (const auto& [g, members] : groups_) {
    std::vector<int> kept;
    for (int id : members)
      if (contains(id) && !in_region[position(id)]) kept.push_back(position(id));
    if (!kept.empty()) groups.push_back(std::move(kept));
  }
  std::sort(groups.begin(), groups.end(), [](const auto& a, const auto& b) { return a.front() < b.front(); });
  partition_.groups = groups;
  partition_.splits.clear();
  partition_.group_of.assign(ids.size(), -1);
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (int k : groups[g]) partition_.group_of[k] = int(g);
  for (auto& group : groups)
    for (int& k : group) k = ids[k];
  return groups;
}

/// How the new groups take the old groups' members, and the id each new
/// group gets: that of the old group it holds most of, when that old group's
/// largest share went to it; a new id otherwise.
template <typename PointT>
typename OnlineGrouping<PointT>::GroupMatch OnlineGrouping<PointT>::matchGroups(
    const std::vector<std::vector<int>>& groups) {
  GroupMatch m;
  m.from_old.resize(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (int id : groups[g])
      if (group_of_[id] >= 0) {
        ++m.from_old[g][group_of_[id]];
        ++m.to_new[group_of_[id]][int(g)];
      }
  std::map<int, int> heir;  // old id -> the new group holding most of it (the first on a tie)
  for (const auto& [old, counts] : m.to_new) {
    int best = -1, best_count = 0;
    for (const auto& [g, count] : counts)
      if (count > best_count) best = g, best_count = count;
    heir[old] = best;
  }
  m.new_id.assign(groups.size(), -1);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    int best = -1, best_count = 0;
    for (const auto& [old, count] : m.from_old[g])
      if (heir[old] == int(g) && count > best_count) best = old, best_count = count;
    m.new_id[g] = best >= 0 ? best : next_group_id_++;
  }
  return m;
}

/// The changes from groups_ to `groups`: splits, then merges, then the
/// rest by group id.
template <typename PointT>
std::vector<GroupChange> OnlineGrouping<PointT>::changesOf(const std::vector<std::vector<int>>& groups,
                                                           const GroupMatch& m) const {
  std::vector<GroupChange> splits, merges, others;
  for (const auto& [old, counts] : m.to_new)
    if (counts.size() > 1) {
      GroupChange c{GroupChange::Kind::Split, old, {}, {}};
      for (const auto& [g, count] : counts) c.related.push_back(m.new_id[g]);
      std::sort(c.related.begin(), c.related.end());
      splits.push_back(std::move(c));
    }
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const int id = m.new_id[g];
    if (m.from_old[g].size() > 1) {
      GroupChange c{GroupChange::Kind::Merged, id, {}, groups[g]};
      for (const auto& [old, count] : m.from_old[g]) c.related.push_back(old);
      merges.push_back(std::move(c));
      continue;
    }
    const auto before = groups_.find(id);
    if (before == groups_.end()) {
      // Only new observations; a group split off an old one is reported as the split.
      if (m.from_old[g].empty()) others.push_back({GroupChange::Kind::Created, id, {}, groups[g]});
      continue;
    }
    if (before->second == groups[g]) continue;
    const auto& old_members = before->second;
    const bool grew = std::includes(groups[g].begin(), groups[g].end(), old_members.begin(), old_members.end());
    const bool shrank = std::includes(old_members.begin(), old_members.end(), groups[g].begin(), groups[g].end());
    if (shrank && m.to_new.at(id).size() > 1) continue;  // reported as the split
    const auto kind = grew ? GroupChange::Kind::Grown : shrank ? GroupChange::Kind::Shrunk : GroupChange::Kind::Changed;
    others.push_back({kind, id, {}, groups[g]});
  }
  for (const auto& [old, members] : groups_)
    if (!m.to_new.count(old)) others.push_back({GroupChange::Kind::Removed, old, {}, {}});
  std::sort(others.begin(), others.end(), [](const GroupChange& a, const GroupChange& b) { return a.group < b.group; });
  splits.insert(splits.end(), merges.begin(), merges.end());
  splits.insert(splits.end(), others.begin(), others.end());
  return splits;
}

template <typename PointT>
void OnlineGrouping<PointT>::assignGroupIds(const std::vector<std::vector<int>>& groups, GroupUpdate& out) {
  const GroupMatch match = matchGroups(groups);
  out.changes = changesOf(groups, match);
  groups_.clear();
  for (std::size_t g = 0; g < groups.size(); ++g) groups_[match.new_id[g]] = groups[g];
  std::fill(group_of_.begin(), group_of_.end(), -1);
  for (const auto& [id, members] : groups_)
    for (int member : members) group_of_[member] = id;
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

template <typename PointT>
int OnlineGrouping<PointT>::getGroupOf(int id) const {
  return id >= 0 && id < int(group_of_.size()) ? group_of_[id] : -1;
}

}  // namespace obsgroup

#define PCL_INSTANTIATE_OnlineGrouping(T) template class obsgroup::OnlineGrouping<T>;
