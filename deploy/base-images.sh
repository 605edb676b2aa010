#!/usr/bin/env bash
# Makes the two base images deploy/Dockerfile starts from, debian:bookworm and debian:bookworm-slim,
# from Debian itself: no container registry is needed. `debootstrap --variant=minbase bookworm`
# into a folder, imported into podman's local storage; the -slim tag is the same tree without
# documentation, manuals and translations (as Debian's own slim images: dpkg path-excludes them, so
# packages installed later leave them out too).
#
#   deploy/base-images.sh             make the two tags unless podman already has them
#   deploy/base-images.sh --rebuild   make them again
#
# Needs root (debootstrap, podman's rootful storage) and deploy/install-deps.sh --image-tools.
set -euo pipefail

MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
SECURITY_MIRROR=${DEBIAN_SECURITY_MIRROR:-http://deb.debian.org/debian-security}
rebuild=0
case "${1:-}" in
  "") ;;
  --rebuild) rebuild=1 ;;
  *) echo "usage: $0 [--rebuild]" >&2; exit 2 ;;
esac

if [ "$rebuild" = 0 ] && podman image exists debian:bookworm && podman image exists debian:bookworm-slim; then
  echo "base-images: debian:bookworm and debian:bookworm-slim present (--rebuild makes them again)"
  exit 0
fi

WORK=$(mktemp -d "${TMPDIR:-/tmp}/tubepick-base.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
root=$WORK/rootfs

echo "base-images: debootstrap --variant=minbase bookworm from $MIRROR"
debootstrap --variant=minbase bookworm "$root" "$MIRROR" >"$WORK/debootstrap.log" 2>&1 \
  || { tail -n 30 "$WORK/debootstrap.log" >&2; exit 1; }

# The suites a maintained bookworm host has: point-release updates and security fixes, so that an
# image built today carries today's fixes (and the very package versions CI's host compiled with).
cat >"$root/etc/apt/sources.list" <<EOF
deb $MIRROR bookworm main
deb $MIRROR bookworm-updates main
deb $SECURITY_MIRROR bookworm-security main
EOF

# What every container image of Debian does: no package caches kept, no lists shipped, and a policy
# that no service starts while packages are installed in a build.
cat >"$root/etc/apt/apt.conf.d/docker-clean" <<'EOF'
DPkg::Post-Invoke { "rm -f /var/cache/apt/archives/*.deb /var/cache/apt/archives/partial/*.deb /var/cache/apt/*.bin || true"; };
APT::Update::Post-Invoke { "rm -f /var/cache/apt/archives/*.deb /var/cache/apt/archives/partial/*.deb /var/cache/apt/*.bin || true"; };
Dir::Cache::pkgcache "";
Dir::Cache::srcpkgcache "";
EOF
printf '#!/bin/sh\nexit 101\n' >"$root/usr/sbin/policy-rc.d"
chmod 0755 "$root/usr/sbin/policy-rc.d"
rm -rf "$root"/var/cache/apt/archives/*.deb "$root"/var/lib/apt/lists/* "$root"/var/log/*.log \
  "$root"/var/log/apt/*
tar --numeric-owner -C "$root" -c . | podman import --quiet - debian:bookworm >/dev/null

# bookworm-slim: documentation, manuals and translations out, now and for every later install.
cat >"$root/etc/dpkg/dpkg.cfg.d/docker" <<'EOF'
path-exclude /usr/share/doc/*
path-include /usr/share/doc/*/copyright
path-exclude /usr/share/man/*
path-exclude /usr/share/groff/*
path-exclude /usr/share/info/*
path-exclude /usr/share/lintian/*
path-exclude /usr/share/linda/*
path-exclude /usr/share/locale/*
EOF
find "$root/usr/share/doc" -mindepth 1 -not -type d -not -name copyright -delete
find "$root/usr/share/doc" -mindepth 1 -type d -empty -delete
rm -rf "$root"/usr/share/man/* "$root"/usr/share/groff/* "$root"/usr/share/info/* \
  "$root"/usr/share/lintian/* "$root"/usr/share/linda/* "$root"/usr/share/locale/*
tar --numeric-owner -C "$root" -c . | podman import --quiet - debian:bookworm-slim >/dev/null

podman images --format '{{.Repository}}:{{.Tag}} {{.Size}}' | grep -E '^localhost/debian:bookworm' \
  | sed 's/^/base-images: /'
