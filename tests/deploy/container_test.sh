#!/usr/bin/env bash
# The container image, built and run: scripts/build-image.sh builds docker/Dockerfile with podman
# (on a debootstrapped Debian 12), podman-compose starts docker/compose.yaml's coordinator and two
# workers from it, and a job submitted from this host with this host's `tessera` must come back
# bit-identical to `tessera render` here. That holds only if the image's build renders the same bits
# as the host's (same Debian, compiler and flags), which the coordinator also checks when each worker
# registers (the build fingerprint): both workers must be admitted.
#
# usage: tests/deploy/container_test.sh [BUILD_DIR]     (from anywhere; BUILD_DIR default: build)
# Run as root. Exit 0 pass, 1 fail, 77 skip (no podman etc.; under CI=true that is a failure).
set -euo pipefail
cd "$(dirname "$0")/../.."

build_dir=${1:-build}
cli=$build_dir/cli/tessera
scene=scenes/demo/scene.xml
# Small, with enough work units (48 tiles x 5 passes) that both workers get some.
settings=(--spp 16 --width 128 --height 96)
project=tessera-test-$$
image=localhost/tessera:test

# shellcheck source=../support/script_test.sh
source "$(dirname "${BASH_SOURCE[0]}")/../support/script_test.sh"

[ "$(id -u)" -eq 0 ] || skip "debootstrap and rootful podman need root"
for tool in podman podman-compose debootstrap curl python3 openssl; do
  command -v "$tool" >/dev/null || skip "$tool is missing (scripts/install-deps.sh installs it)"
done
[ -x "$cli" ] || fail "no $cli: build the project first (scripts/test.sh)"
[ -f "$scene" ] || fail "no scene $scene"

tmp=$(mktemp -d "${TMPDIR:-/tmp}/tessera-container.XXXXXX")
compose=(podman-compose -p "$project" -f docker/compose.yaml)
started=0

cleanup() {
  local rc=$?
  trap - EXIT INT TERM HUP
  if [ $started -eq 1 ]; then
    if [ $rc -ne 0 ]; then
      for c in $(podman ps -a --filter "label=io.podman.compose.project=$project" --format '{{.Names}}'); do
        echo "--- podman logs $c (last 30 lines)"
        podman logs --tail 30 "$c" 2>&1 || true
      done
    fi
    "${compose[@]}" down -v -t 10 >>"$tmp/compose.log" 2>&1 || true
    # What down leaves behind, or everything if it failed: containers, pods, volumes, the network.
    podman ps -aq --filter "label=io.podman.compose.project=$project" | xargs -r podman rm -f -t 0 >/dev/null 2>&1 || true
    podman pod ls -q --filter "name=$project" | xargs -r podman pod rm -f >/dev/null 2>&1 || true
    podman volume ls -q --filter "label=io.podman.compose.project=$project" | xargs -r podman volume rm -f >/dev/null 2>&1 || true
    podman network ls -q --filter "label=io.podman.compose.project=$project" | xargs -r podman network rm -f >/dev/null 2>&1 || true
  fi
  if [ $rc -ne 0 ] && [ $rc -ne 77 ]; then
    for log in "$tmp"/*.log; do
      [ -f "$log" ] && { echo "--- $(basename "$log") (last 30 lines)"; tail -n 30 "$log"; }
    done
  fi
  if [ -n "${TESSERA_CONTAINERS_CONF:-}" ]; then rm -f "$TESSERA_CONTAINERS_CONF"; fi
  rm -rf "$tmp"
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM HUP
. docker/podman-env.sh

# --- the image -----------------------------------------------------------------------------------
# With the programs this host has just built and tested (stripped, as the build stage installs
# them), not compiled a second time: the same Debian 12 compiler and flags make the same binaries
# (docker/Dockerfile, target prebuilt). TESSERA_CONTAINER_COMPILE=1 compiles them in the image.
t0=$SECONDS
programs=()
if [ "${TESSERA_CONTAINER_COMPILE:-0}" != 1 ]; then
  mkdir -p "$tmp/programs"
  install -m 0755 -s "$build_dir/cli/tessera" "$build_dir/server/tessera-server" "$build_dir/worker/tessera-worker" \
    "$tmp/programs/" || fail "cannot gather the programs of $build_dir"
  programs=(--programs "$tmp/programs")
fi
bash scripts/build-image.sh "${programs[@]}" "$image" >"$tmp/build.log" 2>&1 || fail "scripts/build-image.sh failed"
grep '^build-image:' "$tmp/build.log" | sed 's/^/container: /'
echo "container: image ready in $((SECONDS - t0)) s"

# --- the farm: coordinator and two workers, published on loopback only ----------------------------
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
TESSERA_CLIENT_TOKEN=$(openssl rand -hex 32)
TESSERA_WORKER_TOKEN=$(openssl rand -hex 32)
export TESSERA_CLIENT_TOKEN TESSERA_WORKER_TOKEN
export TESSERA_IMAGE=$image TESSERA_PORT=127.0.0.1:$port TESSERA_WORKERS=2 TESSERA_WORKER_THREADS=1
server=http://127.0.0.1:$port
t0=$SECONDS
started=1
"${compose[@]}" up -d >"$tmp/compose.log" 2>&1 || fail "podman-compose up failed"

healthy=0
for _ in $(seq 120); do
  if curl -fsS --max-time 2 -o /dev/null "$server/healthz" 2>/dev/null; then healthy=1; break; fi
  sleep 0.5
done
[ $healthy -eq 1 ] || fail "the coordinator's /healthz did not answer on $server within 60 s"
echo "container: coordinator healthy on $server after $((SECONDS - t0)) s"

api() { curl -fsS --max-time 5 -H "Authorization: Bearer $TESSERA_CLIENT_TOKEN" "$server$1"; }
code=$(curl -s -o /dev/null -w '%{http_code}' --max-time 5 "$server/api/v1/workers")
[ "$code" = 401 ] || fail "the coordinator answered $code without a token (expected 401)"

# A worker whose build fingerprint differed from the coordinator's would be refused (409) and exit.
count_workers='import json, sys; print(sum(w["state"] not in ("gone", "lost") for w in json.load(sys.stdin)["workers"]))'
workers=0
for _ in $(seq 120); do
  workers=$(api /api/v1/workers | python3 -c "$count_workers") || workers=0
  [ "$workers" -ge 2 ] && break
  sleep 0.5
done
[ "$workers" -ge 2 ] || fail "$workers of 2 workers registered"
echo "container: 2 workers registered (same build fingerprint as the coordinator)"

# --- a job from this host, and the same render here ------------------------------------------------
t0=$SECONDS
timeout 300 "$cli" submit "$scene" --server "$server" --wait -o "$tmp/farm.pfm" "${settings[@]}" \
  --tile-size 16 --name container-test -q >"$tmp/submit.log" 2>&1 &
wait $! || fail "tessera submit failed"  # in the background: a signal to this script is taken at once
echo "container: farm render took $((SECONDS - t0)) s"
"$cli" render "$scene" -o "$tmp/local.pfm" "${settings[@]}" -q >"$tmp/render.log" 2>&1 \
  || fail "tessera render failed"

api /api/v1/workers >"$tmp/workers.json"
api /api/v1/jobs/1 >"$tmp/job.json"
python3 - "$tmp/workers.json" "$tmp/job.json" <<'EOF' || fail "the job must be done, with every sample accounted for"
import json, sys
workers = [w for w in json.load(open(sys.argv[1]))["workers"] if w["state"] not in ("gone", "lost")]
job = json.load(open(sys.argv[2]))
shares = {w["id"]: w["samples"] for w in job["workers"]}
for w in workers:
    print(f"container: worker {w['id']} ({w['name']}) rendered {w.get('units_done', 0)} units, "
          f"{shares.get(w['id'], 0)} samples of the job")
if job["state"] != "done" or sum(shares.values()) != job["samples_total"]:
    print(f"container: job {job['state']}, {sum(shares.values())} of {job['samples_total']} samples")
    sys.exit(1)
# Who renders what is up to timing; both rendering is the usual case, so only a note if not.
if sum(1 for w in workers if shares.get(w["id"], 0) > 0) < 2:
    print("container: note: one worker rendered the whole job")
EOF

cmp "$tmp/farm.pfm" "$tmp/local.pfm" || fail "the image from the containers differs from tessera render's here (PFM bytes)"
echo "container: farm image == host render, bit for bit"
echo "PASS: container_test ($SECONDS s)"
