# Dependencies of obsgroup, shared by the build tree and by obsgroupConfig.cmake
# so that find_package(obsgroup) finds exactly what the library was built with.
# Macros, not functions: the targets and PCL's *_FOUND variables must reach the
# caller (a second find_package(PCL ...) there skips what was found here).

# obsgroup::core (graph, spectral, partition, sensed regions, topology):
# Eigen, Spectra and OpenMP only.
macro(obsgroup_find_core_dependencies)
  find_package(Eigen3 3.3 REQUIRED NO_MODULE)
  find_package(Spectra 1.0 REQUIRED CONFIG)
  find_package(OpenMP REQUIRED)
endmacro()

# find_package(PCL ${ARGN}) without the optional extras PCL 1.13's config
# probes: VTK fails on a C++-only project (VTK::mpi -> MPI::MPI_C not found),
# and obsgroup needs none of them. The switches are set for this one call and
# restored, so a caller's own find_package(PCL COMPONENTS visualization) still
# finds VTK.
macro(obsgroup_find_pcl)
  set(_obsgroup_pcl_extras VTK OpenNI OpenNI2 libusb ensenso davidSDK DSSDK RSSDK RSSDK2)
  foreach(_obsgroup_extra IN LISTS _obsgroup_pcl_extras)
    if(DEFINED CMAKE_DISABLE_FIND_PACKAGE_${_obsgroup_extra})
      set(_obsgroup_saved_${_obsgroup_extra} "${CMAKE_DISABLE_FIND_PACKAGE_${_obsgroup_extra}}")
    endif()
    set(CMAKE_DISABLE_FIND_PACKAGE_${_obsgroup_extra} TRUE)
  endforeach()
  find_package(PCL ${ARGN})
  foreach(_obsgroup_extra IN LISTS _obsgroup_pcl_extras)
    if(DEFINED _obsgroup_saved_${_obsgroup_extra})
      set(CMAKE_DISABLE_FIND_PACKAGE_${_obsgroup_extra} "${_obsgroup_saved_${_obsgroup_extra}}")
      unset(_obsgroup_saved_${_obsgroup_extra})
    else()
      unset(CMAKE_DISABLE_FIND_PACKAGE_${_obsgroup_extra})
    endif()
  endforeach()
  unset(_obsgroup_extra)
  unset(_obsgroup_pcl_extras)
endmacro()

# obsgroup::io (the readers): PCL's io, zlib (gzip input), libpng (depth
# images) and, when installed, libdeflate (a faster inflate).
macro(obsgroup_find_io_dependencies)
  obsgroup_find_pcl(1.10 REQUIRED COMPONENTS common io)
  find_package(ZLIB REQUIRED)
  find_package(PNG REQUIRED)
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(LIBDEFLATE QUIET IMPORTED_TARGET libdeflate)
endmacro()

# obsgroup::obsgroup (the PCL templates, local maps): the core's and PCL's.
macro(obsgroup_find_pcl_dependencies)
  obsgroup_find_pcl(1.10 REQUIRED COMPONENTS common kdtree search filters registration)
  set(OBSGROUP_PCL_TARGETS pcl_common pcl_kdtree pcl_search pcl_filters pcl_registration)
  # FLANN's index headers (refinement's nearest-point search, src/maps/refinement.cpp)
  # call LZ4 in their serialisation code; libflann-dev brings liblz4-dev along.
  find_library(OBSGROUP_LZ4_LIBRARY NAMES lz4 REQUIRED)
  if(NOT TARGET obsgroup::lz4)
    add_library(obsgroup::lz4 UNKNOWN IMPORTED)
    set_target_properties(obsgroup::lz4 PROPERTIES IMPORTED_LOCATION "${OBSGROUP_LZ4_LIBRARY}")
  endif()
endmacro()
