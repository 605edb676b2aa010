#!/usr/bin/env bash
# Installs every Debian package tubepick needs to build, test and run, then the npm tools
# (deploy/install-tools.sh: buf for the proto lint and the smoke test).
# Non-interactive and idempotent: safe to run again; it only installs what is missing.
# The Dockerfile and CI (.ci/run) call this very script, so the three never drift apart.
#
#   deploy/install-deps.sh            build + test dependencies and the npm tools (CI, developers,
#                                     the Dockerfile's build stage)
#   deploy/install-deps.sh --runtime  only the shared libraries tubepick-server and tubepick load at
#                                     run time (the Dockerfile's runtime stage); no compiler, no npm
set -euo pipefail

mode=build
case "${1:-}" in
  "") ;;
  --runtime) mode=runtime ;;
  *) echo "usage: $0 [--runtime]" >&2; exit 2 ;;
esac

if [ "$mode" = runtime ]; then
  # What `ldd build/bin/tubepick-server build/bin/tubepick` resolves to on bookworm (their other
  # libraries — abseil, re2, c-ares, ... — come in as dependencies of these).
  packages=(
    ca-certificates
    libgrpc++1.51 libprotobuf32
    libpcl-common1.13 libpcl-kdtree1.13
    libbullet3.24
    libspdlog1.10 libfmt9 libyaml-cpp0.7 libmodbus5 libcurl4 libgomp1 libssl3 libjemalloc2
  )
else
  packages=(
    build-essential cmake ninja-build ccache pkg-config git ca-certificates
    clang-format
    libeigen3-dev libpcl-dev libbullet-dev libbullet-extras-dev
    libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
    libspdlog-dev libfmt-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev
    libmodbus-dev libcurl4-openssl-dev libgtest-dev libgmock-dev libbenchmark-dev
    libjemalloc-dev
    openssl curl
    # deploy/ci/sanitizers.sh and fuzz.sh: clang with its sanitizer and libFuzzer runtimes, its
    # OpenMP, and llvm-symbolizer for the stack traces.
    clang libclang-rt-dev libomp-dev llvm
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
