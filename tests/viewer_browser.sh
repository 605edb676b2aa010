#!/usr/bin/env bash
# The 3-D viewer in a real browser: Debian's chromium, driven by playwright-core from viewer/'s npm
# lock (viewer/test/check-page.mjs). Each page must load with no console error, draw a canvas that
# is not blank, show the tube and plan counts of its own JSON, and select a plan's tube on a click
# (in the table and in 3-D). Pages checked, as a user gets them:
#   1. `tubepick view` of the built-in scene, planned in-process
#   2. `tubepick view --plan` of the JSON `tubepick plan --json` wrote for that cloud, and of one
#      planned with a cell that understates the tube length (the modeling's warning shown)
#   3. a round page of `tubepick cell --sim --view DIR` (frames stepped through)
#   4. a running tubepick-server with debug.keep_last: /debug/calls, then the newest call's page
# Screenshots go to ARTIFACTS (default: build/artifacts/viewer) for a person to look at.
#
# Usage: tests/viewer_browser.sh TUBEPICK_SERVER TUBEPICK_CLI [ARTIFACTS]   (ctest passes them)
set -euo pipefail
SERVER=${1:?usage: viewer_browser.sh TUBEPICK_SERVER TUBEPICK_CLI [ARTIFACTS]}
CLI=${2:?usage: viewer_browser.sh TUBEPICK_SERVER TUBEPICK_CLI [ARTIFACTS]}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
ARTIFACTS=${3:-$ROOT/build/artifacts/viewer}
CHECK=$ROOT/viewer/test/check-page.mjs
export CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
[ -x "$CHROMIUM" ] || { echo "viewer_browser: $CHROMIUM missing: run deploy/install-deps.sh" >&2; exit 1; }
[ -d "$ROOT/viewer/node_modules/playwright-core" ] || {
  echo "viewer_browser: viewer/node_modules missing: run deploy/install-tools.sh" >&2
  exit 1
}
mkdir -p "$ARTIFACTS"
WORK=$(mktemp -d "${TMPDIR:-/tmp}/tubepick-viewer.XXXXXX")
SERVER_PID=""
cleanup() {
  if [ -n "$SERVER_PID" ] && kill -0 "$SERVER_PID" 2>/dev/null; then kill -KILL "$SERVER_PID" 2>/dev/null || true; fi
  rm -rf "$WORK"
}
trap cleanup EXIT
step() { echo "viewer_browser: $*"; }
fail() {
  echo "viewer_browser: FAIL: $*" >&2
  [ -f "$WORK/server.log" ] && tail -n 30 "$WORK/server.log" >&2
  exit 1
}
check() { # PAGE SCREENSHOT [--list]
  timeout 180 node "$CHECK" --page "$1" --screenshot "$ARTIFACTS/$2" "${@:3}" || fail "page check of $1"
}

step "1. tubepick view of the built-in scene (planned here)"
"$CLI" view --no-sim --out "$WORK/scene.html" || fail "tubepick view"
check "$WORK/scene.html" view-planned.png

step "2. tubepick view --plan of tubepick plan --json"
"$CLI" plan --no-sim --seed 3 --json "$WORK/plan.json" >/dev/null || fail "tubepick plan"
"$CLI" view --seed 3 --plan "$WORK/plan.json" --out "$WORK/from-plan.html" || fail "tubepick view --plan"
check "$WORK/from-plan.html" view-from-plan.png
# A plan drawn over another cloud would mislead: refused, naming both point counts.
if "$CLI" view --seed 4 --plan "$WORK/plan.json" --out "$WORK/wrong.html" 2>"$WORK/wrong.err"; then
  fail "a plan of another cloud was accepted"
fi
grep -q "was made from a cloud of" "$WORK/wrong.err" || fail "unexpected message: $(cat "$WORK/wrong.err")"

step "2b. a plan whose cell understates its tubes' length shows the modeling's warning"
"$CLI" scene --tubes 6 --seed 3 --out "$WORK/short" >/dev/null || fail "tubepick scene"
sed 's/^  length: 0\.5 /  length: 0.35 /' "$WORK/short/cell.yaml" >"$WORK/short/cell-short.yaml"
grep -q '^  length: 0.35 ' "$WORK/short/cell-short.yaml" || fail "could not shorten tube.length in the scene's cell.yaml"
"$CLI" plan --no-sim --cloud "$WORK/short/cloud.ply" --cell "$WORK/short/cell-short.yaml" --json "$WORK/short/plan.json" \
  >/dev/null 2>"$WORK/short/plan.err" || fail "tubepick plan with the short cell"
"$CLI" view --cloud "$WORK/short/cloud.ply" --cell "$WORK/short/cell-short.yaml" --plan "$WORK/short/plan.json" \
  --out "$WORK/short.html" || fail "tubepick view --plan (short cell)"
timeout 180 node "$CHECK" --page "$WORK/short.html" --screenshot "$ARTIFACTS/view-warning.png" \
  --expect-warning tube_length_shorter_than_scan || fail "page check of $WORK/short.html"

step "3. a round page of tubepick cell --sim --view"
"$CLI" cell --sim --rounds 1 --tubes 3 --seed 2 --no-sim-planning --view "$WORK/rounds" --view-points 60000 \
  >"$WORK/cell.log" 2>&1 || { cat "$WORK/cell.log" >&2; fail "tubepick cell --view"; }
[ -f "$WORK/rounds/round_000.html" ] || fail "no round_000.html in $(ls "$WORK/rounds")"
check "$WORK/rounds/round_000.html" cell-round.png

step "4. /debug/calls of a running tubepick-server (debug.keep_last: 4)"
cat >"$WORK/server.yaml" <<'YAML'
server: {address: "127.0.0.1:0", metrics_address: "127.0.0.1:0", workers: 1}
debug: {keep_last: 4, max_points: 100000}
YAML
"$SERVER" --config "$WORK/server.yaml" --log-level info >"$WORK/server.log" 2>&1 &
SERVER_PID=$!
PORT="" HTTP=""
for _ in $(seq 1 300); do
  PORT=$(sed -n 's/.*listening on 127\.0\.0\.1:\([0-9][0-9]*\).*/\1/p' "$WORK/server.log" | head -n 1)
  HTTP=$(sed -n 's|.*calls in the viewer at http://127\.0\.0\.1:\([0-9][0-9]*\)/debug/calls.*|\1|p' "$WORK/server.log" | head -n 1)
  [ -n "$PORT" ] && [ -n "$HTTP" ] && break
  kill -0 "$SERVER_PID" 2>/dev/null || fail "server exited during start-up"
  sleep 0.1
done
[ -n "$HTTP" ] || fail "no '/debug/calls' line in the server log within 30 s"
"$CLI" scene --tubes 6 --seed 5 --out "$WORK/clouds/a" >/dev/null || fail "tubepick scene"
for rpc_calls in "model 1" "plan 2"; do  # the newest call is a plan: the list check opens it
  set -- $rpc_calls
  "$CLI" load --target "127.0.0.1:$PORT" --clouds "$WORK/clouds" --rpc "$1" --no-sim -n "$2" \
    >"$WORK/load.log" 2>&1 || { cat "$WORK/load.log" >&2; fail "tubepick load --rpc $1"; }
done
calls=$(curl -sf "http://127.0.0.1:$HTTP/debug/calls.json") || fail "GET /debug/calls.json"
node -e 'const c = JSON.parse(process.argv[1]); if (c.length !== 3 || c[0].id <= c[1].id) process.exit(1)' "$calls" \
  || fail "/debug/calls.json: want 3 calls newest first, got $calls"
check "http://127.0.0.1:$HTTP/debug/calls" debug-calls.png --list
kill -TERM "$SERVER_PID"
wait "$SERVER_PID" || fail "server exit status $? after SIGTERM"
SERVER_PID=""
step "all pages passed; screenshots in $ARTIFACTS"
