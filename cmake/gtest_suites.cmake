# penumbra_gtest_suites(<target> [LABELS l...] [SKIP_REGEX re]): one ctest test per GoogleTest
# suite of <target> (ctest name = the suite's, e.g. `SinkStageTest` or `Bundled/RealtimeHostPath`;
# command `<target> --gtest_filter=<suite>.*`), where gtest_discover_tests adds one per test.
# why: every test process loads the binary and its shared libraries first (app_tests: 195
# libraries, 0.43 s before the first test), which cost a clean CI run about 190 s of its 2 cores
# over 1,411 processes; a suite's tests share one process, as when the binary runs on its own.
# the suites are listed after every link (POST_BUILD, `--gtest_list_tests`, as
# gtest_discover_tests does) by cmake/gtest_suites_discover.cmake, which also gives each suite
# its COST from PENUMBRA_SUITE_COSTS (so ctest starts the long ones first on a clean clone) and
# TIMEOUT 600. SKIP_REGEX: the suite counts as skipped when its output matches (the `gpu`
# binary's "skipped: no CUDA device").
function(penumbra_gtest_suites target)
  cmake_parse_arguments(S "" "SKIP_REGEX" "LABELS" ${ARGN})
  set(base "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites")
  add_custom_command(
    TARGET ${target} POST_BUILD
    BYPRODUCTS "${base}_tests.cmake"
    COMMAND "${CMAKE_COMMAND}" -D "TEST_EXECUTABLE=$<TARGET_FILE:${target}>"
            -D "CTEST_FILE=${base}_tests.cmake" -D "LABELS=${S_LABELS}"
            -D "SKIP_REGEX=${S_SKIP_REGEX}" -D "COSTS=${PENUMBRA_SUITE_COSTS}"
            -P "${CMAKE_SOURCE_DIR}/cmake/gtest_suites_discover.cmake"
    VERBATIM)
  file(WRITE "${base}_include.cmake"
       "if(EXISTS \"${base}_tests.cmake\")\n"
       "  include(\"${base}_tests.cmake\")\n"
       "else()\n"
       "  add_test(${target}_NOT_BUILT ${target}_NOT_BUILT)\n"
       "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${base}_include.cmake")
endfunction()
