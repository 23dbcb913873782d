# MuJoCo 4 from DeepMind's official wheel (`mujoco` on PyPI, whose `mujoco-core` carries
# libmujoco and its C headers), pinned in scripts/requirements.txt and installed into the project
# venv by scripts/install-deps.sh. defines the imported target mujoco::mujoco and
# PENUMBRA_MUJOCO_DIR (the wheel's package folder: plugin/, testdata/, include/).
# -DPENUMBRA_MUJOCO_DIR=DIR takes another folder with include/mujoco/mujoco.h and libmujoco.so.*.
set(PENUMBRA_MUJOCO_VERSION 4.0.0)
if(NOT PENUMBRA_MUJOCO_DIR)
  if(NOT EXISTS ${PENUMBRA_VENV}/bin/python)
    message(FATAL_ERROR "MuJoCo: no venv at ${PENUMBRA_VENV} (PENUMBRA_VENV); run "
                        "`bash scripts/install-deps.sh`, which installs mujoco==${PENUMBRA_MUJOCO_VERSION} "
                        "into it, or configure with -DPENUMBRA_MUJOCO_DIR=<folder of the mujoco package>")
  endif()
  # finds the package folder without importing it (importing pulls in numpy and glfw)
  execute_process(
    COMMAND ${PENUMBRA_VENV}/bin/python -c
            "import importlib.util as u; s = u.find_spec('mujoco'); print(s.submodule_search_locations[0] if s else '')"
    OUTPUT_VARIABLE _mj_dir OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _mj_rc)
  if(NOT _mj_rc EQUAL 0 OR NOT _mj_dir)
    message(FATAL_ERROR "MuJoCo: the venv ${PENUMBRA_VENV} has no `mujoco` package; run "
                        "`bash scripts/install-deps.sh` (it pins mujoco==${PENUMBRA_MUJOCO_VERSION})")
  endif()
  set(PENUMBRA_MUJOCO_DIR ${_mj_dir} CACHE PATH "the mujoco wheel's package folder" FORCE)
endif()
set(_mj_header ${PENUMBRA_MUJOCO_DIR}/include/mujoco/mujoco.h)
file(GLOB _mj_libs ${PENUMBRA_MUJOCO_DIR}/libmujoco.so.*)
if(NOT EXISTS ${_mj_header} OR NOT _mj_libs)
  message(FATAL_ERROR "MuJoCo: ${PENUMBRA_MUJOCO_DIR} lacks include/mujoco/mujoco.h or libmujoco.so.*: "
                      "the `mujoco-core` wheel is missing or broken; run `bash scripts/install-deps.sh`")
endif()
file(STRINGS ${_mj_header} _mj_ver_line REGEX "^#define mjVERSION_HEADER")
string(REGEX MATCH "[0-9]+" _mj_ver "${_mj_ver_line}")
if(_mj_ver LESS 4000000)
  message(FATAL_ERROR "MuJoCo: ${_mj_header} is version ${_mj_ver}; Penumbra needs ${PENUMBRA_MUJOCO_VERSION} "
                      "(scripts/requirements.txt)")
endif()
list(GET _mj_libs 0 _mj_lib)
add_library(mujoco::mujoco SHARED IMPORTED)
set_target_properties(mujoco::mujoco PROPERTIES
  IMPORTED_LOCATION ${_mj_lib}
  IMPORTED_NO_SONAME OFF
  INTERFACE_INCLUDE_DIRECTORIES ${PENUMBRA_MUJOCO_DIR}/include)
message(STATUS "MuJoCo ${_mj_ver}: ${_mj_lib}")
