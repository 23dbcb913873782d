# ROS 2 over Eclipse Cyclone DDS (Debian's cyclonedds-dev and cyclonedds-tools; ROS 2 itself is
# not needed), for the ros module: the ROS 2 bridge and the rosbag2 export.
#
# PENUMBRA_WITH_ROS2: AUTO (use ROS 2 when found), ON (required), OFF (never). ROS 2 needs
#   - Cyclone DDS's C library (CMake package CycloneDDS, target CycloneDDS::ddsc),
#   - its IDL compiler idlc,
#   - the python of the project venv PENUMBRA_VENV (default .venv, made by
#     scripts/install-deps.sh) with the rosbags package, whose ROS 2 Jazzy message definitions
#     scripts/ros2_idl.py turns into ros2_msgs.idl and the type table ros2_types.inc.
# sets PENUMBRA_ROS2_FOUND and, when found, the library penumbra_ros2_msgs (idlc's C types of
# ros2_msgs.idl, linked to CycloneDDS::ddsc) and penumbra_use_ros2(target folder), which links a
# target to it privately (the generated headers are in its include path).
set(PENUMBRA_ROS2_FOUND OFF)
if(NOT PENUMBRA_WITH_ROS2 STREQUAL "OFF")
  find_package(CycloneDDS CONFIG QUIET)
  find_program(PENUMBRA_IDLC idlc)
  set(_ros2_python "${PENUMBRA_VENV}/bin/python")
  set(_ros2_missing "")
  if(NOT CycloneDDS_FOUND OR NOT TARGET CycloneDDS::ddsc)
    list(APPEND _ros2_missing "Cyclone DDS (cyclonedds-dev)")
  endif()
  if(NOT PENUMBRA_IDLC)
    list(APPEND _ros2_missing "idlc (cyclonedds-tools)")
  endif()
  if(EXISTS "${_ros2_python}")
    execute_process(COMMAND "${_ros2_python}" -c "import rosbags.typesys"
                    RESULT_VARIABLE _ros2_rosbags_rc OUTPUT_QUIET ERROR_QUIET)
    if(NOT _ros2_rosbags_rc EQUAL 0)
      list(APPEND _ros2_missing "rosbags in ${PENUMBRA_VENV}")
    endif()
  else()
    list(APPEND _ros2_missing "the venv ${PENUMBRA_VENV}")
  endif()
  if(_ros2_missing)
    if(PENUMBRA_WITH_ROS2 STREQUAL "ON")
      message(FATAL_ERROR "PENUMBRA_WITH_ROS2=ON but ROS 2 is incomplete (not found: "
                          "${_ros2_missing}); run scripts/install-deps.sh")
    endif()
    message(STATUS "ROS 2 not found (${_ros2_missing}): the ROS 2 bridge and rosbag2 export "
                   "are off")
  else()
    set(PENUMBRA_ROS2_FOUND ON)
    message(STATUS "ROS 2 found (Cyclone DDS ${CycloneDDS_VERSION}): building the ROS 2 bridge "
                   "and rosbag2 export")
    enable_language(C)
    set(_ros2_gen "${CMAKE_BINARY_DIR}/generated/ros2")
    # regenerated when the script or rosbags' Jazzy store changes (a pip upgrade of rosbags)
    file(GLOB _ros2_store CONFIGURE_DEPENDS
         "${PENUMBRA_VENV}/lib/python3*/site-packages/rosbags/typesys/stores/ros2_jazzy.py")
    add_custom_command(
      OUTPUT ${_ros2_gen}/ros2_msgs.idl ${_ros2_gen}/ros2_types.inc
      COMMAND "${_ros2_python}" ${CMAKE_SOURCE_DIR}/scripts/ros2_idl.py
              --idl ${_ros2_gen}/ros2_msgs.idl --inc ${_ros2_gen}/ros2_types.inc
      DEPENDS ${CMAKE_SOURCE_DIR}/scripts/ros2_idl.py ${PENUMBRA_VENV}/pyvenv.cfg ${_ros2_store}
      COMMENT "ROS 2 message types from rosbags' Jazzy definitions (scripts/ros2_idl.py)"
      VERBATIM)
    # -Wno-implicit-extensibility: ROS 2's types are final (rmw_cyclonedds's are), idlc's default
    add_custom_command(
      OUTPUT ${_ros2_gen}/ros2_msgs.c ${_ros2_gen}/ros2_msgs.h
      COMMAND ${PENUMBRA_IDLC} -Wno-implicit-extensibility -o ${_ros2_gen}
              ${_ros2_gen}/ros2_msgs.idl
      DEPENDS ${_ros2_gen}/ros2_msgs.idl ${PENUMBRA_IDLC}
      COMMENT "idlc ros2_msgs.idl"
      VERBATIM)
    add_library(penumbra_ros2_msgs STATIC ${_ros2_gen}/ros2_msgs.c ${_ros2_gen}/ros2_msgs.h
                ${_ros2_gen}/ros2_types.inc)
    set_target_properties(penumbra_ros2_msgs PROPERTIES POSITION_INDEPENDENT_CODE ON)
    target_include_directories(penumbra_ros2_msgs SYSTEM PUBLIC ${_ros2_gen})
    target_link_libraries(penumbra_ros2_msgs PUBLIC CycloneDDS::ddsc)
  endif()
else()
  message(STATUS "ROS 2 off (PENUMBRA_WITH_ROS2=OFF): the ROS 2 bridge and rosbag2 export are off")
endif()

# the folder's .cc files are compiled one by one, outside the target's unity batches: Cyclone
# DDS's C headers (macros, short names) stay out of the other files
function(penumbra_use_ros2 target folder)
  file(GLOB ros2_srcs CONFIGURE_DEPENDS ${folder}/*.cc)
  set_source_files_properties(${ros2_srcs} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
  target_link_libraries(${target} PRIVATE penumbra_ros2_msgs)
endfunction()
