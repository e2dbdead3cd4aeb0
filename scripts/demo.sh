#!/usr/bin/env bash
# Sets up Tessera and renders the demo scene (scenes/demo) through the render farm: a coordinator
# with local workers on this machine, `tessera submit --wait --denoise`; the denoised image is
# downloaded to OUT (+ .exr) and the raw one beside it as OUT_STEM.noisy.png (+ .noisy.exr).
# Usage: scripts/demo.sh [OUT.png] [LOCAL_WORKERS]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo.png}
workers=${2:-2}

# What building and running the three programs needs, no more: the tests' browser, container tools
# and test frameworks come with scripts/test.sh.
bash scripts/install-deps.sh --build
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc 2>/dev/null || echo 2)" --target tessera tessera-server tessera-worker
mkdir -p "$(dirname "$out")"

# A fresh coordinator on a free loopback port, its state in a scratch data directory.
data=$(mktemp -d "${TMPDIR:-/tmp}/tessera-demo.XXXXXX")
./build/server/tessera-server --listen 127.0.0.1:0 --port-file "$data/port" --data-dir "$data/state" \
    --local-workers "$workers" > "$data/server.log" 2>&1 &
server=$!
trap 'kill -TERM $server 2>/dev/null; wait $server 2>/dev/null; rm -rf "$data"' EXIT
for _ in $(seq 100); do [ -s "$data/port" ] && break; sleep 0.1; done
[ -s "$data/port" ] || { cat "$data/server.log"; echo "demo: the coordinator did not start" >&2; exit 1; }
url="http://127.0.0.1:$(cat "$data/port")"
echo "demo: coordinator at $url with $workers local workers"

start=$(date +%s)
./build/cli/tessera submit scenes/demo/scene.xml --server "$url" --wait --denoise -o "$out" -o "${out%.*}.exr"
echo "demo: the farm rendered and denoised it in $(( $(date +%s) - start )) s: wrote $out and ${out%.*}.exr" \
     "(denoised), ${out%.*}.noisy.png and ${out%.*}.noisy.exr (raw)"
