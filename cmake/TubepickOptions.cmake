# Per-target options: C++20, warnings, no global flags.
function(tubepick_set_options target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF POSITION_INDEPENDENT_CODE ON)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(TUBEPICK_PCH)
    target_precompile_headers(${target} PRIVATE <algorithm> <cmath> <string> <vector> <Eigen/Core>
                              <Eigen/Geometry>)
  endif()
endfunction()

# Precompiled headers (Eigen, the standard library, GoogleTest): off by default (ccache caches the
# normal build better without them); the sanitizer trees, built cold, turn them on
# (deploy/ci/common.sh). Parsing these headers is most of the time of a small file.
option(TUBEPICK_PCH "Precompile the most included third-party headers in every target" OFF)

# One GoogleTest executable per module: tubepick_add_test(NAME SOURCES ... LIBS ...). Each test is
# labelled with its executable's name, so `ctest -L '^core_test$'` runs one suite (the sanitizer
# trees build only some executables; deploy/ci/sanitizers.sh).
function(tubepick_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  tubepick_set_options(${name})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gmock GTest::gtest_main)
  if(TUBEPICK_PCH)
    target_precompile_headers(${name} PRIVATE <gtest/gtest.h> <gmock/gmock.h>)
  endif()
  gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR} PROPERTIES TIMEOUT 600 LABELS ${name})
endfunction()

# ccache, when installed (deploy/install-deps.sh installs it), makes rebuilds of unchanged sources
# cheap for developers and for CI runs on a machine that built before. -DCMAKE_CXX_COMPILER_LAUNCHER=
# (empty) turns it off.
find_program(TUBEPICK_CCACHE ccache)
if(TUBEPICK_CCACHE AND NOT DEFINED CMAKE_CXX_COMPILER_LAUNCHER)
  set(CMAKE_CXX_COMPILER_LAUNCHER ${TUBEPICK_CCACHE})
endif()
