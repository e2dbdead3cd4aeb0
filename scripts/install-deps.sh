#!/usr/bin/env bash
# Installs every Debian 12 package Tessera's build and tests need. Idempotent; run as root
# (or with sudo available). Nothing is downloaded from anywhere but Debian's archive.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libgtest-dev libgmock-dev
  nlohmann-json3-dev libtinyobjloader-dev libpugixml-dev libstb-dev libspdlog-dev libfmt-dev
  libtbb-dev libcli11-dev libopenexr-dev libimath-dev zlib1g-dev
  libcpp-httplib-dev libsqlite3-dev libssl-dev libzstd-dev libarchive-dev
  curl bc openssl
  python3-yaml iproute2
  chromium chromium-driver python3-selenium
)

# What the built programs load at run time: the runtime stage of docker/Dockerfile installs only
# these (--runtime), plus curl for its HEALTHCHECK. tests/deploy checks them against the binaries.
runtime_packages=(
  libc6 libgcc-s1 libstdc++6 libtbb12 libopenexr-3-1-30 libpugixml1v5 libtinyobjloader2rc10 libstb0
  libspdlog1.10 libfmt9 zlib1g libzstd1 libarchive13 libssl3 libsqlite3-0 libcpp-httplib0.11
  ca-certificates curl
)
case "${1:-}" in
  "") ;;
  --runtime) packages=("${runtime_packages[@]}") ;;
  --list-runtime) printf '%s\n' "${runtime_packages[@]}"; exit 0 ;;
  *) echo "usage: install-deps.sh [--runtime | --list-runtime]" >&2; exit 2 ;;
esac

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
