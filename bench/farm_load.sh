#!/usr/bin/env bash
# Load of one coordinator: tessera-farm-load with 1, 16, 64, 256 and 1000 simulated workers, and 256
# with 1000 jobs queued behind the measured one (driven
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
# The last run: 256 workers with 1000 one-unit jobs of a lower priority queued behind the measured one.
for run in 1:0 16:0 64:0 256:0 1000:0 256:1000; do
  workers=${run%:*} queued=${run#*:}
  "$build/bench/tessera-farm-load" --server-bin "$build/server/tessera-server" --workers "$workers" \
      --queued-jobs "$queued" --seconds "$seconds" --units "$units" --http-threads "$http" --csv "$tmp/load.csv" \
      > "$tmp/run$workers-$queued.log" \
      || { cat "$tmp/run$workers-$queued.log"; echo "tessera-farm-load failed with $workers workers" >&2; exit 1; }
done
column -t -s, "$tmp/load.csv"
echo "latencies in ms (lease: polls; upload: a result and the next lease with it); coord_cpu: the coordinator's utime+stime;"
echo "fsync_per_unit: state-database commits per unit; workers_fed: units/s x 2 s per tile (an upper bound)"
