// Explicit instantiations of LocalMapBuilder (PCL's filters and transforms on
// every point type), kept in this one translation unit.
#include "obsgroup/maps/impl/local_map_builder.hpp"
#include "obsgroup/cloud/point_types.h"

#include <pcl/impl/instantiate.hpp>

PCL_INSTANTIATE(LocalMapBuilder, OBSGROUP_POINT_TYPES)
