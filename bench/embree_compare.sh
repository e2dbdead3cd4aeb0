#!/usr/bin/env bash
# Tessera's BVH against Intel Embree 3 on the same machine, rays and triangles, in one run:
# single-thread Mrays/s per ray set (rtcIntersect1/rtcOccluded1 against Bvh::intersect/occluded) and
# BVH build seconds on 1 and 2 threads (Embree medium and high quality). Embree is run on every
# instruction set it has and this CPU supports (EC_ISAS, default: sse2, sse4.2, avx, avx2, and
# avx512 when the CPU has AVX-512F), and Tessera is compared with the fastest per ray set. The
# tracers run in alternating rounds, because a shared machine's speed drifts by tens of percent
# within minutes; the ratio reported is the median over rounds of each round's own ratio, so a
# round on a slow minute slows both sides. Installs Debian's libembree-dev (a comparator only: the
# product never links it). Prints figures; asserts nothing.
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

default_isas="sse2 sse4.2 avx avx2"
grep -qw avx512f /proc/cpuinfo && default_isas="$default_isas avx512"
isas=(${EC_ISAS:-$default_isas})
out=$(mktemp)
trap 'rm -f "$out"' EXIT
for round in $(seq "$rounds"); do
  for threads in 1 2; do
    "$build/bench/bench_rays_tool" "$geometry" --rays "$rays" --threads "$threads" --repeat 3 \
      --compare "$hits" | sed "s/^/round=$round tessera threads=$threads /" >>"$out"
  done
  "$build/bench/embree_rays" "$geometry" --rays "$rays" --repeat 3 --compare "$hits" | sed "s/^/round=$round /" >>"$out"
  for isa in "${isas[@]}"; do
    "$build/bench/embree_rays" "$geometry" --rays "$rays" --repeat 3 --config "isa=$isa" |
      grep " rays set=" | sed "s/^/round=$round isa=$isa /" >>"$out"
  done
done

python3 - "$out" "$rounds" "${isas[*]}" <<'EOF'
import re, statistics, sys
lines = open(sys.argv[1]).read().splitlines()
def per_round(pattern):
    vals = {}
    for l in lines:
        m = re.search(r"^round=(\d+) " + pattern, l)
        if m:
            vals.setdefault(int(m.group(1)), []).append(float(m.group(2)))
    return {r: statistics.median(v) for r, v in vals.items()}
def med(pattern):
    vals = list(per_round(pattern).values())
    return statistics.median(vals) if vals else float('nan')
isas = sys.argv[3].split()
print(f"# medians over {sys.argv[2]} alternating rounds")
print("| rays (1 thread) | Tessera Mrays/s | " + " | ".join(f"Embree {i}" for i in isas) +
      " | fastest | median of per-round ratios | Tessera disagreeing rays |")
print("|---|---|" + "---|" * len(isas) + "---|---|---|")
for s in ("primary", "diffuse", "shadow"):
    t = per_round(rf"tessera threads=1 rays set={s} .*mrays_per_s=([\d.]+)")
    e = {i: per_round(rf"isa={re.escape(i)} embree rays set={s} .*mrays_per_s=([\d.]+)") for i in isas}
    best = max(isas, key=lambda i: statistics.median(e[i].values()) if e[i] else 0.0)
    ratios = [t[r] / e[best][r] for r in t if r in e[best]]
    d = max([int(m.group(1)) for l in lines for m in [re.search(rf"tessera threads=1 compare set={s} disagree=(\d+)", l)] if m] or [0])
    cols = " | ".join(f"{statistics.median(e[i].values()):.2f}" if e[i] else "-" for i in isas)
    print(f"| {s} | {statistics.median(t.values()):.2f} | {cols} | {best} | {statistics.median(ratios):.2f} "
          f"(min {min(ratios):.2f}, max {max(ratios):.2f}) | {d} |")
print()
print("| build (592,186 triangles) | Tessera s | Embree medium s | ratio | Embree high s |")
print("|---|---|---|---|---|")
for th in (1, 2):
    t = med(rf"tessera threads={th} build .*seconds=([\d.]+)")
    em = med(rf"embree build .*threads={th} quality=medium seconds=([\d.]+)")
    eh = med(rf"embree build .*threads={th} quality=high seconds=([\d.]+)")
    print(f"| {th} thread{'s' if th > 1 else ''} | {t:.3f} | {em:.3f} | {t / em:.2f} | {eh:.3f} |")
m = re.search(r"mbytes=([\d.]+)", "\n".join(lines))
print(f"\nTessera BVH: {float(m.group(1)) * 1024 * 1024 / 592186:.1f} bytes per triangle (nodes and triangle packets)")
EOF
