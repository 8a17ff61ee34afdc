// Links against an installed obsgroup: two overlapping line scans and one
// far away give two groups, each coloured with PCL's visualization module;
// then the same three scans inserted one by one into an OnlineGrouping; the
// same three scans as a CARMEN log, read with obsgroup::io; and, when given
// one, a ROS bag (argv[1]) read with obsgroup::io's BagReader. A caller's
// mistakes reach it as exceptions: a throwing progress callback's own, and
// std::invalid_argument for a local map of a group with an index out of range.
#include <obsgroup/io/carmen_reader.h>
#include <obsgroup/io/ros_bag.h>
#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/observation_grouping.h>
#include <obsgroup/online_grouping.h>

#include <pcl/point_types.h>
#include <pcl/visualization/point_cloud_color_handlers.h>

#include <cstdio>
#include <stdexcept>
#include <string>

int main(int argc, char** argv) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr line(new pcl::PointCloud<pcl::PointXYZ>);
  for (int k = 0; k < 100; ++k) line->push_back({0.05f * k, 0.0f, 0.0f});
  obsgroup::ObservationGrouping<pcl::PointXYZ> grouping;
  grouping.addObservation(line, obsgroup::pose2D(0, 0, 0));
  grouping.addObservation(line, obsgroup::pose2D(0.5, 0, 0));
  grouping.addObservation(line, obsgroup::pose2D(0, 50, 0));
  const auto partition = grouping.compute();
  pcl::visualization::PointCloudColorHandlerCustom<pcl::PointXYZ> colour(line, 255, 0, 0);
  std::printf("package consumer: %zu groups, colour handler %s\n", partition.groups.size(),
              colour.getName().c_str());

  obsgroup::OnlineGrouping<pcl::PointXYZ> online;
  std::size_t changes = 0;
  for (const auto& pose : {obsgroup::pose2D(0, 0, 0), obsgroup::pose2D(0.5, 0, 0), obsgroup::pose2D(0, 50, 0)}) {
    online.insert(line, pose);
    changes += online.update().changes.size();
  }
  std::printf("package consumer: online, %zu groups after %zu changes\n", online.getGroups().size(), changes);

  // Three FLASER scans of a wall 2 m ahead, from (0,0), (0.5,0) and (0,50).
  std::string log;
  for (const char* pose : {"0 0 0", "0.5 0 0", "0 50 0"}) {
    log += "FLASER 181";
    for (int k = 0; k < 181; ++k) log += " 2.0";
    log += std::string(" ") + pose + " " + pose + " 0 host 0\n";
  }
  const obsgroup::io::CarmenLog read = obsgroup::io::parseCarmenLog(log, "inline.log");
  obsgroup::ObservationGrouping<pcl::PointXYZ> from_log;
  for (const auto& scan : read.scans) from_log.addObservation(obsgroup::io::scanToCloud(scan), scan.laser_pose);
  const auto log_partition = from_log.compute();
  std::printf("package consumer: %zu scans read with obsgroup::io, %zu groups\n", read.scans.size(),
              log_partition.groups.size());
  obsgroup::ObservationGrouping<pcl::PointXYZ> failing;
  for (int k = 0; k < 50; ++k) failing.addObservation(line, obsgroup::pose2D(0.1 * k, 0, 0));
  failing.setProgressCallback([](std::size_t, std::size_t) { throw std::runtime_error("stop from the callback"); });
  bool callback_ok = false;
  try {
    failing.compute();
  } catch (const std::runtime_error& e) {
    callback_ok = std::string(e.what()) == "stop from the callback";
  }
  bool bad_group_ok = false;
  try {
    obsgroup::LocalMapBuilder<pcl::PointXYZ>().build(grouping.getObservations(), pcl::Indices{0, 1, 3},
                                                     grouping.getWeightMatrix());
  } catch (const std::invalid_argument& e) {
    bad_group_ok = true;
    std::printf("package consumer: a bad group is refused: %s\n", e.what());
  }
  std::printf("package consumer: the callback's exception %s\n", callback_ok ? "reached the caller" : "was lost");

  bool bag_ok = true;
  if (argc > 1) {
    const auto version = obsgroup::io::detectBag(argv[1]);
    const obsgroup::io::BagSequence bag =
        obsgroup::io::BagReader(argv[1], version.value_or(obsgroup::io::BagVersion::Ros1), {}).observations<pcl::PointXYZ>();
    obsgroup::ObservationGrouping<pcl::PointXYZ> from_bag;
    for (const auto& o : bag.observations) from_bag.addObservation(o.cloud, o.pose);
    const auto bag_partition = from_bag.compute();
    std::printf("package consumer: %zu scans read from %s with obsgroup::io, %zu groups\n", bag.observations.size(),
                bag.topic.c_str(), bag_partition.groups.size());
    bag_ok = version.has_value() && !bag.observations.empty() && !bag_partition.groups.empty();
  }
  return partition.groups.size() == 2 && online.getPartition().groups == partition.groups && colour.isCapable() && read.scans.size() == 3 &&
                 log_partition.groups.size() == 2 && bag_ok && callback_ok && bad_group_ok
             ? 0
             : 1;
}
