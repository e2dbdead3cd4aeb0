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
  curl bc
)

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
