# Dependencies of obsgroup, shared by the build tree and by obsgroupConfig.cmake
# so that find_package(obsgroup) finds exactly what the library was built with.
# Macros, not functions: the targets and PCL's *_FOUND variables must reach the
# caller (a second find_package(PCL ...) there skips what was found here).

# The oldest PCL obsgroup builds with: pcl/types.h (pcl::Indices, pcl::index_t)
# came with PCL 1.11.
set(OBSGROUP_PCL_MINIMUM_VERSION 1.11)

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
  obsgroup_find_pcl(${OBSGROUP_PCL_MINIMUM_VERSION} REQUIRED COMPONENTS common io filters)
  find_package(ZLIB REQUIRED)
  find_package(PNG REQUIRED)
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(LIBDEFLATE QUIET IMPORTED_TARGET libdeflate)
  obsgroup_find_bag_dependencies()
endmacro()

# ROS bags, each optional (a reader built without one says so when asked):
# ROS 1 through rosbag's storage library and the message headers Debian ships
# (librosbag-storage-dev, libsensor-msgs-dev, libtf2-msgs-dev, libnav-msgs-dev,
# libgeometry-msgs-dev); ROS 2's sqlite3 storage through SQLite and Fast CDR.
# rosbag_storage's own CMake config drags in ament and Python, so its library
# and the headers its bag.h includes (pluginlib, class_loader, rcpputils,
# rcutils) are found directly.
macro(obsgroup_find_bag_dependencies)
  find_library(OBSGROUP_ROSBAG_STORAGE_LIBRARY NAMES rosbag_storage)
  find_library(OBSGROUP_ROSCPP_SERIALIZATION_LIBRARY NAMES roscpp_serialization)
  find_library(OBSGROUP_ROSTIME_LIBRARY NAMES rostime)
  find_library(OBSGROUP_CPP_COMMON_LIBRARY NAMES cpp_common)
  find_library(OBSGROUP_CONSOLE_BRIDGE_LIBRARY NAMES console_bridge)
  find_path(OBSGROUP_ROSBAG_INCLUDE_DIR rosbag/bag.h)
  find_path(OBSGROUP_SENSOR_MSGS_INCLUDE_DIR sensor_msgs/LaserScan.h)
  find_path(OBSGROUP_TF2_MSGS_INCLUDE_DIR tf2_msgs/TFMessage.h)
  find_path(OBSGROUP_NAV_MSGS_INCLUDE_DIR nav_msgs/Odometry.h)
  find_path(OBSGROUP_PLUGINLIB_INCLUDE_DIR pluginlib/class_loader.hpp PATH_SUFFIXES pluginlib)
  find_path(OBSGROUP_CLASS_LOADER_INCLUDE_DIR class_loader/class_loader.hpp PATH_SUFFIXES class_loader)
  find_path(OBSGROUP_RCPPUTILS_INCLUDE_DIR rcpputils/shared_library.hpp PATH_SUFFIXES rcpputils)
  find_path(OBSGROUP_RCUTILS_INCLUDE_DIR rcutils/types.h PATH_SUFFIXES rcutils)
  find_path(OBSGROUP_AMENT_INDEX_INCLUDE_DIR ament_index_cpp/get_resource.hpp PATH_SUFFIXES ament_index_cpp)
  set(OBSGROUP_ROS1_FOUND FALSE)
  if(OBSGROUP_ROSBAG_STORAGE_LIBRARY AND OBSGROUP_ROSCPP_SERIALIZATION_LIBRARY AND OBSGROUP_ROSTIME_LIBRARY
     AND OBSGROUP_CPP_COMMON_LIBRARY AND OBSGROUP_CONSOLE_BRIDGE_LIBRARY AND OBSGROUP_ROSBAG_INCLUDE_DIR AND OBSGROUP_SENSOR_MSGS_INCLUDE_DIR
     AND OBSGROUP_TF2_MSGS_INCLUDE_DIR AND OBSGROUP_NAV_MSGS_INCLUDE_DIR AND OBSGROUP_PLUGINLIB_INCLUDE_DIR
     AND OBSGROUP_CLASS_LOADER_INCLUDE_DIR AND OBSGROUP_RCPPUTILS_INCLUDE_DIR AND OBSGROUP_RCUTILS_INCLUDE_DIR
     AND OBSGROUP_AMENT_INDEX_INCLUDE_DIR)
    set(OBSGROUP_ROS1_FOUND TRUE)
    if(NOT TARGET obsgroup::rosbag_storage)
      add_library(obsgroup::rosbag_storage INTERFACE IMPORTED)
      set_target_properties(obsgroup::rosbag_storage PROPERTIES
        INTERFACE_INCLUDE_DIRECTORIES "${OBSGROUP_PLUGINLIB_INCLUDE_DIR};${OBSGROUP_CLASS_LOADER_INCLUDE_DIR};${OBSGROUP_RCPPUTILS_INCLUDE_DIR};${OBSGROUP_RCUTILS_INCLUDE_DIR};${OBSGROUP_AMENT_INDEX_INCLUDE_DIR}"
        INTERFACE_LINK_LIBRARIES "${OBSGROUP_ROSBAG_STORAGE_LIBRARY};${OBSGROUP_ROSCPP_SERIALIZATION_LIBRARY};${OBSGROUP_ROSTIME_LIBRARY};${OBSGROUP_CPP_COMMON_LIBRARY};${OBSGROUP_CONSOLE_BRIDGE_LIBRARY}")
    endif()
  endif()
  find_package(SQLite3 QUIET)
  find_package(fastcdr CONFIG QUIET)
  set(OBSGROUP_ROS2_FOUND FALSE)
  if(SQLite3_FOUND AND fastcdr_FOUND)
    set(OBSGROUP_ROS2_FOUND TRUE)
  endif()
endmacro()

# obsgroup::obsgroup (the PCL templates, local maps): the core's and PCL's.
# OBSGROUP_PCL_TARGETS are what the installed headers include (a user's
# PCL_NO_PRECOMPILE build compiles them); LZ4 is only the compiled library's
# own (refinement's FLANN index), private to it.
macro(obsgroup_find_pcl_dependencies)
  obsgroup_find_pcl(${OBSGROUP_PCL_MINIMUM_VERSION} REQUIRED COMPONENTS common kdtree search filters)
  set(OBSGROUP_PCL_TARGETS pcl_common pcl_kdtree pcl_search pcl_filters)
  # FLANN's index headers (refinement's nearest-point search, src/maps/refinement.cpp)
  # call LZ4 in their serialisation code; libflann-dev brings liblz4-dev along.
  find_library(OBSGROUP_LZ4_LIBRARY NAMES lz4 REQUIRED)
  if(NOT TARGET obsgroup::lz4)
    add_library(obsgroup::lz4 UNKNOWN IMPORTED)
    set_target_properties(obsgroup::lz4 PROPERTIES IMPORTED_LOCATION "${OBSGROUP_LZ4_LIBRARY}")
  endif()
endmacro()
