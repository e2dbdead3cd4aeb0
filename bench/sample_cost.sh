#!/usr/bin/env bash
# Cost of a sample (docs/performance.md, "A sample against an older build"): render time at equal
# spp of two builds of tessera, OLD and NEW, alternating OLD/NEW in each round so that both see the
# same machine load; the median of the rounds per build and the median of the per-round ratios.
# Each run is `tessera render SCENE --spp SPP --width 320 --height 180 --threads THREADS`; its
# "times:" line gives the render seconds (without load and BVH build).
#
# Usage: bench/sample_cost.sh OLD_BUILD_DIR NEW_BUILD_DIR
# Environment: SC_SCENES="bathroom living-room" SC_ROUNDS=5 SC_SPP=16 SC_THREADS=2
# A missing scene is an error, never a skip. Both builds render each scene once, untimed, first.
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/compare_builds.sh
scenes=(${SC_SCENES:-bathroom living-room})
rounds=${SC_ROUNDS:-5}
spp=${SC_SPP:-16}
threads=${SC_THREADS:-2}
compare_builds_setup sample_cost.sh "$@"

# Prints the render seconds of one run.
run() {
  "$1" render "$shared/scenes/$2/scene.xml" --spp "$spp" --width 320 --height 180 --threads "$threads" -q \
    -o "$tmp/out.exr" > "$tmp/log" 2>&1 || { cat "$tmp/log" >&2; exit 1; }
  sed -n 's/^times: .*, render \([0-9.]*\) s.*/\1/p' "$tmp/log"
}

echo "$spp spp, 320x180, $threads threads, $rounds rounds"
printf '| scene | OLD render (s) | NEW render (s) | OLD / NEW (median of rounds) |\n|---|---|---|---|\n'
for s in "${scenes[@]}"; do
  run "$old" "$s" > /dev/null
  run "$new" "$s" > /dev/null
  : > "$tmp/pairs"
  for ((r = 0; r < rounds; r++)); do
    o=$(run "$old" "$s")
    n=$(run "$new" "$s")
    echo "$o $n" >> "$tmp/pairs"
  done
  mo=$(awk '{ print $1 }' "$tmp/pairs" | median)
  mn=$(awk '{ print $2 }' "$tmp/pairs" | median)
  ratio=$(awk '{ print $1 / $2 }' "$tmp/pairs" | median)
  printf '| %s | %s | %s | %.2fx |\n' "$s" "$mo" "$mn" "$ratio"
done
