#pragma once
// The online half of `obsgroup stream`: the observations inserted one at a
// time into an OnlineGrouping, the groups updated every N inserts and each
// change printed as it happens, optionally at the pace of the log's stamps.

#include "grouping_outcome.h"
#include "partition_command.h"
#include "replay_clock.h"

#include <obsgroup/common/invalid_observation.h>
#include <obsgroup/common/parallel_for.h>
#include <obsgroup/io/errors.h>
#include <obsgroup/online_grouping.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

namespace obsgroup::cli {

/// "group 7 grown (12 observations)", "group 3 split into 3 9", ...
inline std::string describeChange(const GroupChange& change) {
  std::string text = "group " + std::to_string(change.group) + " " + toString(change.kind);
  if (change.kind == GroupChange::Kind::Split || change.kind == GroupChange::Kind::Merged) {
    text += change.kind == GroupChange::Kind::Split ? " into" : " from";
    for (int g : change.related) text += " " + std::to_string(g);
  }
  const std::size_t n = change.members.size();
  if (n > 0) text += " (" + std::to_string(n) + " observation" + (n == 1 ? "" : "s") + ")";
  return text;
}

/// The observations' points in the common frame, as the batch keeps them
/// (the places and the pictures draw on them).
template <typename PointT>
void addWorldPoints(const std::vector<Observation<PointT>>& observations, GroupingOutcome<PointT>& out) {
  out.world_points = out.grouping.getSensedSpaceOverlap().toWorld(observations);
  for (int i = 0; i < out.world_points.size(); ++i) out.points_per_observation.push_back(out.world_points.count(i));
}

/// Edges of W: the pairs i < j that overlap (the batch's OverlapResult::pairs).
inline std::size_t edgeCount(const WeightMatrix& W) {
  std::size_t edges = 0;
  for (int j = 0; j < W.outerSize(); ++j)
    for (WeightMatrix::InnerIterator it(W, j); it; ++it)
      if (it.row() < it.col() && it.value() > 0) ++edges;
  return edges;
}

/// What the updates of a stream did, summed.
struct StreamTotals {
  std::size_t updates = 0, observations_recomputed = 0, split_nodes_reused = 0, split_nodes_computed = 0,
              split_nodes_ahead = 0;
  double online_s = 0.0;  ///< inserts and updates, waits excluded
};

/// "observation 35: place 2", and in the same line what the update did to
/// other places: "(new place)", "(places 0 and 2 merged into 2)", "(place 3
/// split into 3 and 14)". Ids are the online grouping's stable ids, those of
/// partition.json's place_ids.
inline std::string observationLine(int id, int place, const std::vector<GroupChange>& changes) {
  const auto joined = [](const std::vector<int>& ids) {
    std::string text;
    for (std::size_t k = 0; k < ids.size(); ++k)
      text += (k == 0 ? "" : k + 1 == ids.size() ? " and " : ", ") + std::to_string(ids[k]);
    return text;
  };
  std::string line = "observation " + std::to_string(id) + ": place " + std::to_string(place);
  std::vector<std::string> notes;
  for (const GroupChange& c : changes) {
    if (c.kind == GroupChange::Kind::Created && c.group == place) notes.push_back("new place");
    if (c.kind == GroupChange::Kind::Merged)
      notes.push_back("places " + joined(c.related) + " merged into " + std::to_string(c.group));
    if (c.kind == GroupChange::Kind::Split)
      notes.push_back("place " + std::to_string(c.group) + " split into " + joined(c.related));
  }
  for (std::size_t k = 0; k < notes.size(); ++k) line += (k == 0 ? " (" : "; ") + notes[k];
  return line + (notes.empty() ? "" : ")");
}

/// One update; on stdout (unless quiet) one line per observation inserted
/// since the last update, saying its place, or with `verbose` every change
/// (named after the observation just inserted).
template <typename PointT>
void updateAndPrint(OnlineGrouping<PointT>& online, int first_id, int last_id, bool last, bool quiet, bool verbose,
                    StreamTotals& totals, std::vector<int>& printed_place) {
  // The last update is exact whatever --exact-every says: the outputs are the batch's.
  const GroupUpdate update = last ? online.updateExact() : online.update();
  ++totals.updates;
  totals.observations_recomputed += update.observations_recomputed;
  totals.split_nodes_reused += update.split_nodes_reused;
  totals.split_nodes_computed += update.split_nodes_computed;
  totals.split_nodes_ahead += update.split_nodes_ahead;
  if (quiet) return;
  if (verbose) {
    for (const GroupChange& change : update.changes)
      std::printf("observation %d: %s\n", last_id, describeChange(change).c_str());
  } else {
    for (int id = first_id; id <= last_id; ++id) {
      const int place = online.getGroupOf(id);
      std::printf("%s\n", observationLine(id, place, id == last_id ? update.changes : std::vector<GroupChange>{}).c_str());
      printed_place.resize(std::max(printed_place.size(), std::size_t(id) + 1), -1);
      printed_place[std::size_t(id)] = place;
    }
  }
  std::fflush(stdout);  // seen as it happens, on a pipe too
}

/// Inserts every observation in input order, updating every `update_every`
/// inserts and after the last. Throws io::InputError naming the input line
/// of an observation the online grouping refuses, as `partition` does.
template <typename PointT>
StreamTotals replay(const PartitionArgs& args, OnlineGrouping<PointT>& online,
                    const std::vector<Observation<PointT>>& observations, const std::vector<std::string>& labels,
                    ReplayClock& clock) {
  StreamTotals totals;
  const std::size_t every = static_cast<std::size_t>(args.stream->update_every);
  int first_since_update = 0;
  std::vector<int> printed_place;  // the place each observation's line gave
  for (std::size_t k = 0; k < observations.size(); ++k) {
    clock.waitFor(k);
    const auto start = ReplayClock::Clock::now();
    throwIfInterrupted(args.interrupt);
    try {
      const int id = online.insert(observations[k].cloud, observations[k].pose);
      const bool last = k + 1 == observations.size();
      if ((k + 1) % every == 0 || last) {
        updateAndPrint(online, first_since_update, id, last, args.quiet, args.stream->verbose, totals, printed_place);
        first_since_update = id + 1;
      }
    } catch (const InvalidObservation& e) {
      throw io::InputError(labels.at(e.index()) + ": " + e.what());  // ids are input positions: none is removed
    } catch (const std::invalid_argument& e) {
      throw io::InputError(args.input + ": " + e.what());
    }
    totals.online_s += std::chrono::duration<double>(ReplayClock::Clock::now() - start).count();
  }
  // Later updates moved some observations to other places: say where they
  // ended, so that each observation's last line gives its place in the results.
  for (std::size_t id = 0; id < printed_place.size(); ++id)
    if (printed_place[id] >= 0 && online.getGroupOf(int(id)) != printed_place[id])
      std::printf("observation %zu: place %d (moved since)\n", id, online.getGroupOf(int(id)));
  std::fflush(stdout);
  return totals;
}

/// Groups the observations online; the result is the batch's (OnlineGrouping
/// is exact), with the statistics the online run measures.
template <typename PointT>
void streamObservations(const PartitionArgs& args, const std::vector<Observation<PointT>>& observations,
                        const std::vector<std::string>& labels, const std::vector<double>& stamps,
                        GroupingOutcome<PointT>& out) {
  OnlineGrouping<PointT> online;
  online.setParameters(out.grouping.getParameters());
  online.setInterruptFlag(args.interrupt);
  online.setExactInterval(args.stream->exact_every);
  ReplayClock clock(args.stream->realtime ? &stamps : nullptr, args.interrupt);
  const StreamTotals totals = replay(args, online, observations, labels, clock);
  out.online = true;
  out.partition = online.getPartition();
  const std::vector<int> ids = online.getIds();
  for (const auto& group : out.partition.groups) out.place_ids.push_back(online.getGroupOf(ids[group.front()]));
  out.W = online.getWeightMatrix();
  const auto start = ReplayClock::Clock::now();
  addWorldPoints(observations, out);
  const std::size_t edges = edgeCount(out.W);
  // The online overlap counts neither the pairs it tests nor the point
  // tests: pairs_evaluated is the edges (each was evaluated at least once),
  // point_tests 0 (not counted); the rest is measured.
  out.statistics = {{"pairs_evaluated", edges},
                    {"point_tests", 0},
                    {"edges", edges},
                    {"updates", totals.updates},
                    {"observations_recomputed", totals.observations_recomputed},
                    {"split_nodes_reused", totals.split_nodes_reused},
                    {"split_nodes_computed", totals.split_nodes_computed},
                    {"split_nodes_ahead", totals.split_nodes_ahead},
                    {"open_floor_joins", online.getOpenFloorJoins().size()}};
  const double world_s = std::chrono::duration<double>(ReplayClock::Clock::now() - start).count();
  out.timing_s = {{"stream", totals.online_s}, {"world_points", world_s}};
  if (args.stream->realtime) out.timing_s["realtime_wait"] = clock.waitedSeconds();
  out.parameters = {{"mode", "stream"},
                    {"update_every", args.stream->update_every},
                    {"exact_every", args.stream->exact_every},
                    {"realtime", args.stream->realtime}};
}

}  // namespace obsgroup::cli
