# Dependencies of obsgroup, shared by the build tree and by obsgroupConfig.cmake
# so that find_package(obsgroup) finds exactly what the library was built with.

# PCL 1.13's config probes VTK (and OpenNI, libusb) as optional extras and then
# fails on a C++-only project (VTK::mpi -> MPI::MPI_C not found). obsgroup
# needs none of them; disabling the look-up also keeps Qt/VTK flags out of
# our targets.
set(CMAKE_DISABLE_FIND_PACKAGE_VTK TRUE)
set(CMAKE_DISABLE_FIND_PACKAGE_OpenNI TRUE)
set(CMAKE_DISABLE_FIND_PACKAGE_OpenNI2 TRUE)
set(CMAKE_DISABLE_FIND_PACKAGE_libusb TRUE)
set(CMAKE_DISABLE_FIND_PACKAGE_ensenso TRUE)
set(CMAKE_DISABLE_FIND_PACKAGE_davidSDK TRUE)
set(CMAKE_DISABLE_FIND_PACKAGE_DSSDK TRUE)
set(CMAKE_DISABLE_FIND_PACKAGE_RSSDK TRUE)
set(CMAKE_DISABLE_FIND_PACKAGE_RSSDK2 TRUE)

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(PCL 1.10 REQUIRED COMPONENTS common kdtree search filters registration)
find_package(OpenMP REQUIRED)
find_package(Spectra 1.0 REQUIRED CONFIG)

set(OBSGROUP_PCL_TARGETS pcl_common pcl_kdtree pcl_search pcl_filters pcl_registration)

# FLANN's index headers (refinement's nearest-point search, src/maps/refinement.cpp)
# call LZ4 in their serialisation code; libflann-dev brings liblz4-dev along.
find_library(OBSGROUP_LZ4_LIBRARY NAMES lz4 REQUIRED)
if(NOT TARGET obsgroup::lz4)
  add_library(obsgroup::lz4 UNKNOWN IMPORTED)
  set_target_properties(obsgroup::lz4 PROPERTIES IMPORTED_LOCATION "${OBSGROUP_LZ4_LIBRARY}")
endif()
