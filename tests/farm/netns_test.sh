#!/usr/bin/env bash
# The farm across three hosts: network namespaces joined by veth pairs stand in for machines.
#
#   tsr-w1-PID  10.201.1.2 ──veth── 10.201.1.1 ┐
#                                              ├ tsr-coord-PID: tessera-server on 0.0.0.0:8420
#   tsr-w2-PID  10.201.2.2 ──veth── 10.201.2.1 ┘
#
# One tessera-worker per worker namespace (each can reach the coordinator only over its veth),
# tokens on, `tessera submit --wait` from the coordinator's namespace. Passes when both workers
# rendered part of the job and the farm's image equals a local `tessera render` bit for bit.
# Usage: netns_test.sh TESSERA_SERVER TESSERA_WORKER TESSERA   (CTest passes the built binaries)
# Exit 77 (skip) without root, `ip` or namespace support, except under CI=true, where that fails.
set -euo pipefail

if [ $# -ne 3 ]; then
  echo "usage: $0 TESSERA_SERVER TESSERA_WORKER TESSERA" >&2
  exit 2
fi
server_bin=$1 worker_bin=$2 cli_bin=$3
root=$(cd "$(dirname "$0")/../.." && pwd)
scene=$root/scenes/demo/scene.xml
# Small enough for ~10 s on two cores, with enough work units (48 tiles x 5 passes) for both workers.
settings=(--spp 16 --width 128 --height 96)

# shellcheck source=../support/script_test.sh
source "$(dirname "${BASH_SOURCE[0]}")/../support/script_test.sh"

[ "$(id -u)" -eq 0 ] || skip "network namespaces need root"
command -v ip > /dev/null || skip "ip (iproute2) is missing"
command -v curl > /dev/null || skip "curl is missing"
command -v python3 > /dev/null || skip "python3 is missing"
for b in "$server_bin" "$worker_bin" "$cli_bin"; do [ -x "$b" ] || fail "not an executable: $b"; done
[ -f "$scene" ] || fail "no scene $scene"

id=$$
ns_c=tsr-coord-$id ns_1=tsr-w1-$id ns_2=tsr-w2-$id
# Interface names: at most 15 characters.
veth_c1=tc1-$id veth_1=tw1-$id veth_c2=tc2-$id veth_2=tw2-$id
port=8420
tmp=$(mktemp -d "${TMPDIR:-/tmp}/tessera-netns.XXXXXX")
pids=()
namespaces=()

cleanup() {
  local rc=$?
  trap - EXIT INT TERM HUP
  # The workers first (SIGTERM: they sign off while the coordinator still answers), then the
  # coordinator (pids[0]); what has not stopped after 5 s, and anything else left in our
  # namespaces, is killed.
  stop() {
    local p
    for p in "$@"; do kill -TERM "$p" 2> /dev/null || true; done
    for _ in $(seq 50); do
      local alive=0
      for p in "$@"; do kill -0 "$p" 2> /dev/null && alive=1; done
      [ $alive -eq 0 ] && break
      sleep 0.1
    done
    for p in "$@"; do kill -KILL "$p" 2> /dev/null || true; done
  }
  [ ${#pids[@]} -gt 1 ] && stop "${pids[@]:1}"
  [ ${#pids[@]} -gt 0 ] && stop "${pids[0]}"
  for ns in "${namespaces[@]}"; do
    for p in $(ip netns pids "$ns" 2> /dev/null); do kill -KILL "$p" 2> /dev/null || true; done
  done
  wait 2> /dev/null || true
  # Deleting a namespace destroys the veth ends in it, and with them their peers.
  for ns in "${namespaces[@]}"; do ip netns del "$ns" 2> /dev/null || true; done
  for v in "$veth_c1" "$veth_1" "$veth_c2" "$veth_2"; do ip link del "$v" 2> /dev/null || true; done
  if [ $rc -ne 0 ] && [ $rc -ne 77 ]; then
    for log in "$tmp"/*.log; do
      [ -f "$log" ] && { echo "--- $(basename "$log") (last 30 lines)"; tail -n 30 "$log"; }
    done
  fi
  rm -rf "$tmp"
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM HUP

# --- three "hosts" -------------------------------------------------------------------------------
ip netns add "$ns_c" 2> "$tmp/ip.err" || skip "cannot create a network namespace: $(cat "$tmp/ip.err")"
namespaces+=("$ns_c")
ip netns add "$ns_1"
namespaces+=("$ns_1")
ip netns add "$ns_2"
namespaces+=("$ns_2")
for ns in "${namespaces[@]}"; do ip -n "$ns" link set lo up; done
ip link add "$veth_c1" netns "$ns_c" type veth peer name "$veth_1" netns "$ns_1"
ip link add "$veth_c2" netns "$ns_c" type veth peer name "$veth_2" netns "$ns_2"
ip -n "$ns_c" addr add 10.201.1.1/24 dev "$veth_c1"
ip -n "$ns_1" addr add 10.201.1.2/24 dev "$veth_1"
ip -n "$ns_c" addr add 10.201.2.1/24 dev "$veth_c2"
ip -n "$ns_2" addr add 10.201.2.2/24 dev "$veth_2"
for pair in "$ns_c:$veth_c1" "$ns_1:$veth_1" "$ns_c:$veth_c2" "$ns_2:$veth_2"; do
  ip -n "${pair%%:*}" link set "${pair#*:}" up
done
echo "netns: $ns_c (10.201.1.1, 10.201.2.1), $ns_1 (10.201.1.2), $ns_2 (10.201.2.2)"

# --- the coordinator, with tokens -----------------------------------------------------------------
client_token=$(od -An -N16 -tx1 /dev/urandom | tr -d ' \n')
worker_token=$(od -An -N16 -tx1 /dev/urandom | tr -d ' \n')
TESSERA_CLIENT_TOKEN=$client_token TESSERA_WORKER_TOKEN=$worker_token \
  ip netns exec "$ns_c" "$server_bin" --listen "0.0.0.0:$port" --data-dir "$tmp/coordinator" \
  > "$tmp/server.log" 2>&1 &
pids+=($!)

in_ns() { ip netns exec "$@"; }
api() {  # api NS URL: GET with the client token
  in_ns "$1" curl -fsS --max-time 5 -H "Authorization: Bearer $client_token" "$2"
}
for _ in $(seq 100); do
  in_ns "$ns_c" curl -fsS --max-time 1 "http://127.0.0.1:$port/healthz" > /dev/null 2>&1 && break
  sleep 0.1
done
in_ns "$ns_c" curl -fsS --max-time 2 "http://127.0.0.1:$port/healthz" > /dev/null || fail "the coordinator did not start"

# Each worker host reaches the coordinator over its own link, and has no coordinator of its own.
for pair in "$ns_1:10.201.1.1" "$ns_2:10.201.2.1"; do
  in_ns "${pair%%:*}" curl -fsS --max-time 2 "http://${pair#*:}:$port/healthz" > /dev/null \
    || fail "${pair%%:*} cannot reach the coordinator at ${pair#*:}:$port"
  if in_ns "${pair%%:*}" curl -fsS --max-time 1 "http://127.0.0.1:$port/healthz" > /dev/null 2>&1; then
    fail "${pair%%:*} reaches a coordinator on its own loopback: the namespaces are not separate"
  fi
done
code=$(in_ns "$ns_1" curl -s -o /dev/null -w '%{http_code}' --max-time 2 "http://10.201.1.1:$port/api/v1/workers")
[ "$code" = 401 ] || fail "the coordinator answered $code without a token (expected 401)"

# --- one worker per worker host ----------------------------------------------------------------
# Short polls: a worker told to stop signs off only once its lease poll has returned.
TESSERA_WORKER_TOKEN=$worker_token ip netns exec "$ns_1" "$worker_bin" --server "http://10.201.1.1:$port" \
  --cache-dir "$tmp/cache-w1" --name w1 --threads 1 --poll-wait 2 > "$tmp/w1.log" 2>&1 &
pids+=($!)
TESSERA_WORKER_TOKEN=$worker_token ip netns exec "$ns_2" "$worker_bin" --server "http://10.201.2.1:$port" \
  --cache-dir "$tmp/cache-w2" --name w2 --threads 1 --poll-wait 2 > "$tmp/w2.log" 2>&1 &
pids+=($!)

count_workers='import json, sys; print(sum(w["state"] not in ("gone", "lost") for w in json.load(sys.stdin)["workers"]))'
workers=0
for _ in $(seq 100); do
  workers=$(api "$ns_c" "http://127.0.0.1:$port/api/v1/workers" | python3 -c "$count_workers") || workers=0
  [ "$workers" -ge 2 ] && break
  sleep 0.1
done
[ "$workers" -ge 2 ] || fail "only $workers of 2 workers registered"
echo "netns: coordinator up, 2 workers registered"

# --- a job through the farm, the same image locally ----------------------------------------------
start=$(date +%s.%N)
TESSERA_CLIENT_TOKEN=$client_token timeout 90 ip netns exec "$ns_c" "$cli_bin" submit "$scene" \
  --server "http://127.0.0.1:$port" --wait -o "$tmp/farm.exr" -o "$tmp/farm.pfm" "${settings[@]}" \
  --tile-size 16 --name netns -q > "$tmp/submit.log" 2>&1 &
wait $! || fail "tessera submit failed"  # in the background: a signal to this script is taken at once
echo "netns: farm render took $(echo "$(date +%s.%N) - $start" | bc) s"
"$cli_bin" render "$scene" -o "$tmp/local.exr" -o "$tmp/local.pfm" "${settings[@]}" -q \
  > "$tmp/render.log" 2>&1 || fail "tessera render failed"

# Both hosts rendered part of it: the workers' counters and the job's own account agree.
api "$ns_c" "http://127.0.0.1:$port/api/v1/workers" > "$tmp/workers.json"
api "$ns_c" "http://127.0.0.1:$port/api/v1/jobs/1" > "$tmp/job.json"
python3 - "$tmp/workers.json" "$tmp/job.json" << 'EOF' || fail "both workers must have rendered part of the job"
import json, sys
workers = {w["name"]: w for w in json.load(open(sys.argv[1]))["workers"]}
job = json.load(open(sys.argv[2]))
shares = {w["name"]: w["samples"] for w in job["workers"]}
for name in ("w1", "w2"):
    units, samples = workers.get(name, {}).get("units_done", 0), shares.get(name, 0)
    print(f"netns: {name} rendered {units} units, {samples} samples of the job")
    if units <= 0 or samples <= 0:
        sys.exit(1)
if job["state"] != "done" or sum(shares.values()) != job["samples_total"]:
    print(f"netns: job {job['state']}, {sum(shares.values())} of {job['samples_total']} samples")
    sys.exit(1)
EOF

cmp "$tmp/farm.pfm" "$tmp/local.pfm" || fail "the farm's image differs from tessera render's (PFM bytes)"
"$cli_bin" compare "$tmp/farm.exr" "$tmp/local.exr" > "$tmp/compare.log" 2>&1 || fail "tessera compare failed"
grep -q ' rel_mse=0 ' "$tmp/compare.log" && grep -q ' mse=0 ' "$tmp/compare.log" || fail "tessera compare: $(cat "$tmp/compare.log")"
echo "netns: farm image == local render, bit for bit ($(cut -c1-40 "$tmp/compare.log"))"

# SIGTERM: each worker signs off over its own link and exits 0; the coordinator marks it gone.
kill -TERM "${pids[1]}" "${pids[2]}"
for _ in $(seq 100); do
  kill -0 "${pids[1]}" 2> /dev/null || kill -0 "${pids[2]}" 2> /dev/null || break
  sleep 0.1
done
for i in 1 2; do
  status=0
  if kill -0 "${pids[i]}" 2> /dev/null; then fail "worker w$i did not stop within 10 s of SIGTERM"; fi
  wait "${pids[i]}" || status=$?
  [ $status -eq 0 ] || fail "worker w$i exited with status $status after SIGTERM"
done
gone=$(api "$ns_c" "http://127.0.0.1:$port/api/v1/workers" |
  python3 -c 'import json, sys; print(sum(w["state"] == "gone" for w in json.load(sys.stdin)["workers"]))')
[ "$gone" -eq 2 ] || fail "$gone of 2 workers signed off"
echo "netns: both workers signed off on SIGTERM"
echo "netns_test: passed"
