#pragma once
/// \file
/// Point types for which obsgroup's templates are precompiled into the
/// library. Other types with x, y, z work too: define PCL_NO_PRECOMPILE
/// before including obsgroup's headers, as with PCL itself.

#include <pcl/point_types.h>

/// Applies MACRO to every precompiled point type.
#define OBSGROUP_FOR_EACH_POINT_TYPE(MACRO) \
  MACRO(pcl::PointXYZ)                      \
  MACRO(pcl::PointXYZI)                     \
  MACRO(pcl::PointXYZRGB)                   \
  MACRO(pcl::PointXYZRGBA)                  \
  MACRO(pcl::PointNormal)                   \
  MACRO(pcl::PointXYZINormal)
