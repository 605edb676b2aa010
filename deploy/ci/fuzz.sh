#!/usr/bin/env bash
# The libFuzzer targets of fuzz/ (ASan + UBSan, tree build-asan/, shared with deploy/ci/sanitizers.sh):
# each replays its seed corpus (fuzz/corpus/<target>/), then fuzzes for FUZZ_SECONDS (default 20)
# into a scratch copy of it. Executions per target go to build-asan/fuzz-summary.txt; a crash
# leaves its input in build-asan/fuzz-artifacts/ and fails the script.
#
#   deploy/ci/fuzz.sh                 every target
#   deploy/ci/fuzz.sh fuzz_ply_reader one target
set -euo pipefail
cd "$(dirname "$0")/../.."
bash deploy/install-deps.sh
source deploy/ci/common.sh

seconds=${FUZZ_SECONDS:-20}
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(fuzz_ply_reader fuzz_pcd_reader fuzz_cloud_stream fuzz_request_validation fuzz_yaml_config
           fuzz_hses_decode fuzz_rdt_decode)
fi

configure_tree build-asan -DTUBEPICK_SANITIZE=address,undefined -DTUBEPICK_FUZZ=ON
build_targets build-asan "${targets[@]}"

summary=build-asan/fuzz-summary.txt
artifacts=$PWD/build-asan/fuzz-artifacts
scratch=build-asan/fuzz-scratch
mkdir -p "$artifacts" "$scratch"
printf '%-26s %8s %10s %8s\n' target seeds execs corpus > "$summary"
failed=()
for target in "${targets[@]}"; do
  binary=build-asan/fuzz/$target
  seeds=fuzz/corpus/$target
  dict=()
  [ -f "fuzz/dict/$target.dict" ] && dict=(-dict="fuzz/dict/$target.dict")
  # The dictionary's entries are what the input formats use (keywords, field names).
  options=(-rss_limit_mb=2048 -timeout=10 -max_len=65536 "${dict[@]}" -artifact_prefix="$artifacts/$target-")
  echo "== fuzz: $target replays $(ls "$seeds" | wc -l) seeds"
  if ! "$binary" "${options[@]}" -runs=0 "$seeds" > "$scratch/$target.replay.log" 2>&1; then
    tail -n 60 "$scratch/$target.replay.log"
    failed+=("$target (replay)")
    continue
  fi
  rm -rf "${scratch:?}/$target" && cp -r "$seeds" "$scratch/$target"
  echo "== fuzz: $target for ${seconds} s"
  if ! "$binary" "${options[@]}" -max_total_time="$seconds" -print_final_stats=1 \
    "$scratch/$target" > "$scratch/$target.log" 2>&1; then
    tail -n 60 "$scratch/$target.log"
    failed+=("$target")
  fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$scratch/$target.log" | tail -n 1)
  printf '%-26s %8s %10s %8s\n' "$target" "$(ls "$seeds" | wc -l)" "${execs:-?}" \
    "$(ls "$scratch/$target" | wc -l)" >> "$summary"
done
cat "$summary"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: FAILED: ${failed[*]} (inputs in $artifacts)" >&2
  exit 1
fi
echo "fuzz: ${#targets[@]} passed, 0 failed"
