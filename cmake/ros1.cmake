# ROS 1 (roscpp, rosbag_storage and the message headers) from Debian 12's packages (ros-base-dev,
# libroscpp-dev, librosbag-dev, lib*-msgs-dev; scripts/install-deps.sh), for the ros module.
#
# PENUMBRA_WITH_ROS: AUTO (use ROS 1 when found), ON (required), OFF (never). sets
# PENUMBRA_ROS1_FOUND and, when found, defines penumbra_use_ros1(target folder): the folder's
# .cc files are compiled as C++17 (ROS 1's generated message headers use
# std::allocator<void>::rebind, which C++20 removed) and the target links ROS 1 privately.
#
# roscpp's catkin config is used for roscpp itself; rosbag_storage's config pulls in Debian's
# ROS 2 pluginlib (ament, which runs whatever python3 is first on PATH), so rosbag_storage and
# the headers it needs are found by hand.
set(PENUMBRA_ROS1_FOUND OFF)
if(NOT PENUMBRA_WITH_ROS STREQUAL "OFF")
  # roscpp's config adds -DROS_PACKAGE_NAME and -DROSCONSOLE_BACKEND_LOG4CXX to every target of
  # the directory (add_definitions); they are kept off the other modules (whose compile lines,
  # and so their ccache entries, stay as without ROS) and given to the ROS files alone below
  get_directory_property(_penumbra_defs_before COMPILE_DEFINITIONS)
  find_package(roscpp CONFIG QUIET)
  set_directory_properties(PROPERTIES COMPILE_DEFINITIONS "${_penumbra_defs_before}")
  find_path(PENUMBRA_ROSBAG_INCLUDE_DIR rosbag/bag.h)
  find_path(PENUMBRA_PLUGINLIB_INCLUDE_DIR pluginlib/class_loader.hpp PATH_SUFFIXES pluginlib)
  find_path(PENUMBRA_CLASS_LOADER_INCLUDE_DIR class_loader/class_loader.hpp
            PATH_SUFFIXES class_loader)
  find_path(PENUMBRA_RCUTILS_INCLUDE_DIR rcutils/types.h PATH_SUFFIXES rcutils)
  find_path(PENUMBRA_RCPPUTILS_INCLUDE_DIR rcpputils/shared_library.hpp PATH_SUFFIXES rcpputils)
  find_path(PENUMBRA_AMENT_INDEX_INCLUDE_DIR ament_index_cpp/get_resource.hpp
            PATH_SUFFIXES ament_index_cpp)
  find_path(PENUMBRA_ROS_MSGS_INCLUDE_DIR sensor_msgs/Image.h)
  find_path(PENUMBRA_ROS_TF2_MSGS_INCLUDE_DIR tf2_msgs/TFMessage.h)
  find_path(PENUMBRA_ROS_NAV_MSGS_INCLUDE_DIR nav_msgs/Odometry.h)
  find_path(PENUMBRA_ROS_STD_SRVS_INCLUDE_DIR std_srvs/Trigger.h)
  find_path(PENUMBRA_ROS_CLOCK_INCLUDE_DIR rosgraph_msgs/Clock.h)
  find_library(PENUMBRA_ROSBAG_STORAGE_LIB rosbag_storage)
  find_library(PENUMBRA_CONSOLE_BRIDGE_LIB console_bridge)
  find_library(PENUMBRA_CLASS_LOADER_LIB class_loader)
  set(_ros1_parts roscpp_FOUND PENUMBRA_ROSBAG_INCLUDE_DIR PENUMBRA_PLUGINLIB_INCLUDE_DIR
      PENUMBRA_CLASS_LOADER_INCLUDE_DIR PENUMBRA_RCUTILS_INCLUDE_DIR
      PENUMBRA_RCPPUTILS_INCLUDE_DIR PENUMBRA_AMENT_INDEX_INCLUDE_DIR
      PENUMBRA_ROS_MSGS_INCLUDE_DIR PENUMBRA_ROS_TF2_MSGS_INCLUDE_DIR
      PENUMBRA_ROS_NAV_MSGS_INCLUDE_DIR PENUMBRA_ROS_STD_SRVS_INCLUDE_DIR
      PENUMBRA_ROS_CLOCK_INCLUDE_DIR PENUMBRA_ROSBAG_STORAGE_LIB PENUMBRA_CONSOLE_BRIDGE_LIB
      PENUMBRA_CLASS_LOADER_LIB)
  set(_ros1_missing "")
  foreach(part IN LISTS _ros1_parts)
    if(NOT ${part})
      list(APPEND _ros1_missing ${part})
    endif()
  endforeach()
  if(_ros1_missing)
    if(PENUMBRA_WITH_ROS STREQUAL "ON")
      message(FATAL_ERROR "PENUMBRA_WITH_ROS=ON but ROS 1 is incomplete (not found: "
                          "${_ros1_missing}); install the ROS packages of scripts/install-deps.sh")
    endif()
    message(STATUS "ROS 1 not found (${_ros1_missing}): the ROS bridge and rosbag export are off")
  else()
    set(PENUMBRA_ROS1_FOUND ON)
    message(STATUS "ROS 1 found: building the ROS bridge and rosbag export")
    add_library(penumbra_ros1_deps INTERFACE)
    target_include_directories(penumbra_ros1_deps SYSTEM INTERFACE
      ${roscpp_INCLUDE_DIRS} ${PENUMBRA_ROSBAG_INCLUDE_DIR} ${PENUMBRA_PLUGINLIB_INCLUDE_DIR}
      ${PENUMBRA_CLASS_LOADER_INCLUDE_DIR} ${PENUMBRA_RCUTILS_INCLUDE_DIR}
      ${PENUMBRA_RCPPUTILS_INCLUDE_DIR} ${PENUMBRA_AMENT_INDEX_INCLUDE_DIR})
    target_link_libraries(penumbra_ros1_deps INTERFACE ${roscpp_LIBRARIES}
      ${PENUMBRA_ROSBAG_STORAGE_LIB} ${PENUMBRA_CONSOLE_BRIDGE_LIB} ${PENUMBRA_CLASS_LOADER_LIB})
    target_compile_definitions(penumbra_ros1_deps INTERFACE ROSCONSOLE_BACKEND_LOG4CXX
                               ROS_PACKAGE_NAME="penumbra")
  endif()
endif()

function(penumbra_use_ros1 target folder)
  file(GLOB ros1_srcs CONFIGURE_DEPENDS ${folder}/*.cc)
  # the last -std wins: these files are C++17, the rest of the target C++20
  set_source_files_properties(${ros1_srcs} PROPERTIES COMPILE_OPTIONS "-std=c++17")
  target_link_libraries(${target} PRIVATE penumbra_ros1_deps)
endfunction()
