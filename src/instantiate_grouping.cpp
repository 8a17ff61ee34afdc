// Explicit instantiations of ObservationGrouping and OnlineGrouping for the common point types.
#include "obsgroup/impl/observation_grouping.hpp"
#include "obsgroup/cloud/point_types.h"

#include <pcl/impl/instantiate.hpp>

PCL_INSTANTIATE(ObservationGrouping, OBSGROUP_POINT_TYPES)

// The online grouping shares this translation unit: its overlap stage is
// SensedSpaceOverlap's, instantiated above through observation_grouping.hpp.
#include "obsgroup/impl/online_grouping.hpp"
PCL_INSTANTIATE(OnlineGrouping, OBSGROUP_POINT_TYPES)
