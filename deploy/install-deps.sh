#!/usr/bin/env bash
# Installs every Debian package tubepick needs to build, test and run, then the npm tools
# (deploy/install-tools.sh: buf for the proto lint and the smoke test).
# Non-interactive and idempotent: safe to run again; it only installs what is missing.
# The Dockerfile and CI (.ci/run) call this very script, so the three never drift apart.
#
#   deploy/install-deps.sh                build + test dependencies (chromium for the viewer's browser
#                                         test included) and the npm packages (CI, developers)
#   deploy/install-deps.sh --image-build  only what compiles the two shipped binaries (the Dockerfile's
#                                         build stage): no test, benchmark or sanitizer tooling, no npm
#   deploy/install-deps.sh --runtime      only the shared libraries tubepick-server and tubepick load at
#                                         run time (the Dockerfile's runtime stage); no compiler, no npm
#   deploy/install-deps.sh --image-tools  what deploy/test-image.sh runs on the host: podman, debootstrap
#                                         (the base images), HAProxy (the gRPC proxy), PyYAML (compose)
set -euo pipefail

mode=build
case "${1:-}" in
  "") ;;
  --image-build) mode=image-build ;;
  --runtime) mode=runtime ;;
  --image-tools) mode=image-tools ;;
  *) echo "usage: $0 [--image-build | --runtime | --image-tools]" >&2; exit 2 ;;
esac

# The libraries the two binaries compile against (also the heart of the full build).
library_dev_packages=(
  libeigen3-dev libpcl-dev libbullet-dev libbullet-extras-dev
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libspdlog-dev libfmt-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev
  libmodbus-dev libcurl4-openssl-dev libjemalloc-dev libcpp-httplib-dev
)

if [ "$mode" = image-tools ]; then
  packages=(podman debootstrap haproxy python3-yaml curl)
elif [ "$mode" = image-build ]; then
  packages=(g++ make cmake ninja-build ccache pkg-config ca-certificates "${library_dev_packages[@]}")
elif [ "$mode" = runtime ]; then
  # The packages of the libraries `readelf -d build/bin/tubepick-server build/bin/tubepick` lists as
  # NEEDED on bookworm; what those load in turn (abseil, re2, c-ares, OpenSSL, FLANN, ...) comes in
  # as their dependencies. deploy/test-image.sh checks with ldd that nothing is missing.
  packages=(
    libgrpc++1.51 libprotobuf32
    libpcl-kdtree1.13
    libbullet3.24
    libspdlog1.10 libfmt9 libyaml-cpp0.7 libcurl4 libgomp1 libjemalloc2
    libmodbus5  # tubepick: the Robotiq driver of `tubepick cell --devices` and `virtual-cell`
    libcpp-httplib0.11  # tubepick-server: /metrics, /healthz, /debug/calls
  )
else
  packages=(
    build-essential cmake ninja-build ccache pkg-config git ca-certificates
    clang-format
    "${library_dev_packages[@]}"
    libgtest-dev libgmock-dev libbenchmark-dev
    openssl curl
    # deploy/ci/sanitizers.sh and fuzz.sh: clang with its sanitizer and libFuzzer runtimes, its
    # OpenMP, and llvm-symbolizer for the stack traces.
    clang libclang-rt-dev libomp-dev llvm
    # tests/viewer_browser.sh: the 3-D pages in a real headless browser (playwright-core drives it)
    chromium
  )
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} $mode packages present"
else
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  echo "install-deps: installing ${missing[*]}"
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if [ "$mode" = build ]; then
  bash "$(dirname "$0")/install-tools.sh"
fi
