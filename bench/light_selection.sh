#!/usr/bin/env bash
# Light selection at equal time: for the many-lights scene and staircase2, renders with power
# (alias table) and bvh (light hierarchy) selection, each with the spp that fills the same render
# time (from a short calibration render), and reports render seconds, spp and relMSE against a
# reference. staircase2: ../shared/references/staircase2/reference.exr (rendered with volpath, the
# scene's own integrator). many-lights: a high-spp bvh render made once with another seed and cached
# in BUILD/bench-cache/ (delete it to remake it).
# Usage: bench/light_selection.sh [BUILD_DIR] [THREADS] [SECONDS_PER_RENDER] [REF_SPP]
# Env: INTEGRATOR (default: each scene's own), SCENES (default "many-lights staircase2").
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
threads=${2:-$(nproc)}
budget=${3:-20}
ref_spp=${4:-4096}
integrator=${INTEGRATOR:-}
read -r -a scenes <<< "${SCENES:-many-lights staircase2}"
tessera="$build/cli/tessera"
cache="$build/bench-cache"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
mkdir -p "$cache"

scene_path() { [ "$1" = many-lights ] && echo scenes/many-lights/scene.xml || echo "../shared/scenes/$1/scene.xml"; }

# render SCENE STRATEGY SPP SEED OUT -> prints the render seconds (the `times:` line, not load)
render() {
  local log="$out/log.txt"
  "$tessera" render "$(scene_path "$1")" -o "$5" --width 320 --height 180 --spp "$3" --seed "$4" \
    --threads "$threads" ${integrator:+--integrator "$integrator"} --light-selection "$2" --allow-unsupported -q 2>"$log"
  sed -n 's/.*render \([0-9.]*\) s$/\1/p' "$log"
}

for s in "${scenes[@]}"; do
  if [ "$s" = many-lights ]; then
    ref="$cache/many-lights-ref-${integrator:-own}-$ref_spp.exr"
    if [ ! -f "$ref" ]; then
      echo "making the many-lights reference ($ref_spp spp, bvh, seed 777): $ref" >&2
      t=$(render many-lights bvh "$ref_spp" 777 "$ref")
      echo "  took ${t} s" >&2
    fi
  else
    ref="../shared/references/$s/reference.exr"
  fi
  for strategy in power bvh; do
    # Calibrate: seconds per spp from a short render.
    t=$(render "$s" "$strategy" 8 1 "$out/cal.exr")
    spp=$(awk -v t="$t" -v b="$budget" 'BEGIN { s = int(b * 8 / (t > 0 ? t : 1e-3) + 0.5); print (s < 1 ? 1 : s) }')
    t=$(render "$s" "$strategy" "$spp" 1 "$out/$s-$strategy.exr")
    cmp=$("$tessera" compare "$out/$s-$strategy.exr" "$ref" | head -1)
    rel=$(echo "$cmp" | sed -n 's/.*rel_mse=\([^ ]*\).*/\1/p')
    # relMSE x seconds: the figure of merit that does not depend on how well the times matched
    # (relMSE falls as 1/time); lower is better.
    printf '%s %s threads=%d spp=%d seconds=%s rel_mse=%s rel_mse_x_seconds=%s\n' "$s" "$strategy" "$threads" \
      "$spp" "$t" "$rel" "$(awk -v r="$rel" -v t="$t" 'BEGIN { printf "%.4g", r * t }')"
  done
done
