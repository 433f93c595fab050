# Helpers so that a core module, a tool or a test suite is one call (docs/developing.md "Layout").

# Warnings for every skybake target.
add_library(skybake_warnings INTERFACE)
target_compile_options(skybake_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wno-unused-parameter)
if(SKYBAKE_SANITIZE)
  target_compile_options(skybake_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer)
  target_link_options(skybake_warnings INTERFACE -fsanitize=address,undefined)
  # Any UBSan finding fails the run (a report is otherwise only a message).
  target_compile_options(skybake_warnings INTERFACE -fno-sanitize-recover=undefined)
endif()
if(SKYBAKE_FUZZ)
  # Coverage instrumentation for libFuzzer in every skybake target (fuzz targets link -fsanitize=fuzzer).
  target_compile_options(skybake_warnings INTERFACE -fsanitize=fuzzer-no-link)
endif()

# skybake_add_core_module(NAME <module> DEPS <targets...>)
# Builds tools/core/<module>/*.cpp into the static library skybake_<module>.
function(skybake_add_core_module)
  cmake_parse_arguments(ARG "" "NAME" "DEPS" ${ARGN})
  file(GLOB _src CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${ARG_NAME}/*.cpp)
  if(NOT _src)
    # A header-only module (or one whose sources are still being written).
    add_library(skybake_${ARG_NAME} INTERFACE)
    target_include_directories(skybake_${ARG_NAME} INTERFACE ${CMAKE_SOURCE_DIR}/tools/core ${CMAKE_BINARY_DIR}/generated)
    target_link_libraries(skybake_${ARG_NAME} INTERFACE ${ARG_DEPS})
    return()
  endif()
  add_library(skybake_${ARG_NAME} STATIC ${_src})
  target_include_directories(skybake_${ARG_NAME} PUBLIC ${CMAKE_SOURCE_DIR}/tools/core ${CMAKE_BINARY_DIR}/generated)
  target_link_libraries(skybake_${ARG_NAME} PUBLIC ${ARG_DEPS} PRIVATE skybake_warnings)
endfunction()

# skybake_add_tool(NAME <tool> [SOURCES ...] DEPS <core modules...>)
# A tool is tools/<tool>/*.cpp (main.cpp plus the tool's own helpers).
function(skybake_add_tool)
  cmake_parse_arguments(ARG "" "NAME" "DEPS" ${ARGN})
  file(GLOB _src CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  add_executable(${ARG_NAME} ${_src})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS} skybake_warnings)
endfunction()

# skybake_add_test_suite(NAME <suite> DEPS <targets...> [VALIDATION <Suite.Test...>])
# tests/<suite>/*_test.cpp -> one GoogleTest binary test_<suite>, registered per test case with the
# label `unit`. VALIDATION names the long validation tests (over ~20 s on 2 cores, mostly against
# the path tracer): they carry the label `validation` instead, so that `ctest -L unit` stays fast;
# `ctest` and scripts/test without a label run both.
function(skybake_add_test_suite)
  cmake_parse_arguments(ARG "" "NAME" "DEPS;VALIDATION" ${ARGN})
  file(GLOB _src CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${ARG_NAME}/*_test.cpp)
  add_executable(test_${ARG_NAME} ${_src})
  target_link_libraries(test_${ARG_NAME} PRIVATE ${ARG_DEPS} GTest::gtest_main skybake_warnings)
  # tests/support: helpers shared by the suites (support/threads.h, support/log.h).
  target_include_directories(test_${ARG_NAME} PRIVATE ${CMAKE_SOURCE_DIR}/tests)
  target_compile_definitions(test_${ARG_NAME} PRIVATE
    SKYBAKE_SOURCE_DIR="${CMAKE_SOURCE_DIR}" SKYBAKE_BIN_DIR="${CMAKE_BINARY_DIR}/bin")
  if(ARG_VALIDATION)
    list(JOIN ARG_VALIDATION ":" _validation)
    gtest_discover_tests(test_${ARG_NAME} DISCOVERY_TIMEOUT 60 TEST_FILTER "-${_validation}" PROPERTIES LABELS unit)
    gtest_discover_tests(test_${ARG_NAME} DISCOVERY_TIMEOUT 60 TEST_FILTER "${_validation}" PROPERTIES LABELS validation)
  else()
    gtest_discover_tests(test_${ARG_NAME} DISCOVERY_TIMEOUT 60 PROPERTIES LABELS unit)
  endif()
endfunction()
