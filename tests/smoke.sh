#!/usr/bin/env bash
# Smoke test of the deployed service, as an operator would poke it: starts tubepick-server on free
# loopback ports, then with `buf curl` over server reflection lists the services and methods, checks
# grpc.health.v1, calls ModelTubes / PlanPick / PlanPickStream / AnalyzeWrench with requests written by
# `tubepick request`, asserts on the JSON answers, runs `tubepick health` and a short `tubepick load`,
# scrapes /metrics, and finally checks that SIGTERM shuts the server down with exit code 0.
#
# Usage: tests/smoke.sh PATH/TO/tubepick-server PATH/TO/tubepick   (ctest passes both; see smoke.cmake)
# Needs buf from deploy/install-tools.sh (deploy/tools/node_modules/.bin/buf), node and curl.
set -euo pipefail

SERVER=${1:?usage: smoke.sh TUBEPICK_SERVER TUBEPICK_CLI}
CLI=${2:?usage: smoke.sh TUBEPICK_SERVER TUBEPICK_CLI}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUF=${BUF:-$ROOT/deploy/tools/node_modules/.bin/buf}
[ -x "$BUF" ] || { echo "smoke: $BUF missing: run deploy/install-tools.sh" >&2; exit 1; }
command -v node >/dev/null || { echo "smoke: node missing" >&2; exit 1; }
command -v curl >/dev/null || { echo "smoke: curl missing" >&2; exit 1; }

WORK=$(mktemp -d "${TMPDIR:-/tmp}/tubepick-smoke.XXXXXX")
SERVER_PID=""
SERVER_LOG=$WORK/server.log
cleanup() {
  if [ -n "$SERVER_PID" ] && kill -0 "$SERVER_PID" 2>/dev/null; then kill -KILL "$SERVER_PID" 2>/dev/null || true; fi
  rm -rf "$WORK"
}
trap cleanup EXIT

step() { echo "smoke: $*"; }
fail() {
  echo "smoke: FAIL: $*" >&2
  echo "--- server log ---" >&2
  tail -n 40 "$SERVER_LOG" >&2 || true
  exit 1
}
# JSON assertion: node evaluates EXPR with `r` bound to the parsed FILE; prints and fails when false.
assert_json() {
  local file=$1 expr=$2 what=$3
  node -e '
    const fs = require("fs");
    const r = JSON.parse(fs.readFileSync(process.argv[1], "utf8"));
    const ok = eval(process.argv[2]);
    if (!ok) { console.error(JSON.stringify(r, null, 1).slice(0, 2000)); process.exit(1); }' "$file" "$expr" \
    || fail "$what ($expr)"
}
bufcurl() { timeout 120 "$BUF" curl --protocol grpc --http2-prior-knowledge "$@"; }
# The first "PATTERN" port of a server's log; empty while the log is not written yet (the shell may
# read it before the background server has even created it).
logged_port() { sed -n "s|$2|\1|p" "$1" 2>/dev/null | head -n 1 || true; }

# --- start -------------------------------------------------------------------------------------
step "starting $SERVER"
SERVER_LOG=$WORK/server.log
"$SERVER" --address 127.0.0.1:0 --metrics-address 127.0.0.1:0 --workers 2 --log-level info >"$SERVER_LOG" 2>&1 &
SERVER_PID=$!
PORT="" METRICS_PORT=""
for _ in $(seq 1 300); do
  PORT=$(logged_port "$SERVER_LOG" '.*listening on 127\.0\.0\.1:\([0-9][0-9]*\).*')
  METRICS_PORT=$(logged_port "$SERVER_LOG" '.*metrics on http://127\.0\.0\.1:\([0-9][0-9]*\)/metrics.*')
  [ -n "$PORT" ] && [ -n "$METRICS_PORT" ] && break
  kill -0 "$SERVER_PID" 2>/dev/null || fail "server exited during start-up"
  sleep 0.1
done
[ -n "$PORT" ] || fail "no 'listening on' line within 30 s"
[ -n "$METRICS_PORT" ] || fail "no 'metrics on' line within 30 s"
URL=http://127.0.0.1:$PORT
step "server pid $SERVER_PID on $URL, metrics on port $METRICS_PORT"

# --- reflection ----------------------------------------------------------------------------------
bufcurl --list-services "$URL" >"$WORK/services.txt" || fail "buf curl --list-services"
for s in tubepick.v1.PickPlannerService grpc.health.v1.Health; do
  grep -qx "$s" "$WORK/services.txt" || fail "reflection does not list $s: $(tr '\n' ' ' <"$WORK/services.txt")"
done
bufcurl --list-methods "$URL" >"$WORK/methods.txt" || fail "buf curl --list-methods"
for m in ModelTubes PlanPick PlanPickStream AnalyzeWrench; do
  grep -qx "tubepick.v1.PickPlannerService/$m" "$WORK/methods.txt" || fail "reflection does not list $m"
done
step "reflection lists $(wc -l <"$WORK/methods.txt") methods"

# --- health --------------------------------------------------------------------------------------
bufcurl "$URL/grpc.health.v1.Health/Check" >"$WORK/health.json" || fail "buf curl Health/Check"
assert_json "$WORK/health.json" 'r.status === "SERVING"' "Health/Check"
bufcurl -d '{"service": "tubepick.v1.PickPlannerService"}' "$URL/grpc.health.v1.Health/Check" >"$WORK/health2.json" \
  || fail "buf curl Health/Check of the service"
assert_json "$WORK/health2.json" 'r.status === "SERVING"' "Health/Check of tubepick.v1.PickPlannerService"
"$CLI" health --target "127.0.0.1:$PORT" || fail "tubepick health"
if "$CLI" health --target "127.0.0.1:$PORT" --service no.such.Service >/dev/null; then
  fail "tubepick health of an unknown service exited 0"
fi
step "health SERVING"

# --- ModelTubes ----------------------------------------------------------------------------------
# Three generated tubes (0.5 m, set A), every 10th scanner return: ~230 k points, 3.7 MB of JSON.
"$CLI" request model --tubes 3 --seed 1 --every 10 --out "$WORK/model.json" >/dev/null || fail "tubepick request model"
bufcurl -d @"$WORK/model.json" "$URL/tubepick.v1.PickPlannerService/ModelTubes" >"$WORK/model_answer.json" \
  || fail "buf curl ModelTubes"
assert_json "$WORK/model_answer.json" 'r.tubes.length === 3' "ModelTubes: 3 tubes generated, 3 modeled"
assert_json "$WORK/model_answer.json" 'r.tubes.every(t => t.length > 0.4 && t.length < 0.6)' \
  "ModelTubes: every tube about 0.5 m long"
assert_json "$WORK/model_answer.json" 'Number(r.inputPoints) > 200000 && r.seed === "1" && r.profile === "fast"' \
  "ModelTubes: input points, seed, profile"
step "ModelTubes: 3 tubes"

# --- PlanPick (no simulation) and AnalyzeWrench --------------------------------------------------
"$CLI" request plan --tubes 3 --seed 1 --every 10 --no-sim --max-plans 5 --out "$WORK/plan.json" >/dev/null \
  || fail "tubepick request plan"
bufcurl -d @"$WORK/plan.json" "$URL/tubepick.v1.PickPlannerService/PlanPick" >"$WORK/plan_answer.json" \
  || fail "buf curl PlanPick"
assert_json "$WORK/plan_answer.json" 'r.plans.length >= 1 && r.plans.length <= 5 && !r.usedSimulation' \
  "PlanPick: 1..5 plans, not simulated"
assert_json "$WORK/plan_answer.json" 'r.plans.every((p, i) => i === 0 || p.cost.total >= r.plans[i - 1].cost.total)' \
  "PlanPick: plans best (lowest cost) first"
"$CLI" request plan-stream --tubes 3 --seed 1 --every 10 --no-sim --chunk-kib 512 --out "$WORK/stream.json" \
  >/dev/null || fail "tubepick request plan-stream"
bufcurl -d @"$WORK/stream.json" "$URL/tubepick.v1.PickPlannerService/PlanPickStream" >"$WORK/stream_answer.json" \
  || fail "buf curl PlanPickStream"
assert_json "$WORK/stream_answer.json" 'r.response.plans.length >= 1 && r.response.tubes.length === 3' \
  "PlanPickStream: header + 6 chunks of 512 KiB answered like PlanPick"
"$CLI" request wrench --held 2 --out "$WORK/wrench.json" >/dev/null || fail "tubepick request wrench"
bufcurl -d @"$WORK/wrench.json" "$URL/tubepick.v1.PickPlannerService/AnalyzeWrench" >"$WORK/wrench_answer.json" \
  || fail "buf curl AnalyzeWrench"
assert_json "$WORK/wrench_answer.json" 'r.outcome === "HELD_OUTCOME_MULTIPLE" && r.estimatedCount === 2' \
  "AnalyzeWrench: two tubes held"
# A caller mistake is INVALID_ARGUMENT (buf curl exits with the gRPC code shifted left by 3: 3 << 3 = 24).
set +e
bufcurl -d '{"cloud": {"xyz": "AAAA"}}' "$URL/tubepick.v1.PickPlannerService/ModelTubes" >/dev/null 2>"$WORK/invalid.txt"
rc=$?
set -e
[ "$rc" -eq 24 ] || fail "a 3-byte cloud: buf curl exit $rc, expected 24 (INVALID_ARGUMENT): $(cat "$WORK/invalid.txt")"
grep -q "cloud.xyz" "$WORK/invalid.txt" || fail "INVALID_ARGUMENT does not name cloud.xyz: $(cat "$WORK/invalid.txt")"
step "PlanPick, PlanPickStream, AnalyzeWrench, INVALID_ARGUMENT ok"

# --- tubepick load -------------------------------------------------------------------------------
"$CLI" scene --tubes 3 --seed 2 --out "$WORK/clouds/scene-2" >/dev/null || fail "tubepick scene"
"$CLI" load --target "127.0.0.1:$PORT" --clouds "$WORK/clouds" --rpc model --concurrency 2 --total 2 --fail-on-error \
  --json "$WORK/load.json" --metrics-url "http://127.0.0.1:$METRICS_PORT/metrics" --metrics-interval 0.5 \
  >"$WORK/load.txt" 2>&1 || { cat "$WORK/load.txt"; fail "tubepick load"; }
assert_json "$WORK/load.json" 'r.count === 2 && r.ok === 2 && r.latency_seconds.p50 > 0' "tubepick load: 2 OK calls"
assert_json "$WORK/load.json" 'r.server_rss.peak_bytes > 0 && r.server_rss.failed_scrapes === 0' "tubepick load: RSS"
step "load: $(grep 'Requests/sec' "$WORK/load.txt" | sed 's/^ *//')"

# --- metrics -------------------------------------------------------------------------------------
curl -sf "http://127.0.0.1:$METRICS_PORT/metrics" >"$WORK/metrics.txt" || fail "GET /metrics"
# 1 ModelTubes from buf curl + 2 from tubepick load answered OK, one INVALID_ARGUMENT.
grep -qx 'tubepick_rpc_requests_total{method="ModelTubes",code="OK"} 3' "$WORK/metrics.txt" \
  || fail "ModelTubes OK counter is not 3: $(grep 'method="ModelTubes"' "$WORK/metrics.txt" | grep requests_total)"
grep -qx 'tubepick_rpc_requests_total{method="ModelTubes",code="INVALID_ARGUMENT"} 1' "$WORK/metrics.txt" \
  || fail "ModelTubes INVALID_ARGUMENT counter is not 1"
grep -q '^process_resident_memory_bytes [0-9]' "$WORK/metrics.txt" || fail "no process_resident_memory_bytes"
step "metrics ok"

# --- SIGTERM -------------------------------------------------------------------------------------
kill -TERM "$SERVER_PID"
set +e
wait "$SERVER_PID"
rc=$?
set -e
SERVER_PID=""
[ "$rc" -eq 0 ] || fail "server exit code $rc after SIGTERM, expected 0"
step "SIGTERM: exit 0"

# --- reflection off (production profile) ---------------------------------------------------------
printf 'server:\n  reflection: false\n  metrics_address: ""\n' >"$WORK/no-reflection.yaml"
# A log of its own: read from the first server's log, the port was once the first server's (the
# shell read the old file before the new server had truncated it): CI at 4be7c72, "connection refused".
SERVER_LOG=$WORK/server-no-reflection.log
"$SERVER" --config "$WORK/no-reflection.yaml" --address 127.0.0.1:0 --workers 1 >"$SERVER_LOG" 2>&1 &
SERVER_PID=$!
PORT=""
for _ in $(seq 1 300); do
  PORT=$(logged_port "$SERVER_LOG" '.*listening on 127\.0\.0\.1:\([0-9][0-9]*\).*')
  [ -n "$PORT" ] && break
  kill -0 "$SERVER_PID" 2>/dev/null || fail "server with reflection off exited during start-up"
  sleep 0.1
done
[ -n "$PORT" ] || fail "server with reflection off: no 'listening on' line within 30 s"
if bufcurl --list-methods "http://127.0.0.1:$PORT" >"$WORK/methods-off.txt" 2>&1; then
  fail "reflection: false still lists methods: $(tr '\n' ' ' <"$WORK/methods-off.txt")"
fi
# The check is that a fresh server answers SERVING at all, not how fast (ctest runs the heaviest suites
# beside it on two cores): 30 s.
"$CLI" health --target "127.0.0.1:$PORT" --timeout 30 >"$WORK/health-off.txt" 2>&1 ||
  fail "health with reflection off: $(tr '\n' ' ' <"$WORK/health-off.txt")"
kill -TERM "$SERVER_PID"
wait "$SERVER_PID" || fail "server with reflection off: non-zero exit after SIGTERM"
SERVER_PID=""
step "reflection: false lists nothing; health still SERVING"
echo "smoke: all checks passed"
