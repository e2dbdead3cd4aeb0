#!/usr/bin/env bash
# A reference rendered by `bdpt` for a shared scene whose own reference, a path render, carries part
# of its light in fireflies (kitchenette: docs/performance.md, "Bidirectional path tracing").
#
# 1. RENDERS independent `bdpt` renders (seeds 1001, 1002, ...) of SPP samples each at the shared
#    reference's resolution, averaged. Writes OUT/SCENE/reference.exr (the mean), variance.exr (the
#    variance of that mean per pixel: the renders' sample variance / RENDERS) and README.md (the
#    settings, the time, the channel means with their standard errors, and whether they match the
#    shared reference's within 3 combined standard errors).
# 2. The channel means at a wall-clock budget: BR_BUDGET_RENDERS renders (seeds 2001, ...) whose
#    samples add up to BR_BUDGET seconds at the rate of an 8-spp calibration render (seed 2000),
#    averaged; against both references, within max(3%, 3 combined standard errors) or not.
# Standard errors of a render's channel means come from the spread of independent renders' means
# (a light path's splats land in many pixels, so pixels are not independent); the shared
# reference's from its per-pixel variance (Mitsuba's path tracer: independent pixels).
#
# Usage: bench/bdpt_reference.sh [BUILD_DIR] [SCENE] [RENDERS] [SPP] [OUT]
#        (defaults: build kitchenette 16 256 out/references)
# Environment: BR_THREADS=2  BR_BUDGET=60  BR_BUDGET_RENDERS=8  TESSERA=path/to/tessera
#   BR_SKIP_REFERENCE=1: reuse OUT/SCENE/reference.exr and runs.csv, run step 2 only.
# Needs oiiotool (OpenImageIO's tools). A missing scene or reference is an error, never a skip.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
scene=${2:-kitchenette}
renders=${3:-16}
spp=${4:-256}
out=${5:-out/references}
tessera=${TESSERA:-$build/cli/tessera}
threads=${BR_THREADS:-2}
budget=${BR_BUDGET:-60}
budget_renders=${BR_BUDGET_RENDERS:-8}
shared=../shared
xml=$shared/scenes/$scene/scene.xml
shared_ref=$shared/references/$scene
for f in "$xml" "$shared_ref/reference.exr" "$shared_ref/variance.exr" "$shared_ref/README.md"; do
  [ -f "$f" ] || { echo "bdpt_reference.sh: missing $f" >&2; exit 1; }
done
[ -x "$tessera" ] || { echo "bdpt_reference.sh: no tessera binary at $tessera" >&2; exit 1; }
command -v oiiotool > /dev/null || { echo "bdpt_reference.sh: needs oiiotool (apt install openimageio-tools)" >&2; exit 1; }
[ "$renders" -ge 2 ] && [ "$budget_renders" -ge 2 ] || { echo "bdpt_reference.sh: at least 2 renders" >&2; exit 1; }
res=$(grep -o 'Resolution [0-9]*×[0-9]*' "$shared_ref/README.md" | grep -o '[0-9][0-9]*')
w=$(echo "$res" | sed -n 1p); h=$(echo "$res" | sed -n 2p)
dir=$out/$scene
mkdir -p "$dir"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# render SEED SPP FILE: prints the render's seconds.
render() {
  "$tessera" render "$xml" --allow-unsupported --integrator bdpt --width "$w" --height "$h" --spp "$2" \
    --seed "$1" --threads "$threads" -q -o "$3" 2> "$tmp/log"
  grep -o 'render [0-9.e+-]* s' "$tmp/log" | tail -1 | awk '{print $2}'
}
# means FILE: the image's channel means (tessera compare's mean=R,G,B).
means() { "$tessera" compare "$1" "$shared_ref/reference.exr" | grep -o ' mean=[^ ]*' | cut -d= -f2; }

# mean_and_variance TMP_DIR OUT_MEAN OUT_VARIANCE FILE... (bench/lib/image_stats.sh)
source bench/lib/image_stats.sh

if [ -z "${BR_SKIP_REFERENCE:-}" ]; then
  : > "$tmp/runs.csv"
  files=()
  for ((i = 0; i < renders; i++)); do
    seed=$((1001 + i))
    secs=$(render "$seed" "$spp" "$tmp/r$i.exr")
    echo "$seed,$secs,$(means "$tmp/r$i.exr")" | tee -a "$tmp/runs.csv" >&2
    files+=("$tmp/r$i.exr")
  done
  mean_and_variance "$tmp" "$dir/reference.exr" "$dir/variance.exr" "${files[@]}"
  cp "$tmp/runs.csv" "$dir/runs.csv"
fi
[ -f "$dir/runs.csv" ] || { echo "bdpt_reference.sh: no $dir/runs.csv: run without BR_SKIP_REFERENCE first" >&2; exit 1; }

# Step 2: the budget renders.
: > "$tmp/budget.csv"
# The rate from a calibration render, so that step 2 measures the machine as it is now.
rate=$(awk -v s="$(render 2000 8 "$tmp/calibration.exr")" 'BEGIN {print s / 8}')
budget_spp=$(awk -v b="$budget" -v k="$budget_renders" -v r="$rate" 'BEGIN {s = int(b / (k * r)); print s < 1 ? 1 : s}')
for ((i = 0; i < budget_renders; i++)); do
  seed=$((2001 + i))
  secs=$(render "$seed" "$budget_spp" "$tmp/b$i.exr")
  echo "$seed,$secs,$(means "$tmp/b$i.exr")" | tee -a "$tmp/budget.csv" >&2
done
shared_var=$(oiiotool "$shared_ref/variance.exr" --printstats | grep -m1 'Stats Avg' | sed 's/.*Avg: *//')
shared_mean=$(oiiotool "$shared_ref/reference.exr" --printstats | grep -m1 'Stats Avg' | sed 's/.*Avg: *//')

python3 - "$dir" "$scene" "$renders" "$spp" "$threads" "$budget" "$budget_spp" "$w" "$h" \
  "$shared_mean" "$shared_var" "$tmp/budget.csv" <<'PY'
import csv, math, statistics, sys
d, scene, renders, spp, threads, budget, budget_spp, w, h, shared_mean, shared_var, budget_csv = sys.argv[1:]
n_pix = int(w) * int(h)
def runs(path):
    rows = [r for r in csv.reader(open(path)) if r]
    secs = sum(float(r[1]) for r in rows)
    means = [[float(x) for x in r[2:5]] for r in rows]
    k = len(means)
    m = [sum(v[c] for v in means) / k for c in range(3)]
    se = [statistics.stdev([v[c] for v in means]) / math.sqrt(k) for c in range(3)]
    return k, secs, m, se
shared_m = [float(x) for x in shared_mean.split()[:3]]
shared_se = [math.sqrt(float(x) / n_pix) for x in shared_var.split()[:3]]
k, secs, ref_m, ref_se = runs(d + "/runs.csv")
bk, bsecs, b_m, b_se = runs(budget_csv)
names = "RGB"
def agree(m, se, rm, rse, floor):
    out = []
    for c in range(3):
        tol = max(floor * rm[c], 3 * math.hypot(se[c], rse[c]))
        out.append("%s %.5f vs %.5f: %+.2f%%, %.2f combined SE, %s" % (
            names[c], m[c], rm[c], 100 * (m[c] / rm[c] - 1), abs(m[c] - rm[c]) / math.hypot(se[c], rse[c]),
            "within" if abs(m[c] - rm[c]) <= tol else "OUTSIDE"))
    return out
lines = ["# %s: a bdpt reference" % scene, "",
         "Made by `bench/bdpt_reference.sh` (see its header): %d bdpt renders of %s spp (seeds 1001..%d), %s×%s, "
         "%s threads, %.0f s of rendering in all; `reference.exr` their mean, `variance.exr` the per-pixel "
         "variance of that mean." % (k, spp, 1000 + k, w, h, threads, secs), "",
         "Channel means (standard error from the spread of the renders' means):"]
lines += ["- %s %.5f ± %.5f" % (names[c], ref_m[c], ref_se[c]) for c in range(3)]
lines += ["", "Against the shared reference's means (standard error from its variance.exr), within 3 combined standard errors or not:"]
lines += ["- " + s for s in agree(ref_m, ref_se, shared_m, shared_se, 0.0)]
lines += ["", "At a %s-s budget (%d renders of %s spp, seeds 2001.., %.1f s in all), channel means within "
          "max(3%%, 3 combined standard errors) or not:" % (budget, bk, budget_spp, bsecs), "", "Against the shared reference:"]
lines += ["- " + s for s in agree(b_m, b_se, shared_m, shared_se, 0.03)]
lines += ["", "Against this reference:"]
lines += ["- " + s for s in agree(b_m, b_se, ref_m, ref_se, 0.03)]
open(d + "/README.md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
