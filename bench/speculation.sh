#!/usr/bin/env bash
# How many leases a job costs: a denoised Cornell box of 150 units (25 tiles x 6 passes) through a
# coordinator with two 1-thread workers, once untouched and once with one worker killed (kill -9) at
# 30% and the coordinator killed (kill -9) and restarted at 60%, alternating ROUNDS times. Prints
# leases issued per unit, the most leases of one unit, and the leases issued for a unit whose result
# was already acknowledged; the two images must be identical (checked).
# Builds nothing; needs curl and jq.
# Usage: bench/speculation.sh [BUILD_DIR] [ROUNDS] [SERVER_FLAGS]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
rounds=${2:-3}
read -r -a server_flags <<< "${3:-}"
scene=../shared/scenes/cornell-box
source bench/farm_processes.sh

start_server() {  # DIR LISTEN
  "$build/server/tessera-server" --listen "$2" --port-file "$1/port" --data-dir "$1/data" \
      --log-level warn "${server_flags[@]}" >> "$1/server.log" 2>&1 &
  server=$!
  pids+=("$server")
  for _ in $(seq 200); do [ -s "$1/port" ] && curl -sf "http://127.0.0.1:$(cat "$1/port")/healthz" > /dev/null && return; sleep 0.05; done
  echo "the coordinator did not start" >&2; exit 1
}

add_worker() {  # DIR URL N
  "$build/worker/tessera-worker" --server "$2" --threads 1 --cache-dir "$1/c$3" --poll-wait 2 > "$1/w$3.log" 2>&1 &
  pids+=($!)
  last_worker=$!
}

# One run: KILL=1 kills worker 0 at 30% and the coordinator at 60% (then restarts it on its port).
run() {
  local kill=$1 dir="$tmp/run$RANDOM" s id state progress stage=0 w0
  mkdir -p "$dir"
  start_server "$dir" 127.0.0.1:0
  s="http://127.0.0.1:$(cat "$dir/port")"
  add_worker "$dir" "$s" 0; w0=$last_worker
  add_worker "$dir" "$s" 1
  id=$(curl -sS --fail-with-body -F 'settings={"spp": 37, "width": 200, "height": 200, "tile_size": 40, "seed": 7, "denoise": true};type=application/json' \
           -F bundle=@"$tmp/cornell.tar.gz" "$s/api/v1/jobs" | jq -r .id)
  while :; do
    read -r state progress < <(curl -sS "$s/api/v1/jobs/$id" | jq -r '"\(.state) \(.progress)"')
    [ "$state" = done ] && break
    if [ "$kill" = 1 ] && [ "$stage" = 0 ] && (( $(echo "$progress >= 0.3" | bc -l) )); then
      kill -9 "$w0"; stage=1
    elif [ "$kill" = 1 ] && [ "$stage" = 1 ] && (( $(echo "$progress >= 0.6" | bc -l) )); then
      kill -9 "$server"; wait "$server" 2>/dev/null || true
      rm -f "$dir/port"
      start_server "$dir" "127.0.0.1:${s##*:}"; stage=2
    fi
    sleep 0.05
  done
  curl -sS "$s/api/v1/jobs/$id" |
    jq -r '"\(.leases_issued / .units_total * 1000 | round / 1000) leases/unit (\(.leases_issued) for \(.units_total)), max \(.max_leases_per_unit) per unit, \(.reissued_acknowledged_passes) acknowledged re-issued"'
  curl -sS -o "$tmp/image$kill.pfm" "$s/api/v1/jobs/$id/image?format=pfm"
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  pids=()
}

tar czf "$tmp/cornell.tar.gz" -C "$scene" scene.xml
printf "cornell-box 200x200, 37 spp, 40-pixel tiles (150 units), denoised, 2 workers x 1 thread, server flags '%s'\n" "${3:-}"
for r in $(seq "$rounds"); do
  untouched=$(run 0)
  killed=$(run 1)
  cmp -s "$tmp/image0.pfm" "$tmp/image1.pfm" || { echo "round $r: the images differ" >&2; exit 1; }
  printf "round %s: untouched: %s\n         worker and coordinator killed: %s\n" "$r" "$untouched" "$killed"
done
