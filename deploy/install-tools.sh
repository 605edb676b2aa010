#!/usr/bin/env bash
# Installs the npm packages pinned by the project's lock files, each into its own node_modules:
#   deploy/tools/   buf: `buf lint proto` in tests/proto_lint.sh, `buf curl` in tests/smoke.sh
#   viewer/         three (the 3-D page), esbuild (bundles it at build time), playwright-core (drives
#                   Debian's chromium in tests/viewer_browser.sh; it downloads no browser)
# Idempotent: a tree that matches its lock file is left alone. Called at the end of
# deploy/install-deps.sh, so CI and developers get the same packages.
set -euo pipefail
cd "$(dirname "$0")/.."

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

# current DIR: npm wrote DIR/node_modules/.package-lock.json after a successful install; the same
# packages and versions as the lock file means the tree is current.
current() {
  [ -f "$1/node_modules/.package-lock.json" ] && node -e '
    const fs = require("fs");
    const want = JSON.parse(fs.readFileSync(process.argv[1] + "/package-lock.json")).packages;
    const have = JSON.parse(fs.readFileSync(process.argv[1] + "/node_modules/.package-lock.json")).packages;
    for (const [k, v] of Object.entries(want)) if (k && !v.optional && (!have[k] || have[k].version !== v.version)) process.exit(1);
    for (const [k, v] of Object.entries(have)) if (!want[k] || want[k].version !== v.version) process.exit(1);
    process.exit(0);' "$1"
}

# --ignore-scripts: the packages' install scripts only check for their platform binary packages,
# which npm installs as optional dependencies anyway; running no registry code at install time is
# safer.
install_tree() {
  local dir=$1
  if current "$dir"; then
    echo "install-tools: $dir current"
  else
    echo "install-tools: npm ci in $dir"
    (cd "$dir" && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error)
  fi
}

install_tree deploy/tools
deploy/tools/node_modules/.bin/buf --version >/dev/null || { echo "install-tools: buf does not run" >&2; exit 1; }
echo "install-tools: buf $(deploy/tools/node_modules/.bin/buf --version)"
install_tree viewer
node -e 'for (const p of ["three", "esbuild", "playwright-core"]) console.log(`install-tools: ${p} ${require(`./viewer/node_modules/${p}/package.json`).version}`)'
