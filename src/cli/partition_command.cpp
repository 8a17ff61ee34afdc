#include "partition_command.h"

#include <obsgroup/io/depth_sequence.h>
#include <obsgroup/io/errors.h>
#include <obsgroup/io/input_file.h>
#include <obsgroup/io/kitti_sequence.h>
#include <obsgroup/io/ros_bag.h>
#include "local_maps.h"
#include "output_folder.h"
#include "place_outputs.h"
#include <obsgroup/io/pcd_sequence.h>
#include "pictures.h"
#include "group_colours.h"
#include "report.h"
#include "grouping_outcome.h"
#include "progress_bar.h"
#include "result_writers.h"
#include "stream_grouping.h"

#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/maps/topological_map.h>
#include <obsgroup/common/freed_memory.h>
#include <obsgroup/common/parallel_for.h>
#include <obsgroup/observation_grouping.h>
#include <obsgroup/io/pose_file.h>
#include <obsgroup/places/localize.h>
#include <obsgroup/partition/keyframes.h>
#include <obsgroup/places/place_map.h>

#include <omp.h>
#include <sys/stat.h>
#include <unistd.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <unordered_map>

namespace obsgroup::cli {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

std::string detectFormat(const PartitionArgs& args) {
  namespace fs = std::filesystem;
  if (args.input == "-") {  // a log on a pipe
    if (args.format == "pcd") throw io::UsageError("-: standard input carries a CARMEN log, not a PCD sequence");
    return "carmen";
  }
  std::error_code ec;
  if (!fs::exists(args.input, ec)) throw io::InputError(args.input + ": no such file or folder");
  const bool folder = fs::is_directory(args.input, ec);
  if (args.format == "pcd" && !folder)
    throw io::UsageError(args.input + ": --format pcd needs a folder of .pcd files");
  if (args.format == "carmen" && folder) throw io::UsageError(args.input + ": --format carmen needs a log file");
  if (args.format == "ros1" && folder) throw io::UsageError(args.input + ": --format ros1 needs a .bag file");
  const bool db3 = fs::path(args.input).extension() == ".db3";
  if (args.format != "auto" && args.format != "carmen" && args.format != "ros1" && !(args.format == "ros2" && db3) &&
      !folder)
    throw io::UsageError(args.input + ": --format " + args.format + " needs a folder");
  if (args.format != "auto") return args.format;
  if (const auto bag = io::detectBag(args.input)) return io::toString(*bag);
  if (folder) {
    if (const auto layout = io::detectDepthLayout(args.input)) return io::toString(*layout);
    if (io::isKittiFolder(args.input) || (args.poses && fs::is_directory(fs::path(args.input) / "velodyne", ec)))
      return "kitti";
    return "pcd";
  }
  if (fs::path(args.input).extension() == ".bag")
    throw io::InputError(args.input + ": not a ROS 1 bag (it does not start with \"#ROSBAG V2.0\"; ROS 1 bags of "
                         "format 1.2 or older: migrate them with rosbag fix)");
  if (fs::path(args.input).extension() == ".pcd")
    throw io::UsageError(args.input + ": a single PCD file; give the folder holding the sequence");
  return "carmen";
}

void checkOptionsFit(const PartitionArgs& args, const std::string& format) {
  if (format == "carmen" && args.poses) throw io::UsageError("--poses applies to PCD sequences, depth images, KITTI and bags");
  const bool depth = format == "tum-rgbd" || format == "redwood";
  if (!depth && (args.intrinsics || args.depth_scale || args.depth_max || args.stride || args.up))
    throw io::UsageError("--intrinsics, --depth-scale, --depth-max, --stride and --up apply to depth images only");
  const bool bag = format == "ros1" || format == "ros2";
  if (format != "pcd" && format != "tum-rgbd" && !bag && args.max_time_difference)
    throw io::UsageError("--max-time-difference applies to TUM poses matched by timestamp (tum-rgbd, pcd, bags)");
  if (bag && args.max_time_difference && !args.poses)
    throw io::UsageError("--max-time-difference applies to a bag with --poses (TUM poses matched by timestamp)");
  if (format != "pcd" && args.pose_format)
    throw io::UsageError("--pose-format applies to PCD sequences (depth images and KITTI have their own)");
  if (format != "carmen" && (args.laser != io::LaserSource::Auto || args.field_of_view_deg || args.max_range))
    throw io::UsageError("--laser, --fov and --max-range apply to CARMEN logs only");
  if (format != "carmen" && args.skip_bad_lines) throw io::UsageError("--skip-bad-lines applies to CARMEN logs only");
  if (args.skip_bad_files && format != "pcd" && format != "tum-rgbd" && format != "redwood" && format != "kitti")
    throw io::UsageError("--skip-bad-files applies to folders of files: PCD sequences, depth images and KITTI");
  if (!bag && (args.topic || args.pose_topic || args.fixed_frame))
    throw io::UsageError("--topic, --pose-topic and --fixed-frame apply to ROS bags only");
  if (args.pose_topic && args.fixed_frame)
    throw io::UsageError("--fixed-frame applies to poses from /tf; a --pose-topic gives its own frame");
}

/// Warnings go to stderr as they happen and into partition.json.
class Warnings {
 public:
  explicit Warnings(bool quiet) : quiet_(quiet) {}
  void operator()(const std::string& message) {
    if (!quiet_) std::fprintf(stderr, "obsgroup: warning: %s\n", message.c_str());
    all_.push_back(message);
  }
  const std::vector<std::string>& all() const { return all_; }

 private:
  bool quiet_;
  std::vector<std::string> all_;
};

/// How the readers of dense inputs reduce each frame: at --voxel when given,
/// else dense frames at the default leaf; the bar counts the frames read.
io::FrameReading frameReduction(const PartitionArgs& args, ProgressBar& bar) {
  io::FrameReading reduction = args.voxel ? io::FrameReading{*args.voxel, 0, {}, false} : io::FrameReading::denseDefault();
  reduction.skip_bad_files = args.skip_bad_files;
  reduction.progress = [&bar](std::size_t done, std::size_t total) { bar(done, total); };
  return reduction;
}

/// What partition.json records of the reduction: the leaf and how many frames it filtered.
void recordReduction(const io::FrameReading& reduction, std::size_t reduced, nlohmann::json& parameters) {
  parameters["frame_voxel"] = reduction.voxel_leaf;
  parameters["frame_voxel_min_points"] = reduction.min_points;
  parameters["frames_reduced"] = reduced;
}

template <typename PointT>
std::vector<Eigen::Isometry3d> posesOf(const std::vector<Observation<PointT>>& observations) {
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(observations.size());
  for (const auto& o : observations) poses.push_back(o.pose);
  return poses;
}

/// Each sensor's position re-centred on `world_origin`, as the world points are.
template <typename PointT>
std::vector<Eigen::Vector3d> sensorOrigins(const std::vector<Observation<PointT>>& observations,
                                           const Eigen::Vector3d& world_origin) {
  std::vector<Eigen::Vector3d> origins;
  origins.reserve(observations.size());
  for (const auto& o : observations) origins.push_back(o.pose.translation() - world_origin);
  return origins;
}

template <typename PointT>
std::vector<Eigen::Vector3d> sensorOrigins(const std::vector<Observation<PointT>>& observations,
                                           const WorldPoints& world) {
  return sensorOrigins(observations, world.origin);
}

/// The method's parameters, for the batch and the online grouping alike.
template <typename PointT>
void configureGrouping(const PartitionArgs& args, ObservationGrouping<PointT>& grouping) {
  grouping.setInterruptFlag(args.interrupt);
  grouping.setParameters(args.method);
  grouping.setKeepRegions(true);         // the places are cut from these
  grouping.setKeepOverlapMatrix(false);  // W is all the rest needs
}

/// The places' options of the run.
PlaceOptions placeOptions(const PartitionArgs& args) {
  PlaceOptions options;
  options.band_low = args.method.regions.band_low;
  options.band_high = args.method.regions.band_high;
  return options;
}

/// Observation i's points in the common frame, made when the places ask.
template <typename PointT>
PlacePointSource pointsOnDemand(const SensedSpaceOverlap<PointT>& sso,
                                const std::vector<Observation<PointT>>& observations,
                                const Eigen::Vector3d& origin) {
  return [&sso, &observations, origin](int i, std::vector<Eigen::Vector3f>& scratch) {
    scratch = sso.observationToWorld(observations[std::size_t(i)], origin);
    return std::make_pair(scratch.data(), scratch.data() + scratch.size());
  };
}

/// Groups the observations at once: the overlap, W and the partition (sec. II-III).
template <typename PointT>
void groupObservations(const PartitionArgs& args, const std::vector<Observation<PointT>>& observations,
                       const InputRecord& input, GroupingOutcome<PointT>& out) {
  ObservationGrouping<PointT>& grouping = out.grouping;
  for (const auto& o : observations) grouping.addObservation(o.cloud, o.pose);
  // The places' pass over every beam needs the regions alone: it runs on a
  // thread of its own while the partition, whose first levels keep one core
  // busy, is computed; with one thread asked for, after it.
  const auto observeFloorNow = [&args, &observations, &out](const ObservationRegions& regions) {
    if (regions.size() != int(observations.size())) return;  // the points model: the places compute their own
    out.floor = std::async(std::launch::async, [&args, &observations, &regions,
                                                sso = out.grouping.getSensedSpaceOverlap()] {
      const Eigen::Vector3d origin = SensedSpaceOverlap<PointT>::worldOrigin(observations);
      return observeFloor(regions, origin, pointsOnDemand(sso, observations, origin),
                          sensorOrigins(observations, origin), placeOptions(args), 1, args.interrupt);
    });
  };
  if (threadCount(args.method.threads) > 1) grouping.setRegionsCallback(observeFloorNow);
  ProgressBar bar("overlap", !args.quiet, args.progress);
  grouping.setProgressCallback([&bar](std::size_t done, std::size_t total) { bar(done, total); });
  try {
    out.partition = grouping.compute();
  } catch (const InvalidObservation& e) {
    throw io::InputError(input.labels[e.index()] + ": " + e.what());
  } catch (const std::invalid_argument& e) {
    throw io::InputError(args.input + ": " + e.what());
  }
  bar.finish();
  for (std::size_t g = 0; g < out.partition.groups.size(); ++g) out.place_ids.push_back(int(g));
  const auto& overlap = grouping.getOverlap();
  out.points_per_observation = overlap.points_per_observation;
  // The back-ends count ordered pairs (i, j) and (j, i) alike (each row is
  // matched on its own); a user counts a pair once.
  out.statistics = {{"pairs_evaluated", overlap.pairs_evaluated / 2},
                    {"point_tests", overlap.point_tests},
                    {"edges", edgeCount(out.weights())},
                    {"open_floor_joins", grouping.getOpenFloorJoins().size()}};
  const auto& t = grouping.getTimings();
  out.timing_s = {{"overlap", t.overlap_s}, {"graph", t.graph_s}, {"partition", t.partition_s}};
}

/// The grouping's warnings. The core's name observation indices; the user
/// knows lines and files. The readers already warned about empty clouds.
template <typename PointT>
void warnAboutGrouping(const std::vector<Observation<PointT>>& observations, const InputRecord& input,
                       const GroupingOutcome<PointT>& out, Warnings& warn) {
  const auto& points_per_observation = out.points_per_observation;
  for (std::size_t i = 0; i < points_per_observation.size(); ++i)
    if (points_per_observation[i] == 0 && !observations[i].cloud->empty())
      warn(input.labels[i] + ": only NaN/Inf points; kept as a group of its own");
  for (const auto& w : out.partition.warnings) warn(w);
}

template <typename PointT>
struct MapsOfRun {
  std::vector<LocalMap<PointT>> maps;
  TopologicalMap topology;
  RefinementReport refinement;  ///< summed over the maps: one line for the run, not one per map
  double voxel = 0.0;
  double seconds = 0.0;
};

/// The local maps (refined as asked) and the topological map over them.
template <typename PointT>
MapsOfRun<PointT> buildMaps(const PartitionArgs& args, const std::vector<Observation<PointT>>& observations,
                            const Partition& partition, const WeightMatrix& W, Warnings& warn) {
  const auto start = Clock::now();
  MapsOfRun<PointT> run;
  LocalMapBuilder<PointT> builder;
  builder.setRefinement(args.refine);
  run.voxel = args.map_voxel.value_or(args.method.match_distance / 2);
  builder.setVoxelLeafSize(run.voxel);
  builder.setNumberOfThreads(args.method.threads);
  builder.setInterruptFlag(args.interrupt);
  ProgressBar bar("local maps", !args.quiet, args.progress);
  builder.setProgressCallback([&bar](std::size_t done, std::size_t total) { bar(done, total); });
  run.maps = builder.build(observations, partition, W);
  bar.finish();
  std::vector<LocalMapFrame> frames;
  for (std::size_t g = 0; g < run.maps.size(); ++g) {
    frames.push_back(run.maps[g].frame);
    if (!run.maps[g].filtered)
      warn("local map " + std::to_string(g) + ": too large for a " + std::to_string(run.voxel) +
           " m voxel filter; written unfiltered");
    run.refinement += run.maps[g].refinement;
  }
  if (!run.refinement.warning().empty())
    warn("refinement: " + run.refinement.warning() + " (see partition.json: statistics.refinement)");
  run.topology = buildTopologicalMap(std::move(frames), W, posesOf(observations), args.method.threads);
  run.seconds = secondsSince(start);
  return run;
}

/// map.png/.svg, weights.png, fiedler.png and a picture per local map.
template <typename PointT>
void drawPictures(const PartitionArgs& args, const io::OutputFolder& out, const GroupingOutcome<PointT>& grouped,
                  const std::vector<Observation<PointT>>& observations, const MapsOfRun<PointT>& maps,
                  const ObservationRegions& regions, const PlaceMap* places) {
  // The points and regions as the grouping saw them, at the input poses;
  // map.png draws each observation at its refined pose.
  const WorldPoints& world = grouped.world();
  const Partition& partition = grouped.partition;
  const bool tinted = args.method.model != SensedSpaceModel::Points;
  // Staged with the other results, so that they appear together or not at all.
  const render::PictureWriter staged = [&out](const std::string& name,
                                              const std::function<void(const std::string&)>& write) {
    out.write(name, write);
  };
  // 3D input is drawn as a horizontal slice: the visibility model's band, without floor and ceiling.
  const bool planar = isPlanarData(world, sensorOrigins(observations, world), args.method.regions.cell_size);
  const render::HeightBand band{args.method.regions.band_low, args.method.regions.band_high};
  const render::HeightBand* slice = planar ? nullptr : &band;
  ProgressBar bar("pictures", !args.quiet, args.progress);
  bar(0, 4);
  render::writeMapPictures(staged, world, posesOf(observations),
                           globalPoses(maps.topology, observations.size()), partition, maps.topology,
                           tinted ? &regions : nullptr, places, slice);
  bar(1, 4);
  render::writeWeightsPicture(staged, grouped.weights(), partition);
  bar(2, 4);
  render::writeFiedlerPicture(staged, partition);
  bar(3, 4);
  render::writeLocalMapPictures(staged, maps.maps, args.method.threads, render::groupColours(maps.topology), slice);
  bar(4, 4);
}

/// The settings the grouping ran with, as partition.json records them: only
/// those its model uses.
nlohmann::json methodParameters(const GroupingParameters& method, const PartitionArgs& args, double map_voxel) {
  nlohmann::json p;
  p["sso"] = toString(method.model);
  if (method.model == SensedSpaceModel::Points) {
    p["delta"] = method.match_distance;
    p["neighbour_search"] = method.neighbour_search == NeighbourSearch::SharedGrid ? "shared_grid" : "pcl_search";
  } else {
    p["cell"] = method.regions.cell_size;
    p["range"] = method.regions.max_range;
    if (method.model == SensedSpaceModel::Visibility) {
      p["clearance"] = method.regions.clearance;
      p["min_observations"] = method.regions.min_observations;
      p["band"] = {method.regions.band_low, method.regions.band_high};
      p["door_width"] = method.regions.door_width;
      p["door_depth"] = method.regions.door_depth;
      p["open_floor_width"] = method.open_floor_width;
      p["join_passages"] = method.join_passages;
    }
  }
  p["voxel"] = method.voxel_leaf;
  p["ncut_threshold"] = method.ncut_threshold;
  p["split"] = toString(method.split);
  p["boundary_passes"] = method.boundary_passes;
  p["mutual_neighbours"] = method.mutual_neighbours;
  p["mutual_neighbours_share"] = method.mutual_neighbours_share;
  p["min_group_size"] = method.min_group_size;
  p["max_depth"] = method.max_depth == GroupingParameters{}.max_depth ? nlohmann::json() : nlohmann::json(method.max_depth);
  p["diagonal"] = method.diagonal_weight;
  p["map_voxel"] = map_voxel;
  p["refine"] = toString(args.refine);
  p["correct_odometry"] = toString(args.correct_odometry);
  return p;
}

/// Seconds spent writing, pictures included.
struct OutputTimes {
  double outputs_s = 0.0, pictures_s = 0.0, places_s = 0.0;
  std::size_t map_points = 0;
  /// The places as report.html shows them (null: none were made), kept so
  /// that the page need not read places.json back (10 MB at 100,100 scans).
  nlohmann::json place_outlines;
};

/// The sensed regions the places are cut from: the grouping's own, or for
/// the points model (which has none) those of the visibility model's defaults.
template <typename PointT>
ObservationRegions regionsOfRun(const PartitionArgs& args, const GroupingOutcome<PointT>& grouped,
                                const std::vector<Observation<PointT>>& observations) {
  if (args.method.model != SensedSpaceModel::Points)
    return grouped.grouping.getSensedSpaceOverlap().computeRegions(observations, grouped.world());
  return computeRegions(SensedSpaceModel::Visibility, grouped.world(), sensorOrigins(observations, grouped.world()),
                        RegionParameters{}, args.method.threads, args.interrupt);
}

/// The regions the places read: the grouping's own when it kept them
/// (partition), else computed once (stream, points model).
template <typename PointT>
const ObservationRegions& regionsForPlaces(const PartitionArgs& args, GroupingOutcome<PointT>& grouped,
                                          const std::vector<Observation<PointT>>& observations) {
  const ObservationRegions& kept = grouped.grouping.getRegions();
  if (kept.size() == int(observations.size())) return kept;
  if (grouped.computed_regions.size() != int(observations.size())) {
    if (grouped.world_points.size() != int(observations.size()))
      grouped.world_points = grouped.grouping.getSensedSpaceOverlap().toWorld(observations);
    grouped.computed_regions = regionsOfRun(args, grouped, observations);
  }
  return grouped.computed_regions;
}

/// The places of the run's groups (grouped.partition, grouped.place_ids):
/// those made before the local maps when they stand, else cut now. The
/// pass over the beams is made once (or taken from the partition's thread).
/// Throws std::invalid_argument as buildPlaceMap does.
template <typename PointT>
PlaceMap placesOfRun(const PartitionArgs& args, GroupingOutcome<PointT>& grouped,
                     const std::vector<Observation<PointT>>& observations) {
  if (grouped.places) {
    PlaceMap made = std::move(*grouped.places);
    grouped.places.reset();
    return made;
  }
  const ObservationRegions& regions = regionsForPlaces(args, grouped, observations);
  const PlaceOptions options = placeOptions(args);
  const Eigen::Vector3d origin = SensedSpaceOverlap<PointT>::worldOrigin(observations);
  if (!grouped.floor_evidence) {
    if (grouped.floor.valid()) {  // the pass over the beams, made while the partition ran
      grouped.floor_evidence = grouped.floor.get();
    } else if (grouped.world_points.size() == int(observations.size())) {
      const WorldPoints& world = grouped.world();
      const PlacePointSource points_of = [&world](int i, std::vector<Eigen::Vector3f>&) {
        return std::make_pair(world.begin(i), world.end(i));
      };
      grouped.floor_evidence = observeFloor(regions, world.origin, points_of, sensorOrigins(observations, world),
                                            options, args.method.threads, args.interrupt);
    } else {
      const auto& sso = grouped.grouping.getSensedSpaceOverlap();
      grouped.floor_evidence = observeFloor(regions, origin, pointsOnDemand(sso, observations, origin),
                                            sensorOrigins(observations, origin), options, args.method.threads,
                                            args.interrupt);
    }
  }
  return buildPlaceMap(regions, *grouped.floor_evidence, sensorOrigins(observations, origin),
                       grouped.partition.groups, grouped.place_ids, options);
}

/// Joins the groups whose places meet through a passage (a corridor cut
/// across, not a door: joinThroughPassages), before the local maps are made
/// of them; the places of the joined groups are cut again. Visibility model
/// only. Places that cannot be cut join nothing (the outputs say why).
template <typename PointT>
void joinPassages(const PartitionArgs& args, GroupingOutcome<PointT>& grouped,
                  const std::vector<Observation<PointT>>& observations) {
  grouped.statistics["passage_joins"] = 0;
  if (!args.method.join_passages || args.method.model != SensedSpaceModel::Visibility || observations.empty()) return;
  const auto start = Clock::now();
  try {
    PlaceMap places = placesOfRun(args, grouped, observations);
    std::vector<int> before(grouped.partition.group_of.size());  // each observation's place id
    for (std::size_t g = 0; g < grouped.partition.groups.size(); ++g)
      for (int i : grouped.partition.groups[g]) before[std::size_t(i)] = grouped.place_ids[g];
    const std::vector<Door> joined = joinThroughPassages(grouped.partition, grouped.place_ids, places);
    grouped.statistics["passage_joins"] = joined.size();
    if (joined.empty()) {
      grouped.places = std::move(places);
    } else {
      if (grouped.online) {
        // Each observation's last line gives its place in the results.
        std::unordered_map<int, int> joined_into;  // place id before -> after
        for (std::size_t g = 0; g < grouped.partition.groups.size(); ++g)
          for (int i : grouped.partition.groups[g]) joined_into[before[std::size_t(i)]] = grouped.place_ids[g];
        for (std::size_t i = 0; i < before.size(); ++i)
          if (joined_into.at(before[i]) != before[i] && !args.quiet)
            std::printf("observation %zu: place %d (joined through a passage)\n", i, joined_into.at(before[i]));
        std::fflush(stdout);
      } else {
        std::iota(grouped.place_ids.begin(), grouped.place_ids.end(), 0);  // a batch run's place ids are its group indices
      }
      grouped.places = placesOfRun(args, grouped, observations);
    }
  } catch (const std::invalid_argument&) {
    grouped.places.reset();  // writeResults tries again and says why
  }
  grouped.floor_evidence.reset();  // in the places now: not held through the local maps
  grouped.timing_s["passages"] = secondsSince(start);
}

/// places.json/.geojson, the label map and the occupancy map; with more
/// than one thread, the GeoJSON and the occupancy map on a second one.
void writePlaces(const io::OutputFolder& out, const PlaceMap& places, Warnings& warn, int threads) {
  const auto writeSecondHalf = [&out, &places] {
    out.writeText("places.geojson", io::placesGeoJson(places));
    out.write("occupancy.pgm", [&places](const std::string& path) { io::writeOccupancyPgm(path, places); });
    out.writeText("occupancy.yaml", io::mapYaml(places, "occupancy.pgm", "trinary"));
  };
  std::future<void> second_half;
  if (threadCount(threads) > 1)
    second_half = std::async(std::launch::async, writeSecondHalf);
  else
    writeSecondHalf();
  out.writeText("places.json", io::placesJson(places));
  int largest = -1;
  for (const Place& place : places.places) largest = std::max(largest, place.id);
  if (largest + 1 <= 65535) {
    out.write("places.png", [&places](const std::string& path) { io::writePlaceLabels(path, places); });
    out.writeText("places.yaml", io::mapYaml(places, "places.png", "raw"));
  } else {
    // A long stream never reuses an id: past 65534 a 16-bit label map cannot hold them.
    warn("places.png not written: place ids reach " + std::to_string(largest) +
         ", beyond a 16-bit label map; places.json has every place");
  }
  if (second_half.valid()) second_half.get();  // rethrows what writing it threw
}

template <typename PointT>
OutputTimes writeResults(const PartitionArgs& args, const io::OutputFolder& out, GroupingOutcome<PointT>& grouped,
                         const std::vector<Observation<PointT>>& observations, MapsOfRun<PointT>& maps,
                         const Partition& of_every_frame, Warnings& warn) {
  const auto start = Clock::now();
  OutputTimes t;
  t.map_points = io::writeLocalMaps(out, maps.maps, args.method.threads);
  io::writeLabelledMap(out, maps.maps, grouped.place_ids);
  if (!args.pictures) {  // written: only the local maps' pictures would read their points again
    for (auto& map : maps.maps) map.cloud = std::make_shared<pcl::PointCloud<PointT>>();
    returnFreedMemory(kTrimBytes);
  }
  // The topology's files (about 18 MB of JSON at 100,100 scans) are
  // written on a thread of their own while the places are cut, whose
  // later steps use one core: the same files, in less time.
  const auto writeTopology = [&out, &maps] {
    out.writeText("topology.json", io::topologyJson(maps.topology));
    out.writeText("topology.dot", io::topologyDot(maps.topology));
    out.writeText("local_maps/poses.txt", io::localMapPosesTum(maps.topology));
  };
  std::future<void> topology_written;
  if (threadCount(args.method.threads) > 1)
    topology_written = std::async(std::launch::async, writeTopology);
  else
    writeTopology();
  const auto places_start = Clock::now();
  ProgressBar bar("places", !args.quiet, args.progress);
  bar(0, 2);
  if (args.pictures && grouped.world_points.size() != int(observations.size()))
    grouped.world_points = grouped.grouping.getSensedSpaceOverlap().toWorld(observations);
  bar(1, 2);
  std::optional<PlaceMap> places;
  try {
    places = placesOfRun(args, grouped, observations);
  } catch (const std::invalid_argument& e) {
    // The groups and local maps stand without them.
    warn(std::string("places not written: ") + e.what());
  }
  grouped.floor_evidence.reset();
  returnFreedMemory(kTrimBytes);
  if (places) {
    PlaceMap written = *places;  // with keyframes, each place's members are all the frames of its keyframes
    std::unordered_map<int, std::size_t> group_of_place;  // a million scans make 50,000 places: no scan of all per place
    for (std::size_t g = 0; g < grouped.place_ids.size(); ++g) group_of_place.emplace(grouped.place_ids[g], g);
    for (Place& place : written.places)
      if (const auto g = group_of_place.find(place.id); g != group_of_place.end())
        place.members = of_every_frame.groups[g->second];
    writePlaces(out, written, warn, args.method.threads);
    t.place_outlines = io::placeOutlinesJson(written);
  }
  bar(2, 2);
  bar.finish();
  t.places_s = secondsSince(places_start);
  if (topology_written.valid()) topology_written.get();  // rethrows what writing them threw
  if (args.pictures) {
    const auto pictures_start = Clock::now();
    drawPictures(args, out, grouped, observations, maps, regionsForPlaces(args, grouped, observations),
                 places ? &*places : nullptr);
    t.pictures_s = secondsSince(pictures_start);
  }
  grouped.computed_regions = ObservationRegions{};
  grouped.world_points = WorldPoints{};  // nothing after needs them
  returnFreedMemory(kTrimBytes);
  t.outputs_s = secondsSince(start);
  return t;
}

/// report.html, from the run's record, its places and the local-map
/// pictures staged so far (inside the page up to kReportPictureBytes in
/// all; beyond, linked beside it, so that a run of thousands of places does
/// not make a page of hundreds of megabytes).
constexpr std::size_t kReportPictureBytes = 24u << 20;

/// What the page shows of partition.json, made from the same values rather
/// than read back (16 MB of JSON at 100,100 scans).
nlohmann::json reportRecord(const Partition& of_every_frame, const io::RunRecord& run) {
  return {{"input", run.input},
          {"observations", of_every_frame.group_of.size()},
          {"groups", of_every_frame.groups},
          {"place_ids", run.place_ids},
          {"stamps", run.stamps.empty() ? nlohmann::json() : nlohmann::json(run.stamps)},
          {"parameters", run.parameters},
          {"statistics", run.statistics},
          {"timing_s", run.timing_s},
          {"warnings", run.warnings}};
}

template <typename PointT>
void writeReport(const PartitionArgs& args, const io::OutputFolder& out, const Partition& of_every_frame,
                 const io::RunRecord& run, const OutputTimes& written, const GroupingOutcome<PointT>& grouped,
                 const std::vector<Observation<PointT>>& observations, const MapsOfRun<PointT>& maps) {
  ReportInput report;
  report.partition = reportRecord(of_every_frame, run);
  report.places = written.place_outlines;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const Eigen::Vector3d t = observations[i].pose.translation();
    report.positions.push_back({t.x(), t.y(), grouped.partition.group_of[i]});
  }
  const std::vector<int> colours = render::groupColours(maps.topology);
  for (int c : colours) report.colours.push_back(render::paletteHex(c));
  report.pictures.resize(colours.size());
  if (args.pictures) {
    std::vector<std::string> bytes(colours.size());
    std::size_t total = 0;
    for (std::size_t g = 0; g < colours.size(); ++g) {
      char name[64];
      std::snprintf(name, sizeof name, "local_maps/group_%03zu.png", g);
      report.pictures[g] = name;
      if (std::ifstream file(out.path(name), std::ios::binary); file)
        total += (bytes[g] = std::string(std::istreambuf_iterator<char>(file), {})).size();
    }
    if (total <= kReportPictureBytes)
      for (std::size_t g = 0; g < colours.size(); ++g)
        report.pictures[g] = bytes[g].empty() ? std::string() : pngDataUri(bytes[g]);
  }
  out.writeText("report.html", reportHtml(report));
}

/// What partition.json records besides the groups and the split tree.
template <typename PointT>
io::RunRecord runRecord(const PartitionArgs& args, const InputRecord& input, const GroupingOutcome<PointT>& grouped,
                        const MapsOfRun<PointT>& maps, const OutputTimes& written, const Warnings& warn) {
  std::size_t points = 0;
  for (std::size_t m : grouped.points_per_observation) points += m;
  io::RunRecord run;
  run.input = args.input;
  run.parameters = input.parameters;
  run.parameters["format"] = input.format;
  run.parameters.update(methodParameters(grouped.grouping.getParameters(), args, maps.voxel));
  run.parameters.update(grouped.parameters);
  // Objects keep their keys sorted: the grouping's own entries fall in place.
  run.statistics = grouped.statistics;
  run.statistics.update({{"points", points},
                         {"groups", grouped.partition.groups.size()},
                         {"local_map_points", written.map_points}});
  if (args.refine != Refinement::None) {
    const RefinementReport& r = maps.refinement;
    run.statistics["refinement"] = {{"members", r.members},
                                    {"moved", r.moved},
                                    {"kept_not_better", r.kept_not_better},
                                    {"kept_beyond_bound", r.kept_beyond_bound},
                                    {"kept_unaligned", r.kept_unaligned},
                                    {"pairs", r.pairs},
                                    {"pairs_refused", r.pairs_refused},
                                    {"pairs_partial", r.pairs_partial},
                                    {"unlinked", r.unlinked}};
  }
  run.warnings = warn.all();
  run.place_ids = grouped.place_ids;
  run.sources = input.labels;
  run.stamps = input.stamps;
  run.timing_s = grouped.timing_s;
  run.timing_s.update({{"load", input.load_s},
                       {"local_maps", maps.seconds},
                       {"outputs", written.outputs_s},
                       {"pictures", written.pictures_s},
                       {"places", written.places_s},
                       {"threads", threadCount(args.method.threads)}});
  return run;
}

std::string plural(std::size_t n, const char* word) { return std::to_string(n) + " " + word + (n == 1 ? "" : "s"); }

void printWritten(const PartitionArgs& args) {
  std::fprintf(stderr, "  wrote %s (partition.json, topology.json/.dot, local_maps/%s)\n", args.output.c_str(),
               args.pictures ? ", map.png/.svg, weights.png, fiedler.png, local_maps/group_NNN.png" : "");
}

/// One line saying the poses were corrected, if they were.
void printOdometryCorrection(const io::RunRecord& run) {
  const auto& s = run.statistics;
  if (!s.contains("odometry_correction") || !s.at("odometry_correction").at("applied").get<bool>()) return;
  const auto& c = s.at("odometry_correction");
  const double blocked = c.at("corrected_blocked_share").get<double>();
  if (blocked > 0 || c.at("input_blocked_share").get<double>() > 0)
    std::fprintf(stderr,
                 "  poses corrected by scan matching: %d of %d steps changed (%.0f%% of beams through a wall, %.0f%% at "
                 "the input poses)\n",
                 c.at("matched").get<int>(), c.at("steps").get<int>(), 100 * blocked,
                 100 * c.at("input_blocked_share").get<double>());
  else
    std::fprintf(stderr, "  poses corrected by scan matching: %d of %d steps changed (map %zu cells, %zu at the input poses)\n",
                 c.at("matched").get<int>(), c.at("steps").get<int>(), c.at("corrected_map_cells").get<std::size_t>(),
                 c.at("input_map_cells").get<std::size_t>());
  // A robot's odometry calibration, as the matched steps measured it: worth telling its user.
  const auto& bias = c.at("odometry_bias");
  std::string terms;
  const auto term = [&terms](bool found, const char* format, double value) {
    if (!found) return;
    char text[64];
    std::snprintf(text, sizeof text, format, value);
    terms += (terms.empty() ? "" : ", ") + std::string(text);
  };
  const double scale = bias.at("scale").get<double>(), turn = bias.at("turn_scale").get<double>();
  term(scale != 1.0, "step lengths x %.3f", scale);
  term(bias.at("yaw_deg_per_m").get<double>() != 0.0, "heading %+.2f degrees per metre",
       bias.at("yaw_deg_per_m").get<double>());
  term(turn != 0.0, "turns x %.2f", 1 + turn);
  if (!terms.empty()) std::fprintf(stderr, "  odometry calibration the matched steps found (applied to the others): %s\n", terms.c_str());
}

void printSummary(const PartitionArgs& args, const io::RunRecord& run, std::size_t observations) {
  const auto& s = run.statistics;
  const auto& t = run.timing_s;
  std::string counted = plural(observations, "observation");
  if (s.contains("keyframes")) counted += ", " + plural(s.at("keyframes").get<std::size_t>(), "keyframe") + " grouped";
  std::fprintf(stderr,
               "obsgroup: %s (%s), %s evaluated, %zu overlapping, %s\n"
               "  load %.2f s, overlap %.2f s, graph %.2f s, partition %.2f s, local maps %.2f s, outputs %.2f s"
               " (pictures %.2f s)\n",
               counted.c_str(), plural(s.at("points").get<std::size_t>(), "point").c_str(),
               plural(s.at("pairs_evaluated").get<std::size_t>(), "pair").c_str(), s.at("edges").get<std::size_t>(),
               plural(s.at("groups").get<std::size_t>(), "group").c_str(), t.at("load").get<double>(), t.at("overlap").get<double>(),
               t.at("graph").get<double>(), t.at("partition").get<double>(), t.at("local_maps").get<double>(),
               t.at("outputs").get<double>(), t.at("pictures").get<double>());
  printOdometryCorrection(run);
  printWritten(args);
}

void printStreamSummary(const PartitionArgs& args, const io::RunRecord& run, std::size_t observations) {
  const auto& s = run.statistics;
  const auto& t = run.timing_s;
  std::fprintf(stderr,
               "obsgroup: %s (%s) streamed, %s, %zu overlapping, %s\n"
               "  load %.2f s, stream %.2f s, local maps %.2f s, outputs %.2f s (pictures %.2f s)\n",
               plural(observations, "observation").c_str(), plural(s.at("points").get<std::size_t>(), "point").c_str(),
               plural(s.at("updates").get<std::size_t>(), "update").c_str(), s.at("edges").get<std::size_t>(),
               plural(s.at("groups").get<std::size_t>(), "group").c_str(), t.at("load").get<double>(),
               t.at("stream").get<double>(), t.at("local_maps").get<double>(), t.at("outputs").get<double>(),
               t.at("pictures").get<double>());
  printOdometryCorrection(run);
  printWritten(args);
}

/// Writes `text` to `path` through a temporary file beside it, so that the
/// file is whole or absent; an existing file is replaced only with --force.
void writeFileAtomically(const std::string& path, const std::string& text) {
  // A temporary of our own beside the target (never a file the user has).
  const std::filesystem::path target(path);
  std::string temporary = (target.parent_path() / ("." + target.filename().string() + ".obsgroup-XXXXXX")).string();
  const int fd = mkstemp(temporary.data());
  if (fd < 0) throw io::InputError(path + ": cannot write here");
  const mode_t mask = umask(0);  // mkstemp makes it 0600: give it the permissions any new file gets
  umask(mask);
  fchmod(fd, 0666 & ~mask);
  bool written = true;
  for (std::size_t done = 0; done < text.size() && written;) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    written = n > 0;
    done += written ? std::size_t(n) : 0;
  }
  written = ::close(fd) == 0 && written;
  std::error_code ec;
  if (written) std::filesystem::rename(temporary, target, ec);
  if (!written || ec) {
    std::filesystem::remove(temporary, ec);
    throw io::InputError(path + ": cannot write");
  }
}

/// The local maps of an output folder, for `locate --align`: each place's
/// map cloud and its reference's pose, loaded when first asked for.
template <typename PointT>
class PlaceLocalMaps {
 public:
  explicit PlaceLocalMaps(const std::string& folder) : folder_(folder) {
    const std::string partition_path = folder + "/partition.json";
    try {
      const nlohmann::json partition = nlohmann::json::parse(io::readInputBytes(partition_path, "partition.json"));
      const auto& ids = partition.at("place_ids");
      for (std::size_t g = 0; g < ids.size(); ++g) group_of_place_[ids[g].get<int>()] = g;
    } catch (const nlohmann::json::exception& e) {
      throw io::InputError(partition_path + ": no place_ids (" + e.what() + ")");
    }
    const std::string poses_path = folder + "/local_maps/poses.txt";
    poses_ = io::parsePoses(io::readInputBytes(poses_path, "local map poses"), poses_path, io::PoseFormat::Tum);
    clouds_.resize(poses_.size());
  }

  /// The local map of place `id` and its reference's pose; null when the
  /// folder has none for it.
  std::pair<typename pcl::PointCloud<PointT>::ConstPtr, Eigen::Isometry3d> of(int id) {
    const auto it = group_of_place_.find(id);
    if (it == group_of_place_.end() || it->second >= poses_.size()) return {nullptr, Eigen::Isometry3d::Identity()};
    const std::size_t g = it->second;
    if (!clouds_[g]) {
      char name[64];
      std::snprintf(name, sizeof name, "/local_maps/group_%03zu.pcd", g);
      typename pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
      if (pcl::io::loadPCDFile(folder_ + name, *cloud) < 0) throw io::InputError(folder_ + name + ": cannot read");
      clouds_[g] = cloud;
    }
    return {clouds_[g], poses_[g]};
  }

 private:
  std::string folder_;
  std::map<int, std::size_t> group_of_place_;
  std::vector<Eigen::Isometry3d> poses_;
  std::vector<typename pcl::PointCloud<PointT>::ConstPtr> clouds_;
};

nlohmann::json poseJson(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d t = pose.translation();
  return {{"x", t.x()}, {"y", t.y()}, {"z", t.z()}, {"qw", q.w()}, {"qx", q.x()}, {"qy", q.y()}, {"qz", q.z()}};
}

/// True for a ground robot's pose: in the plane z = 0, turned about z only.
bool isPlanarPose(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d& R = pose.linear();
  return std::abs(R(2, 2) - 1) < 1e-9 && std::abs(pose.translation().z()) < 1e-9;
}

/// The x, y and heading of `pose`, as a pose in the plane z = 0 (ICP on a
/// planar scan leaves z, roll and pitch unconstrained).
Eigen::Isometry3d planarPart(const Eigen::Isometry3d& pose) {
  return pose2D(pose.translation().x(), pose.translation().y(), std::atan2(pose.linear()(1, 0), pose.linear()(0, 0)));
}

/// `obsgroup locate`: each observation's place in the places of a run.
template <typename PointT>
int locateObservations(const PartitionArgs& args, const std::vector<Observation<PointT>>& observations,
                       const InputRecord& input, const nlohmann::json& odometry) {
  Warnings warn(args.quiet);
  for (const auto& w : input.warnings) warn(w);
  const PlaceMap places = io::readPlaceLabels(args.locate->places);
  std::optional<PlaceLocalMaps<PointT>> maps;
  const bool track = args.locate->track;
  if (args.locate->align || track) maps.emplace(args.locate->places);
  bool planar = true;  // a ground robot's poses: the tracked pose stays in SE(2)
  for (const auto& o : observations) planar = planar && isPlanarPose(o.pose);
  Eigen::Isometry3d tracked = Eigen::Isometry3d::Identity();
  std::size_t followed = 0;
  const double tolerance = args.locate->tolerance;
  std::string text = "{\"places\": " + nlohmann::json(args.locate->places).dump() +
                     ", \"tolerance_m\": " + nlohmann::json(tolerance).dump() + ",\n" +
                     (odometry.is_null() ? "" : " \"odometry_correction\": " + odometry.dump() + ",\n") +
                     " \"locations\": [";
  std::size_t inside = 0, near = 0, converged = 0;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    throwIfInterrupted(args.interrupt);
    // Tracking: the previous observation's aligned pose, moved by the input's step.
    const Eigen::Isometry3d pose =
        track && i > 0 ? tracked * (observations[i - 1].pose.inverse() * observations[i].pose) : observations[i].pose;
    tracked = pose;
    const Eigen::Vector2d position = pose.translation().template head<2>();
    Location at = places.locate(position, tolerance);
    nlohmann::json line = {
        {"observation", i},
        {"source", input.labels.at(i)},
        {"stamp", input.stamps.empty() ? nlohmann::json() : nlohmann::json(input.stamps[i])},
        {"place", at.place ? nlohmann::json(*at.place) : nlohmann::json()},
        {"distance_m", at.place ? nlohmann::json(at.distance_m) : nlohmann::json()}};
    if (maps && at.place) {
      LocalizeOptions options;
      options.tolerance = tolerance;
      const Localization aligned = localize(
          places, [&maps](int id) { return maps->of(id); }, *observations[i].cloud, pose, options);
      if (track && aligned.converged && aligned.fitness_m2 < args.locate->track_fit_m2) {
        tracked = planar ? planarPart(aligned.pose) : aligned.pose;
        at = places.locate(tracked.translation().template head<2>(), tolerance);
        line["place"] = at.place ? nlohmann::json(*at.place) : nlohmann::json();
        line["distance_m"] = at.place ? nlohmann::json(at.distance_m) : nlohmann::json();
        ++followed;
      }
      line["converged"] = aligned.converged;
      line["fitness_m2"] = aligned.converged ? nlohmann::json(aligned.fitness_m2) : nlohmann::json();
      if (aligned.converged) {
        ++converged;
        line["aligned_pose"] = poseJson(aligned.pose);
        line["aligned_place"] = aligned.place ? nlohmann::json(*aligned.place) : nlohmann::json();
      }
    }
    if (track) line["tracked_pose"] = poseJson(tracked);
    inside += at.place && at.distance_m == 0;
    near += at.place && at.distance_m > 0;
    text += (i ? ",\n  " : "\n  ") + line.dump();
  }
  text += observations.empty() ? "]}\n" : "\n ]}\n";
  writeFileAtomically(args.output, text);
  if (!args.quiet) {
    std::fprintf(stderr, "obsgroup: %zu observations: %zu in a place, %zu within %g m of one, %zu in none\n",
                 observations.size(), inside, near, tolerance, observations.size() - inside - near);
    if (maps) std::fprintf(stderr, "  %zu of %zu aligned to their place's local map\n", converged, inside + near);
    if (track) std::fprintf(stderr, "  %zu followed their alignment (fit below %g m^2)\n", followed, args.locate->track_fit_m2);
    if (!odometry.is_null() && odometry.at("applied").get<bool>())
      std::fprintf(stderr, "  poses corrected by scan matching first: %d of %d steps changed\n",
                   odometry.at("matched").get<int>(), odometry.at("steps").get<int>());
    std::fprintf(stderr, "  wrote %s\n", args.output.c_str());
  }
  return 0;
}

/// With --keyframes: keeps the keyframes of `observations` and of what the
/// input says of each; returns each frame's keyframe (empty without).
template <typename PointT>
std::vector<int> keepKeyframes(const PartitionArgs& args, std::vector<Observation<PointT>>& observations,
                               InputRecord& input) {
  if (!args.keyframes) return {};
  std::vector<int> keyframe_of = selectKeyframes(posesOf(observations), *args.keyframes);
  std::vector<Observation<PointT>> kept;
  std::vector<std::string> labels;
  std::vector<double> stamps;
  for (int k : keyframesOf(keyframe_of)) {
    kept.push_back(std::move(observations[std::size_t(k)]));
    labels.push_back(input.labels[std::size_t(k)]);
    if (!input.stamps.empty()) stamps.push_back(input.stamps[std::size_t(k)]);
  }
  observations = std::move(kept);
  input.labels = std::move(labels);
  input.stamps = std::move(stamps);
  return keyframe_of;
}

/// --correct-odometry: the observations' poses corrected by scan matching
/// (in place, when the mode and the maps' sharpness say so); what
/// partition.json records of it, null when off.
template <typename PointT>
nlohmann::json correctPoses(const PartitionArgs& args, std::vector<Observation<PointT>>& observations, double& seconds) {
  if (args.correct_odometry == OdometryCorrection::Off) return nullptr;
  const Clock::time_point start = Clock::now();
  OdometryCorrectionParameters parameters;
  parameters.threads = args.method.threads;
  parameters.interrupt = args.interrupt;
  ProgressBar bar("scan matching", !args.quiet, args.progress);
  parameters.progress = [&bar](std::size_t done, std::size_t total) { bar(done, total); };
  const OdometryCorrectionReport r = correctOdometry(observations, args.correct_odometry, parameters);
  bar.finish();
  throwIfInterrupted(args.interrupt);
  seconds = secondsSince(start);
  return {{"applied", r.applied},
          {"steps", r.steps},
          {"matched", r.matched},
          {"kept", r.kept},
          {"unaligned", r.unaligned},
          {"sampled", r.sampled},
          {"sample_matched", r.sample_matched},
          {"input_map_cells", r.input_cells},
          {"corrected_map_cells", r.corrected_cells},
          {"input_blocked_share", r.input_blocked_share},
          {"corrected_blocked_share", r.corrected_blocked_share},
          {"odometry_bias",
           {{"scale", r.bias.scale},
            {"yaw_deg_per_m", r.bias.yaw_per_metre * 180.0 / M_PI},
            {"turn_scale", r.bias.turn_scale},
            {"steps", r.bias.steps}}}};
}

template <typename PointT>
int runPipeline(const PartitionArgs& args, std::vector<Observation<PointT>> observations, InputRecord input) {
  double odometry_seconds = 0;
  if (args.locate) return locateObservations(args, observations, input, correctPoses(args, observations, odometry_seconds));
  Warnings warn(args.quiet);
  for (const auto& w : input.warnings) warn(w);
  throwIfInterrupted(args.interrupt);
  const std::vector<std::string> sources = input.labels;
  const std::vector<double> stamps = input.stamps;
  const std::vector<int> keyframe_of = keepKeyframes(args, observations, input);
  // The keyframes' poses only: the frames between them take their keyframe's group.
  const nlohmann::json odometry = correctPoses(args, observations, odometry_seconds);
  GroupingOutcome<PointT> grouped;
  configureGrouping(args, grouped.grouping);
  if (args.stream)
    streamObservations(args, observations, input.labels, input.stamps, grouped);
  else
    groupObservations(args, observations, input, grouped);
  warnAboutGrouping(observations, input, grouped, warn);
  joinPassages(args, grouped, observations);
  returnFreedMemory(kTrimBytes);  // the partition's matrices, many below malloc's own threshold for returning them
  MapsOfRun<PointT> maps = buildMaps(args, observations, grouped.partition, grouped.weights(), warn);
  returnFreedMemory(kTrimBytes);
  io::OutputFolder out(args.output, args.force, args.interrupt);
  const Partition of_every_frame =
      keyframe_of.empty() ? grouped.partition : expandKeyframePartition(grouped.partition, keyframe_of);
  const OutputTimes written = writeResults(args, out, grouped, observations, maps, of_every_frame, warn);
  io::RunRecord run = runRecord(args, input, grouped, maps, written, warn);
  if (!odometry.is_null()) {
    run.statistics["odometry_correction"] = odometry;
    run.timing_s["odometry_correction"] = odometry_seconds;
  }
  run.sources = sources;
  run.stamps = stamps;
  run.keyframe_of = keyframe_of;
  if (args.keyframes) {
    run.parameters["keyframes"] = {{"distance", args.keyframes->distance}, {"angle_deg", args.keyframes->angle_deg}};
    run.statistics["keyframes"] = observations.size();
    if (run.statistics.contains("refinement")) {  // the maps' observations are the keyframes: name the frames
      const std::vector<int> keyframes = keyframesOf(keyframe_of);
      for (auto& k : run.statistics["refinement"]["unlinked"]) k = keyframes.at(k.get<std::size_t>());
    }
  }
  const std::string partition_json = io::partitionJson(of_every_frame, run);
  out.writeText("partition.json", partition_json);
  writeReport(args, out, of_every_frame, run, written, grouped, observations, maps);
  out.commit();
  if (!args.quiet) (args.stream ? printStreamSummary : printSummary)(args, run, of_every_frame.group_of.size());
  return 0;
}

AnyInput readCarmen(const PartitionArgs& args) {
  const auto start = Clock::now();
  io::CarmenOptions options;
  options.laser = args.laser;
  options.field_of_view_deg = args.field_of_view_deg;
  options.max_range = args.max_range;
  options.threads = args.method.threads;
  options.skip_bad_lines = args.skip_bad_lines;
  options.require_timestamps = args.stream && args.stream->realtime;
  io::CarmenLog log = io::readCarmenLog(args.input, options);
  const std::string name = io::inputName(args.input);
  const int n = static_cast<int>(log.scans.size());
  std::vector<Observation<pcl::PointXYZ>> observations(n);
  const io::BeamDirections beams(log.scans.empty() ? io::LaserScan{} : log.scans.front());  // the trigonometry once
  InputRecord input;
  input.format = "carmen";
  input.labels.resize(n);
  input.stamps.resize(n);
#pragma omp parallel for schedule(dynamic, 64)
  for (int i = 0; i < n; ++i) {
    observations[i] = {beams.cloudOf(log.scans[i]), log.scans[i].laser_pose};
    input.labels[i] = name + ":" + std::to_string(log.scans[i].line);
    input.stamps[i] = log.scans[i].timestamp;
  }
  // The beam geometry actually used (from the messages, PARAM lines or options), as read off the first scan.
  const io::LaserScan& first = log.scans.front();
  input.parameters = {{"laser", io::toString(log.source)},
                      {"fov_deg", log.fov_deg},
                      {"fov_source", log.fov_source},
                      {"max_range", first.max_range},
                      {"point_type", io::toString(io::PointKind::XYZ)}};
  input.warnings = std::move(log.warnings);
  log.scans = {};  // the ranges are in the clouds now: free them for the rest of the run
  returnFreedMemory(kTrimBytes);
  input.load_s = secondsSince(start);
  return InputObservations<pcl::PointXYZ>{std::move(observations), std::move(input)};
}

/// A PCD file named by a timestamp ("1305031102.175304.pcd"): its stamp.
std::optional<double> stampOfName(const std::string& file) {
  const std::string stem = std::filesystem::path(file).stem().string();
  if (stem.find('.') == std::string::npos) return std::nullopt;  // 000012.pcd is an index, not a time
  double value = 0.0;
  const auto [end, error] = std::from_chars(stem.data(), stem.data() + stem.size(), value);
  if (error != std::errc() || end != stem.data() + stem.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

template <typename PointT>
AnyInput readPcd(const PartitionArgs& args, std::vector<std::string> files, io::PointKind kind, Clock::time_point start) {
  std::optional<std::vector<Eigen::Isometry3d>> poses;
  std::optional<io::PoseFormat> pose_format = args.pose_format;
  std::string matched = "line order";
  std::vector<std::string> warnings;
  if (args.poses) {
    const std::string bytes = io::readInputBytes(*args.poses, "poses file");
    const std::string name = io::inputName(*args.poses);
    if (!pose_format) pose_format = io::detectPoseFormat(bytes, name);
    std::vector<std::optional<double>> stamps;
    for (const auto& file : files) stamps.push_back(stampOfName(file));
    const bool stamped = *pose_format == io::PoseFormat::Tum &&
                         std::all_of(stamps.begin(), stamps.end(), [](const auto& t) { return t.has_value(); });
    if (stamped) {  // match each cloud to the pose nearest its stamp
      matched = "timestamp";
      const double tolerance = args.max_time_difference.value_or(io::kDefaultMaxTimeDifference);
      const io::StampedPoseIndex stamped_poses(io::parseStampedPoses(bytes, name), tolerance);
      std::vector<std::string> kept;
      poses.emplace();
      for (std::size_t k = 0; k < files.size(); ++k)
        if (const auto pose = stamped_poses.at(*stamps[k])) {
          kept.push_back(files[k]);
          poses->push_back(*pose);
        }
      if (kept.empty())
        throw io::InputError(name + ": no pose within " + std::to_string(tolerance) + " s of any of the " +
                             std::to_string(files.size()) + " PCD files' timestamps (--max-time-difference)");
      if (kept.size() < files.size())
        warnings.push_back(std::to_string(files.size() - kept.size()) + " of " + std::to_string(files.size()) +
                           " PCD files have no pose in " + name + " within " + std::to_string(tolerance) +
                           " s of the timestamp in their name: skipped");
      files = std::move(kept);
    } else {
      if (args.max_time_difference)
        throw io::UsageError("--max-time-difference: the PCD files are not named by timestamps (or the poses are "
                             "not TUM): poses are matched by line order");
      poses = io::parsePoses(bytes, name, *pose_format);
    }
  }
  ProgressBar bar("read", !args.quiet, args.progress);
  const io::FrameReading reduction = frameReduction(args, bar);
  io::PcdSequence<PointT> sequence = io::loadPcdSequence<PointT>(files, poses, args.poses.value_or(""), reduction);
  bar.finish();
  InputRecord input;
  input.format = "pcd";
  input.labels = std::move(sequence.labels);
  input.parameters = {{"poses", args.poses ? nlohmann::json(*args.poses) : nlohmann::json("VIEWPOINT")},
                      {"pose_format", pose_format ? nlohmann::json(io::toString(*pose_format)) : nlohmann::json()},
                      {"point_type", io::toString(kind)}};
  if (args.poses) input.parameters["poses_matched_by"] = matched;
  recordReduction(reduction, sequence.reduced, input.parameters);
  input.warnings = std::move(warnings);
  for (auto& w : sequence.warnings) input.warnings.push_back(std::move(w));
  input.load_s = secondsSince(start);
  return InputObservations<PointT>{std::move(sequence.observations), std::move(input)};
}

AnyInput readDepth(const PartitionArgs& args, io::DepthLayout layout) {
  const auto start = Clock::now();
  io::DepthOptions options;
  if (args.intrinsics) options.intrinsics = io::parseIntrinsics(*args.intrinsics);
  options.depth_scale = args.depth_scale;
  options.max_depth = args.depth_max;
  options.stride = args.stride.value_or(1);
  options.max_time_difference = args.max_time_difference.value_or(io::kDefaultMaxTimeDifference);
  options.poses = args.poses;
  options.up = args.up;
  ProgressBar bar("read", !args.quiet, args.progress);
  options.reduction = frameReduction(args, bar);
  io::DepthSequence sequence = io::loadDepthSequence(args.input, layout, options);
  bar.finish();
  InputRecord input;
  input.format = io::toString(layout);
  input.labels = std::move(sequence.labels);
  const auto& k = options.intrinsics;
  input.parameters = {{"intrinsics", {k.fx, k.fy, k.cx, k.cy}},
                      {"depth_scale", sequence.depth_scale},
                      {"depth_max", args.depth_max ? nlohmann::json(*args.depth_max) : nlohmann::json()},
                      {"stride", options.stride},
                      {"up_axis", io::toString(sequence.up)},
                      {"point_type", io::toString(io::PointKind::XYZ)}};
  if (layout == io::DepthLayout::TumRgbd) {
    input.parameters["max_time_difference"] = options.max_time_difference;
    input.parameters["skipped_frames"] = sequence.skipped;
  }
  if (args.poses) input.parameters["poses"] = *args.poses;
  recordReduction(options.reduction, sequence.reduced, input.parameters);
  input.warnings = std::move(sequence.warnings);
  input.load_s = secondsSince(start);
  return InputObservations<pcl::PointXYZ>{std::move(sequence.observations), std::move(input)};
}

AnyInput readKitti(const PartitionArgs& args) {
  const auto start = Clock::now();
  ProgressBar bar("read", !args.quiet, args.progress);
  const io::FrameReading reduction = frameReduction(args, bar);
  io::KittiSequence sequence = io::loadKittiSequence(args.input, args.poses, reduction);
  bar.finish();
  InputRecord input;
  input.format = "kitti";
  input.labels = std::move(sequence.labels);
  input.parameters = {{"poses", sequence.poses_file},
                      {"calibration", sequence.calib_file},
                      {"point_type", io::toString(io::PointKind::XYZI)}};
  recordReduction(reduction, sequence.reduced, input.parameters);
  input.warnings = std::move(sequence.warnings);
  input.load_s = secondsSince(start);
  return InputObservations<pcl::PointXYZI>{std::move(sequence.observations), std::move(input)};
}

template <typename PointT>
AnyInput readBagAs(const PartitionArgs& args, const io::BagReader& reader, const io::FrameReading& reduction,
             ProgressBar& bar, io::PointKind kind, Clock::time_point start) {
  io::BagSequenceOf<PointT> sequence = reader.observations<PointT>();
  bar.finish();
  InputRecord input;
  input.format = io::toString(sequence.version);
  input.labels = std::move(sequence.labels);
  input.stamps = std::move(sequence.stamps);
  input.parameters = {{"topic", sequence.topic},
                      {"message_type", sequence.message_type},
                      {"poses_from", sequence.pose_source},
                      {"fixed_frame", sequence.fixed_frame.empty() ? nlohmann::json() : nlohmann::json(sequence.fixed_frame)},
                      {"skipped_messages", sequence.skipped},
                      {"point_type", io::toString(kind)}};
  recordReduction(reduction, sequence.reduced, input.parameters);
  if (args.poses) {
    input.parameters["poses"] = *args.poses;
    input.parameters["max_time_difference"] = args.max_time_difference.value_or(io::kDefaultMaxTimeDifference);
  }
  input.warnings = std::move(sequence.warnings);
  input.load_s = secondsSince(start);
  return InputObservations<PointT>{std::move(sequence.observations), std::move(input)};
}

AnyInput readBag(const PartitionArgs& args, io::BagVersion version) {
  const auto start = Clock::now();
  if (!io::bagSupported(version))
    throw io::InputError(args.input + ": this obsgroup was built without " +
                         (version == io::BagVersion::Ros1 ? std::string("ROS 1 bag support (librosbag-storage-dev)")
                                                          : std::string("ROS 2 bag support (libsqlite3-dev, "
                                                                        "libfastcdr-dev)")));
  io::BagOptions options;
  options.topic = args.topic;
  options.pose_topic = args.pose_topic;
  options.fixed_frame = args.fixed_frame;
  options.poses_file = args.poses;
  options.max_time_difference = args.max_time_difference.value_or(io::kDefaultMaxTimeDifference);
  ProgressBar bar("convert", !args.quiet, args.progress);
  options.reduction = frameReduction(args, bar);
  const io::BagReader reader(args.input, version, options);
  switch (const io::PointKind kind = reader.pointKind()) {
    case io::PointKind::XYZI: return readBagAs<pcl::PointXYZI>(args, reader, options.reduction, bar, kind, start);
    case io::PointKind::XYZRGB: return readBagAs<pcl::PointXYZRGB>(args, reader, options.reduction, bar, kind, start);
    case io::PointKind::XYZ: break;
  }
  return readBagAs<pcl::PointXYZ>(args, reader, options.reduction, bar, io::PointKind::XYZ, start);
}

AnyInput readInputOfFormat(const PartitionArgs& args, const std::string& format) {
  if (format == "carmen") return readCarmen(args);
  if (format == "tum-rgbd") return readDepth(args, io::DepthLayout::TumRgbd);
  if (format == "redwood") return readDepth(args, io::DepthLayout::Redwood);
  if (format == "kitti") return readKitti(args);
  if (format == "ros1") return readBag(args, io::BagVersion::Ros1);
  if (format == "ros2") return readBag(args, io::BagVersion::Ros2);

  const auto start = Clock::now();
  const auto files = io::listPcdFiles(args.input);
  switch (const io::PointKind kind = io::detectPointKind(files.front())) {
    case io::PointKind::XYZI: return readPcd<pcl::PointXYZI>(args, files, kind, start);
    case io::PointKind::XYZRGB: return readPcd<pcl::PointXYZRGB>(args, files, kind, start);
    case io::PointKind::XYZ: break;
  }
  return readPcd<pcl::PointXYZ>(args, files, io::PointKind::XYZ, start);
}

}  // namespace

AnyInput readInput(const PartitionArgs& args) {
  const std::string format = detectFormat(args);
  checkOptionsFit(args, format);
  return readInputOfFormat(args, format);
}

int runPartition(const PartitionArgs& args) {
  if (args.method.threads > 0) omp_set_num_threads(args.method.threads);  // every parallel stage, the writers' too
  const std::string format = detectFormat(args);
  checkOptionsFit(args, format);
  const bool stamped = format == "carmen" || format == "ros1" || format == "ros2";
  if (args.stream && args.stream->realtime && !stamped)
    throw io::UsageError("--realtime replays a CARMEN log or a ROS bag at its timestamps; " + args.input + " is " +
                         format + ", a format with no timestamps");
  if (args.locate) {  // fail before reading the input, not after
    io::readPlaceLabels(args.locate->places);  // a folder without places, or a damaged label map, before the input
    if (std::filesystem::exists(args.output) && !args.force)
      throw io::UsageError(args.output + " exists; --force replaces it");
    if (std::filesystem::is_directory(args.output)) throw io::UsageError(args.output + " is a folder, not a file");
  } else {
    io::OutputFolder::check(args.output, args.force);  // fail before a long run, not after
  }
  return std::visit(
      [&](auto&& read) { return runPipeline(args, std::move(read.observations), std::move(read.input)); },
      readInputOfFormat(args, format));
}

}  // namespace obsgroup::cli
