#!/usr/bin/env bash
# The coordinator's resident memory under submissions of a large scene: living-room (19 MB, about
# 0.6 M triangles) uploaded once, then CYCLES jobs submitted and cancelled one after another, then
# CYCLES jobs submitted and left queued (no workers). Prints VmRSS and VmHWM after each phase.
# Submitting plans the scene in a short-lived child process, so none of the loaded meshes,
# textures or BVH stay in the coordinator. Builds nothing; needs curl and jq.
# Usage: bench/coordinator_memory.sh [BUILD_DIR] [CYCLES] [SCENE_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
cycles=${2:-30}
scene=${3:-../shared/scenes/living-room}
tmp=$(mktemp -d)
server_pid=""
cleanup() {
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT

"$build/server/tessera-server" --listen 127.0.0.1:0 --port-file "$tmp/port" --data-dir "$tmp/data" \
    --log-level warn 2> "$tmp/server.log" &
server_pid=$!
for _ in $(seq 100); do [ -s "$tmp/port" ] && break; sleep 0.1; done
S="http://127.0.0.1:$(cat "$tmp/port")"
rss() { awk -v what="$1" '$1 == what":" { printf "%.0f MB", $2 / 1024 }' "/proc/$server_pid/status"; }

tar czf "$tmp/scene.tar.gz" -C "$scene" .
hash=$(curl -sS --fail-with-body --data-binary @"$tmp/scene.tar.gz" -H 'Content-Type: application/gzip' \
       "$S/api/v1/scenes" | jq -r .hash)
printf "after start and upload (%s KiB bundle): RSS %s\n" "$(( $(stat -c %s "$tmp/scene.tar.gz") / 1024 ))" "$(rss VmRSS)"

submit() {
  curl -sS --fail-with-body -H 'Content-Type: application/json' \
       -d "{\"scene\": \"$hash\", \"spp\": 64, \"width\": 1280, \"height\": 720}" "$S/api/v1/jobs" | jq -r .id
}
start=$(date +%s.%N)
for _ in $(seq "$cycles"); do
  id=$(submit)
  curl -sS --fail-with-body -X DELETE "$S/api/v1/jobs/$id" > /dev/null
done
printf "after %s submit-and-cancel cycles (%.1f s each): RSS %s, peak %s\n" "$cycles" \
    "$(echo "($(date +%s.%N) - $start) / $cycles" | bc -l)" "$(rss VmRSS)" "$(rss VmHWM)"
for _ in $(seq "$cycles"); do submit > /dev/null; done
printf "with %s more jobs queued: RSS %s, peak %s\n" "$cycles" "$(rss VmRSS)" "$(rss VmHWM)"
