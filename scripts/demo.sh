#!/usr/bin/env bash
# Sets up Tessera and renders the demo scene. Usage: scripts/demo.sh [OUT.png]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo.png}

bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc 2>/dev/null || echo 2)" --target tessera
mkdir -p "$(dirname "$out")"
./build/cli/tessera render scenes/demo/scene.xml -o "$out" -o "${out%.*}.exr"
echo "demo: wrote $out and ${out%.*}.exr"
