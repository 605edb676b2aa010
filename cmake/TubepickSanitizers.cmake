# Sanitizer and fuzzing builds (deploy/ci/sanitizers.sh, deploy/ci/fuzz.sh).
#
#   -DTUBEPICK_SANITIZE=address,undefined   ASan + UBSan (the unit suites and the fuzz targets)
#   -DTUBEPICK_SANITIZE=thread              TSan (the service tests)
#   -DTUBEPICK_FUZZ=ON                      the libFuzzer targets in fuzz/ (clang only)
#
# Unlike warnings and the standard (per target, tubepick_set_options), instrumentation is a property
# of the whole build tree: a target built without it would hide errors (ASan) or report false races
# (TSan). So these are the only tree-wide flags, and only when asked for.
set(TUBEPICK_SANITIZE "" CACHE STRING
  "Sanitizers for every target of this build tree: address,undefined | thread | (empty: none)")
option(TUBEPICK_FUZZ "Build the libFuzzer targets in fuzz/ (needs clang)" OFF)

if(TUBEPICK_SANITIZE)
  add_compile_options(-fsanitize=${TUBEPICK_SANITIZE} -fno-omit-frame-pointer)
  add_link_options(-fsanitize=${TUBEPICK_SANITIZE})
  if(TUBEPICK_SANITIZE MATCHES "undefined")
    # Any undefined behaviour fails the test or the fuzz run instead of printing and going on.
    add_compile_options(-fno-sanitize-recover=undefined)
  endif()
endif()

if(TUBEPICK_SANITIZE MATCHES "thread" AND TARGET OpenMP::OpenMP_CXX)
  # libgomp / libomp are not instrumented: TSan would take their barriers for races. A TSan tree
  # compiles the OpenMP pragmas out (every region runs on the calling thread) and still links the
  # runtime for the omp_* calls; our own threads (the worker pool, the upload watchdog, the Bullet
  # trajectory workers) are what it checks.
  set_property(TARGET OpenMP::OpenMP_CXX PROPERTY INTERFACE_COMPILE_OPTIONS -Wno-unknown-pragmas)
endif()

if(TUBEPICK_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "TUBEPICK_FUZZ needs clang (libFuzzer): -DCMAKE_CXX_COMPILER=clang++")
  endif()
  # Coverage feedback for libFuzzer, compiled into the sources that read fuzzed input only
  # (fuzz/coverage.allowlist): the unit tests of the same tree keep their speed. Only the fuzz
  # executables link the fuzzer's main (-fsanitize=fuzzer, fuzz/CMakeLists.txt).
  add_compile_options(-fsanitize=fuzzer-no-link
                      -fsanitize-coverage-allowlist=${PROJECT_SOURCE_DIR}/fuzz/coverage.allowlist)
endif()
