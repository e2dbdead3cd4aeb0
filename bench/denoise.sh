#!/usr/bin/env bash
# The denoiser at equal samples (docs/performance.md, "Denoising"): every shared scene at its
# reference's resolution, rendered raw at 16, 64, 128 and 256 spp, and the 16- and 64-spp renders
# denoised (full and preview mode); relMSE of each against ../shared/references/, and the denoised
# image's channel means against the raw image's, with the raw mean's standard error (from the
# variance layer). Then the time to denoise a render of at least one megapixel (living-room at
# 1280×800), per megapixel, in both modes.
# Writes OUT/denoise.csv and OUT/denoise.md (the table) and prints the table.
#
# Usage: bench/denoise.sh [BUILD_DIR]      (default: build)
# Environment: DN_SCENES="cornell-box ..." (default all seven)  DN_SEED=1  DN_THREADS=2
#   DN_OUT=docs/performance  TESSERA=path/to/tessera (default BUILD_DIR/cli/tessera)
# Needs oiiotool (openimageio-tools). A missing scene or reference is an error, never a skip.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
tessera=${TESSERA:-$build/cli/tessera}
shared=../shared
scenes=(${DN_SCENES:-cornell-box veach-mis veach-bidir living-room bathroom kitchenette staircase2})
seed=${DN_SEED:-1}
threads=${DN_THREADS:-2}
out=${DN_OUT:-docs/performance}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

[ -x "$tessera" ] || { echo "denoise.sh: no tessera binary at $tessera" >&2; exit 1; }
command -v oiiotool > /dev/null || { echo "denoise.sh: needs oiiotool (package openimageio-tools)" >&2; exit 1; }
for s in "${scenes[@]}"; do
  for f in scenes/$s/scene.xml references/$s/reference.exr references/$s/README.md; do
    [ -f "$shared/$f" ] || { echo "denoise.sh: missing $shared/$f" >&2; exit 1; }
  done
done
mkdir -p "$out"
csv="$out/denoise.csv"
echo "scene,spp,image,seconds,rel_mse,mean_shift_pct,mean_shift_limit_pct" > "$csv"

rel_mse() { "$tessera" compare "$1" "$shared/references/$2/reference.exr" | grep -o 'rel_mse=[^ ]*' | cut -d= -f2; }
# "avg_r avg_g avg_b" of channels $2 of image $1.
avgs() { oiiotool "$1" --ch "$2" --printstats | grep 'Stats Avg' | sed 's/.*Avg: //; s/ (float)//'; }
# The largest |denoised - raw| channel mean over raw, and the allowed max(1%, 3 standard errors), in %.
mean_shift() {
  local raw=$1 dn=$2 n=$3
  python3 - "$(avgs "$raw" R,G,B)" "$(avgs "$dn" R,G,B)" "$(avgs "$raw" variance.R,variance.G,variance.B)" "$n" <<'PY'
import math, sys
raw, dn, var = ([float(v) for v in a.split()] for a in sys.argv[1:4])
n = float(sys.argv[4])
shift = max(abs(d - r) / r for r, d in zip(raw, dn))
limit = max(max(0.01, 3 * math.sqrt(v / n) / r) for r, v in zip(raw, var))
print("%.2f,%.2f" % (100 * shift, 100 * limit))
PY
}

for s in "${scenes[@]}"; do
  res=$(grep -o 'Resolution [0-9]*×[0-9]*' "$shared/references/$s/README.md" | grep -o '[0-9][0-9]*')
  w=$(echo "$res" | sed -n 1p); h=$(echo "$res" | sed -n 2p)
  extra=()
  [ "$s" = kitchenette ] && extra=(--integrator path --allow-unsupported)
  for spp in 16 64 128 256; do
    "$tessera" render "$shared/scenes/$s/scene.xml" "${extra[@]}" --width "$w" --height "$h" --spp "$spp" \
      --seed "$seed" --threads "$threads" --aovs all -q -o "$tmp/raw.exr" 2> /dev/null
    echo "$s,$spp,raw,,$(rel_mse "$tmp/raw.exr" "$s"),," | tee -a "$csv" >&2
    [ "$spp" -le 64 ] || continue
    for mode in full preview; do
      secs=$("$tessera" denoise "$tmp/raw.exr" -o "$tmp/dn.exr" --mode "$mode" --threads "$threads" 2>&1 |
        grep -o 'in [0-9.]* s' | awk '{print $2}')
      echo "$s,$spp,$mode,$secs,$(rel_mse "$tmp/dn.exr" "$s"),$(mean_shift "$tmp/raw.exr" "$tmp/dn.exr" $((w * h)))" |
        tee -a "$csv" >&2
    done
  done
done

# Seconds per megapixel on a 1-megapixel render.
"$tessera" render "$shared/scenes/living-room/scene.xml" --width 1280 --height 800 --spp 4 --seed "$seed" \
  --threads "$threads" --aovs all -q -o "$tmp/big.exr" 2> /dev/null
timing=""
for mode in full preview; do
  per_mp=$("$tessera" denoise "$tmp/big.exr" -o "$tmp/big_dn.exr" --mode "$mode" --threads "$threads" 2>&1 |
    grep -o '([0-9.]* s per megapixel)' | grep -o '[0-9.]*' | head -1)
  timing+="$mode ${per_mp} s per megapixel; "
done

python3 - "$csv" "$out/denoise.md" "$timing" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
get = lambda s, spp, img: next((r for r in rows if r["scene"] == s and r["spp"] == spp and r["image"] == img), None)
lines = ["| scene | raw 16 | denoised 16 (preview) | raw 128 | raw 64 | denoised 64 (preview) | raw 256 | "
         "16 spp: denoised ≤ raw 128 | 64 spp: denoised ≤ raw 256 | largest mean shift, % (allowed) |",
         "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
for s in dict.fromkeys(r["scene"] for r in rows):
    e = lambda spp, img: float(get(s, spp, img)["rel_mse"])
    shift = max((get(s, spp, "full") for spp in ("16", "64")), key=lambda r: float(r["mean_shift_pct"]))
    lines.append("| %s | %.4g | %.4g (%.4g) | %.4g | %.4g | %.4g (%.4g) | %.4g | %s | %s | %s (%s) |" % (
        s, e("16", "raw"), e("16", "full"), e("16", "preview"), e("128", "raw"), e("64", "raw"), e("64", "full"),
        e("64", "preview"), e("256", "raw"), "yes" if e("16", "full") <= e("128", "raw") else "no",
        "yes" if e("64", "full") <= e("256", "raw") else "no", shift["mean_shift_pct"], shift["mean_shift_limit_pct"]))
lines.append("")
lines.append("Time to denoise living-room at 1280×800 (1.02 megapixels): " + sys.argv[3].strip("; ") + ".")
open(sys.argv[2], "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
