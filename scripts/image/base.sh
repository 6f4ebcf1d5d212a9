#!/usr/bin/env bash
# The base images the Dockerfile's FROM lines name, made from Debian's packages, for a machine
# that reaches Debian's mirror but no image registry:
#
#   bash scripts/image/base.sh            # then: podman build --pull=never -t mocapqa .
#
# A minimal root file system of the Debian release the names carry (bookworm) is made with
# `debootstrap --variant=minbase` and imported with `podman import`; each base is then one
# `apt-get install` on it, tagged under exactly the name its FROM line uses (podman stores it as
# localhost/NAME, which `podman build --pull=never` resolves the short name to):
#
#   python:X.Y.Z-slim-bookworm   Debian's python3 (X.Y must be the release's), pip, `python` and
#                                `pip` on PATH, pip allowed to install into the system
#   node:N.N.N-bookworm-slim     Debian's nodejs (>= 18) with npm (10.8.2) from its own package
#                                on the npm registry (`npm pack`), as the official image ships
#                                it, enough for `npm ci`
#
# Patch releases differ from the official images (bookworm has Python 3.11.2 and Node.js 18):
# the image's behaviour is checked by scripts/image/check.sh, not its version strings. Debian's
# own npm package would cost 384 packages and two minutes to install; npm's published package
# carries its dependencies in one 2.5 MB file.
#
# Debian marks its system Python "externally managed" (PEP 668), so a plain `pip install`
# refuses to run; the official python images have no such marker and install into the system
# interpreter, which is what the Dockerfile does. The marker is removed rather than a virtual
# environment put first on PATH, so that the one Dockerfile installs the same way, into the same
# places (/usr/local/bin/mocapqa, /usr/local/lib/python3.11), on this base and on the official one.
#
# Cached by the hash of this script and the names: images already in podman's storage with that
# key are kept; else an archive in $MOCAPQA_IMAGE_CACHE (default ~/.cache/mocapqa/image) is
# loaded; else they are made (1 to 2 min here, mostly debootstrap) and the archive written.
# Needs root, debootstrap, podman, and npm to fetch npm's package.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
DOCKERFILE=${DOCKERFILE:-$ROOT/Dockerfile}
MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
CACHE=${MOCAPQA_IMAGE_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/mocapqa/image}
LABEL=org.mocapqa.base.key
# The npm that node:20.18.0 ships; it runs on Node.js ^18.17 || >= 20.5.
NPM_VERSION=${NPM_VERSION:-10.8.2}

say() { printf 'base: %s\n' "$*" >&2; }
die() { say "$*"; exit 1; }

python_ref="" node_ref=""
while read -r ref; do
  case "$ref" in
    python:*) python_ref=$ref ;;
    node:*) node_ref=$ref ;;
  esac
done < <(awk 'toupper($1) == "FROM" { print $2 }' "$DOCKERFILE")
[ -n "$python_ref" ] || die "Expected a 'FROM python:…' line in $DOCKERFILE, got none"
[ -n "$node_ref" ] || die "Expected a 'FROM node:…' line in $DOCKERFILE, got none"

suite=""
for release in bookworm trixie bullseye; do
  case "$python_ref" in *"$release"*) suite=$release ;; esac
done
[ -n "$suite" ] || die "Expected a Debian release name in '$python_ref', got none"
case "$node_ref" in *"$suite"*) ;; *) die "Expected '$node_ref' on $suite, like '$python_ref'" ;; esac
python_minor=$(printf '%s' "${python_ref#python:}" | cut -d. -f1,2)

key=$( { cat "${BASH_SOURCE[0]}"; printf '%s\n' "$python_ref" "$node_ref" "$MIRROR" "$NPM_VERSION"; } \
  | sha256sum | cut -c1-16)
archive=$CACHE/base-$suite-$key.tar

stored_key() { podman image inspect --format "{{ index .Labels \"$LABEL\" }}" "$1" 2>/dev/null || true; }

if [ "$(stored_key "$python_ref")" = "$key" ] && [ "$(stored_key "$node_ref")" = "$key" ]; then
  say "$python_ref and $node_ref already in podman's storage (key $key)"
  exit 0
fi
if [ -f "$archive" ]; then
  say "loading $archive"
  podman load --quiet --input "$archive" >/dev/null
  if [ "$(stored_key "$python_ref")" = "$key" ] && [ "$(stored_key "$node_ref")" = "$key" ]; then
    say "$python_ref and $node_ref loaded from the cache (key $key)"
    exit 0
  fi
  say "the archive did not hold both images; making them again"
fi

command -v debootstrap >/dev/null || die "Expected debootstrap (apt-get install debootstrap), got none"
command -v npm >/dev/null || die "Expected npm on this machine (to fetch npm $NPM_VERSION), got none"
command -v podman >/dev/null || die "Expected podman (apt-get install podman), got none"
[ "$(id -u)" = 0 ] || die "Expected to run as root (debootstrap, podman's storage), got uid $(id -u)"

work=$(mktemp -d "${TMPDIR:-/var/tmp}/mocapqa-base.XXXXXX")
core=localhost/mocapqa-debian-core:$suite-$key
cleanup() {
  # debootstrap leaves nothing mounted when it ends, but one killed midway may: unmount before
  # removing, and never cross into another file system.
  if [ -d "$work/rootfs" ]; then
    for point in $(awk -v r="$work/rootfs" 'index($2, r) == 1 { print $2 }' /proc/mounts | sort -r); do
      umount -l "$point" 2>/dev/null || true
    done
  fi
  rm -rf --one-file-system "$work"
}
trap cleanup EXIT

started=$(date +%s)
# npm's own package, fetched (and checked against the registry's integrity hash) meanwhile.
(cd "$work" && npm pack --silent "npm@$NPM_VERSION" >npm-pack.log 2>&1) & npm_pid=$!
say "debootstrap --variant=minbase $suite from $MIRROR"
# In two stages, so that dpkg skips its fsync of every file from the start (force-unsafe-io,
# which the official Debian images set too): 65 s instead of 140 s here. The second stage
# mounts /proc in the root file system itself and unmounts it when it ends.
debootstrap --foreign --variant=minbase --include=ca-certificates,netbase,tzdata \
  "$suite" "$work/rootfs" "$MIRROR" >"$work/debootstrap.log" 2>&1 \
  || { tail -n 30 "$work/debootstrap.log" >&2; die "debootstrap (first stage) failed"; }
mkdir -p "$work/rootfs/etc/dpkg/dpkg.cfg.d"
printf 'force-unsafe-io\n' >"$work/rootfs/etc/dpkg/dpkg.cfg.d/docker-apt-speedup"
chroot "$work/rootfs" /debootstrap/debootstrap --second-stage >>"$work/debootstrap.log" 2>&1 \
  || { tail -n 30 "$work/debootstrap.log" >&2; die "debootstrap (second stage) failed"; }
# The official images' sources (the release, its updates, its security fixes) and their
# trimming: no documentation or man pages in later installs, no package lists kept.
rm -f "$work/rootfs/etc/apt/sources.list"
cat >"$work/rootfs/etc/apt/sources.list.d/debian.sources" <<EOF
Types: deb
URIs: $MIRROR
Suites: $suite $suite-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: ${MIRROR%/debian}/debian-security
Suites: $suite-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
cat >"$work/rootfs/etc/dpkg/dpkg.cfg.d/excludes" <<'EOF'
path-exclude /usr/share/doc/*
path-include /usr/share/doc/*/copyright
path-exclude /usr/share/man/*
path-exclude /usr/share/info/*
path-exclude /usr/share/locale/*
EOF
printf 'APT::Install-Recommends "false";\n' >"$work/rootfs/etc/apt/apt.conf.d/docker-no-recommends"
rm -rf "$work/rootfs/var/lib/apt/lists/"* "$work/rootfs/var/cache/apt/archives/"*.deb \
  "$work/rootfs/usr/share/doc/"*/changelog* "$work/rootfs/usr/share/man/"*
say "root file system made in $(($(date +%s) - started)) s"
wait "$npm_pid" || { cat "$work/npm-pack.log" >&2; die "npm pack npm@$NPM_VERSION failed"; }
mv "$work/npm-$NPM_VERSION.tgz" "$work/npm.tgz"

tar --numeric-owner -C "$work/rootfs" -c . \
  | podman import --quiet \
      --change 'ENV PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
      --change 'ENV LANG=C.UTF-8' \
      --change 'CMD ["bash"]' \
      - "$core" >/dev/null
rm -rf --one-file-system "$work/rootfs"

# One install per base on the imported root file system, in podman's own build (it mounts
# /proc and /dev for the packages' scripts). Both run at once: mostly downloads and unpacking.
cat >"$work/python.Containerfile" <<EOF
FROM $core
RUN apt-get update \\
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \\
      python3 python3-pip python-is-python3 \\
 && rm -f /usr/lib/python3*/EXTERNALLY-MANAGED \\
 && rm -rf /var/lib/apt/lists/* /var/cache/apt/*.bin \\
 && test "\$(python -c 'import sys; print("%d.%d" % sys.version_info[:2])')" = "$python_minor"
RUN python --version && pip --version && test ! -e /usr/lib/python3.11/EXTERNALLY-MANAGED
LABEL $LABEL=$key org.mocapqa.base.made-from="Debian $suite packages"
CMD ["python3"]
EOF
cat >"$work/node.Containerfile" <<EOF
FROM $core
COPY npm.tgz /tmp/npm.tgz
RUN apt-get update \\
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends nodejs \\
 && rm -rf /var/lib/apt/lists/* /var/cache/apt/*.bin \\
 && mkdir -p /usr/local/lib/node_modules/npm \\
 && tar -xzf /tmp/npm.tgz --strip-components=1 -C /usr/local/lib/node_modules/npm \\
 && rm /tmp/npm.tgz \\
 && ln -s ../lib/node_modules/npm/bin/npm-cli.js /usr/local/bin/npm \\
 && ln -s ../lib/node_modules/npm/bin/npx-cli.js /usr/local/bin/npx
RUN node -e 'process.exit(Number(process.versions.node.split(".")[0]) >= 18 ? 0 : 1)' && npm --version
LABEL $LABEL=$key org.mocapqa.base.made-from="Debian $suite packages"
CMD ["node"]
EOF
started=$(date +%s)
build() {
  podman build --isolation chroot --pull=never --layers=false --quiet -t "$1" \
    -f "$work/$2.Containerfile" "$work" >"$work/$2.log" 2>&1 \
    || { tail -n 30 "$work/$2.log" >&2; return 1; }
}
build "$python_ref" python & python_pid=$!
build "$node_ref" node & node_pid=$!
failed=0
wait "$python_pid" || failed=1
wait "$node_pid" || failed=1
[ "$failed" = 0 ] || die "installing the bases' packages failed"
podman untag "$core" >/dev/null 2>&1 || true
say "$python_ref and $node_ref made in $(($(date +%s) - started)) s (key $key)"

mkdir -p "$CACHE"
rm -f "$CACHE"/base-"$suite"-*.tar
podman save --quiet --multi-image-archive --output "$archive.part" "$python_ref" "$node_ref"
mv "$archive.part" "$archive"
say "cached in $archive"
