#!/usr/bin/env bash
# Scene load time and texture memory (docs/performance.md, "Scene load and texture memory"): the
# textured shared scenes loaded by two builds of tessera, OLD and NEW, alternating OLD/NEW in each
# round so that both see the same machine load; the median of the rounds per build. Each run is
# `tessera render SCENE --spp 1 --width 64 --height 64` (the render itself takes milliseconds);
# its "times:" line gives load (meshes, images, BSDFs) and BVH build, the "memory:" line of NEW
# gives texture bytes as stored and as float (the layout OLD keeps every texel in).
#
# Usage: bench/scene_load.sh OLD_BUILD_DIR NEW_BUILD_DIR
# Environment: SL_SCENES="bathroom ..." (default: the four textured scenes)  SL_ROUNDS=5
# A missing scene is an error, never a skip. The file cache is warmed by one untimed run each.
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/compare_builds.sh
scenes=(${SL_SCENES:-bathroom kitchenette living-room staircase2})
rounds=${SL_ROUNDS:-5}
compare_builds_setup scene_load.sh "$@"

# Prints "load bvh" (seconds) of one run, and keeps its log for the memory line.
run() {
  "$1" render "$shared/scenes/$2/scene.xml" --spp 1 --width 64 --height 64 -q -o "$tmp/out.exr" > "$tmp/log" 2>&1 ||
    { cat "$tmp/log" >&2; exit 1; }
  sed -n 's/^times: parse [0-9.]* s, load \([0-9.]*\) s (BVH build \([0-9.]*\) s).*/\1 \2/p' "$tmp/log"
}

printf '| scene | load OLD (s) | load NEW (s) | speed-up | load+BVH OLD (s) | load+BVH NEW (s) | speed-up | textures NEW (MB) | textures as float (MB) |\n'
printf '|---|---|---|---|---|---|---|---|---|\n'
for s in "${scenes[@]}"; do
  run "$old" "$s" > /dev/null
  run "$new" "$s" > /dev/null
  : > "$tmp/old"
  : > "$tmp/new"
  for ((r = 0; r < rounds; r++)); do
    run "$old" "$s" >> "$tmp/old"
    run "$new" "$s" >> "$tmp/new"
  done
  read -r tex_mb float_mb < <(sed -n 's/^memory:.*textures \([0-9.]*\) MB in [0-9]* images (\([0-9.]*\) MB as float).*/\1 \2/p' "$tmp/log")
  lo=$(awk '{ print $1 }' "$tmp/old" | median)
  ln=$(awk '{ print $1 }' "$tmp/new" | median)
  to=$(awk '{ print $1 + $2 }' "$tmp/old" | median)
  tn=$(awk '{ print $1 + $2 }' "$tmp/new" | median)
  awk -v s="$s" -v lo="$lo" -v ln="$ln" -v to="$to" -v tn="$tn" -v tm="${tex_mb:-0}" -v fm="${float_mb:-0}" \
    'BEGIN { printf "| %s | %.3f | %.3f | %.2fx | %.3f | %.3f | %.2fx | %.1f | %.1f |\n", s, lo, ln, lo / ln, to, tn, to / tn, tm, fm }'
done
