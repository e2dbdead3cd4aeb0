# Sourced by the farm benchmarks: a temporary folder `tmp`, removed at exit once the processes
# whose ids were added to `pids` are killed.
tmp=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT
