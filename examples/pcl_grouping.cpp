// The few lines a PCL user needs: clouds in (PCD files whose VIEWPOINT holds
// the pose), ObservationGrouping configured, groups out, and each group's
// clouds merged into one local cloud with plain PCL calls.
//
//   pcl_grouping [--paper [--delta METRES]] [--out FOLDER] file1.pcd file2.pcd ...
//
// The defaults group by visibility (obsgroup::GroupingParameters); --paper
// uses the paper's method, whose points model matches within --delta.
//
// Example: pcl_grouping data/real/localization_demo/pcd/*.pcd

#include <obsgroup/observation_grouping.h>

#include <pcl/common/transforms.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

int main(int argc, char** argv) {
  bool paper = false;
  std::optional<double> delta;
  std::string out_folder;
  std::vector<std::string> files;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--paper") paper = true;
    else if (arg == "--delta" && a + 1 < argc) delta = std::atof(argv[++a]);
    else if (arg == "--out" && a + 1 < argc) out_folder = argv[++a];
    else files.push_back(arg);
  }
  if (files.empty() || (delta && !paper)) {
    std::cerr << "usage: " << argv[0] << " [--paper [--delta METRES]] [--out FOLDER] file1.pcd file2.pcd ...\n";
    return 2;
  }

  // 1. Clouds in: the pose of each comes from its VIEWPOINT.
  obsgroup::ObservationGrouping<pcl::PointXYZ> grouping;
  std::vector<Cloud::Ptr> clouds;
  for (const auto& file : files) {
    Cloud::Ptr cloud(new Cloud);
    if (pcl::io::loadPCDFile(file, *cloud) < 0) {
      std::cerr << "error: " << file << ": cannot read this PCD file\n";
      return 3;
    }
    clouds.push_back(cloud);
    grouping.addObservation(cloud);  // pose = cloud->sensor_origin_, sensor_orientation_
  }

  // 2. Configure and compute.
  obsgroup::GroupingParameters params;  // the defaults
  if (paper) {
    params = obsgroup::GroupingParameters::paper();
    params.match_distance = delta.value_or(params.match_distance);
  }
  try {
    grouping.setParameters(params);  // checks every setting
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  const obsgroup::Partition partition = grouping.compute();

  // 3. Groups out, each merged in the frame of its first observation.
  const auto& observations = grouping.getObservations();
  for (std::size_t g = 0; g < partition.groups.size(); ++g) {
    const auto& group = partition.groups[g];
    const Eigen::Isometry3d reference = observations[group.front()].pose;
    Cloud local;
    for (int i : group) {
      Cloud moved;
      const Eigen::Isometry3d relative = reference.inverse() * observations[i].pose;
      pcl::transformPointCloud(*clouds[i], moved, relative.matrix().cast<float>());
      local += moved;
    }
    std::printf("group %zu: %zu clouds, %zu points:", g, group.size(), local.size());
    for (int i : group) std::printf(" %d", i);
    std::printf("\n");
    if (!out_folder.empty()) {
      std::filesystem::create_directories(out_folder);
      char name[32];
      std::snprintf(name, sizeof name, "group_%03zu.pcd", g);
      const std::string path = (std::filesystem::path(out_folder) / name).string();
      if (std::filesystem::exists(path)) {
        std::cerr << "error: " << path << " exists; not overwriting it\n";
        return 3;
      }
      local.sensor_origin_ << reference.translation().cast<float>(), 0.0f;
      local.sensor_orientation_ = Eigen::Quaternionf(reference.linear().cast<float>());
      pcl::io::savePCDFileBinary(path, local);
    }
  }
  return 0;
}
