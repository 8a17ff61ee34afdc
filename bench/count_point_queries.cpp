// The work of a per-observation neighbour search on an input: one point query
// per point of observation i and per other observation j whose world bounding
// box, grown by delta, meets i's. It is what a kd-tree per observation (the
// PCL search back-end) answers, and the unit in which the reference rates of
// the scaling targets were measured ("19.6 M point queries" for 300 real
// scans). bench/scaling.sh divides it by the time of the overlap stage, which
// computes the same matrix without asking most of these queries.
//
//   count_point_queries INPUT DELTA [VOXEL]   INPUT: a CARMEN log or a folder of PCD files

#include <obsgroup/io/carmen_reader.h>
#include <obsgroup/io/pcd_sequence.h>

#include <obsgroup/overlap/sensed_space_overlap.h>
#include <obsgroup/overlap/world_points.h>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s INPUT DELTA [VOXEL]\n", argv[0]);
    return 2;
  }
  try {
    const std::string input = argv[1];
    std::vector<obsgroup::Observation<pcl::PointXYZ>> observations;
    if (std::filesystem::is_directory(input)) {
      observations = obsgroup::io::loadPcdSequence<pcl::PointXYZ>(obsgroup::io::listPcdFiles(input), std::nullopt)
                         .observations;
    } else {
      for (const auto& scan : obsgroup::io::readCarmenLog(input).scans)
        observations.push_back({obsgroup::io::scanToCloud(scan), scan.laser_pose});
    }
    obsgroup::SensedSpaceOverlap<pcl::PointXYZ> overlap;
    overlap.setMatchDistance(std::stod(argv[2]));
    overlap.setVoxelLeafSize(argc > 3 ? std::stod(argv[3]) : 0.0);
    const obsgroup::WorldPoints world = overlap.toWorld(observations);
    const auto candidates = obsgroup::overlappingBoxes(world, overlap.getMatchDistance());
    std::uint64_t queries = 0;
    for (const auto& of_j : candidates)
      for (int i : of_j) queries += world.count(i);
    std::printf("%llu\n", static_cast<unsigned long long>(queries));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "count_point_queries: %s\n", e.what());
    return 3;
  }
  return 0;
}
