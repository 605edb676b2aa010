#!/usr/bin/env bash
# Installs the Debian dependencies (if missing), configures and builds tubepick into build/.
# Used by the README and CI (.ci/run via deploy/test.sh); the Dockerfile's build stage runs it with
# --image.
#
#   deploy/build.sh          everything: libraries, binaries, tests, benchmarks
#   deploy/build.sh --image  only what the image ships (tubepick-server, tubepick): no tests, no
#                            benchmarks, and only the build dependencies those need
set -euo pipefail
cd "$(dirname "$0")/.."
targets=()
case "${1:-}" in
  "")
    bash deploy/install-deps.sh
    ;;
  --image)
    bash deploy/install-deps.sh --image-build
    TUBEPICK_CMAKE_ARGS="-DTUBEPICK_BUILD_TESTS=OFF -DTUBEPICK_BUILD_BENCHMARKS=OFF ${TUBEPICK_CMAKE_ARGS:-}"
    targets=(--target tubepick-server tubepick)
    ;;
  *) echo "usage: $0 [--image]" >&2; exit 2 ;;
esac
# ccache keys on paths relative to the checkout, and on the locale (it changes the compiler's
# messages): both the same wherever this runs, so that a build in another directory or environment
# (the image's /src, a second clone) hits what this one compiled.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$PWD}
export LANG=C.UTF-8
unset LC_ALL LC_CTYPE LC_MESSAGES
BUILD_DIR=${BUILD_DIR:-build}
BUILD_TYPE=${BUILD_TYPE:-Release}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE="$BUILD_TYPE" ${TUBEPICK_CMAKE_ARGS:-} > "$BUILD_DIR.configure.log" 2>&1 \
  || { cat "$BUILD_DIR.configure.log"; exit 1; }
cmake --build "$BUILD_DIR" -j "$(nproc)" "${targets[@]}"
