// Links against an installed obsgroup: two overlapping line scans and one
// far away give two groups.
#include <obsgroup/observation_grouping.h>

#include <pcl/point_types.h>

#include <cstdio>

int main() {
  pcl::PointCloud<pcl::PointXYZ>::Ptr line(new pcl::PointCloud<pcl::PointXYZ>);
  for (int k = 0; k < 100; ++k) line->push_back({0.05f * k, 0.0f, 0.0f});
  obsgroup::ObservationGrouping<pcl::PointXYZ> grouping;
  grouping.addObservation(line, obsgroup::pose2D(0, 0, 0));
  grouping.addObservation(line, obsgroup::pose2D(0.5, 0, 0));
  grouping.addObservation(line, obsgroup::pose2D(0, 50, 0));
  const auto partition = grouping.compute();
  std::printf("package consumer: %zu groups\n", partition.groups.size());
  return partition.groups.size() == 2 ? 0 : 1;
}
