#!/usr/bin/env bash
# Speed against error (docs/performance.md): `tessera bench convergence` for cornell-box, veach-mis,
# living-room and bathroom at their references' resolution (../shared/references/NAME/README.md),
# per sampling strategy (bsdf, nee, mis), writing NAME.csv, NAME.svg and NAME.txt (the command's
# output, with the times to relMSE 0.01 and 0.001) into docs/performance/.
#
# Usage: bench/convergence.sh [BUILD_DIR] [BUDGET]
#   BUDGET  seconds: after spp 1,2,4 each strategy keeps doubling spp until one render takes this
#           long (so about 2 x BUDGET per strategy and scene); 0: only the spp list. Default 8.
# Environment (for the CI smoke run and experiments):
#   CONV_SCENES="cornell-box ..."  CONV_STRATEGIES=bsdf,nee,mis  CONV_SPP=1,2,4  CONV_OUT=docs/performance
#   CONV_GUIDING=off,on (path guiding, each strategy with each; default off)
#   CONV_ADAPTIVE=off,on (adaptive sampling, each series with each; default off)
#   CONV_THREADS=N (default: all cores)  TESSERA=path/to/tessera (default: BUILD_DIR/cli/tessera)
# A missing scene or reference is an error (exit 1), never a skip.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
budget=${2:-8}
tessera=${TESSERA:-$build/cli/tessera}
shared=../shared
scenes=(${CONV_SCENES:-cornell-box veach-mis living-room bathroom})
strategies=${CONV_STRATEGIES:-bsdf,nee,mis}
guiding=${CONV_GUIDING:-off}
adaptive=${CONV_ADAPTIVE:-off}
spp=${CONV_SPP:-1,2,4}
out=${CONV_OUT:-docs/performance}
threads=${CONV_THREADS:-$(nproc)}

[ -x "$tessera" ] || { echo "convergence.sh: no tessera binary at $tessera" >&2; exit 1; }
for s in "${scenes[@]}"; do
  for f in "$shared/scenes/$s/scene.xml" "$shared/references/$s/reference.exr" "$shared/references/$s/README.md"; do
    [ -f "$f" ] || { echo "convergence.sh: missing $f" >&2; exit 1; }
  done
done
mkdir -p "$out"

seconds_args=()
awk "BEGIN { exit !($budget > 0) }" && seconds_args=(--seconds "$budget")
for s in "${scenes[@]}"; do
  res=$(grep -o 'Resolution [0-9]*×[0-9]*' "$shared/references/$s/README.md" | grep -o '[0-9][0-9]*')
  w=$(echo "$res" | sed -n 1p); h=$(echo "$res" | sed -n 2p)
  [ -n "$w" ] && [ -n "$h" ] || { echo "convergence.sh: no resolution in $shared/references/$s/README.md" >&2; exit 1; }
  echo "== $s ${w}x${h} strategies=$strategies guiding=$guiding adaptive=$adaptive spp=$spp budget=${budget}s threads=$threads" >&2
  "$tessera" bench convergence "$shared/scenes/$s/scene.xml" --reference "$shared/references/$s/reference.exr" \
    --width "$w" --height "$h" --spp "$spp" "${seconds_args[@]}" --strategy "$strategies" --guiding "$guiding" \
    --adaptive "$adaptive" --threads "$threads" \
    --csv "$out/$s.csv" --plot "$out/$s.svg" | tee "$out/$s.txt"
done
