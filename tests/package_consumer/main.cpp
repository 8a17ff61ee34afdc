// Links against an installed obsgroup: two overlapping line scans and one
// far away give two groups, each coloured with PCL's visualization module.
#include <obsgroup/observation_grouping.h>

#include <pcl/point_types.h>
#include <pcl/visualization/point_cloud_color_handlers.h>

#include <cstdio>

int main() {
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
  return partition.groups.size() == 2 && colour.isCapable() ? 0 : 1;
}
