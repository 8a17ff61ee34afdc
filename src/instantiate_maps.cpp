// Explicit instantiations of LocalMapBuilder (PCL registration: the heaviest
// headers of the library, kept in this one translation unit).
#include "obsgroup/maps/impl/local_map_builder.hpp"
#include "obsgroup/point_types.h"

OBSGROUP_FOR_EACH_POINT_TYPE(OBSGROUP_INSTANTIATE_LocalMapBuilder)
