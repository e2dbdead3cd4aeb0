#!/usr/bin/env bash
# Builds the Tessera image (docker/Dockerfile) with podman, from a Debian 12 base image made here
# with debootstrap instead of pulled from a registry: the only network this needs is the Debian
# archive the machine's apt already uses, and the image installs from exactly that archive.
#
# usage: scripts/build-image.sh [--rebuild-base] [--programs DIR] [TAG]
#        (TAG default: $TESSERA_IMAGE or tessera:0.1.0). --programs DIR: put the tessera,
#        tessera-server and tessera-worker of DIR (a Release build on this Debian 12 host, e.g. build/cli
#        etc. gathered by the caller) into the image instead of compiling them in its build stage.
# Run as root. The base is built once and reused (localhost/debian:12, also tagged debian:12-slim
# for the runtime stage); --rebuild-base makes it again, e.g. after the archive moved on.
set -euo pipefail
cd "$(dirname "$0")/.."

rebuild_base=0
programs=""
tag="${TESSERA_IMAGE:-tessera:0.1.0}"
while [ $# -gt 0 ]; do
  case "$1" in
    --rebuild-base) rebuild_base=1 ;;
    --programs) programs=${2:?--programs needs a folder}; shift ;;
    -*) echo "usage: build-image.sh [--rebuild-base] [--programs DIR] [TAG]" >&2; exit 2 ;;
    *) tag="$1" ;;
  esac
  shift
done
if [ -n "$programs" ]; then
  for p in tessera tessera-server tessera-worker; do
    [ -x "$programs/$p" ] || { echo "build-image: --programs $programs has no $p" >&2; exit 1; }
  done
fi

need() { command -v "$1" >/dev/null || { echo "build-image: $1 is missing (scripts/install-deps.sh installs it)" >&2; exit 1; }; }
need podman
need debootstrap
if [ "$(id -u)" -ne 0 ]; then echo "build-image: run as root (debootstrap and rootful podman)" >&2; exit 1; fi

rootfs=""
cleanup() {
  if [ -n "$rootfs" ]; then rm -rf "$rootfs" "$rootfs.log"; fi
  if [ -n "${TESSERA_CONTAINERS_CONF:-}" ]; then rm -f "$TESSERA_CONTAINERS_CONF"; fi
}
trap cleanup EXIT
. docker/podman-env.sh

# Every active apt source file of this machine: one-line .list files and deb822 .sources files.
sources_files() {
  [ -s /etc/apt/sources.list ] && echo /etc/apt/sources.list
  for f in /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] && echo "$f"
  done
  return 0
}

# The archive that carries bookworm itself (not -updates or -security): the first `deb` source
# whose suites include it. A mirror is never written here: it is whatever this machine's apt uses.
debian_mirror() {
  local f
  for f in $(sources_files); do
    case "$f" in
      *.sources)
        awk 'BEGIN { RS = ""; FS = "\n" }
             { types = ""; uris = ""; suites = ""; enabled = "yes"
               for (i = 1; i <= NF; i++) {
                 line = $i; sub(/^[ \t]+/, "", line)
                 if (line ~ /^#/) continue
                 key = tolower(substr(line, 1, index(line, ":") - 1)); val = substr(line, index(line, ":") + 1)
                 if (key == "types") types = val; else if (key == "uris") uris = val
                 else if (key == "suites") suites = val; else if (key == "enabled") enabled = val }
               if (types ~ /(^|[ \t])deb([ \t]|$)/ && (" " suites " ") ~ /[ \t]bookworm[ \t]/ && enabled !~ /no/) {
                 split(uris, u, " "); for (k in u) if (u[k] != "") { print u[k]; exit } } }' "$f" ;;
      *)
        awk '$1 == "deb" { i = 2; if ($2 ~ /^\[/) { while ($i !~ /\]$/) i++; i++ }
                           if ($(i + 1) == "bookworm") { print $i; exit } }' "$f" ;;
    esac
  done | head -n 1
}

# Keyrings the sources name (Signed-By / signed-by=), so apt in the image trusts what the host does.
signed_by_files() {
  local f
  for f in $(sources_files); do
    grep -hoiE '(signed-by[:=][[:space:]]*)/[^] ,]+' "$f" | sed -E 's/^[^/]*//'
  done | sort -u
}

base=localhost/debian:12
if [ "$rebuild_base" -eq 1 ] || ! podman image exists "$base"; then
  mirror="${TESSERA_DEBIAN_MIRROR:-$(debian_mirror)}"
  if [ -z "$mirror" ]; then
    echo "build-image: no bookworm source in /etc/apt/sources.list{,.d/*}; set TESSERA_DEBIAN_MIRROR" >&2
    exit 1
  fi
  # Not /tmp: that may be a small tmpfs, and the system is ~200 MB before the cleanup below.
  rootfs=$(mktemp -d /var/tmp/tessera-rootfs.XXXXXX)
  echo "build-image: debootstrap --variant=minbase bookworm from $mirror"
  t0=$SECONDS
  debootstrap --variant=minbase bookworm "$rootfs" "$mirror" >"$rootfs.log" 2>&1 \
    || { tail -n 30 "$rootfs.log" >&2; exit 1; }
  # The host's sources replace debootstrap's one-line list (updates and security included).
  rm -f "$rootfs/etc/apt/sources.list"
  mkdir -p "$rootfs/etc/apt/sources.list.d"
  for f in $(sources_files); do
    cp "$f" "$rootfs$f"
  done
  for k in $(signed_by_files); do
    if [ -f "$k" ] && [ ! -e "$rootfs$k" ]; then
      mkdir -p "$rootfs$(dirname "$k")"
      cp "$k" "$rootfs$k"
    fi
  done
  # apt over https needs CAs before ca-certificates is installed; the host's bundle is the one its
  # apt trusts, which is what matters for the same sources.
  if cat $(sources_files) | grep -qE '^[^#]*https://' && [ -f /etc/ssl/certs/ca-certificates.crt ]; then
    mkdir -p "$rootfs/etc/ssl/certs"
    cp /etc/ssl/certs/ca-certificates.crt "$rootfs/etc/ssl/certs/ca-certificates.crt"
  fi
  # Package lists and caches are stale in an image; the official images leave them out too.
  rm -rf "$rootfs"/var/cache/apt/archives/*.deb "$rootfs"/var/lib/apt/lists/* "$rootfs"/tmp/* "$rootfs"/var/tmp/*
  tar -C "$rootfs" --numeric-owner -cf - . | podman import --quiet \
    --change 'ENV PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
    --change 'CMD ["bash"]' - "$base" >/dev/null
  rm -rf "$rootfs" "$rootfs.log"
  rootfs=""
  echo "build-image: base $base in $((SECONDS - t0)) s"
fi
# The Dockerfile's runtime stage names debian:12-slim; here it is the same minbase system.
podman tag "$base" localhost/debian:12-slim

echo "build-image: building $tag from docker/Dockerfile"
t0=$SECONDS
# --pull=never: the bases are the local ones above, never a registry's. --format docker keeps the
# HEALTHCHECK (the OCI format has none).
from=()
if [ -n "$programs" ]; then
  from=(--target prebuilt --build-context "host-build=$(cd "$programs" && pwd)")
  echo "build-image: the programs are $programs's (not compiled again)"
fi
podman build --pull=never --format docker "${from[@]}" -f docker/Dockerfile -t "$tag" .
echo "build-image: $tag built in $((SECONDS - t0)) s"
