#!/usr/bin/env bash
# Builds Tessera and runs every test: the Release suite, then the loader fuzz test and the farm's
# input decoders under AddressSanitizer/UBSan. Usage: scripts/test.sh   (from anywhere; installs packages if missing)
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -LE fuzz -j1

# Sanitizer build: the loader fuzz test, and the farm's decoders of untrusted bytes (bundles, tile
# results, JSON settings) under AddressSanitizer/UBSan too.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTESSERA_SANITIZE=ON
cmake --build build-asan -j"$jobs" --target loader_fuzz_test farm_test
ctest --test-dir build-asan --output-on-failure -L fuzz
ctest --test-dir build-asan --output-on-failure -R '^farm_test$'
