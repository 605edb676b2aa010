#!/usr/bin/env bash
# Installs the npm-distributed developer tools pinned in deploy/tools/package-lock.json (today: buf,
# for `buf lint proto` in tests/proto_lint.sh and `buf curl` in tests/smoke.sh) into
# deploy/tools/node_modules. Idempotent: does nothing when the installed tree matches the lock file.
# Called at the end of deploy/install-deps.sh, so CI, the Dockerfile's build stage and developers get
# the same tools.
set -euo pipefail
cd "$(dirname "$0")/tools"

if ! command -v npm >/dev/null 2>&1; then
  # A fresh Debian machine: take Debian's node and npm. (Machines with NodeSource's nodejs have npm
  # bundled and never get here; installing Debian's npm there would conflict with it.)
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  echo "install-tools: npm missing, installing Debian's nodejs and npm"
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends nodejs npm
fi

# npm writes node_modules/.package-lock.json after a successful install; equal to the lock file's
# packages means the tree is current.
if [ -x node_modules/.bin/buf ] && [ -f node_modules/.package-lock.json ] \
  && node -e '
    const fs = require("fs");
    const want = JSON.parse(fs.readFileSync("package-lock.json")).packages;
    const have = JSON.parse(fs.readFileSync("node_modules/.package-lock.json")).packages;
    for (const [k, v] of Object.entries(have)) if (!want[k] || want[k].version !== v.version) process.exit(1);
    process.exit(0);' \
  && node_modules/.bin/buf --version >/dev/null 2>&1; then
  echo "install-tools: buf $(node_modules/.bin/buf --version) present"
  exit 0
fi

# --ignore-scripts: buf's postinstall only checks for the platform binary package, which npm
# installs as an optional dependency anyway; running no registry code at install time is safer.
echo "install-tools: npm ci in deploy/tools"
npm ci --ignore-scripts --no-audit --no-fund --loglevel=error
echo "install-tools: buf $(node_modules/.bin/buf --version) installed"
