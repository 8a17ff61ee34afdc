// Explicit instantiations of ObservationGrouping for the common point types.
#include "obsgroup/impl/observation_grouping.hpp"
#include "obsgroup/cloud/point_types.h"

#include <pcl/impl/instantiate.hpp>

PCL_INSTANTIATE(ObservationGrouping, OBSGROUP_POINT_TYPES)
