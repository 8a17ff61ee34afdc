#include "obsgroup/partition/group_tracking.h"

#include <algorithm>
#include <set>

namespace obsgroup {

StableGroupIds::Match StableGroupIds::match(const std::vector<std::vector<int>>& groups) {
  Match m;
  m.from_old.resize(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (int id : groups[g])
      if (groupOf(id) >= 0) {
        ++m.from_old[g][groupOf(id)];
        ++m.to_new[groupOf(id)][int(g)];
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
    m.new_id[g] = best >= 0 ? best : next_id_++;
  }
  return m;
}

std::vector<GroupChange> StableGroupIds::changesOf(const std::vector<std::vector<int>>& groups,
                                                   const Match& m) const {
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

std::vector<GroupChange> StableGroupIds::assign(const std::vector<std::vector<int>>& groups, std::size_t id_count) {
  group_of_.resize(std::max(group_of_.size(), id_count), -1);
  const Match m = match(groups);
  std::vector<GroupChange> changes = changesOf(groups, m);
  groups_.clear();
  for (std::size_t g = 0; g < groups.size(); ++g) groups_[m.new_id[g]] = groups[g];
  std::fill(group_of_.begin(), group_of_.end(), -1);
  for (const auto& [id, members] : groups_)
    for (int member : members) group_of_[member] = id;
  return changes;
}

Partition partitionAroundChanges(const WeightMatrix& W, const std::vector<int>& ids,
                                 const std::vector<int>& changed_ids, const StableGroupIds& current,
                                 PartitionOptions options) {
  const auto position = [&ids](int id) { return int(std::lower_bound(ids.begin(), ids.end(), id) - ids.begin()); };
  const auto present = [&ids](int id) { return std::binary_search(ids.begin(), ids.end(), id); };
  std::vector<char> in_region(ids.size(), 0);
  std::set<int> region_groups;
  for (int id : changed_ids)
    if (current.groupOf(id) >= 0) region_groups.insert(current.groupOf(id));
  for (std::size_t k = 0; k < ids.size(); ++k)
    if (current.groupOf(ids[k]) < 0) in_region[k] = 1;
  for (int g : region_groups)
    for (int id : current.groups().at(g))
      if (present(id)) in_region[position(id)] = 1;
  // ...and the groups the changed and new observations overlap. Not the
  // groups next to the whole region: where observations see far (a lab whose
  // corridor looks into every room), that is most of the map.
  std::set<int> next_to;
  const auto add_neighbours = [&](std::size_t k) {
    for (WeightMatrix::InnerIterator it(W, Eigen::Index(k)); it; ++it)
      if (!in_region[it.row()] && current.groupOf(ids[it.row()]) >= 0) next_to.insert(current.groupOf(ids[it.row()]));
  };
  for (int id : changed_ids)
    if (present(id)) add_neighbours(std::size_t(position(id)));
  for (std::size_t k = 0; k < ids.size(); ++k)
    if (current.groupOf(ids[k]) < 0) add_neighbours(k);
  for (int g : next_to)
    for (int id : current.groups().at(g))
      if (present(id)) in_region[position(id)] = 1;

  std::vector<int> region;
  for (std::size_t k = 0; k < ids.size(); ++k)
    if (in_region[k]) region.push_back(int(k));
  Partition out;
  if (!region.empty()) {
    options.keep_eigenvectors = false;
    Partition local = recursivePartition(inducedSubgraph(W, region), options);
    for (auto& group : local.groups) {
      for (int& k : group) k = region[k];
      out.groups.push_back(std::move(group));
    }
    out.warnings = std::move(local.warnings);
  }
  for (const auto& [g, members] : current.groups()) {
    std::vector<int> kept;
    for (int id : members)
      if (present(id) && !in_region[position(id)]) kept.push_back(position(id));
    if (!kept.empty()) out.groups.push_back(std::move(kept));
  }
  std::sort(out.groups.begin(), out.groups.end(), [](const auto& a, const auto& b) { return a.front() < b.front(); });
  out.group_of.assign(ids.size(), -1);
  for (std::size_t g = 0; g < out.groups.size(); ++g)
    for (int k : out.groups[g]) out.group_of[k] = int(g);
  return out;
}

}  // namespace obsgroup
