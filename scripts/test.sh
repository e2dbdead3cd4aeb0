#!/usr/bin/env bash
# Builds Tessera and runs every test: the Release suite (8-wide AVX2 BVH), the container image
# (tests/deploy/container_test.sh), then the loader fuzz test, the farm's input decoders and the BVH
# tests under AddressSanitizer/UBSan in the other SIMD baseline (TESSERA_SIMD=sse2: 4-wide BVH), so
# both widths are tested. Usage: scripts/test.sh   (from anywhere; installs packages if missing)
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -LE fuzz -j1

# The container image: built with podman (on a debootstrapped Debian 12) and run as a farm whose
# image must equal this build's `tessera render`. 77 is a skip (not root, no podman), never under CI.
status=0
bash tests/deploy/container_test.sh build || status=$?
[ $status -eq 0 ] || [ $status -eq 77 ] || exit $status

# Sanitizer build: the loader fuzz test, and the farm's decoders of untrusted bytes (bundles, tile
# results, JSON settings, guides and training records) under AddressSanitizer/UBSan too; built for
# SSE2, so the BVH tests (against brute force and Embree's answers) also cover the 4-wide nodes.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTESSERA_SANITIZE=ON -DTESSERA_SIMD=sse2
cmake --build build-asan -j"$jobs" --target loader_fuzz_test farm_test accel_test guiding_test
ctest --test-dir build-asan --output-on-failure -L fuzz
ctest --test-dir build-asan --output-on-failure -R '^(farm_test|accel_test|guiding_test)$'
