#!/usr/bin/env bash
# Builds the deployment images with podman and checks them from outside, as an operator would
# (docs/SERVICE.md, "Deployment"). CI runs it on every change (.ci/run), after deploy/test.sh built
# the host's client (build/bin/tubepick) and buf.
#
#   1. base     debian:bookworm and debian:bookworm-slim made from Debian itself (base-images.sh)
#   2. build    deploy/Dockerfile -> tubepick:latest, deploy/haproxy.Dockerfile -> tubepick-proxy
#   3. cache    the dependency layer is reused when only sources change
#   4. image    size, and every binary in it resolves all its shared libraries (ldd)
#   5. run      tubepick-server started as the image says: health SERVING, the service listed by
#               reflection, /healthz, one PlanPick of a generated cloud with plans, SIGTERM -> exit 0
#   6. compose  planner-1 of deploy/docker-compose.yml, started with the file's command, passes the
#               file's health check
#   7. proxy    the file's topology: three replicas behind HAProxy (deploy/haproxy.cfg), `tubepick
#               load` through it, one replica killed mid-run: only calls in flight on it fail, the
#               others carry the rest
#
# Containers run with `podman run` where the host allows it; where it refuses (a sandbox without
# CAP_SYS_RESOURCE or cgroup delegation, like our CI machines), from the container's own root file
# system (`podman mount`) with chroot as the image's user, the image's entrypoint, command,
# environment and working directory, on the host's network.
#
#   deploy/test-image.sh             all of it
#   deploy/test-image.sh --prepare   only what needs no sources built: the base images, the
#                                    dependency stage and the proxy image (CI starts this while
#                                    deploy/test.sh compiles: mostly downloads and unpacking)
#   deploy/test-image.sh --no-build  the checks only, on the images podman already has (parts 4-7)
#
# Env: TUBEPICK_CLI (default build/bin/tubepick), TUBEPICK_IMAGE_RUNNER=podman|chroot (default: probe).
# Needs root (podman's rootful storage, chroot).
set -euo pipefail
build=1
prepare=0
case "${1:-}" in
  "") ;;
  --no-build) build=0 ;;
  --prepare) prepare=1 ;;
  *) echo "usage: $0 [--prepare | --no-build]" >&2; exit 2 ;;
esac
cd "$(dirname "$0")/.."
ROOT=$(pwd)
CLI=${TUBEPICK_CLI:-$ROOT/build/bin/tubepick}
BUF=${BUF:-$ROOT/deploy/tools/node_modules/.bin/buf}
IMAGE=tubepick:latest
PROXY_IMAGE=tubepick-proxy:latest
PY=/usr/bin/python3 # Debian's, with PyYAML (install-deps.sh --image-tools)

if [ "$prepare" = 0 ]; then
  [ -x "$CLI" ] || { echo "test-image: $CLI missing: run deploy/build.sh first" >&2; exit 1; }
  [ -x "$BUF" ] || { echo "test-image: $BUF missing: run deploy/install-tools.sh" >&2; exit 1; }
fi

WORK=$(mktemp -d "${TMPDIR:-/tmp}/tubepick-image.XXXXXX")
CONTAINERS=() # started by start_container: "name pid root"
cleanup() {
  local entry name pid root
  for entry in "${CONTAINERS[@]}"; do
    read -r name pid root <<<"$entry"
    [ "$pid" = - ] || kill -KILL "$pid" 2>/dev/null || true
    if [ "$root" != "-" ]; then
      umount "$root/proc" 2>/dev/null || true
      umount "$root/dev" 2>/dev/null || true
    fi
    podman rm -f "$name" >/dev/null 2>&1 || true
  done
  rm -rf "$WORK"
}
trap cleanup EXIT

fail() {
  echo "test-image: FAIL: $*" >&2
  for log in "$WORK"/*.log; do
    [ -f "$log" ] || continue
    echo "--- $(basename "$log") (last 25 lines) ---" >&2
    tail -n 25 "$log" >&2
  done
  exit 1
}
say() { echo "test-image: $*"; }
part() {
  local name=$1 start=$SECONDS
  shift
  say "--- $name"
  "$@"
  say "--- $name took $((SECONDS - start)) s"
}
# Waits up to $2 seconds for the command "${@:3}" to succeed; $1 names what is awaited.
wait_for() {
  local what=$1 seconds=$2
  shift 2
  local end=$((SECONDS + seconds))
  until "$@" >/dev/null 2>&1; do
    [ $SECONDS -lt $end ] || fail "$what: not within $seconds s"
    sleep 0.2
  done
}
# The image's configuration field $2 ({{json .Config.Entrypoint}}, ...) as JSON.
image_field() { podman image inspect --format "{{json .Config.$2}}" "$1"; }
json_words() { "$PY" -c 'import json,sys; sys.stdout.write("".join(w + "\n" for w in json.loads(sys.stdin.read()) or []))'; }

# container_user ROOT USER FIELDS: USER (a name or a uid; empty = root) as the container's own
# /etc/passwd knows it, printed as awk prints FIELDS ($3 ":" $4 for chroot's --userspec, $6 home).
container_user() {
  awk -F: -v u="${2:-root}" "\$1 == u || \$3 == u { print $3; exit }" "$1/etc/passwd"
}

# --- runner --------------------------------------------------------------------------------------
RUNNER=${TUBEPICK_IMAGE_RUNNER:-}
probe_runner() {
  if [ -z "$RUNNER" ]; then
    if podman run --rm --network host --entrypoint /bin/true "$IMAGE" >"$WORK/probe.txt" 2>&1; then
      RUNNER=podman
    else
      RUNNER=chroot
      say "podman run refused here ($(grep -m 1 '^Error' "$WORK/probe.txt" || tail -n 1 "$WORK/probe.txt")):" \
        "containers run chrooted in their own root"
    fi
  fi
  say "containers run with: $RUNNER"
}

# start_container NAME IMAGE [ENV=VALUE ...] -- [ARG ...]: starts IMAGE's entrypoint with ARGs (or
# the image's command when none) on the host's network, its output in $WORK/NAME.log. Sets PID.
start_container() {
  local name=$1 image=$2
  shift 2
  local envs=()
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do envs+=("$1"); shift; done
  [ "${1:-}" = "--" ] && shift
  local args=("$@")
  podman rm -f "$name" >/dev/null 2>&1 || true # left by an interrupted run
  if [ "$RUNNER" = podman ]; then
    local env_flags=()
    for e in "${envs[@]}"; do env_flags+=(--env "$e"); done
    podman run -d --name "$name" --network host "${env_flags[@]}" "$image" "${args[@]}" >/dev/null
    podman logs -f "$name" >"$WORK/$name.log" 2>&1 &
    PID=$(podman inspect --format '{{.State.Pid}}' "$name")
    CONTAINERS+=("$name $PID -")
    return
  fi
  podman create --name "$name" "$image" >/dev/null
  local root
  root=$(podman mount "$name")
  mount -t proc proc "$root/proc"
  mount --bind /dev "$root/dev"
  local entrypoint=() command=() image_env=() user workdir
  mapfile -t entrypoint < <(image_field "$image" Entrypoint | json_words)
  mapfile -t command < <(image_field "$image" Cmd | json_words)
  mapfile -t image_env < <(image_field "$image" Env | json_words)
  [ ${#args[@]} -gt 0 ] && command=("${args[@]}")
  user=$(podman image inspect --format '{{.Config.User}}' "$image")
  workdir=$(podman image inspect --format '{{.Config.WorkingDir}}' "$image")
  local ids home
  ids=$(container_user "$root" "$user" '$3 ":" $4')
  home=$(container_user "$root" "$user" '$6')
  [ -n "$ids" ] || fail "$image: user '$user' is not in its /etc/passwd"
  env -i "${image_env[@]}" HOME="$home" "${envs[@]}" \
    chroot --userspec="$ids" "$root" /bin/sh -c 'cd "$0" && exec "$@"' "${workdir:-/}" \
    "${entrypoint[@]}" "${command[@]}" >"$WORK/$name.log" 2>&1 &
  PID=$!
  CONTAINERS+=("$name $PID $root")
}

# exec_in NAME CMD...: runs CMD inside container NAME (as `docker exec` would, for health checks).
exec_in() {
  local name=$1
  shift
  if [ "$RUNNER" = podman ]; then
    podman exec "$name" "$@"
    return
  fi
  local root user ids
  root=$(podman mount "$name")
  user=$(podman inspect --format '{{.Config.User}}' "$name")
  ids=$(container_user "$root" "$user" '$3 ":" $4')
  env -i PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin chroot --userspec="$ids" "$root" "$@"
}

# stop_container NAME SIGNAL: sends SIGNAL, waits for the exit; its exit code in STOP_RC.
stop_container() {
  local name=$1 signal=$2 entry n pid root rc=0
  for entry in "${CONTAINERS[@]}"; do
    read -r n pid root <<<"$entry"
    [ "$n" = "$name" ] || continue
    if [ "$RUNNER" = podman ]; then
      podman kill --signal "$signal" "$name" >/dev/null
      rc=$(podman wait "$name")
    else
      kill -s "$signal" "$pid"
      wait "$pid" || rc=$?
    fi
    STOP_RC=$rc
    return
  done
  fail "stop_container: no container $name"
}

# `tubepick health` exits 0 only for SERVING (a grep for "SERVING" would take NOT_SERVING too).
serving() { "$CLI" health --target "$1" --timeout 2 >/dev/null; }

# --- 1. base images, tools ------------------------------------------------------------------------
base() {
  bash deploy/install-deps.sh --image-tools
  bash deploy/base-images.sh
}

# --- 2. build -------------------------------------------------------------------------------------
# The host's CA bundle, lent to the viewer stage's npm install (the Dockerfile's host_ca secret): where
# a proxy inspects TLS, the registry's certificate chains to a CA only the host trusts.
CA_SECRET=()
[ -s /etc/ssl/certs/ca-certificates.crt ] && CA_SECRET=(--secret id=host_ca,src=/etc/ssl/certs/ca-certificates.crt)
build_prerequisites() {
  local start=$SECONDS
  podman build --isolation chroot --network host --format docker --target deps -f deploy/Dockerfile . \
    >"$WORK/build-deps.log" 2>&1 || fail "podman build --target deps"
  say "dependency stage ready in $((SECONDS - start)) s"
  start=$SECONDS
  podman build --isolation chroot --network host --format docker "${CA_SECRET[@]}" --target viewer \
    -f deploy/Dockerfile . \
    >"$WORK/build-viewer.log" 2>&1 || fail "podman build --target viewer"
  say "viewer stage (npm ci, page script bundled) ready in $((SECONDS - start)) s"
  start=$SECONDS
  podman build --isolation chroot --network host --format docker -f deploy/haproxy.Dockerfile \
    -t "$PROXY_IMAGE" . >"$WORK/build-proxy.log" 2>&1 || fail "podman build deploy/haproxy.Dockerfile"
  say "proxy image built in $((SECONDS - start)) s"
}
build_images() {
  build_prerequisites
  # The compiler cache the host build filled (deploy/build.sh), lent to the image's build stage.
  local cache_flags=() cache_dir=""
  if command -v ccache >/dev/null && [ -z "${CCACHE_DISABLE:-}" ]; then
    cache_dir=$(ccache -k cache_dir)
    mkdir -p "$cache_dir"
    cache_flags=(--volume "$cache_dir:/ccache")
  fi
  local start=$SECONDS
  podman build --isolation chroot --network host --format docker "${cache_flags[@]}" "${CA_SECRET[@]}" \
    -f deploy/Dockerfile -t "$IMAGE" . >"$WORK/build-image.log" 2>&1 || fail "podman build deploy/Dockerfile"
  say "tubepick image built in $((SECONDS - start)) s${cache_dir:+ (compiler cache $cache_dir lent to the build stage)}"
  grep -a -o 'ccache-stats: Cacheable.*' "$WORK/build-image.log" | sed 's/^/test-image: /' || true
}

# --- 3. layer cache -------------------------------------------------------------------------------
# A copy of the context with one source changed: the dependency stage must come from the cache
# (every step "Using cache"), so a source change never reinstalls the -dev packages.
layer_cache() {
  local context=$WORK/context
  mkdir -p "$context"
  tar -C "$ROOT" --exclude=./build --exclude='./build-*' --exclude=./.git --exclude='*/node_modules' \
    -c . | tar -C "$context" -x
  echo "// changed by deploy/test-image.sh" >>"$context/server/server_main.cc"
  podman build --isolation chroot --network host --format docker --target deps -f deploy/Dockerfile \
    "$context" >"$WORK/cache.log" 2>&1 || fail "podman build --target deps"
  local steps cached
  steps=$(grep -c '^\[1/3\] STEP\|^STEP' "$WORK/cache.log" || true)
  cached=$(grep -c 'Using cache' "$WORK/cache.log" || true)
  grep -q 'install-deps: installing' "$WORK/cache.log" && fail "the dependency layer was rebuilt after a source change"
  [ "$cached" -ge 2 ] || fail "the dependency stage did not come from the cache ($cached of $steps steps cached)"
  say "a source change reuses the dependency layer ($cached steps from the cache)"
  rm -rf "$context"
}

# --- 4. the image ---------------------------------------------------------------------------------
image_facts() {
  local size
  size=$(podman image inspect --format '{{.Size}}' "$IMAGE")
  say "image $IMAGE: $((size / 1000000)) MB"
  podman rm -f tubepick-facts >/dev/null 2>&1 || true
  podman create --name tubepick-facts "$IMAGE" >/dev/null
  CONTAINERS+=("tubepick-facts - -")
  local root missing=0
  root=$(podman mount tubepick-facts)
  for bin in "$root"/usr/local/bin/*; do
    chroot "$root" ldd "/usr/local/bin/$(basename "$bin")" >"$WORK/ldd.txt" 2>&1 || fail "ldd $(basename "$bin"): $(cat "$WORK/ldd.txt")"
    if grep -q 'not found' "$WORK/ldd.txt"; then
      grep 'not found' "$WORK/ldd.txt" >&2
      missing=1
    fi
    say "$(basename "$bin"): $(grep -c '=>' "$WORK/ldd.txt") shared libraries, all found"
  done
  [ "$missing" = 0 ] || fail "a binary in the image misses shared libraries"
  # What takes the space: the five biggest directories two levels under /usr, and the binaries.
  say "largest parts: $(cd "$root" && du -sm usr/lib/x86_64-linux-gnu usr/share usr/bin usr/local/bin var 2>/dev/null \
    | sort -rn | awk '{printf "%s %s MB; ", $2, $1}')"
  podman umount tubepick-facts >/dev/null
}

# --- 5. run ---------------------------------------------------------------------------------------
run_server() {
  "$CLI" scene --tubes 10 --seed 1 --out "$WORK/clouds/scene-1" >/dev/null
  start_container tubepick-run "$IMAGE" --
  local pid=$PID
  wait_for "health SERVING on 127.0.0.1:50051 (the image's default command)" 60 serving 127.0.0.1:50051
  say "health: SERVING on the image's default address"
  local listed
  listed=$(timeout 60 "$BUF" curl --protocol grpc --http2-prior-knowledge --list-services http://127.0.0.1:50051) \
    || fail "buf curl --list-services"
  grep -qx 'tubepick.v1.PickPlannerService' <<<"$listed" || fail "reflection does not list the planner: $listed"
  say "reflection lists: $(tr '\n' ' ' <<<"$listed")"
  curl -fsS http://127.0.0.1:9464/healthz | grep -qx SERVING || fail "/healthz is not SERVING"
  curl -fsS http://127.0.0.1:9464/metrics | grep -q '^tubepick_workers ' || fail "/metrics has no tubepick_workers"
  # One PlanPick of the generated cloud: the JSON report carries the plans.
  "$CLI" request plan --cloud "$WORK/clouds/scene-1/cloud.ply" --no-sim --out "$WORK/plan-request.json" >/dev/null
  timeout 120 "$BUF" curl --protocol grpc --http2-prior-knowledge -d @"$WORK/plan-request.json" \
    http://127.0.0.1:50051/tubepick.v1.PickPlannerService/PlanPick >"$WORK/plan.json" || fail "PlanPick"
  local plans
  plans=$("$PY" -c 'import json,sys; print(len(json.load(open(sys.argv[1])).get("plans", [])))' "$WORK/plan.json")
  [ "$plans" -gt 0 ] || fail "PlanPick answered no plans: $(head -c 400 "$WORK/plan.json")"
  say "PlanPick of a 10-tube cloud: $plans plans"
  # The HTTP side keeps no calls by default (debug.keep_last: 0) and says how to turn it on; the
  # image's tubepick writes a viewer page (the page script embedded at build time).
  local debug_answer
  debug_answer=$(curl -sS -o /dev/stdout -w ' %{http_code}' http://127.0.0.1:9464/debug/calls) || fail "GET /debug/calls"
  [[ "$debug_answer" == *"debug.keep_last is 0"*" 404" ]] || fail "/debug/calls: $debug_answer"
  exec_in tubepick-run tubepick view --no-sim --tubes 3 --out /tmp/view.html >"$WORK/view.txt" 2>&1 \
    || fail "tubepick view in the image: $(cat "$WORK/view.txt")"
  say "/debug/calls off by default (404 naming debug.keep_last); $(head -n 1 "$WORK/view.txt")"
  stop_container tubepick-run TERM
  [ "$STOP_RC" = 0 ] || fail "tubepick-server exited $STOP_RC on SIGTERM"
  grep -q 'shut down after' "$WORK/tubepick-run.log" || fail "no 'shut down after' line in the server's log"
  say "SIGTERM: drained and exited 0 (pid $pid)"
}

# --- 6. compose -----------------------------------------------------------------------------------
# planner-1 as deploy/docker-compose.yml describes it: its image, command and health check (test,
# interval, retries, start period), run as the file says.
compose_service() {
  "$PY" - "$ROOT/deploy/docker-compose.yml" planner-1 >"$WORK/compose.sh" <<'EOF'
import shlex, sys, yaml
spec = yaml.safe_load(open(sys.argv[1]))
svc = spec["services"][sys.argv[2]]
def seconds(text):
    text = str(text)
    return float(text[:-1]) * (60 if text.endswith("m") else 1) if text[-1] in "sm" else float(text)
hc = svc["healthcheck"]
test = hc["test"]
assert test[0] == "CMD", f"healthcheck.test must be an exec form, not {test[0]}"
print("SVC_IMAGE=" + shlex.quote(svc["image"]))
print("SVC_COMMAND=(" + " ".join(shlex.quote(a) for a in svc["command"]) + ")")
print("SVC_TEST=(" + " ".join(shlex.quote(a) for a in test[1:]) + ")")
print(f"SVC_INTERVAL={seconds(hc['interval'])} SVC_RETRIES={int(hc['retries'])} SVC_START={seconds(hc['start_period'])}")
proxy = spec["services"]["proxy"]
print("PROXY_IMAGE_FILE=" + shlex.quote(proxy["image"]))
print("PROXY_ENV=(" + " ".join(shlex.quote(f"{k}={v}") for k, v in proxy["environment"].items()) + ")")
print(f"PLANNERS={sum(1 for name in spec['services'] if name.startswith('planner-'))}")
EOF
  # shellcheck disable=SC1091
  source "$WORK/compose.sh"
  [ "$SVC_IMAGE" = "$IMAGE" ] || fail "compose planner image '$SVC_IMAGE' is not the image built here ($IMAGE)"
  [ "$PROXY_IMAGE_FILE" = "$PROXY_IMAGE" ] || fail "compose proxy image '$PROXY_IMAGE_FILE' is not $PROXY_IMAGE"
  start_container compose-planner-1 "$SVC_IMAGE" -- "${SVC_COMMAND[@]}"
  # Docker's rule: checks every interval from the start; failures within the start period do not
  # count; healthy at the first pass, unhealthy after `retries` failures past the start period.
  local started=$SECONDS failures=0 checks=0
  sleep 1
  for ((;;)); do
    checks=$((checks + 1))
    if exec_in compose-planner-1 "${SVC_TEST[@]}" >"$WORK/healthcheck.txt" 2>&1; then break; fi
    if [ "$(( SECONDS - started ))" -ge "${SVC_START%.*}" ]; then failures=$((failures + 1)); fi
    [ "$failures" -lt "$SVC_RETRIES" ] || fail "compose health check failed $failures times: $(cat "$WORK/healthcheck.txt")"
    sleep 2 # a shorter interval than the file's ${SVC_INTERVAL} s: the verdict is the same, sooner
  done
  say "compose planner-1 healthy after $((SECONDS - started)) s ($checks checks): $(tr -s '\n' ' ' <"$WORK/healthcheck.txt")"
  stop_container compose-planner-1 TERM
  [ "$STOP_RC" = 0 ] || fail "compose planner-1 exited $STOP_RC on SIGTERM"
}

# --- 7. replicas behind the proxy -----------------------------------------------------------------
# metric PORT SERIES: the value of SERIES on a replica's /metrics (awk reads to the end: no SIGPIPE).
metric() { curl -fsS "http://127.0.0.1:$1/metrics" | awk -v s="$2" '$1 == s { v = $2 } END { print v }'; }
# planpicks_served: each replica's successful PlanPicks, "-" for the one named in $1 (dead).
planpicks_served() {
  local n
  for n in 1 2 3; do
    if [ "$n" = "${1:-}" ]; then echo -n "- "; else echo -n "$(metric "947$n" 'tubepick_rpc_requests_total{method="PlanPick",code="OK"}') "; fi
  done
}
# proxy_has SERVER STATE: HAProxy's Prometheus page says SERVER (planner-N) is in STATE (UP, DOWN).
proxy_has() {
  curl -fsS http://127.0.0.1:8404/metrics \
    | grep -q "^haproxy_server_status{proxy=\"planners\",server=\"$1\",state=\"$2\"} 1"
}
proxy_all_up() { proxy_has planner-1 UP && proxy_has planner-2 UP && proxy_has planner-3 UP; }
proxy_failover() {
  [ "$PLANNERS" = 3 ] || fail "the compose file has $PLANNERS planners; this test expects 3"
  local n grpc_port health_port proxy_env=()
  for n in 1 2 3; do
    start_container "replica-$n" "$IMAGE" -- --address "127.0.0.1:5016$n" --metrics-address "127.0.0.1:947$n" \
      --log-format json
    eval "REPLICA_PID_$n=$PID"
  done
  # The compose file's proxy environment, its addresses moved to the host's loopback ports.
  for e in "${PROXY_ENV[@]}"; do
    case "$e" in
      TUBEPICK_PROXY_BIND=*) proxy_env+=("TUBEPICK_PROXY_BIND=127.0.0.1:50160") ;;
      TUBEPICK_PROXY_STATS=*) proxy_env+=("TUBEPICK_PROXY_STATS=127.0.0.1:8404") ;;
      TUBEPICK_PLANNER_?_HEALTH_PORT=*) n=${e:17:1}; proxy_env+=("TUBEPICK_PLANNER_${n}_HEALTH_PORT=947$n") ;;
      TUBEPICK_PLANNER_?=*) n=${e:17:1}; proxy_env+=("TUBEPICK_PLANNER_$n=127.0.0.1:5016$n") ;;
      *) fail "unexpected proxy environment entry $e" ;;
    esac
  done
  for n in 1 2 3; do wait_for "replica $n SERVING" 60 serving "127.0.0.1:5016$n"; done
  start_container proxy "$PROXY_IMAGE" "${proxy_env[@]}" --
  wait_for "HAProxy sees 3 replicas UP" 30 proxy_all_up
  wait_for "health SERVING through the proxy" 30 serving 127.0.0.1:50160
  say "3 replicas UP behind HAProxy"

  # 16 s of PlanPick at concurrency 2 through the proxy; at ~6 s, SIGKILL a replica that is busy.
  "$CLI" load --target 127.0.0.1:50160 --clouds "$WORK/clouds" --rpc plan --no-sim --concurrency 2 \
    --duration 16 --json "$WORK/proxy-load.json" >"$WORK/proxy-load.log" 2>&1 &
  local load_pid=$! victim="" t_kill t_dead
  sleep 6
  for _ in $(seq 1 50); do
    for n in 1 2 3; do
      if [ "$(metric "947$n" tubepick_workers_busy)" != 0 ]; then victim=$n; break 2; fi
    done
    sleep 0.05
  done
  [ -n "$victim" ] || fail "no replica was busy 6 s into the load run"
  local victim_pid_var=REPLICA_PID_$victim
  local served_before
  served_before=$(planpicks_served)
  t_kill=$(date +%s.%N)
  kill -KILL "${!victim_pid_var}"
  wait "${!victim_pid_var}" 2>/dev/null || true # reaped: its sockets are closed
  t_dead=$(date +%s.%N)
  say "killed replica $victim (busy) at $(date -u +%T.%3N); PlanPicks served so far per replica: $served_before"
  wait_for "HAProxy marks replica $victim DOWN" 10 proxy_has "planner-$victim" DOWN
  say "HAProxy marked planner-$victim DOWN after $("$PY" -c "import time,sys; print(f'{time.time()-float(sys.argv[1]):.1f}')" "$t_kill") s"
  wait "$load_pid" || true
  local after
  after=$(planpicks_served "$victim")
  say "PlanPicks served per replica at the end: $after"
  "$PY" - "$WORK/proxy-load.json" "$t_kill" "$t_dead" "$served_before" <<'EOF' || fail "failover"
import json, sys
report = json.load(open(sys.argv[1]))
t_kill, t_dead = float(sys.argv[2]), float(sys.argv[3])
before = [float(x) for x in sys.argv[4].split()]
# A call that reached the proxy within 0.1 s of the replica's death may still have been sent on its
# closing connection before HAProxy read the close: that is "in flight" too.
GRACE = 0.1
calls = report["calls"]
failed = [c for c in calls if c["code"] != "OK"]
late = [c for c in calls if c["start_unix_seconds"] > t_dead + GRACE]
print(f"test-image: through the proxy: {len(calls)} calls, {len(failed)} failed "
      f"({', '.join(sorted({c['code'] for c in failed})) or 'none'}), {len(late)} started after the kill, all "
      f"{'OK' if all(c['code'] == 'OK' for c in late) else 'NOT OK'}")
ok = True
# Before the kill every replica had served calls: balanced per call, not per connection.
if min(before) < 1:
    print(f"test-image: a replica served no call before the kill: {before}"); ok = False
# Only calls in flight on the dead replica may fail: started before the kill, still running then.
# The proxy runs one replica's calls one at a time per client thread: at most --concurrency of them.
for c in failed:
    end = c["start_unix_seconds"] + c["seconds"]
    if not (c["start_unix_seconds"] <= t_dead + GRACE and end >= t_kill - 0.05):
        print(f"test-image: a call failed that was not in flight at the kill: {c}"); ok = False
if len(failed) > report["concurrency"]:
    print(f"test-image: {len(failed)} calls failed, more than the {report['concurrency']} in flight"); ok = False
# Then none: every call that started after the kill succeeded, and there were enough of them.
if any(c["code"] != "OK" for c in late) or len(late) < 6:
    print(f"test-image: after the kill: {[c['code'] for c in late]}"); ok = False
sys.exit(0 if ok else 1)
EOF
  for n in 1 2 3; do
    [ "$n" = "$victim" ] && continue
    stop_container "replica-$n" TERM
    [ "$STOP_RC" = 0 ] || fail "replica $n exited $STOP_RC on SIGTERM"
  done
  stop_container proxy USR1
}

if [ "$prepare" = 1 ]; then
  part "base images and tools" base
  part "prerequisites" build_prerequisites
  exit 0
fi
if [ "$build" = 1 ]; then
  part "base images and tools" base
  part "build" build_images
fi
probe_runner
[ "$build" = 1 ] && part "layer cache" layer_cache
part "image" image_facts
part "run" run_server
part "compose" compose_service
part "proxy" proxy_failover
say "PASS"
