#pragma once
/// \file
/// Point types for which obsgroup's templates are precompiled into the
/// library, as a Boost.Preprocessor sequence for PCL_INSTANTIATE. Other types
/// with x, y, z work too: define PCL_NO_PRECOMPILE before including
/// obsgroup's headers, as with PCL itself.
///
/// Not PCL_XYZ_POINT_TYPES: its 18 types would each instantiate PCL's
/// kd-tree, voxel grid and search templates three times over (overlap,
/// grouping, local maps), tripling the library's build for types no reader
/// produces. These six are what the readers give and the usual sensors carry.

#include <pcl/point_types.h>

#define OBSGROUP_POINT_TYPES \
  (pcl::PointXYZ)(pcl::PointXYZI)(pcl::PointXYZRGB)(pcl::PointXYZRGBA)(pcl::PointNormal)(pcl::PointXYZINormal)
