#!/usr/bin/env bash
# Installs the Debian 12 packages Tessera needs. Idempotent; run as root (or with sudo available).
# Nothing is downloaded from anywhere but Debian's archive.
#   install-deps.sh              build and every test (what CI and scripts/test.sh use)
#   install-deps.sh --build      only what compiling and running tessera, tessera-server and
#                                tessera-worker needs (scripts/demo.sh and the image's build stage: no
#                                browser, test framework or container tools)
#   install-deps.sh --runtime    only what the built programs load (the image's runtime stage)
#   --list, --list-build, --list-runtime print a list instead of installing it
set -euo pipefail

build_packages=(
  build-essential cmake ninja-build pkg-config
  nlohmann-json3-dev libtinyobjloader-dev libpugixml-dev libstb-dev libspdlog-dev libfmt-dev
  libtbb-dev libcli11-dev libopenexr-dev libimath-dev zlib1g-dev
  libcpp-httplib-dev libsqlite3-dev libssl-dev libzstd-dev libxxhash-dev libarchive-dev
)

# The tests on top of the build: GoogleTest, the tools test scripts call (OpenImageIO's read the
# AOV layers; jsonschema checks the farm's answers against docs/openapi.json; clang-tidy runs the
# clang stage, scripts/clang-checks.sh), the dashboard's browser test, and tests/deploy/container_test.sh, which makes a
# Debian base with debootstrap and builds and runs the image with podman. runc is named so apt does not pick crun for podman (crun fails on some
# cgroup v1 hosts, docker/podman-env.sh); catatonit is compose's `init: true`, netavark and
# aardvark-dns the network and service names, iptables its port publishing.
test_packages=(
  libgtest-dev libgmock-dev clang-tidy
  curl bc openssl jq openimageio-tools
  python3-yaml python3-jsonschema iproute2
  chromium chromium-driver python3-selenium
  podman runc catatonit netavark aardvark-dns iptables buildah debootstrap podman-compose
)

# What the built programs load at run time: the runtime stage of docker/Dockerfile installs only
# these (--runtime), plus curl for its HEALTHCHECK. tests/deploy checks them against the binaries.
runtime_packages=(
  libc6 libgcc-s1 libstdc++6 libtbb12 libopenexr-3-1-30 libpugixml1v5 libtinyobjloader2rc10 libstb0
  libspdlog1.10 libfmt9 zlib1g libzstd1 libxxhash0 libarchive13 libssl3 libsqlite3-0 libcpp-httplib0.11
  ca-certificates curl
)

packages=("${build_packages[@]}" "${test_packages[@]}")
case "${1:-}" in
  "") ;;
  --build) packages=("${build_packages[@]}") ;;
  --runtime) packages=("${runtime_packages[@]}") ;;
  --list) printf '%s\n' "${packages[@]}"; exit 0 ;;
  --list-build) printf '%s\n' "${build_packages[@]}"; exit 0 ;;
  --list-runtime) printf '%s\n' "${runtime_packages[@]}"; exit 0 ;;
  *) echo "usage: install-deps.sh [--build | --runtime | --list | --list-build | --list-runtime]" >&2; exit 2 ;;
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
