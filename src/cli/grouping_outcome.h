#pragma once
// What the steps after grouping (local maps, pictures, partition.json) take
// from a grouping, so that `partition` (ObservationGrouping::compute) and
// `stream` (OnlineGrouping, one update per insert) share them.

#include <obsgroup/observation_grouping.h>
#include <obsgroup/places/place_map.h>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <future>
#include <optional>
#include <vector>

namespace obsgroup::cli {

template <typename PointT>
struct GroupingOutcome {
  /// The method's parameters (both modes set them here; `stream` copies them
  /// into its OnlineGrouping). After a batch run, also its results.
  ObservationGrouping<PointT> grouping;
  Partition partition;
  /// The place id of each group of `partition` (places.json, partition.json's place_ids).
  std::vector<int> place_ids;
  /// The stream's W (the batch's stays in `grouping`: weights() gives either).
  WeightMatrix W;
  /// Points of each observation after filtering, as the overlap counts them.
  std::vector<std::size_t> points_per_observation;
  /// The observations' points in the common frame for the places and the
  /// pictures (SensedSpaceOverlap::toWorld): the stream's, made after its
  /// last update; the batch's, made again for the places (the grouping does
  /// not keep its own through the partition: they are as large as the clouds).
  WorldPoints world_points;
  bool online = false;
  /// pairs_evaluated, point_tests, edges, and what else the mode measures.
  nlohmann::json statistics = nlohmann::json::object();
  /// Seconds of the grouping's own stages.
  nlohmann::json timing_s = nlohmann::json::object();
  /// What partition.json records of the mode besides the method's parameters.
  nlohmann::json parameters = nlohmann::json::object();

  /// The places' floor evidence, once taken from `floor` or made (the places
  /// are cut twice when passages join groups).
  std::optional<FloorEvidence> floor_evidence;
  /// The regions the places read when the grouping kept none (stream, points model).
  ObservationRegions computed_regions;
  /// The places of `partition`, made before the local maps when passages
  /// may join groups; else made with the outputs.
  std::optional<PlaceMap> places;

  /// The places' pass over every beam (observeFloor), made on a thread of
  /// its own while a batch run partitions; not valid otherwise. Last, so
  /// that it is destroyed, waiting for the pass, before `grouping`, whose
  /// regions it reads.
  std::future<FloorEvidence> floor;

  const WorldPoints& world() const { return world_points; }
  const WeightMatrix& weights() const { return online ? W : grouping.getWeightMatrix(); }
};

}  // namespace obsgroup::cli
