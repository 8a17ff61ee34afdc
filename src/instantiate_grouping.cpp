// Explicit instantiations of ObservationGrouping for the common point types.
#include "obsgroup/impl/observation_grouping.hpp"
#include "obsgroup/point_types.h"

OBSGROUP_FOR_EACH_POINT_TYPE(OBSGROUP_INSTANTIATE_ObservationGrouping)
