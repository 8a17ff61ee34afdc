// Explicit instantiations of SensedSpaceOverlap for the common point types, so
// that users of these types do not compile PCL's search and filter templates.
#include "obsgroup/overlap/impl/sensed_space_overlap.hpp"
#include "obsgroup/cloud/point_types.h"

#include <pcl/impl/instantiate.hpp>

PCL_INSTANTIATE(SensedSpaceOverlap, OBSGROUP_POINT_TYPES)
