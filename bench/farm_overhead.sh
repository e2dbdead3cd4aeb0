#!/usr/bin/env bash
# The farm's cost against a local render: wall time of the Cornell box through a coordinator with
# 1 and 2 local workers vs `tessera render` on the same cores, the coordinator's CPU time per work
# unit, and the bytes a unit's result takes on the wire. Checks the images are bit-identical.
# With ADAPTIVE=on, both render with --adaptive on, and the time the coordinator spent deciding the
# adaptive passes' counts at their barriers is printed too. With GUIDING=on, both guide, and the
# learned trees' bytes (as stored and sent to workers) and the time spent making them are printed,
# in all and per barrier.
# Usage: bench/farm_overhead.sh [BUILD_DIR] [SPP] [SIZE] [TILE] [ADAPTIVE] [GUIDING] [SCENE]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
spp=${2:-256}
size=${3:-256}
tile=${4:-32}
adaptive=${5:-off}
guiding=${6:-off}
scene=${7:-../shared/scenes/cornell-box/scene.xml}
integrator=()
[ -n "${8:-}" ] && integrator=(--integrator "$8")
cores=$(nproc)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
now() { date +%s.%N; }

t0=$(now)
"$build/cli/tessera" render "$scene" --spp "$spp" --width "$size" --height "$size" --tile-size "$tile" -q \
    --adaptive "$adaptive" --guiding "$guiding" ${integrator[@]+"${integrator[@]}"} -o "$tmp/local.exr" 2> /dev/null
local_s=$(echo "$(now) - $t0" | bc -l)
printf "%s %dx%d %d spp, %d cores, tile %d, adaptive %s, guiding %s, integrator %s\n" "$(basename "$(dirname "$scene")")" \
    "$size" "$size" "$spp" "$cores" "$tile" "$adaptive" "$guiding" "${8:-as the scene says}"
printf "%-28s %8.2f s\n" "tessera render ($cores threads)" "$local_s"

for workers in 1 2; do
  threads=$(( cores / workers > 0 ? cores / workers : 1 ))
  data="$tmp/farm$workers"
  mkdir -p "$data"
  "$build/server/tessera-server" --listen 127.0.0.1:0 --port-file "$data/port" --data-dir "$data/state" \
      --local-workers "$workers" --local-worker-threads "$threads" > "$data/server.log" 2>&1 &
  server=$!
  for _ in $(seq 100); do [ -s "$data/port" ] && break; sleep 0.1; done
  url="http://127.0.0.1:$(cat "$data/port")"
  until curl -sf "$url/api/v1/workers" | grep -c '"idle"' | grep -q "$workers"; do sleep 0.1; done
  read -r u0 s0 < <(awk '{print $14, $15}' "/proc/$server/stat")
  t0=$(now)
  "$build/cli/tessera" submit "$scene" --server "$url" --spp "$spp" --width "$size" --height "$size" \
      --tile-size "$tile" --adaptive "$adaptive" --guiding "$guiding" ${integrator[@]+"${integrator[@]}"} -q \
      -o "$data/farm.exr" 2> /dev/null > /dev/null
  wall=$(echo "$(now) - $t0" | bc -l)
  read -r u1 s1 < <(awk '{print $14, $15}' "/proc/$server/stat")
  status=$(curl -sf "$url/api/v1/jobs/1")
  kill -TERM "$server"; wait "$server" || true
  units=$(echo "$status" | python3 -c 'import json,sys; print(json.load(sys.stdin)["units_total"])')
  bytes=$(echo "$status" | python3 -c 'import json,sys; print(json.load(sys.stdin)["result_bytes"])')
  lbytes=$(echo "$status" | python3 -c 'import json,sys; print(json.load(sys.stdin)["lease_bytes"])')
  cpu=$(echo "($u1 + $s1 - $u0 - $s0) / $(getconf CLK_TCK)" | bc -l)
  same=$("$build/cli/tessera" compare "$data/farm.exr" "$tmp/local.exr" | grep -o 'rel_mse=[^ ]*')
  printf "%-28s %8.2f s  (%.2fx local)  %d units, coordinator CPU %.2f ms/unit, result %.0f + lease %.0f bytes/unit, %s\n" \
      "farm, $workers local worker(s) x $threads" "$wall" "$(echo "$wall / $local_s" | bc -l)" "$units" \
      "$(echo "1000 * $cpu / $units" | bc -l)" "$(echo "$bytes / $units" | bc -l)" "$(echo "$lbytes / $units" | bc -l)" "$same"
  planned=$(grep -o 'job.pass_planned.*' "$data/server.log" | grep -o 'seconds=[0-9.e-]*' | cut -d= -f2 || true)
  if [ -n "$planned" ]; then
    printf "%-28s %d adaptive passes planned at barriers in %.1f ms in all\n" "" "$(echo "$planned" | wc -l)" \
        "$(echo "$planned" | awk '{s += $1} END {print 1000 * s}')"
  fi
  guides=$(grep -o 'job.guide_stored.*' "$data/server.log" || true)
  if [ -n "$guides" ]; then
    field() { echo "$guides" | grep -o " $1=[0-9.e+-]*" | cut -d= -f2; }
    printf "%-28s %d guides stored, %.2f MB in all (last %.2f MB, %.1f MB in memory); trees made at barriers in %.1f ms, encoded and written in %.1f ms in all\n" \
        "" "$(echo "$guides" | wc -l)" "$(field bytes | awk '{s += $1} END {print s / 1e6}')" \
        "$(field bytes | tail -1 | awk '{print $1 / 1e6}')" "$(field memory_bytes | tail -1 | awk '{print $1 / 1e6}')" \
        "$(field barrier_seconds | awk '{s += $1} END {print 1000 * s}')" "$(field seconds | awk '{s += $1} END {print 1000 * s}')"
    # Per barrier: the iteration the tree serves, its bytes on the wire, the time the coordinator
    # took to make it under the job's lock and then to encode and write it off the lock.
    paste -d' ' <(field iteration) <(field bytes) <(field barrier_seconds) <(field seconds) |
      while read -r it b made written; do
        awk -v it="$it" -v b="$b" -v made="$made" -v w="$written" 'BEGIN {
          printf "%-28s   iteration %2d: tree %8.3f MB, made in %6.1f ms, encoded and written in %6.1f ms\n", "", it, b / 1e6, 1000 * made, 1000 * w }'
      done
  fi
done
