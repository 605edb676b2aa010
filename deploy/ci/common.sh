# Shared by deploy/ci/sanitizers.sh and deploy/ci/fuzz.sh (sourced, not run).
#
# Sanitizer trees are clang builds at -O1 with line tables only (stack traces with file:line, a
# fraction of full debug info), precompiled headers, the benchmarks off, and the tree-wide options of
# cmake/TubepickSanitizers.cmake. Only the targets a check needs are built (see the callers).
#
# The compiler cache serves these trees too, on a machine that built the same sources in the same
# checkout path before: clang's precompiled headers then carry no timestamp (-fno-pch-timestamp),
# and the cache accepts a header built during the build (the sloppiness below, as ccache's manual
# asks for precompiled headers). A precompiled header records the checkout's absolute path, so a
# clone elsewhere compiles its sanitizer trees afresh (measured on wire_test's 82 compiles: 261 s
# cold, 4 s again in the same path, no hits from another path).
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$PWD}
export CCACHE_SLOPPINESS=${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}
export LANG=C.UTF-8 # the cache keys on the locale, as deploy/build.sh says
unset LC_ALL LC_CTYPE LC_MESSAGES

# configure_tree DIR CMAKE_ARGS...: configures DIR unless it is configured already.
configure_tree() {
  local dir=$1
  shift
  cmake -S . -B "$dir" -G Ninja \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=Debug \
    "-DCMAKE_C_FLAGS_DEBUG=-O1 -gline-tables-only" "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -gline-tables-only" \
    "-DCMAKE_CXX_FLAGS=-Xclang -fno-pch-timestamp" \
    -DTUBEPICK_BUILD_BENCHMARKS=OFF -DTUBEPICK_PCH=ON "$@" > "$dir.configure.log" 2>&1 || {
    cat "$dir.configure.log"
    exit 1
  }
}

# Two cores are shared with whoever else builds: JOBS=2 unless told otherwise, at low priority.
build_targets() {
  local dir=$1
  shift
  nice -n 10 cmake --build "$dir" -j "${JOBS:-2}" --target "$@"
}

# Seconds since the epoch, for the timings each script prints.
now() { date +%s; }

# ASan + UBSan: stop at the first error, with a stack trace; leaks count as errors.
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
