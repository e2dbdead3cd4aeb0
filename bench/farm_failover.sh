#!/usr/bin/env bash
# What losing a worker costs a job: the Cornell box through a coordinator with two workers, once
# untouched and once with one worker killed (kill -9) at 90% progress, alternating ROUNDS times.
# Prints each run's wall time from submission to done; the images must be identical (checked).
# Builds nothing; needs curl and jq.
# Usage: bench/farm_failover.sh [BUILD_DIR] [ROUNDS] [SPP] [SIZE] [SERVER_FLAGS]
#   e.g. SERVER_FLAGS=--no-speculation: the dead worker's units wait for it to miss 3 heartbeats
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
rounds=${2:-3}
spp=${3:-64}
size=${4:-128}
read -r -a server_flags <<< "${5:-}"
scene=../shared/scenes/cornell-box
source bench/farm_processes.sh

# One run: a fresh coordinator and two 1-thread workers; KILL=1 kills worker 0 at 90%.
run() {
  local kill_at=$1 dir="$tmp/run$RANDOM"
  mkdir -p "$dir"
  "$build/server/tessera-server" --listen 127.0.0.1:0 --port-file "$dir/port" --data-dir "$dir/data" \
      --log-level warn "${server_flags[@]}" > "$dir/server.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 100); do [ -s "$dir/port" ] && break; sleep 0.1; done
  local s="http://127.0.0.1:$(cat "$dir/port")" w0 w1
  "$build/worker/tessera-worker" --server "$s" --threads 1 --cache-dir "$dir/c0" > "$dir/w0.log" 2>&1 & w0=$!
  "$build/worker/tessera-worker" --server "$s" --threads 1 --cache-dir "$dir/c1" > "$dir/w1.log" 2>&1 & w1=$!
  pids+=("$w0" "$w1")
  local id start state progress killed=0
  id=$(curl -sS --fail-with-body -F "settings={\"spp\": $spp, \"width\": $size, \"height\": $size, \"tile_size\": 16};type=application/json" \
           -F bundle=@"$tmp/cornell.tar.gz" "$s/api/v1/jobs" | jq -r .id)
  start=$(date +%s.%N)
  while :; do
    read -r state progress < <(curl -sS "$s/api/v1/jobs/$id" | jq -r '"\(.state) \(.progress)"')
    [ "$state" = done ] && break
    if [ "$kill_at" = 1 ] && [ "$killed" = 0 ] && (( $(echo "$progress >= 0.9" | bc -l) )); then
      kill -9 "$w0"
      killed=1
    fi
    sleep 0.05
  done
  printf "%.2f" "$(echo "$(date +%s.%N) - $start" | bc -l)"
  curl -sS -o "$dir/image.pfm" "$s/api/v1/jobs/$id/image?format=pfm"
  cp "$dir/image.pfm" "$tmp/image$kill_at.pfm"
  kill "$w0" "$w1" 2>/dev/null || true
  kill "${pids[0]}" 2>/dev/null || true
  wait 2>/dev/null || true
  pids=()
}

tar czf "$tmp/cornell.tar.gz" -C "$scene" scene.xml
printf "cornell-box %sx%s, %s spp, 16-pixel tiles, 2 workers x 1 thread, server flags '%s'; seconds from submission to done\n" \
    "$size" "$size" "$spp" "${5:-}"
for r in $(seq "$rounds"); do
  untouched=$(run 0)
  killed=$(run 1)
  cmp -s "$tmp/image0.pfm" "$tmp/image1.pfm" || { echo "round $r: the images differ" >&2; exit 1; }
  printf "round %s: untouched %s s, worker killed at 90%% %s s\n" "$r" "$untouched" "$killed"
done
