#!/usr/bin/env bash
# Tessera's BVH against Intel Embree 3 on the same machine, rays and triangles, in one run:
# single-thread Mrays/s per ray set (rtcIntersect1/rtcOccluded1 against Bvh::intersect/occluded) and
# BVH build seconds on 1 and 2 threads (Embree medium and high quality). The two tracers run in
# alternating rounds and the medians are compared, because a shared machine's speed drifts by tens
# of percent within minutes. Installs Debian's libembree-dev (a comparator only: the product never
# links it). Prints figures; asserts nothing.
#
#   bash bench/embree_compare.sh [BUILD_DIR] [ROUNDS]      (defaults: build, 5)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
rounds=${2:-5}
shared=../shared
geometry=$shared/scenes/bathroom/models
rays=$shared/rays/bathroom.rays
hits=$shared/rays/bathroom.embree.hits

if ! dpkg-query -W -f='${Status}' libembree-dev 2>/dev/null | grep -q "install ok installed"; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends libembree-dev >/dev/null
fi
cmake -S . -B "$build" >/dev/null
cmake --build "$build" --target bench_rays_tool embree_rays >/dev/null

out=$(mktemp)
trap 'rm -f "$out"' EXIT
for round in $(seq "$rounds"); do
  for threads in 1 2; do
    "$build/bench/bench_rays_tool" "$geometry" --rays "$rays" --threads "$threads" --repeat 3 \
      --compare "$hits" | sed "s/^/tessera threads=$threads /" >>"$out"
  done
  "$build/bench/embree_rays" "$geometry" --rays "$rays" --repeat 3 --compare "$hits" >>"$out"
done

python3 - "$out" "$rounds" <<'EOF'
import re, statistics, sys
lines = open(sys.argv[1]).read().splitlines()
def med(pattern):
    vals = [float(m.group(1)) for l in lines for m in [re.search(pattern, l)] if m]
    return statistics.median(vals) if vals else float('nan')
print(f"# medians over {sys.argv[2]} alternating rounds")
print("| rays (1 thread) | Tessera Mrays/s | Embree Mrays/s | ratio | Tessera disagreeing rays |")
print("|---|---|---|---|---|")
for s in ("primary", "diffuse", "shadow"):
    t = med(rf"^tessera threads=1 rays set={s} .*mrays_per_s=([\d.]+)")
    e = med(rf"^embree rays set={s} .*mrays_per_s=([\d.]+)")
    d = max([int(m.group(1)) for l in lines for m in [re.search(rf"^tessera threads=1 compare set={s} disagree=(\d+)", l)] if m] or [0])
    print(f"| {s} | {t:.2f} | {e:.2f} | {t / e:.2f} | {d} |")
print()
print("| build (592,186 triangles) | Tessera s | Embree medium s | ratio | Embree high s |")
print("|---|---|---|---|---|")
for th in (1, 2):
    t = med(rf"^tessera threads={th} build .*seconds=([\d.]+)")
    em = med(rf"^embree build .*threads={th} quality=medium seconds=([\d.]+)")
    eh = med(rf"^embree build .*threads={th} quality=high seconds=([\d.]+)")
    print(f"| {th} thread{'s' if th > 1 else ''} | {t:.3f} | {em:.3f} | {t / em:.2f} | {eh:.3f} |")
m = re.search(r"mbytes=([\d.]+)", "\n".join(lines))
print(f"\nTessera BVH: {float(m.group(1)) * 1024 * 1024 / 592186:.1f} bytes per triangle (nodes and triangle packets)")
EOF
