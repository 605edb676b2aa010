#!/usr/bin/env bash
# `buf breaking` (FILE rules, proto/buf.yaml) of the wire contract, with the buf pinned in
# deploy/tools/package-lock.json (installed by deploy/install-tools.sh). Run by ctest (smoke.cmake).
# The working tree's proto/ (uncommitted changes included) is compared with the repository's own git
# history (buf clones the local .git; nothing is fetched from elsewhere), against two baselines:
#  1. HEAD~1, the parent commit: catches a break made in the newest commit. A clean clone does not know
#     which commit was "the previous main", so the parent stands in for it. Skipped, with a message, if
#     HEAD has no parent or the parent's tree has no proto/.
#  2. BASELINE, a fixed commit: the contract as first published. The parent check alone sees only the
#     last commit: a break followed by any other commit would pass it from then on.
# Needs git and the full history (CI clones fully; a shallow clone lacks BASELINE).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUF=${BUF:-$ROOT/deploy/tools/node_modules/.bin/buf}
# 906a7e5 "proto: PickPlannerService ...": the commit that added service.proto (and buf.yaml), i.e. where
# tubepick/v1 was published as the contract (git log --diff-filter=A -- proto/tubepick/v1/service.proto).
# Today's proto/ passes against it and against every later commit that touched proto/. Move it only on a
# deliberate break of the contract (and say so in that commit).
BASELINE=${PROTO_BREAKING_BASELINE:-906a7e5e4405c2edb0d3f7348dec0bc4315d173d}

[ -x "$BUF" ] || { echo "proto_breaking: $BUF missing: run deploy/install-tools.sh" >&2; exit 1; }
command -v git >/dev/null \
  || { echo "proto_breaking: git missing: the check compares proto/ with the git history" >&2; exit 1; }
cd "$ROOT"
git rev-parse --is-inside-work-tree >/dev/null 2>&1 \
  || { echo "proto_breaking: $ROOT is not a git checkout: the check needs its history" >&2; exit 1; }
# The repository's object store as an absolute path; in a worktree .git is a file, the common dir is not.
GIT_COMMON=$(cd "$(git rev-parse --git-common-dir)" && pwd)

# $1: a label for messages; $2: a full commit id.
check() {
  if ! "$BUF" breaking proto --against "$GIT_COMMON#format=git,ref=$2,subdir=proto"; then
    echo "proto_breaking: proto/ breaks the wire contract of $1 ($2): see above" >&2
    exit 1
  fi
}

git cat-file -e "$BASELINE^{commit}" 2>/dev/null || {
  echo "proto_breaking: baseline commit $BASELINE not in this repository" \
    "(a shallow clone? git fetch --unshallow)" >&2
  exit 1
}

compared=()
if PARENT=$(git rev-parse -q --verify 'HEAD~1^{commit}'); then
  if git cat-file -e "$PARENT:proto" 2>/dev/null; then
    check HEAD~1 "$PARENT"
    compared+=("HEAD~1 (${PARENT:0:12})")
  else
    echo "proto_breaking: HEAD~1 (${PARENT:0:12}) has no proto/: parent check skipped"
  fi
else
  echo "proto_breaking: HEAD has no parent in this repository: parent check skipped"
fi
check baseline "$BASELINE"
compared+=("baseline ${BASELINE:0:12}")

list=$(printf '%s and ' "${compared[@]}")
echo "proto_breaking: buf $("$BUF" --version) breaking proto (FILE): no breaking change against ${list% and }"
