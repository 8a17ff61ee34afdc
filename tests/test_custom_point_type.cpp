// A user's own point type, compiled from obsgroup's templates with
// PCL_NO_PRECOMPILE as with PCL itself. Built with -Werror=unknown-pragmas:
// the templates' OpenMP pragmas must reach this translation unit through
// obsgroup's interface, or the grouping would silently run on one thread.
#define PCL_NO_PRECOMPILE
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

struct EIGEN_ALIGN16 RangePoint {
  PCL_ADD_POINT4D;
  float range;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};
POINT_CLOUD_REGISTER_POINT_STRUCT(RangePoint, (float, x, x)(float, y, y)(float, z, z)(float, range, range))

#include <obsgroup/observation_grouping.h>

#include <gtest/gtest.h>

#ifndef _OPENMP
#error "obsgroup::obsgroup must carry OpenMP to users of its templates"
#endif

namespace {

template <typename PointT>
obsgroup::Partition groupThreeLines(int threads) {
  typename pcl::PointCloud<PointT>::Ptr line(new pcl::PointCloud<PointT>);
  for (int k = 0; k < 100; ++k) {
    PointT p;
    p.x = 0.05f * k;
    p.y = 0.0f;
    p.z = 0.0f;
    line->push_back(p);
  }
  obsgroup::ObservationGrouping<PointT> grouping;
  grouping.setNumberOfThreads(threads);
  grouping.addObservation(line, obsgroup::pose2D(0, 0, 0));
  grouping.addObservation(line, obsgroup::pose2D(0.5, 0, 0));
  grouping.addObservation(line, obsgroup::pose2D(0, 50, 0));
  return grouping.compute();
}

TEST(CustomPointType, GroupsAsThePrecompiledTypesDo) {
  const obsgroup::Partition own = groupThreeLines<RangePoint>(2);
  const obsgroup::Partition xyz = groupThreeLines<pcl::PointXYZ>(2);
  ASSERT_EQ(own.groups.size(), 2u);
  EXPECT_EQ(own.groups, xyz.groups);
  EXPECT_EQ(groupThreeLines<RangePoint>(1).groups, own.groups);
}

}  // namespace
