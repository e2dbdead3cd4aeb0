#!/usr/bin/env bash
# Every shared scene at its reference's resolution (../shared/references/NAME/README.md) with the
# path tracer: render time (parse + load + render, wall clock) at 16 spp, and relMSE against the
# reference at 16 and 64 spp.
# Usage: bench/reference_scenes.sh [BUILD_DIR] [THREADS] [SCENE...]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
threads=${2:-$(nproc)}
shift $(( $# > 2 ? 2 : $# )) || true
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(cornell-box veach-mis veach-bidir living-room bathroom kitchenette staircase2)
shared=../shared
out=$(mktemp -d)
for s in "${scenes[@]}"; do
  res=$(grep -o 'Resolution [0-9]*×[0-9]*' "$shared/references/$s/README.md" | grep -o '[0-9][0-9]*')
  w=$(echo "$res" | sed -n 1p); h=$(echo "$res" | sed -n 2p)
  extra=()
  [ "$s" = staircase2 ] && extra=(--allow-unsupported)  # for its medium
  for spp in 16 64; do
    start=$(date +%s%N)
    "$build/cli/tessera" render "$shared/scenes/$s/scene.xml" -o "$out/$s.exr" --width "$w" --height "$h" \
      --spp "$spp" --threads "$threads" --integrator path "${extra[@]}" -q 2>/dev/null
    end=$(date +%s%N)
    ms=$(( (end - start) / 1000000 ))
    printf '%s %dx%d spp=%d threads=%d seconds=%d.%03d ' "$s" "$w" "$h" "$spp" "$threads" $((ms / 1000)) $((ms % 1000))
    "$build/cli/tessera" compare "$out/$s.exr" "$shared/references/$s/reference.exr" | head -1
  done
done
rm -rf "$out"
