// Explicit instantiations of SensedSpaceOverlap for the common point types, so
// that users of these types do not compile PCL's search and filter templates.
#include "obsgroup/overlap/impl/sensed_space_overlap.hpp"
#include "obsgroup/point_types.h"

OBSGROUP_FOR_EACH_POINT_TYPE(OBSGROUP_INSTANTIATE_SensedSpaceOverlap)
