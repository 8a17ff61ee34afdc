#pragma once
/// \file
/// What the online grouping needs beyond a partition: group ids that stay
/// put while observations come and go, the changes between two partitions,
/// and the local re-partition of OnlineGrouping::setExactInterval. None of
/// it depends on the point type.

#include "obsgroup/common/enum_names.h"
#include "obsgroup/graph/observation_graph.h"
#include "obsgroup/partition/recursive_partitioner.h"

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace obsgroup {

/// One change of the groups made by OnlineGrouping::update().
struct GroupChange {
  enum class Kind {
    Created,  ///< A new group of observations that were in no group (new ones).
    Grown,    ///< The group kept its id and gained observations.
    Shrunk,   ///< The group kept its id and lost observations.
    Changed,  ///< The group kept its id, gained some observations and lost others.
    Split,    ///< `group`'s observations now lie in the groups `related` (one may still be `group`).
    Merged,   ///< `group` now holds observations of the groups `related` (one may be `group` itself).
    Removed   ///< The group is gone: its observations were removed.
  };
  Kind kind = Kind::Created;
  int group = -1;
  std::vector<int> related;
  std::vector<int> members;  ///< The group's observations after the change (empty for Removed, Split).
};

inline constexpr EnumName<GroupChange::Kind> kGroupChangeNames[] = {
    {GroupChange::Kind::Created, "created"}, {GroupChange::Kind::Grown, "grown"},
    {GroupChange::Kind::Shrunk, "shrunk"},   {GroupChange::Kind::Changed, "changed"},
    {GroupChange::Kind::Split, "split"},     {GroupChange::Kind::Merged, "merged"},
    {GroupChange::Kind::Removed, "removed"}};
inline std::string toString(GroupChange::Kind kind) { return nameOf(kGroupChangeNames, kind); }

/// What one OnlineGrouping::update() did.
struct GroupUpdate {
  std::vector<GroupChange> changes;  ///< Split and Merged first, then the rest, each by group id.
  /// True when the partition was computed exactly (equal to compute()); false
  /// for a local update (OnlineGrouping::setExactInterval).
  bool exact = true;
  std::size_t observations_recomputed = 0;  ///< Observations whose overlaps were recomputed.
  std::size_t split_nodes_reused = 0;       ///< Nodes of the split tree copied from the last update.
  std::size_t split_nodes_computed = 0;     ///< Nodes solved anew by an exact update (0 for a local one).
  /// Nodes solved ahead of their level on another thread (SplitCache::aheadNodes), whether the update
  /// then met them or not: those it met are among split_nodes_computed, the others were guessed wrong.
  std::size_t split_nodes_ahead = 0;
};

/// Group ids that survive re-partitions: a group whose members did not
/// change keeps its id, and a group that changed keeps the id of the old
/// group it holds most of (when that old group gave it its largest share);
/// any other group gets a new id, never reused.
class StableGroupIds {
 public:
  /// Takes the new groups (observation ids, each ascending, every id below
  /// `id_count`), gives each its id and returns the changes from the last
  /// groups: splits, then merges, then the rest by group id.
  std::vector<GroupChange> assign(const std::vector<std::vector<int>>& groups, std::size_t id_count);
  /// Group id -> member ids, ascending.
  const std::map<int, std::vector<int>>& groups() const { return groups_; }
  /// The group of an observation id (-1: none yet).
  int groupOf(int id) const { return id >= 0 && id < int(group_of_.size()) ? group_of_[id] : -1; }

 private:
  struct Match {
    std::vector<std::map<int, int>> from_old;  // new group -> old id -> members it took
    std::map<int, std::map<int, int>> to_new;  // old id -> new group -> members it gave
    std::vector<int> new_id;                   // the id of each new group
  };
  Match match(const std::vector<std::vector<int>>& groups);
  std::vector<GroupChange> changesOf(const std::vector<std::vector<int>>& groups, const Match& m) const;

  std::map<int, std::vector<int>> groups_;
  std::vector<int> group_of_;  // by id
  int next_id_ = 0;
};

/// The local update of OnlineGrouping::setExactInterval: the groups of
/// `current` holding an observation of `changed_ids` (those inserted, moved or
/// removed), the observations in no group yet and the groups these
/// observations overlap in W are re-partitioned on their own (with
/// `options`); the other groups are kept. W is over the positions
/// of `ids` (the observation ids present, ascending). The partition returned
/// is over those positions, with no split tree.
Partition partitionAroundChanges(const WeightMatrix& W, const std::vector<int>& ids,
                                 const std::vector<int>& changed_ids, const StableGroupIds& current,
                                 PartitionOptions options);

}  // namespace obsgroup
