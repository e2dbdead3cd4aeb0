#!/usr/bin/env bash
# Builds Tessera and runs every test, stage by stage, printing how long each took:
#   1. packages   scripts/install-deps.sh (the build's and the tests' Debian packages)
#   2. build      the Release build (8-wide AVX2 BVH)
#   3. suite      every CTest entry but the fuzz ones, two at a time (GoogleTest cases one by one)
#   4. clang      Clang's thread-safety analysis and the 80-line function limit on server/ and cli/
#                 (scripts/clang-checks.sh)
#   5. container  the image with this build's programs, run as a farm whose image must equal this
#                 build's `tessera render` (tests/deploy/container_test.sh)
#   6. sanitizers the loader fuzz test, the farm's decoders of untrusted bytes and the BVH tests under
#                 AddressSanitizer/UBSan, built for SSE2 (4-wide BVH), so both widths are tested
# Usage: scripts/test.sh   (from anywhere; installs packages if missing)
set -euo pipefail
cd "$(dirname "$0")/.."

jobs=$(nproc 2>/dev/null || echo 2)
started=$SECONDS
stage_start=$SECONDS
stages=()
stage() {  # stage NAME: ends the previous stage (printing its time) and starts NAME
  if [ -n "${stage_name:-}" ]; then
    stages+=("$(printf '%-11s %5d s' "$stage_name" $((SECONDS - stage_start)))")
    echo "=== $stage_name: $((SECONDS - stage_start)) s"
  fi
  stage_name=${1:-}
  stage_start=$SECONDS
  [ -z "$stage_name" ] || echo "=== $stage_name"
}
summary() {
  stage
  echo "=== stages (scripts/test.sh):"
  printf '    %s\n' "${stages[@]}"
  echo "    total       $((SECONDS - started)) s"
}
trap 'summary' EXIT

stage packages
bash scripts/install-deps.sh

stage build
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"

stage suite
ctest --test-dir build --output-on-failure -LE fuzz -j"$jobs"

stage clang
bash scripts/clang-checks.sh build

# 77 is a skip (not root, no podman), never under CI.
stage container
status=0
bash tests/deploy/container_test.sh build || status=$?
[ $status -eq 0 ] || [ $status -eq 77 ] || exit $status

stage sanitizers
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTESSERA_SANITIZE=ON -DTESSERA_SIMD=sse2
cmake --build build-asan -j"$jobs" --target loader_fuzz_test farm_test accel_test guiding_test
ctest --test-dir build-asan --output-on-failure -j"$jobs" -L fuzz
ctest --test-dir build-asan --output-on-failure -j"$jobs" -R '^(farm_test|accel_test|guiding_test)\.'
