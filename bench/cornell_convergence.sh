#!/usr/bin/env bash
# Error against Mitsuba 3's reference over time: renders ../shared/scenes/cornell-box at the
# reference's 256x256 with 64, 256 and 1024 spp and prints time and relMSE for each.
# Usage: bench/cornell_convergence.sh [BUILD_DIR] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
threads=${2:-$(nproc)}
shared=../shared
out=$(mktemp -d)
for spp in 64 256 1024; do
  start=$(date +%s%N)
  "$build/cli/tessera" render "$shared/scenes/cornell-box/scene.xml" -o "$out/cb_$spp.exr" \
    --width 256 --height 256 --spp "$spp" --threads "$threads" -q 2>/dev/null
  end=$(date +%s%N)
  ms=$(( (end - start) / 1000000 ))
  printf 'cornell-box spp=%d threads=%d seconds=%d.%03d ' "$spp" "$threads" $((ms / 1000)) $((ms % 1000))
  "$build/cli/tessera" compare "$out/cb_$spp.exr" "$shared/references/cornell-box/reference.exr" \
    --variance "$shared/references/cornell-box/variance.exr"
done
rm -rf "$out"
