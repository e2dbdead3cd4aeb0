#!/usr/bin/env bash
# Load of one coordinator: tessera-farm-load with 1, 16, 64, 256 and 1000 simulated workers (driven
# by two event-loop threads, speaking the real protocol, synthetic results, no rendering) against a
# fresh tessera-server each, one table at the end. Builds nothing. The load generator runs on the same machine as the
# coordinator, so on a small machine they share its cores (bench_% says how much it took).
# Usage: bench/farm_load.sh [BUILD_DIR] [SECONDS] [UNITS] [HTTP_THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
seconds=${2:-15}
units=${3:-100000}
http=${4:-64}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

printf "coordinator load: %s s per run (or %s units), %s HTTP threads, %d cores shared with the load generator\n" \
    "$seconds" "$units" "$http" "$(nproc)"
for workers in 1 16 64 256 1000; do
  "$build/bench/tessera-farm-load" --server-bin "$build/server/tessera-server" --workers "$workers" \
      --seconds "$seconds" --units "$units" --http-threads "$http" --csv "$tmp/load.csv" > "$tmp/run$workers.log" \
      || { cat "$tmp/run$workers.log"; echo "tessera-farm-load failed with $workers workers" >&2; exit 1; }
done
column -t -s, "$tmp/load.csv"
echo "latencies in ms (lease: polls; upload: a result and the next lease with it); coord_cpu: the coordinator's utime+stime;"
echo "fsync_per_unit: state-database commits per unit; workers_fed: units/s x 2 s per tile (an upper bound)"
