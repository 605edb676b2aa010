#!/usr/bin/env bash
# The unit suites of core, wire and server under ASan + UBSan (tree build-asan/, which also holds
# the fuzz targets of deploy/ci/fuzz.sh), then the server tests and the service suites of our own
# threads under TSan (tree build-tsan/).
# Each tree builds only what its tests need. Timings go to build-asan/sanitizers-summary.txt.
#
#   deploy/ci/sanitizers.sh          both
#   deploy/ci/sanitizers.sh asan     only ASan + UBSan
#   deploy/ci/sanitizers.sh tsan     only TSan
set -euo pipefail
cd "$(dirname "$0")/../.."
what=${1:-all}
case "$what" in all | asan | tsan) ;; *) echo "usage: $0 [all|asan|tsan]" >&2; exit 2 ;; esac
bash deploy/install-deps.sh
source deploy/ci/common.sh

summary=build-asan/sanitizers-summary.txt
mkdir -p build-asan
: > "$summary"
step() {  # step NAME COMMAND...: runs, times and records one step
  local name=$1 start
  shift
  start=$(now)
  echo "== sanitizers: $name"
  "$@"
  echo "$name: $(($(now) - start)) s" | tee -a "$summary"
}

# run_tests TREE SUITE [CTEST_ARGS...]: the tests of one executable (each is labelled with it).
run_tests() {
  ctest --test-dir "$1" -L "^$2\$" --output-on-failure -j "${JOBS:-2}" --timeout 900 "${@:3}"
}

if [ "$what" != tsan ]; then
  step "asan configure" configure_tree build-asan -DTUBEPICK_SANITIZE=address,undefined -DTUBEPICK_FUZZ=ON
  step "asan build (core_test wire_test server_test fuzz_targets)" \
    build_targets build-asan core_test wire_test server_test fuzz_targets
  step "asan core_test" run_tests build-asan core_test
  step "asan wire_test" run_tests build-asan wire_test
  step "asan server_test" run_tests build-asan server_test
fi

if [ "$what" != asan ]; then
  # TSan runs what meets on our own threads: server_test (planning jobs: the simulation's worker
  # threads, stops from another thread) and the service_test suites of the worker pool, metrics,
  # their HTTP endpoint and the request log. The gRPC call suites stay out: gRPC is not
  # instrumented, so its hand-offs between threads look like races (deploy/ci/tsan.supp says why).
  # OpenMP's runtime is not instrumented either: the TSan tree compiles the OpenMP pragmas out
  # (cmake/TubepickSanitizers.cmake); the simulation threads are ours and stay on.
  export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1:ignore_noninstrumented_modules=1:suppressions=$PWD/deploy/ci/tsan.supp}
  step "tsan configure" configure_tree build-tsan -DTUBEPICK_SANITIZE=thread
  step "tsan build (server_test service_test)" build_targets build-tsan server_test service_test
  step "tsan server_test" run_tests build-tsan server_test
  step "tsan service_test (WorkerPool, UploadSlots, UploadWatchdog, Metrics, HttpEndpoints, RequestLog)" \
    run_tests build-tsan service_test -R '^(WorkerPool|UploadSlots|UploadWatchdog|Metrics|HttpEndpoints|RequestLog)\.'
fi
cat "$summary"
