#!/usr/bin/env bash
# Cost of motion-blur support on a scene where nothing moves, and of real motion.
# Renders ../shared/scenes/SCENE (default cornell-box) at 256x256, SPP (default 32) with the path
# tracer, best of RUNS (default 3) wall-clock runs, in four variants written next to symlinks of the
# scene's folder in a temp dir (nothing is copied):
#   static      the scene as shipped (shutter 0/0: no time sample, no motion instances)
#   shutter     shutterOpen 0 / shutterClose 1, nothing moving (the time sample only)
#   offscreen   + a small sphere moving far outside the view (every ray tests the motion branch)
#   moving      + a sphere moving through the view (real motion blur)
# Prints samples per second (camera samples); static vs offscreen is the cost for a still scene.
# Usage: bench/motion_blur.sh [BUILD_DIR] [THREADS] [SCENE] [SPP] [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
threads=${2:-$(nproc)}
scene=${3:-cornell-box}
spp=${4:-32}
runs=${5:-3}
src=$(cd ../shared/scenes/"$scene" && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for f in "$src"/*; do [ "$(basename "$f")" = scene.xml ] || ln -s "$f" "$out/"; done
shutter='<float name="shutterOpen" value="0"/><float name="shutterClose" value="1"/>'
# The sensor opening tag may carry attributes and spaces; the shutter goes right after it.
sed "0,/<sensor[^>]*>/s||&$shutter|" "$src/scene.xml" > "$out/shutter.xml"
far='<shape type="sphere"><float name="radius" value="0.01"/><point name="center" x="1000" y="1000" z="1000"/><point name="centerClose" x="1000.5" y="1000" z="1000"/></shape>'
sed "s|</scene>|$far</scene>|" "$out/shutter.xml" > "$out/offscreen.xml"
# Cornell box: the room spans about [-1, 1] x [0, 2] x [-1, 1]; the camera looks along -z from (0, 1, 6.8).
near='<shape type="sphere"><float name="radius" value="0.25"/><point name="center" x="-0.5" y="1" z="0"/><point name="centerClose" x="0.5" y="1.2" z="0"/></shape>'
sed "s|</scene>|$near</scene>|" "$out/shutter.xml" > "$out/moving.xml"
cp "$src/scene.xml" "$out/static.xml"
w=256 h=256
for v in static shutter offscreen moving; do
  best=0
  for ((r = 0; r < runs; ++r)); do
    start=$(date +%s%N)
    "$build/cli/tessera" render "$out/$v.xml" -o "$out/$v.exr" --width $w --height $h --spp "$spp" \
      --threads "$threads" --integrator path -q 2>/dev/null
    end=$(date +%s%N)
    ns=$((end - start))
    (( best == 0 || ns < best )) && best=$ns
  done
  awk -v v="$v" -v ns="$best" -v n=$((w * h * spp)) -v t="$threads" -v s="$scene" \
    'BEGIN { printf "%-10s %s 256x256 spp=%d threads=%d seconds=%.3f samples/s=%.0f\n", v, s, n / 65536, t, ns / 1e9, n / (ns / 1e9) }'
done
