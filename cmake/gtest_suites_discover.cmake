# cmake -P script (cmake/gtest_suites.cmake runs it after each link of a test binary): lists the
# GoogleTest suites of TEST_EXECUTABLE and writes CTEST_FILE with one add_test per suite.
# inputs: TEST_EXECUTABLE, CTEST_FILE, LABELS (list), SKIP_REGEX, COSTS (list: suite seconds ...).
execute_process(COMMAND "${TEST_EXECUTABLE}" --gtest_list_tests
                OUTPUT_VARIABLE listing ERROR_VARIABLE errors RESULT_VARIABLE rc TIMEOUT 60)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${TEST_EXECUTABLE} --gtest_list_tests failed (${rc}): ${errors}")
endif()
set(costs ${COSTS})
set(content "")
string(REPLACE "\n" ";" lines "${listing}")
foreach(line IN LISTS lines)
  # a suite line: "Suite." or "Prefix/Suite.  # TypeParam = ..." (tests are indented)
  if(line MATCHES "^([A-Za-z0-9_/]+)\\.( .*)?$")
    set(suite "${CMAKE_MATCH_1}")
    string(APPEND content
           "add_test([==[${suite}]==] [==[${TEST_EXECUTABLE}]==] [==[--gtest_filter=${suite}.*]==])\n"
           "set_tests_properties([==[${suite}]==] PROPERTIES TIMEOUT 600")
    if(LABELS)
      string(APPEND content " LABELS [==[${LABELS}]==]")
    endif()
    if(SKIP_REGEX)
      string(APPEND content " SKIP_REGULAR_EXPRESSION [==[${SKIP_REGEX}]==]")
    endif()
    list(FIND costs "${suite}" at)
    if(at GREATER -1)
      math(EXPR at "${at} + 1")
      list(GET costs ${at} cost)
      string(APPEND content " COST ${cost}")
    endif()
    string(APPEND content ")\n")
  endif()
endforeach()
file(WRITE "${CTEST_FILE}" "${content}")
