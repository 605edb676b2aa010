#!/usr/bin/env bash
# `buf lint` (STANDARD rules, proto/buf.yaml) of the wire contract, with the buf pinned in
# deploy/tools/package-lock.json (installed by deploy/install-tools.sh). Run by ctest (smoke.cmake).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUF=${BUF:-$ROOT/deploy/tools/node_modules/.bin/buf}
[ -x "$BUF" ] || { echo "proto_lint: $BUF missing: run deploy/install-tools.sh" >&2; exit 1; }
cd "$ROOT"
"$BUF" lint proto
echo "proto_lint: buf $("$BUF" --version) lint proto: clean"
