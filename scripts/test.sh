#!/usr/bin/env bash
# Builds Tessera and runs every test: the Release suite, then the loader fuzz test under
# AddressSanitizer/UBSan. Usage: scripts/test.sh   (from anywhere; installs packages if missing)
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -LE fuzz -j1

# Sanitizer build: only what the fuzz label needs.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTESSERA_SANITIZE=ON
cmake --build build-asan -j"$jobs" --target loader_fuzz_test
ctest --test-dir build-asan --output-on-failure -L fuzz
