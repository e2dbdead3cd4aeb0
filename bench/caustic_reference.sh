#!/usr/bin/env bash
# A reference for one of Tessera's own scenes (scenes/SCENE/scene.xml: pool, glass-caustic,
# door-ajar, window-pane), which have no Mitsuba reference in ../shared, made by two independent
# methods that must agree:
#
# 1. Method A, CR_METHOD_A (default `sppm`): RENDERS independent renders of SPP_A passes (seeds 1001, 1002, ...) at the
#    scene's own resolution, averaged: OUT/SCENE/A/reference.exr (the mean), variance.exr (the
#    variance of that mean per pixel: the renders' sample variance / RENDERS) and runs.csv (per
#    render its seed, seconds and channel means).
# 2. Method B, CR_METHOD_B (default `bdpt`; `vcm` for glass-caustic, whose point light's caustic
#    seen in a mirror `bdpt` cannot render): RENDERS renders of SPP_B samples (vcm: iterations),
#    seeds 2001, 2002, ...: OUT/SCENE/B/reference.exr, variance.exr, runs.csv.
# 3. OUT/SCENE/reference.exr = (A + B) / 2 and variance.exr = (var A + var B) / 4, the layout
#    bench/equal_time.sh reads through ET_REFERENCES, and OUT/SCENE/README.md: "Resolution W×H",
#    the settings and times, each method's channel means with standard errors, the energy balance
#    (mean radiance of A and B, the ratio of their total image energy), and their agreement:
#    - per channel (and for the total energy) the difference in combined standard errors, within
#      max(2%, 3 combined standard errors) or not;
#    - per 16×16-pixel block (the last row of blocks is 4 pixels high at 180 rows) and channel, the
#      z-score of A's block mean against B's; blocks with |z| > 4 in any channel are counted and
#      the worst listed. At most CR_MAX_BLOCKS of them (default 2% of the blocks, rounded up) may
#      exceed: a few are expected by chance (the standard errors come from only RENDERS renders),
#      and where sppm's radius still blurs a sharp caustic edge.
#    Then "AGREE" or "DISAGREE"; the script exits 1 on DISAGREE (after writing everything).
# sppm and vcm are consistent, not unbiased: at finite passes their mean carries a blur bias that
# the standard errors do not include, so A and B agreeing is the check that it is small.
# Standard errors come from the spread of the independent renders' means (of the image, of a
# block): a light path's or a photon's contributions land in many pixels, so pixels are not
# independent. Per-pixel data for the block check are read from the renders' PFM files (Tessera
# writes them beside the EXR), with python3's standard library.
#
# Usage: bench/caustic_reference.sh [BUILD_DIR] [SCENE] [RENDERS] [SPP_A] [SPP_B] [OUT]
#        (defaults: build pool 8 256 256 out/references)
# Environment: CR_THREADS=2  CR_METHOD_A, CR_METHOD_B: sppm|bdpt|vcm|path|volpath|ptracer (defaults
#   above; not the same)
#   CR_MAX_BLOCKS=N (default above)  TESSERA=path/to/tessera (default BUILD_DIR/cli/tessera)
# Each method keeps the scene's depths (`--integrator` keeps maxDepth and rrDepth); its other
# parameters are at their defaults (docs/plugins.md). Needs oiiotool (OpenImageIO's tools) and
# python3. A missing scene, binary or tool is an error, never a skip.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
scene=${2:-pool}
renders=${3:-8}
spp_a=${4:-256}
spp_b=${5:-256}
out=${6:-out/references}
tessera=${TESSERA:-$build/cli/tessera}
threads=${CR_THREADS:-2}
method_a=${CR_METHOD_A:-sppm}
case "$scene" in glass-caustic) method_b=${CR_METHOD_B:-vcm} ;; *) method_b=${CR_METHOD_B:-bdpt} ;; esac
max_blocks=${CR_MAX_BLOCKS:-}
xml=scenes/$scene/scene.xml
[ -f "$xml" ] || { echo "caustic_reference.sh: missing $xml" >&2; exit 1; }
[ -x "$tessera" ] || { echo "caustic_reference.sh: no tessera binary at $tessera" >&2; exit 1; }
command -v oiiotool > /dev/null || { echo "caustic_reference.sh: needs oiiotool (apt install openimageio-tools)" >&2; exit 1; }
command -v python3 > /dev/null || { echo "caustic_reference.sh: needs python3" >&2; exit 1; }
for m in "$method_a" "$method_b"; do
  case "$m" in
    sppm|bdpt|vcm|path|volpath|ptracer) ;;
    *) echo "caustic_reference.sh: unknown method '$m' (sppm, bdpt, vcm, path, volpath, ptracer)" >&2; exit 1 ;;
  esac
done
if [ "$method_a" = "$method_b" ]; then
  echo "caustic_reference.sh: methods A and B are both $method_a: not an independent check" >&2; exit 1
fi
for n in "$renders" "$spp_a" "$spp_b" "$threads" ${max_blocks:+"$max_blocks"}; do
  [[ "$n" =~ ^[0-9]+$ ]] || { echo "caustic_reference.sh: '$n' is not a number" >&2; exit 1; }
done
if [ "$renders" -lt 2 ] || [ "$renders" -gt 1000 ]; then
  echo "caustic_reference.sh: RENDERS from 2 to 1000 (the seed ranges are 1001.. and 2001..)" >&2; exit 1
fi
if [ "$spp_a" -lt 1 ] || [ "$spp_b" -lt 1 ]; then
  echo "caustic_reference.sh: SPP_A and SPP_B at least 1" >&2; exit 1
fi
dir=$out/$scene
mkdir -p "$dir/A" "$dir/B"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# render INTEGRATOR SEED SPP STEM: writes STEM.exr and STEM.pfm, prints the render's seconds.
render() {
  if ! "$tessera" render "$xml" --integrator "$1" --spp "$3" --seed "$2" --threads "$threads" -q \
      -o "$4.exr" -o "$4.pfm" 2> "$tmp/log"; then
    cat "$tmp/log" >&2
    echo "caustic_reference.sh: $1 render (seed $2) failed" >&2
    exit 1
  fi
  grep -o 'render [0-9.e+-]* s' "$tmp/log" | tail -1 | awk '{print $2}'
}

# mean_and_variance TMP_DIR OUT_MEAN OUT_VARIANCE FILE... (bench/lib/image_stats.sh)
source bench/lib/image_stats.sh

# method LABEL INTEGRATOR SPP FIRST_SEED: the renders, their mean and variance in OUT/SCENE/LABEL,
# and $tmp/LABEL.csv (seed, seconds, PFM file) for the analysis.
method() {
  local label=$1 integrator=$2 spp=$3 seed0=$4 i seed secs files=()
  : > "$tmp/$label.csv"
  for ((i = 0; i < renders; i++)); do
    seed=$((seed0 + i))
    secs=$(render "$integrator" "$seed" "$spp" "$tmp/$label$i")
    echo "$label $integrator --spp $spp --seed $seed: $secs s" >&2
    echo "$seed,$secs,$tmp/$label$i.pfm" >> "$tmp/$label.csv"
    files+=("$tmp/$label$i.exr")
  done
  mean_and_variance "$tmp" "$dir/$label/reference.exr" "$dir/$label/variance.exr" "${files[@]}"
}

method A "$method_a" "$spp_a" 1001
method B "$method_b" "$spp_b" 2001
oiiotool "$dir/A/reference.exr" "$dir/B/reference.exr" --add --mulc 0.5 -d float -o "$dir/reference.exr"
oiiotool "$dir/A/variance.exr" "$dir/B/variance.exr" --add --mulc 0.25 -d float -o "$dir/variance.exr"
commit=$(git rev-parse --short HEAD 2> /dev/null || echo unknown)
git diff --quiet HEAD 2> /dev/null || commit="$commit (with uncommitted changes)"

python3 - "$dir" "$scene" "$method_a" "$method_b" "$spp_a" "$spp_b" "$renders" "$threads" "$SECONDS" \
  "$max_blocks" "$commit" "$tmp/A.csv" "$tmp/B.csv" <<'PY'
import array, csv, math, statistics, sys
(d, scene, meth_a, meth_b, spp_a, spp_b, renders, threads, wall, max_blocks, commit,
 csv_a, csv_b) = sys.argv[1:]
BLOCK, Z, FLOOR, NSE = 16, 4.0, 0.02, 3.0
names = "RGB"

def read_pfm(path):
    """A PFM image (Tessera's writer: "PF", little- or big-endian by the scale's sign, rows bottom
    to top): (width, height, float32 RGB array with row 0 the image's top)."""
    data = open(path, "rb").read()
    tokens, pos = [], 0
    while len(tokens) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        tokens.append(data[pos:end].decode("ascii"))
        pos = end
    pos += 1  # the single whitespace byte after the scale
    if tokens[0] != "PF":
        sys.exit("caustic_reference.sh: %s is not an RGB PFM (%s)" % (path, tokens[0]))
    w, h, scale = int(tokens[1]), int(tokens[2]), float(tokens[3])
    px = array.array("f")
    px.frombytes(data[pos:pos + 12 * w * h])
    if len(px) != 3 * w * h:
        sys.exit("caustic_reference.sh: %s is short" % path)
    if (scale < 0) != (sys.byteorder == "little"):
        px.byteswap()
    top_down = array.array("f")
    for r in range(h - 1, -1, -1):
        top_down.extend(px[3 * w * r:3 * w * (r + 1)])
    return w, h, top_down

def load(path):
    """Per render: seed, seconds, channel means, block means [block][channel]."""
    out, size = [], None
    for seed, secs, pfm in csv.reader(open(path)):
        w, h, px = read_pfm(pfm)
        if size not in (None, (w, h)):
            sys.exit("caustic_reference.sh: %s is %dx%d, the others %dx%d" % (pfm, w, h, *size))
        size = (w, h)
        means = [math.fsum(px[c::3]) / (w * h) for c in range(3)]
        if not all(math.isfinite(m) for m in means):
            sys.exit("caustic_reference.sh: %s holds non-finite pixels" % pfm)
        blocks = []
        for y0 in range(0, h, BLOCK):
            for x0 in range(0, w, BLOCK):
                y1, x1 = min(y0 + BLOCK, h), min(x0 + BLOCK, w)
                n = (y1 - y0) * (x1 - x0)
                blocks.append([math.fsum(math.fsum(px[3 * (y * w + x0) + c:3 * (y * w + x1):3])
                                         for y in range(y0, y1)) / n for c in range(3)])
        out.append((int(seed), float(secs), means, blocks))
    return size, out

def mean_se(values):
    return statistics.fmean(values), statistics.stdev(values) / math.sqrt(len(values))

(w, h), runs_a = load(csv_a)
size_b, runs_b = load(csv_b)
if size_b != (w, h):
    sys.exit("caustic_reference.sh: method B's renders are %dx%d, method A's %dx%d" % (*size_b, w, h))
k = len(runs_a)
for label, runs in (("A", runs_a), ("B", runs_b)):
    with open("%s/%s/runs.csv" % (d, label), "w") as f:
        f.write("seed,seconds,mean_r,mean_g,mean_b\n")
        for seed, secs, m, _ in runs:
            f.write("%d,%s,%.7g,%.7g,%.7g\n" % (seed, secs, *m))
stats = {}
for label, runs in (("A", runs_a), ("B", runs_b)):
    stats[label] = {
        "secs": sum(r[1] for r in runs),
        "ch": [mean_se([r[2][c] for r in runs]) for c in range(3)],
        # The channel average: the total image energy over 3 × pixels.
        "energy": mean_se([sum(r[2]) / 3 for r in runs]),
    }

def compare(a, sa, b, sb):
    """Difference of A and B in combined standard errors, and whether within max(2%, 3 SE)."""
    se = math.hypot(sa, sb)
    diff = a - b
    tol = max(FLOOR * abs(a + b) / 2, NSE * se)
    nse = abs(diff) / se if se > 0 else (0.0 if diff == 0 else math.inf)
    return diff, nse, abs(diff) <= tol

ok = True
agree_lines = []
for c in range(3):
    (a, sa), (b, sb) = stats["A"]["ch"][c], stats["B"]["ch"][c]
    diff, nse, within = compare(a, sa, b, sb)
    ok &= within
    agree_lines.append("- %s: A %.6g, B %.6g: A − B %+.3g (%+.2f%% of B), %.2f combined SE, %s" % (
        names[c], a, b, diff, 100 * diff / b if b else math.inf, nse, "within" if within else "OUTSIDE"))
(ea, sea), (eb, seb) = stats["A"]["energy"], stats["B"]["energy"]
ediff, ense, ewithin = compare(ea, sea, eb, seb)
ok &= ewithin
ratio = ea / eb if eb else math.inf
ratio_se = ratio * math.hypot(sea / ea, seb / eb) if ea and eb else math.inf

# Blocks: z-score of A's block mean against B's, per channel; standard errors from the spread of the
# renders' block means.
n_blocks = len(runs_a[0][3])
bw = (w + BLOCK - 1) // BLOCK
flagged = []
for i in range(n_blocks):
    worst = None
    for c in range(3):
        ma, sa = mean_se([r[3][i][c] for r in runs_a])
        mb, sb = mean_se([r[3][i][c] for r in runs_b])
        se = math.hypot(sa, sb)
        z = (ma - mb) / se if se > 0 else (0.0 if ma == mb else math.inf)
        if worst is None or abs(z) > abs(worst[0]):
            worst = (z, c, ma, mb)
    if abs(worst[0]) > Z:
        flagged.append((i, *worst))
allowed = int(max_blocks) if max_blocks else math.ceil(0.02 * n_blocks)
blocks_ok = len(flagged) <= allowed
ok &= blocks_ok
verdict = "AGREE" if ok else "DISAGREE"

def rect(i):
    x0, y0 = (i % bw) * BLOCK, (i // bw) * BLOCK
    return "x %d–%d, y %d–%d" % (x0, min(x0 + BLOCK, w) - 1, y0, min(y0 + BLOCK, h) - 1)

spp_word = {"sppm": "passes", "vcm": "iterations"}
def settings(label, meth, spp, seed0):
    s = stats[label]
    return "- %s: `%s`, %d renders of %s %s (seeds %d–%d), %.1f s of rendering" % (
        label, meth, k, spp, spp_word.get(meth, "spp"), seed0, seed0 + k - 1, s["secs"])

lines = ["# %s: a reference by two methods" % scene, "",
         "Resolution %d×%d" % (w, h), "",
         "Made by `bench/caustic_reference.sh` (see its header) from `scenes/%s/scene.xml` at commit %s, "
         "%s threads, %s s wall clock in all. Each method keeps the scene's depths; its other parameters "
         "are at their defaults." % (scene, commit, threads, wall), "",
         settings("A", meth_a, spp_a, 1001), settings("B", meth_b, spp_b, 2001), "",
         "`A/reference.exr`, `B/reference.exr`: each method's mean of its renders; `variance.exr` beside "
         "each the per-pixel variance of that mean; `A/runs.csv`, `B/runs.csv` the renders. "
         "`reference.exr` here is (A + B) / 2, `variance.exr` (var A + var B) / 4.", "",
         "## Channel means", "",
         "Standard errors from the spread of the renders' means:", ""]
for label, meth in (("A", meth_a), ("B", meth_b)):
    lines.append("- %s (`%s`): " % (label, meth) + ", ".join(
        "%s %.6g ± %.2g" % (names[c], *stats[label]["ch"][c]) for c in range(3)))
lines += ["", "## Energy balance", "",
          "Mean radiance (the channels' average): A %.6g ± %.2g, B %.6g ± %.2g. Total image energy "
          "(every pixel and channel) A / B = %.4f ± %.4f: %.2f combined SE, %s max(2%%, 3 SE)." % (
              ea, sea, eb, seb, ratio, ratio_se, ense, "within" if ewithin else "OUTSIDE"),
          "", "## Agreement of A and B", "",
          "Per channel, within max(2%, 3 combined standard errors) or not:", ""] + agree_lines
lines += ["", "Per %d×%d-pixel block (%d blocks; y from the top), z = (A − B) / combined standard error of "
          "the block's mean, from the spread of the renders' block means: %d blocks with |z| > %g in some "
          "channel (%d allowed)%s" % (BLOCK, BLOCK, n_blocks, len(flagged), Z, allowed,
                                       ":" if flagged else ".")]
if flagged:
    lines.append("")
    for i, z, c, ma, mb in sorted(flagged, key=lambda f: -abs(f[1]))[:10]:
        lines.append("- %s: %s A %.4g, B %.4g (%+.1f%%), z %+.1f" % (
            rect(i), names[c], ma, mb, 100 * (ma / mb - 1) if mb else math.inf, z))
    if len(flagged) > 10:
        lines.append("- and %d more" % (len(flagged) - 10))
lines += ["", "**%s**" % verdict]
open(d + "/README.md", "w").write("\n".join(lines) + "\n")

print("%s %d×%d: A %s (%s), B %s (%s), %d renders each, %s s" % (
    scene, w, h, meth_a, spp_a, meth_b, spp_b, k, wall))
for s in agree_lines:
    print(s[2:])
print("total energy A / B = %.4f ± %.4f; %d of %d blocks |z| > %g (%d allowed)" % (
    ratio, ratio_se, len(flagged), n_blocks, Z, allowed))
print("%s: %s/README.md, reference.exr, variance.exr, A/, B/" % (verdict, d))
sys.exit(0 if ok else 1)
PY
