// The whole method on maps whose answer is known: the paper's Fig. 3
// situation, and invariance of the result to the thread count.
#include "test_support.h"

#include <obsgroup/observation_grouping.h>
#include <obsgroup/common/parallel_for.h>
#include <obsgroup/partition/keyframes.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <cstring>

using namespace obsgroup;

namespace {

/// Every observation exactly once, groups ordered by their first member, and
/// each accepted split's children partition their parent.
void expectWellFormed(const Partition& p, int n) {
  std::vector<int> seen(n, 0);
  int previous_first = -1;
  for (const auto& g : p.groups) {
    ASSERT_FALSE(g.empty());
    EXPECT_TRUE(std::is_sorted(g.begin(), g.end()));
    EXPECT_GT(g.front(), previous_first);
    previous_first = g.front();
    for (int i : g) ++seen[i];
  }
  for (int i = 0; i < n; ++i) EXPECT_EQ(seen[i], 1) << "observation " << i;
  for (const SplitNode& node : p.splits) {
    if (!node.accepted) {
      EXPECT_TRUE(node.children.empty());
      continue;
    }
    std::vector<int> united;
    for (int c : node.children) {
      EXPECT_EQ(p.splits[c].parent, &node - p.splits.data());
      united.insert(united.end(), p.splits[c].members.begin(), p.splits[c].members.end());
    }
    std::sort(united.begin(), united.end());
    EXPECT_EQ(united, node.members);
  }
}

template <typename PointT>
Partition groupScans(ObservationGrouping<PointT>& grouping, const std::vector<Observation<PointT>>& obs) {
  for (const auto& o : obs) grouping.addObservation(o.cloud, o.pose);
  return grouping.compute();
}

}  // namespace

TEST(RecursivePartition, ThreeRoomsJoinedByDoorsGiveThreeGroups) {
  // Fig. 3: scans in three rooms joined by doors are split into the rooms.
  const auto plan = sim::threeRooms();
  const auto poses = sim::threeRoomsPoses(5);
  sim::LaserModel laser;
  laser.field_of_view = 2 * 3.14159265358979;
  laser.beams = 360;
  laser.range_noise = 0.01;
  ObservationGrouping<pcl::PointXYZ> grouping;
  const Partition p = groupScans(grouping, test::simulate<pcl::PointXYZ>(plan, poses, laser));
  expectWellFormed(p, 15);
  ASSERT_EQ(p.groups.size(), 3u);
  for (int room = 0; room < 3; ++room) {
    std::vector<int> expected;
    for (int k = 0; k < 5; ++k) expected.push_back(room * 5 + k);
    EXPECT_EQ(p.groups[room], expected);
    for (int i : expected) EXPECT_EQ(plan.roomAt(poses[i].x, poses[i].y), room);
  }
  // The root splits one room off and the rest again, as {G1} and {G2, G3}.
  ASSERT_EQ(p.splits[0].kind, SplitNode::Kind::Bisection);
  EXPECT_LT(p.splits[0].ncut, 1.0);
  EXPECT_EQ(p.splits[0].eigenvector.size(), 15);
  // Every group's own best split is rejected: Ncut >= 1.
  for (const SplitNode& node : p.splits) {
    if (!node.accepted) {
      EXPECT_GE(node.ncut, 1.0);
    }
  }
}

TEST(RecursivePartition, SimulatedOfficeIsWellFormedForEveryCriterion) {
  const auto plan = sim::office();
  const auto obs = test::simulate<pcl::PointXYZ>(plan, sim::officeRoute(77));
  for (SplitCriterion c : {SplitCriterion::Mean, SplitCriterion::Sign, SplitCriterion::BestNcut}) {
    ObservationGrouping<pcl::PointXYZ> grouping;
    grouping.setSplitCriterion(c);
    const Partition p = groupScans(grouping, obs);
    expectWellFormed(p, 77);
    EXPECT_GT(p.groups.size(), 4u) << toString(c);
    EXPECT_LT(p.groups.size(), 40u) << toString(c);
  }
}

TEST(RecursivePartition, ThreadCountDoesNotChangeWOrThePartition) {
  const auto obs = test::realLog();
  ASSERT_EQ(obs.size(), 72u);
  ObservationGrouping<pcl::PointXYZ> one, two;
  one.setNumberOfThreads(1);
  two.setNumberOfThreads(2);
  const Partition a = groupScans(one, obs);
  const Partition b = groupScans(two, obs);
  const WeightMatrix& wa = one.getWeightMatrix();
  const WeightMatrix& wb = two.getWeightMatrix();
  ASSERT_EQ(wa.nonZeros(), wb.nonZeros());
  EXPECT_EQ(std::memcmp(wa.valuePtr(), wb.valuePtr(), sizeof(double) * wa.nonZeros()), 0);
  EXPECT_EQ(std::memcmp(wa.innerIndexPtr(), wb.innerIndexPtr(), sizeof(int) * wa.nonZeros()), 0);
  EXPECT_EQ(a.groups, b.groups);
  ASSERT_EQ(a.splits.size(), b.splits.size());
  for (std::size_t s = 0; s < a.splits.size(); ++s) {
    EXPECT_EQ(a.splits[s].members, b.splits[s].members);
    if (a.splits[s].attempted) {
      EXPECT_EQ(a.splits[s].ncut, b.splits[s].ncut);
    }
  }
  expectWellFormed(a, 72);
}

TEST(RecursivePartition, ACallFromInsideTheCallersOwnThreadsGivesTheSamePartition) {
  // A program may partition several graphs at once on its own OpenMP
  // threads; the levels of one node then run on the caller's thread.
  const auto obs = test::realLog();
  ObservationGrouping<pcl::PointXYZ> grouping;
  const Partition expected = groupScans(grouping, obs);
  const WeightMatrix& W = grouping.getWeightMatrix();
  PartitionOptions options = grouping.getParameters().partitionOptions();
  const Partition direct = recursivePartition(W, options);
  ASSERT_EQ(direct.groups, expected.groups);
  for (int threads : {1, 2}) {
    options.threads = threads;
    std::vector<Partition> inside(4);
#pragma omp parallel for num_threads(4)
    for (int k = 0; k < 4; ++k) inside[std::size_t(k)] = recursivePartition(W, options);
    for (const Partition& p : inside) EXPECT_EQ(p.groups, expected.groups) << "threads " << threads;
  }
}

namespace {

/// The groups of a `{"observations": N, "groups": [[...], ...]}` file.
std::vector<std::vector<int>> readGroups(const std::string& path) {
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::vector<int>> groups;
  std::size_t k = text.find("\"groups\"");
  if (k == std::string::npos) return groups;
  int depth = 0;
  for (k = text.find('[', k); k < text.size(); ++k) {
    const char c = text[k];
    if (c == '[' && ++depth == 2) groups.emplace_back();
    if (c == ']' && --depth == 0) break;
    if (std::isdigit(static_cast<unsigned char>(c)) && depth == 2) {
      std::size_t used = 0;
      groups.back().push_back(std::stoi(text.substr(k), &used));
      k += used - 1;
    }
  }
  return groups;
}

}  // namespace

TEST(RecursivePartition, RealOfficeLogRefinesMrptsGroups) {
  // MRPT's map-partition (delta 0.2, threshold 0.9) finds 6 groups on this log.
  // Its Ncut counts within-group weight once, so its values are higher than
  // eq. (1)'s and it splits less: the faithful method finds finer groups that
  // nest inside MRPT's, up to scans on the boundaries between them.
  const auto obs = test::realLog();
  ASSERT_EQ(obs.size(), 72u);
  const auto mrpt = readGroups(std::string(OBSGROUP_DATA_DIR) + "/real/localization_demo/groups_mrpt.json");
  ASSERT_EQ(mrpt.size(), 6u);
  std::vector<int> mrpt_group(72, -1);
  for (std::size_t g = 0; g < mrpt.size(); ++g)
    for (int i : mrpt[g]) mrpt_group.at(i) = static_cast<int>(g);

  ObservationGrouping<pcl::PointXYZ> grouping;
  grouping.usePaperMethod();  // MRPT implements the paper's points model and mean split
  grouping.setMatchDistance(0.2);
  const Partition p = groupScans(grouping, obs);
  expectWellFormed(p, 72);
  EXPECT_GE(p.groups.size(), mrpt.size());
  // Purity: the share of scans whose group's majority MRPT group is their own.
  int agreeing = 0;
  for (const auto& g : p.groups) {
    std::vector<int> votes(mrpt.size(), 0);
    for (int i : g) ++votes[mrpt_group[i]];
    agreeing += *std::max_element(votes.begin(), votes.end());
  }
  EXPECT_GE(agreeing, 0.85 * 72) << agreeing << " of 72 scans agree";
}

// The boundary refinement (PartitionOptions::boundary_passes) on a graph
// whose answer is known: a large room A (observations 0-9, a clique of weight
// 1), a small room B (10-12, the same) and a doorway observation 13 that
// overlaps each of A's members at 0.3 and each of B's at 0.5. Ncut sums the
// weights, so the tree keeps it with A (cut 1.5 against 3.0); by its mean
// overlap (0.3 against 0.5) it belongs to B, and the refinement moves it.
TEST(RecursivePartition, BoundaryRefinementMovesAnObservationToTheGroupItOverlapsMostOnAverage) {
  std::vector<WeightedPair> pairs;
  for (auto [first, last] : {std::pair<int, int>{0, 10}, std::pair<int, int>{10, 13}})
    for (int i = first; i < last; ++i)
      for (int j = i + 1; j < last; ++j) pairs.push_back({i, j, 1.0});
  for (int i = 0; i < 10; ++i) pairs.push_back({i, 13, 0.3});
  for (int i = 10; i < 13; ++i) pairs.push_back({i, 13, 0.5});
  const WeightMatrix W = buildWeightMatrix(14, pairs);
  PartitionOptions options;
  options.split = SplitCriterion::BestNcut;
  options.ncut_threshold = 0.7;
  const Partition tree = recursivePartition(W, options);
  ASSERT_EQ(tree.groups.size(), 2u);
  EXPECT_EQ(tree.group_of[13], tree.group_of[0]);
  options.boundary_passes = 3;
  for (int threads : {1, 2}) {
    options.threads = threads;
    const Partition refined = recursivePartition(W, options);
    ASSERT_EQ(refined.groups.size(), 2u);
    EXPECT_EQ(refined.groups[0], std::vector<int>({0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
    EXPECT_EQ(refined.groups[1], std::vector<int>({10, 11, 12, 13}));
    EXPECT_EQ(refined.splits.size(), tree.splits.size());  // the tree is kept as it was
  }
  options.boundary_passes = -1;
  EXPECT_THROW(recursivePartition(W, options), std::invalid_argument);
}

/// The boundary refinement by its definition: every sweep decides every
/// observation from the previous sweep's groups (mean weight to each group,
/// its own without it; ties stay, else the lower group), no minimum size.
std::vector<int> refinedByDefinition(const WeightMatrix& W, std::vector<int> group_of, int groups, int passes) {
  const int n = int(W.rows());
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<int> size(std::size_t(groups), 0);
    for (int g : group_of) ++size[std::size_t(g)];
    std::vector<int> next = group_of;
    for (int i = 0; i < n; ++i) {
      std::vector<double> sum(std::size_t(groups), 0.0);
      for (WeightMatrix::InnerIterator it(W, i); it; ++it)
        if (it.row() != i) sum[std::size_t(group_of[std::size_t(it.row())])] += it.value();
      const int own = group_of[std::size_t(i)];
      int best = own;
      double best_mean = size[std::size_t(own)] > 1 ? sum[std::size_t(own)] / (size[std::size_t(own)] - 1) : 0.0;
      for (int g = 0; g < groups; ++g)
        if (g != own && sum[std::size_t(g)] > 0.0 && sum[std::size_t(g)] / size[std::size_t(g)] > best_mean)
          best = g, best_mean = sum[std::size_t(g)] / size[std::size_t(g)];
      next[std::size_t(i)] = best;
    }
    if (next == group_of) break;
    group_of = std::move(next);
  }
  return group_of;
}

TEST(RecursivePartition, BoundaryRefinementEqualsItsDefinitionOnAnyThreadCount) {
  // 120 rooms of 25 observations in a row (3,000: the sweeps run in blocks
  // on every thread), each observation overlapping its own room, and some
  // the next room more on average, so that observations move over several
  // sweeps. The refinement, which visits again only the observations whose
  // choice can change, must give what full sweeps give.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> weight(0.2, 1.0);
  std::vector<WeightedPair> pairs;
  const int rooms = 120, per_room = 25, n = rooms * per_room;
  for (int r = 0; r < rooms; ++r)
    for (int a = 0; a < per_room; ++a)
      for (int b = a + 1; b < per_room; ++b)
        if (weight(rng) > 0.5) pairs.push_back({r * per_room + a, r * per_room + b, weight(rng)});
  for (int r = 0; r + 1 < rooms; ++r)
    for (int a = per_room - 6; a < per_room; ++a)
      for (int b = 0; b < 6; ++b) pairs.push_back({r * per_room + a, (r + 1) * per_room + b, 0.6 * weight(rng)});
  const WeightMatrix W = buildWeightMatrix(n, pairs);
  PartitionOptions options;
  options.mutual_neighbours = 0;
  options.boundary_passes = 0;
  const Partition tree = recursivePartition(W, options);
  ASSERT_GT(tree.groups.size(), 10u);
  const std::vector<int> expected = refinedByDefinition(W, tree.group_of, int(tree.groups.size()), 3);
  ASSERT_NE(expected, tree.group_of);  // observations do move
  options.boundary_passes = 3;
  for (int threads : {1, 2}) {
    options.threads = threads;
    const Partition refined = recursivePartition(W, options);
    // The same membership; the groups are renumbered by their first member.
    std::vector<std::vector<int>> by_definition(tree.groups.size());
    for (int i = 0; i < n; ++i) by_definition[std::size_t(expected[std::size_t(i)])].push_back(i);
    by_definition.erase(std::remove_if(by_definition.begin(), by_definition.end(),
                                       [](const std::vector<int>& g) { return g.empty(); }),
                        by_definition.end());
    std::sort(by_definition.begin(), by_definition.end());
    EXPECT_EQ(refined.groups, by_definition) << threads << " threads";
  }
}

// The refinement keeps the minimum group size the tree guarantees.
TEST(RecursivePartition, BoundaryRefinementKeepsTheMinimumGroupSize) {
  const auto obs = test::realLog();
  for (int min_size : {2, 4, 6}) {
    ObservationGrouping<pcl::PointXYZ> grouping;
    grouping.setMinGroupSize(min_size);
    ASSERT_GT(grouping.getBoundaryPasses(), 0);
    const Partition p = groupScans(grouping, obs);
    ASSERT_GT(p.groups.size(), 1u);
    for (const auto& g : p.groups) EXPECT_GE(int(g.size()), min_size) << "minimum " << min_size;
    expectWellFormed(p, int(obs.size()));
  }
}

// Three rooms in a row, weakly joined: a new link from room A to room C
// changes the rows of one node in each, but the block of W of the node
// holding B and C only where A's node is: told that node 0 is the source,
// the cache copies B and C's node and its children, and the tree is still
// the one computed from scratch, to the bit.
TEST(RecursivePartition, TheSplitCacheCopiesTheNodesThatHoldNoSourceOfAChange) {
  const auto rooms = [](double a_to_c) {
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < 24; ++i)
      for (int j = 0; j < 24; ++j) {
        if (i == j) continue;
        const int ri = i / 8, rj = j / 8;
        const double w = ri == rj ? 1.0 - 0.01 * ((i + j) % 5) : std::abs(ri - rj) == 1 ? 0.02 : 0.0;
        if (w > 0) t.emplace_back(i, j, w);
      }
    t.emplace_back(0, 20, a_to_c);
    t.emplace_back(20, 0, a_to_c);
    WeightMatrix W(24, 24);
    W.setFromTriplets(t.begin(), t.end());
    return W;
  };
  PartitionOptions options;
  options.min_group_size = 1;
  std::vector<int> ids(24);
  for (int i = 0; i < 24; ++i) ids[i] = i;
  const std::vector<char> none(24, 0);
  SplitCache by_rows, by_sources;
  recursivePartition(rooms(0.0), options, ids, none, by_rows);
  recursivePartition(rooms(0.0), options, ids, none, none, by_sources);
  std::vector<char> changed(24, 0), sources(24, 0);
  changed[0] = changed[20] = 1;
  sources[0] = 1;
  const WeightMatrix W = rooms(0.01);
  const Partition fresh = recursivePartition(W, options);
  const Partition rows = recursivePartition(W, options, ids, changed, by_rows);
  const Partition from_sources = recursivePartition(W, options, ids, changed, sources, by_sources);
  ASSERT_EQ(fresh.groups.size(), 3u);
  for (const Partition* p : {&rows, &from_sources}) {
    EXPECT_EQ(p->groups, fresh.groups);
    ASSERT_EQ(p->splits.size(), fresh.splits.size());
    for (std::size_t k = 0; k < fresh.splits.size(); ++k) {
      EXPECT_EQ(p->splits[k].members, fresh.splits[k].members);
      EXPECT_EQ(p->splits[k].accepted, fresh.splits[k].accepted);
      EXPECT_EQ(0, std::memcmp(&p->splits[k].ncut, &fresh.splits[k].ncut, sizeof(double))) << "node " << k;
      EXPECT_EQ(0, std::memcmp(&p->splits[k].threshold, &fresh.splits[k].threshold, sizeof(double))) << "node " << k;
    }
  }
  EXPECT_GT(by_sources.reusedNodes(), by_rows.reusedNodes());
  EXPECT_LT(by_sources.computedNodes(), by_rows.computedNodes());
}

// Two rooms, A and B, split at the root; then a third room C, linked to B
// more weakly than A is, is added. The new root splits C off, and the node
// holding A and B, with its children, moves a level down: the same members
// and the same block of W, so their decisions are copied from the previous
// tree, where they stood a level higher, and the tree is still the one
// computed from scratch, to the bit, depths included.
TEST(RecursivePartition, TheSplitCacheCopiesNodesThatMovedToAnotherDepth) {
  const auto rooms = [](int count) {
    std::vector<WeightedPair> pairs;
    for (int i = 0; i < 8 * count; ++i)
      for (int j = i + 1; j < 8 * count; ++j) {
        const int ri = i / 8, rj = j / 8;
        const double w = ri == rj ? 1.0 - 0.01 * ((i + j) % 5) : (ri + rj == 1 ? 0.05 : (ri + rj == 3 ? 0.005 : 0.0));
        if (w > 0) pairs.push_back({i, j, w});
      }
    return buildWeightMatrix(8 * count, pairs);
  };
  PartitionOptions options;
  options.min_group_size = 1;
  std::vector<int> ids(24);
  for (int i = 0; i < 24; ++i) ids[std::size_t(i)] = i;
  SplitCache cache;
  const std::vector<int> first_ids(ids.begin(), ids.begin() + 16);
  const std::vector<char> none(16, 0);
  const Partition before = recursivePartition(rooms(2), options, first_ids, none, cache);
  ASSERT_EQ(before.groups.size(), 2u);
  ASSERT_EQ(before.splits.size(), 3u);
  EXPECT_EQ(before.splits[1].depth, 1);
  std::vector<char> changed(24, 0), sources(24, 0);
  for (int i = 8; i < 24; ++i) changed[std::size_t(i)] = 1;  // B's rows gain C's entries
  for (int i = 16; i < 24; ++i) sources[std::size_t(i)] = 1;
  const WeightMatrix W = rooms(3);
  const Partition fresh = recursivePartition(W, options);
  const Partition cached = recursivePartition(W, options, ids, changed, sources, cache);
  ASSERT_EQ(fresh.groups.size(), 3u);
  EXPECT_EQ(cached.groups, fresh.groups);
  ASSERT_EQ(cached.splits.size(), fresh.splits.size());
  for (std::size_t k = 0; k < fresh.splits.size(); ++k) {
    EXPECT_EQ(cached.splits[k].members, fresh.splits[k].members) << "node " << k;
    EXPECT_EQ(cached.splits[k].depth, fresh.splits[k].depth) << "node " << k;
    EXPECT_EQ(cached.splits[k].children, fresh.splits[k].children) << "node " << k;
    EXPECT_EQ(0, std::memcmp(&cached.splits[k].ncut, &fresh.splits[k].ncut, sizeof(double))) << "node " << k;
  }
  // A and B's node, the root before, now stands at depth 1 (A and B at depth 2, at 1 before).
  const std::vector<int> a_and_b(ids.begin(), ids.begin() + 16);
  const auto moved = std::find_if(fresh.splits.begin(), fresh.splits.end(),
                                  [&](const SplitNode& node) { return node.members == a_and_b; });
  ASSERT_NE(moved, fresh.splits.end());
  EXPECT_EQ(moved->depth, 1);
  EXPECT_EQ(cache.reusedNodes(), 3u);   // A and B's node, A, B
  EXPECT_EQ(cache.computedNodes(), 2u);  // the new root and C

  // Where the depth limit reaches, a node's depth decides it: A and B's
  // node a level down is a group, not the split it was at the root.
  options.max_depth = 1;
  SplitCache limited;
  recursivePartition(rooms(2), options, first_ids, none, limited);
  const Partition limited_fresh = recursivePartition(W, options);
  const Partition limited_cached = recursivePartition(W, options, ids, changed, sources, limited);
  ASSERT_EQ(limited_fresh.groups.size(), 2u);
  EXPECT_EQ(limited_cached.groups, limited_fresh.groups);
  ASSERT_EQ(limited_cached.splits.size(), limited_fresh.splits.size());
  for (std::size_t k = 0; k < limited_fresh.splits.size(); ++k)
    EXPECT_EQ(limited_cached.splits[k].outcome, limited_fresh.splits[k].outcome) << "node " << k;
}

TEST(RecursivePartition, MutualNeighboursSeparateASmallRoomFromACorridorDrivenManyTimes) {
  // A corridor of 120 scans, each overlapping the 40 on either side (a
  // corridor driven again and again), and a room of 8 scans looked into from
  // it: each room scan overlaps its 7 mates strongly and 60 corridor scans
  // a little, which adds up to more than the room's own. Cut from W, the
  // room's Ncut is above the threshold and it stays with the corridor; no
  // corridor scan counts a room scan among its 20 nearest, so on the
  // mutual-neighbour graph the room stands alone.
  std::vector<WeightedPair> pairs;
  for (int i = 0; i < 120; ++i)
    for (int j = i + 1; j <= std::min(119, i + 40); ++j) pairs.push_back({i, j, 0.9 - 0.02 * (j - i)});
  for (int a = 120; a < 128; ++a) {
    for (int b = a + 1; b < 128; ++b) pairs.push_back({a, b, 0.95});
    for (int c = 30; c < 90; ++c) pairs.push_back({c, a, 0.35});
  }
  const WeightMatrix W = buildWeightMatrix(128, pairs);
  const std::vector<int> room{120, 121, 122, 123, 124, 125, 126, 127};
  const auto hasRoom = [&](const Partition& p) { return std::find(p.groups.begin(), p.groups.end(), room) != p.groups.end(); };
  PartitionOptions options = GroupingParameters{}.partitionOptions();
  options.mutual_neighbours = 0;
  const Partition every_overlap = recursivePartition(W, options);
  expectWellFormed(every_overlap, 128);
  EXPECT_FALSE(hasRoom(every_overlap));
  options.mutual_neighbours = 20;
  options.mutual_neighbours_share = 0.0;
  const Partition mutual = recursivePartition(W, options);
  expectWellFormed(mutual, 128);
  EXPECT_TRUE(hasRoom(mutual));
  // The share of the median number of neighbours (80 here) raises k: at 0.5,
  // k = 40, and the corridor scans still rank the room's below their 40.
  options.mutual_neighbours_share = 0.5;
  EXPECT_TRUE(hasRoom(recursivePartition(W, options)));
  options.mutual_neighbours = -1;
  EXPECT_THROW(recursivePartition(W, options), std::invalid_argument);
}

TEST(RecursivePartition, TheSplitCacheFollowsTheMutualNeighboursOfAGrowingGraph) {
  // Appending nodes to a chain moves the neighbour thresholds of the nodes
  // next to them (and k, with the median): a node whose threshold moved is
  // solved again even where no entry of its row changed in W.
  PartitionOptions options = GroupingParameters{}.partitionOptions();
  options.mutual_neighbours = 3;
  options.mutual_neighbours_share = 0.4;
  SplitCache cache;
  std::vector<WeightedPair> pairs;
  for (int n = 2; n <= 60; ++n) {
    const int added = n - 1;
    for (int j = std::max(0, added - 8); j < added; ++j)
      pairs.push_back({j, added, 0.9 - 0.05 * (added - j) + 0.01 * ((added * 7 + j) % 3)});
    const WeightMatrix W = buildWeightMatrix(n, pairs);
    std::vector<int> ids(n);
    for (int i = 0; i < n; ++i) ids[i] = i;
    std::vector<char> changed(n, 0), sources(n, 0);
    for (int j = std::max(0, added - 8); j <= added; ++j) changed[j] = 1;
    sources[added] = 1;
    const Partition fresh = recursivePartition(W, options);
    const Partition cached = recursivePartition(W, options, ids, changed, sources, cache);
    ASSERT_EQ(cached.groups, fresh.groups) << n << " nodes";
    ASSERT_EQ(cached.splits.size(), fresh.splits.size()) << n << " nodes";
    for (std::size_t k = 0; k < fresh.splits.size(); ++k)
      ASSERT_EQ(0, std::memcmp(&cached.splits[k].ncut, &fresh.splits[k].ncut, sizeof(double))) << n << " nodes, node " << k;
  }
  EXPECT_GT(cache.reusedNodes(), 0u);
}

TEST(RecursivePartition, NodesSolvedAheadOfTheirLevelGiveTheDecisionsOfOneThread) {
  // Rooms of six scans along a corridor, one scan at a time, as a robot
  // drives: every insert changes the nodes on the path from the root to its
  // group, and two threads solve the path's lower nodes ahead, from the
  // previous tree. Each node's decision must be the one a single thread (which
  // solves nothing ahead) and a run from scratch give, to the bit, including
  // where the guess was wrong (a room that starts after the previous run).
  std::vector<WeightedPair> pairs;
  const auto roomOf = [](int i) { return i / 6; };
  PartitionOptions options = GroupingParameters{}.partitionOptions();
  options.min_group_size = 2;
  SplitCache one_thread, two_threads;
  std::size_t ahead_nodes = 0, ahead_used = 0, groups = 0;
  for (int n = 2; n <= 96; ++n) {
    const int added = n - 1;
    for (int j = std::max(0, added - 12); j < added; ++j) {
      const bool same_room = roomOf(j) == roomOf(added);
      const double w = same_room ? 0.8 + 0.01 * ((added * 5 + j) % 7) : 0.05 / (1 + roomOf(added) - roomOf(j));
      pairs.push_back({j, added, w});
    }
    const WeightMatrix W = buildWeightMatrix(n, pairs);
    std::vector<int> ids(n);
    for (int i = 0; i < n; ++i) ids[i] = i;
    std::vector<char> changed(n, 0), sources(n, 0);
    for (int j = std::max(0, added - 12); j <= added; ++j) changed[j] = 1;
    sources[added] = 1;
    const Partition fresh = recursivePartition(W, options);
    options.threads = 1;
    const Partition single = recursivePartition(W, options, ids, changed, sources, one_thread);
    options.threads = 2;
    const Partition ahead = recursivePartition(W, options, ids, changed, sources, two_threads);
    for (const Partition* p : {&single, &ahead}) {
      ASSERT_EQ(p->groups, fresh.groups) << n << " nodes";
      ASSERT_EQ(p->splits.size(), fresh.splits.size()) << n << " nodes";
      for (std::size_t k = 0; k < fresh.splits.size(); ++k) {
        ASSERT_EQ(p->splits[k].members, fresh.splits[k].members) << n << " nodes, node " << k;
        ASSERT_EQ(p->splits[k].depth, fresh.splits[k].depth) << n << " nodes, node " << k;
        ASSERT_EQ(0, std::memcmp(&p->splits[k].ncut, &fresh.splits[k].ncut, sizeof(double))) << n << " nodes, node " << k;
        ASSERT_EQ(0, std::memcmp(&p->splits[k].eigenvalue, &fresh.splits[k].eigenvalue, sizeof(double)))
            << n << " nodes, node " << k;
      }
    }
    EXPECT_EQ(one_thread.aheadNodes(), 0u);
    ahead_nodes += two_threads.aheadNodes();
    ahead_used += two_threads.aheadNodesUsed();
    groups = fresh.groups.size();
  }
  EXPECT_EQ(groups, 16u);
  if (threadCount(2) > 1) {  // built with OpenMP: two threads solve ahead
    EXPECT_GT(ahead_used, 0u);
    EXPECT_LT(ahead_used, ahead_nodes);  // some guesses were wrong, and nothing showed it
  }
}

TEST(Keyframes, AFrameIsAKeyframeWhenItMovedOrTurnedEnoughSinceTheLast) {
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k < 8; ++k) poses.push_back(pose2D(0.04 * k, 0.0, 0.0));  // 4 cm a frame
  EXPECT_EQ(selectKeyframes(poses, {0.1, 90.0}), (std::vector<int>{0, 0, 0, 3, 3, 3, 6, 6}));
  std::vector<Eigen::Isometry3d> turning;
  for (int k = 0; k < 7; ++k) turning.push_back(pose2D(1.0, 2.0, k * 2.0 * M_PI / 180.0));  // 2 degrees a frame
  EXPECT_EQ(selectKeyframes(turning, {1.0, 5.0}), (std::vector<int>{0, 0, 0, 3, 3, 3, 6}));
  EXPECT_EQ(selectKeyframes(turning, {0.0, 0.0}), (std::vector<int>{0, 1, 2, 3, 4, 5, 6}));  // every frame
  EXPECT_EQ(keyframesOf({0, 0, 0, 3, 3, 3, 6}), (std::vector<int>{0, 3, 6}));
  EXPECT_TRUE(selectKeyframes({}, {0.1, 5.0}).empty());
  EXPECT_THROW(selectKeyframes(poses, {-0.1, 5.0}), std::invalid_argument);
  EXPECT_THROW(selectKeyframes(poses, {0.1, std::nan("")}), std::invalid_argument);
}

TEST(Keyframes, EveryFrameTakesTheGroupOfItsKeyframe) {
  // Frames 0..5, keyframes 0, 2, 3; the keyframes grouped {0, 2} (frames 0 and 3) and {1} (frame 2).
  const std::vector<int> keyframe_of{0, 0, 2, 3, 3, 3};
  Partition of_keyframes;
  of_keyframes.groups = {{0, 2}, {1}};
  of_keyframes.group_of = {0, 1, 0};
  SplitNode root;
  root.members = {0, 1, 2};
  root.eigenvector = Eigen::VectorXd::Ones(3);
  of_keyframes.splits = {root};
  of_keyframes.warnings = {"kept"};
  const Partition every = expandKeyframePartition(of_keyframes, keyframe_of);
  EXPECT_EQ(every.groups, (std::vector<std::vector<int>>{{0, 1, 3, 4, 5}, {2}}));
  EXPECT_EQ(every.group_of, (std::vector<int>{0, 0, 1, 0, 0, 0}));
  ASSERT_EQ(every.splits.size(), 1u);
  EXPECT_EQ(every.splits[0].members, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(every.splits[0].eigenvector.size(), 0);
  EXPECT_EQ(every.warnings, of_keyframes.warnings);
}
