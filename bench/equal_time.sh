#!/usr/bin/env bash
# Path guiding, adaptive sampling and the bidirectional integrators at equal time
# (docs/performance.md, "Guiding and adaptive sampling", "Bidirectional path tracing"): every shared scene at its reference's resolution, each configuration rendered with the
# same spp and several seeds (Tessera's own scenes too, against ET_REFERENCES: below); per run the
# render's seconds, its relMSE against ../shared/references/,
# the same without the worst 0.1% of pixels, and the reference's own noise floor (what relMSE gains
# from the reference's noise: `tessera compare --variance`, ref_floor). Per scene and configuration
# the medians over seeds, and the relMSE at the plain render's median time, taking the error above
# the floor to fall as 1/time (the estimators are unbiased):
#   equal-time relMSE = floor + (relMSE - floor) * seconds / plain's seconds
# and, the same way, the time each configuration needs to bring the error above the floor down to
# 0.05 and 0.01 (against the floor, since kitchenette's and veach-bidir's floors are above 0.01):
#   time to X = (relMSE - floor) * seconds / X
# and the relMSE without the worst 0.1% of pixels at plain's time, scaled the same way (plain's own
# unscaled: a path tracer's firefly-ridden error there need not fall as 1/time).
# Writes OUT/equal_time.csv (every run) and OUT/equal_time.md (the table), and prints the table.
#
# Usage: bench/equal_time.sh [BUILD_DIR] [SPP]      (defaults: build, 128)
# Environment: ET_SCENES="cornell-box ..." (default all seven)  ET_SEEDS="1 2 3"
#   ET_CONFIGS="plain adaptive guided guided+adaptive" (also: bdpt, ptracer, sppm, vcm: the path
#   tracer's passes by `--integrator bdpt|ptracer|sppm|vcm`, keeping the scene's depths; for sppm
#   SPP is passes, for vcm iterations)  ET_THREADS=2  ET_OUT=docs/performance
#   TESSERA=path/to/tessera (default BUILD_DIR/cli/tessera)
#   ET_TABLE_ONLY=1: render nothing, make the table again from OUT/equal_time.csv
#   ET_CONFIG_SPP="bdpt=222 ...": those configurations' spp instead of SPP (to render them in
#   about plain's time, for the last column)
#   ET_REFERENCES=DIR: for each scene with DIR/NAME/reference.exr and variance.exr (as
#   bench/bdpt_reference.sh and bench/caustic_reference.sh write them), compare against those
#   instead of ../shared/references/
# A scene that is not a shared one (../shared/scenes/NAME/scene.xml) but Tessera's own
# (scenes/NAME/scene.xml: pool, glass-caustic) has no shared reference: it needs ET_REFERENCES with
# NAME/reference.exr, variance.exr and README.md (its "Resolution W×H" line sets the render's size),
# as bench/caustic_reference.sh writes them.
# sppm and vcm are consistent, not unbiased: their error has a bias part that falls more slowly
# than 1/time, so their "at plain's time" and "seconds to" columns (which assume 1/time) are only
# meaningful when their spp are chosen (ET_CONFIG_SPP="sppm=N vcm=M") so that they take about
# plain's time; then read their direct relMSE columns.
# A missing scene or reference is an error (exit 1), never a skip.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
spp=${2:-128}
tessera=${TESSERA:-$build/cli/tessera}
shared=../shared
read -r -a scenes <<< "${ET_SCENES:-cornell-box veach-mis veach-bidir living-room bathroom kitchenette staircase2}"
read -r -a seeds <<< "${ET_SEEDS:-1 2 3}"
read -r -a configs <<< "${ET_CONFIGS:-plain adaptive guided guided+adaptive}"
threads=${ET_THREADS:-2}
out=${ET_OUT:-docs/performance}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

[ -x "$tessera" ] || { echo "equal_time.sh: no tessera binary at $tessera" >&2; exit 1; }
# scene_xml NAME: the scene's file, a shared one or, failing that, Tessera's own.
scene_xml() {
  if [ -f "$shared/scenes/$1/scene.xml" ] || [ ! -f "scenes/$1/scene.xml" ]; then
    echo "$shared/scenes/$1/scene.xml"
  else
    echo "scenes/$1/scene.xml"
  fi
}
for s in "${scenes[@]}"; do
  xml=$(scene_xml "$s")
  if [ "$xml" = "scenes/$s/scene.xml" ]; then
    # Tessera's own scene: only ET_REFERENCES has its reference.
    [ -n "${ET_REFERENCES:-}" ] || { echo "equal_time.sh: $xml has no shared reference: set ET_REFERENCES (bench/caustic_reference.sh)" >&2; exit 1; }
    files=("$xml" "$ET_REFERENCES/$s/reference.exr" "$ET_REFERENCES/$s/variance.exr" "$ET_REFERENCES/$s/README.md")
  else
    files=("$xml")
    for f in reference.exr variance.exr README.md; do files+=("$shared/references/$s/$f"); done
  fi
  for f in "${files[@]}"; do
    [ -f "$f" ] || { echo "equal_time.sh: missing $f" >&2; exit 1; }
  done
done
mkdir -p "$out"
csv="$out/equal_time.csv"
[ -n "${ET_TABLE_ONLY:-}" ] && scenes=() || echo "scene,config,seed,spp,seconds,rel_mse,rel_mse_trim,ref_floor" > "$csv"

for s in ${scenes[@]+"${scenes[@]}"}; do
  xml=$(scene_xml "$s")
  # The resolution from the shared reference's README, or, for Tessera's own scenes, from ET_REFERENCES'.
  readme=$shared/references/$s/README.md
  [ "$xml" = "scenes/$s/scene.xml" ] && readme=$ET_REFERENCES/$s/README.md
  res=$(grep -m1 -o 'Resolution [0-9]*×[0-9]*' "$readme" | grep -o '[0-9][0-9]*') ||
    { echo "equal_time.sh: no 'Resolution W×H' line in $readme" >&2; exit 1; }
  w=$(echo "$res" | sed -n 1p); h=$(echo "$res" | sed -n 2p)
  extra=() path=()
  # Its reference was rendered with `path`; its sky is seen through window glass (docs/performance.md).
  [ "$s" = kitchenette ] && extra=(--allow-unsupported) path=(--integrator path)
  ref=$shared/references/$s
  if [ -n "${ET_REFERENCES:-}" ] && [ -f "$ET_REFERENCES/$s/reference.exr" ]; then
    ref=$ET_REFERENCES/$s
    [ -f "$ref/variance.exr" ] || { echo "equal_time.sh: missing $ref/variance.exr" >&2; exit 1; }
  fi
  for seed in "${seeds[@]}"; do
    for c in "${configs[@]}"; do
      guiding=off adaptive=off integrator=("${path[@]}")
      case "$c" in
        plain) ;; adaptive) adaptive=on ;; guided) guiding=on ;; guided+adaptive) guiding=on adaptive=on ;;
        bdpt|ptracer|sppm|vcm) integrator=(--integrator "$c") ;;
        *) echo "equal_time.sh: unknown configuration '$c'" >&2; exit 1 ;;
      esac
      config_spp=$spp
      for o in ${ET_CONFIG_SPP:-}; do [ "${o%%=*}" = "$c" ] && config_spp=${o#*=}; done
      "$tessera" render "$xml" ${extra[@]+"${extra[@]}"} ${integrator[@]+"${integrator[@]}"} \
        --width "$w" --height "$h" --spp "$config_spp" \
        --seed "$seed" --threads "$threads" --guiding "$guiding" --adaptive "$adaptive" -q -o "$tmp/img.exr" \
        2> "$tmp/log"
      secs=$(grep -o 'render [0-9.e+-]* s' "$tmp/log" | tail -1 | awk '{print $2}')
      cmp=$("$tessera" compare "$tmp/img.exr" "$ref/reference.exr" --variance "$ref/variance.exr")
      field() { echo "$cmp" | grep -o " $1=[^ ]*" | cut -d= -f2; }
      echo "$s,$c,$seed,$config_spp,$secs,$(field rel_mse),$(field rel_mse_trim),$(field ref_floor)" | tee -a "$csv" >&2
    done
  done
done

python3 - "$csv" "$out/equal_time.md" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
med = lambda xs: statistics.median(xs)
runs = {}
for r in rows:
    runs.setdefault((r["scene"], r["config"]), []).append(r)
lines = ["| scene | configuration | spp | seconds | relMSE | relMSE, worst 0.1% left out | reference floor | "
         "relMSE at plain's time | against plain | seconds to 0.05 above floor | seconds to 0.01 above floor | "
         "worst 0.1% left out, at plain's time |",
         "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
def time_to(rs, floor, target):
    return "%.3g" % med([(float(r["rel_mse"]) - floor) * float(r["seconds"]) / target for r in rs])
for scene in dict.fromkeys(r["scene"] for r in rows):
    plain = runs.get((scene, "plain"))
    t_plain = med([float(r["seconds"]) for r in plain]) if plain else None
    e_plain = None
    for (sc, config), rs in runs.items():
        if sc != scene:
            continue
        t = med([float(r["seconds"]) for r in rs])
        floor = float(rs[0]["ref_floor"])
        # Per seed, then the median: each seed's error scaled to plain's median time.
        eq = med([floor + (float(r["rel_mse"]) - floor) * float(r["seconds"]) / t_plain for r in rs]) if t_plain else None
        eq_trim = med([floor + (float(r["rel_mse_trim"]) - floor) * float(r["seconds"]) / t_plain for r in rs]) if t_plain else None
        if config == "plain":
            e_plain = eq
        ratio = "%.3g" % (eq / e_plain) if eq is not None and e_plain else ""
        if config == "plain":
            eq_trim = med([float(r["rel_mse_trim"]) for r in rs])  # its own, not scaled: it need not fall as 1/time
        lines.append("| %s | %s | %s | %.2f | %.4g | %.4g | %.2g | %s | %s | %s | %s | %s |" % (
            scene, config, rs[0]["spp"], t, med([float(r["rel_mse"]) for r in rs]), med([float(r["rel_mse_trim"]) for r in rs]),
            floor, "%.4g" % eq if eq is not None else "", ratio, time_to(rs, floor, 0.05), time_to(rs, floor, 0.01),
            "%.4g" % eq_trim if eq_trim is not None else ""))
open(sys.argv[2], "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
