#!/usr/bin/env bash
# What stalled uploads cost everyone else: a coordinator with default settings and one local worker
# gets STALLED uploads from 127.0.0.2 that announce a 2 GB bundle, send 16 bytes and stop. Meanwhile,
# from 127.0.0.1, /healthz is timed every 20 ms and a small Cornell box job is rendered. Prints how
# each stalled connection ended (status, seconds until the server closed it), /healthz latency over
# the stall and the job's wall time. Targets: /healthz p99 <= 100 ms, the job done, every stalled
# connection closed within 30 s. Builds nothing; needs curl, jq and python3, and 127.0.0.2 on the
# loopback interface (Linux routes all of 127/8 there).
# Usage: bench/stalled_uploads.sh [BUILD_DIR] [STALLED] [SERVER_FLAGS]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
stalled=${2:-200}
read -r -a server_flags <<< "${3:-}"
scene=../shared/scenes/cornell-box
source bench/farm_processes.sh

"$build/server/tessera-server" --listen 127.0.0.1:0 --port-file "$tmp/port" --data-dir "$tmp/data" \
    --local-workers 1 --log-level warn "${server_flags[@]}" > "$tmp/server.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do [ -s "$tmp/port" ] && break; sleep 0.1; done
port=$(cat "$tmp/port")
s="http://127.0.0.1:$port"
tar czf "$tmp/cornell.tar.gz" -C "$scene" scene.xml

# The stalled uploads and the /healthz probe, in one python3 process; a JSON summary on stdout.
python3 - "$port" "$stalled" > "$tmp/stall.json" <<'EOF' &
import http.client, json, selectors, socket, sys, time
port, count = int(sys.argv[1]), int(sys.argv[2])
request = (b"POST /api/v1/scenes HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/gzip\r\n"
           b"Content-Length: 2147483648\r\n\r\n" + b"\x1f\x8b" + b"x" * 14)
sel, conns = selectors.DefaultSelector(), {}
for i in range(count):
    c = socket.socket()
    c.bind(("127.0.0.2", 0))
    c.connect(("127.0.0.1", port))
    c.sendall(request)
    c.setblocking(False)
    conns[c] = {"start": time.monotonic(), "reply": b"", "closed": None}
    sel.register(c, selectors.EVENT_READ)
latencies, deadline, last_probe = [], time.monotonic() + 60, 0.0
while conns and any(v["closed"] is None for v in conns.values()) and time.monotonic() < deadline:
    for key, _ in sel.select(timeout=0.02):
        v = conns[key.fileobj]
        try:
            data = key.fileobj.recv(65536)
        except (ConnectionResetError, OSError):
            data = b""
        if data:
            v["reply"] += data
        else:
            v["closed"] = time.monotonic() - v["start"]
            sel.unregister(key.fileobj)
            key.fileobj.close()
    if time.monotonic() - last_probe >= 0.02:  # /healthz from 127.0.0.1, a fresh connection each time
        last_probe = t0 = time.monotonic()
        h = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        h.request("GET", "/healthz")
        ok = h.getresponse().status == 200
        latencies.append((time.monotonic() - t0) * 1000 if ok else float("inf"))
        h.close()
statuses = {}
for v in conns.values():
    r = v["reply"]
    st = r[9:12].decode() if r.startswith(b"HTTP/1.") else "none"
    statuses[st] = statuses.get(st, 0) + 1
closed = sorted(v["closed"] for v in conns.values() if v["closed"] is not None)
lat = sorted(latencies)
pick = lambda xs, q: xs[min(len(xs) - 1, int(q * len(xs)))] if xs else None
print(json.dumps({"stalled": count, "closed": len(closed), "statuses": statuses,
                  "close_s": {"min": pick(closed, 0), "median": pick(closed, 0.5), "max": pick(closed, 1.0)},
                  "close_s_by_status": {st: max(v["closed"] or 1e9 for v in conns.values()
                                                if (v["reply"][9:12].decode() if v["reply"].startswith(b"HTTP/1.") else "none") == st)
                                        for st in statuses},
                  "healthz_ms": {"n": len(lat), "p50": pick(lat, 0.5), "p99": pick(lat, 0.99), "max": pick(lat, 1.0)}}))
EOF
stall_pid=$!
pids+=("$stall_pid")

# Meanwhile, a small job from 127.0.0.1.
sleep 0.5
start=$(date +%s.%N)
id=$(curl -sS --fail-with-body -F 'settings={"spp": 16, "width": 64, "height": 64, "tile_size": 16};type=application/json' \
         -F bundle=@"$tmp/cornell.tar.gz" "$s/api/v1/jobs" | jq -r .id)
state=queued
for _ in $(seq 1200); do
  state=$(curl -sS "$s/api/v1/jobs/$id" | jq -r .state)
  case "$state" in done|failed|cancelled) break ;; esac
  sleep 0.05
done
job_seconds=$(echo "$(date +%s.%N) - $start" | bc -l)
wait "$stall_pid"

printf "coordinator: default settings%s, 1 local worker; %s stalled uploads from 127.0.0.2 (2 GB announced, 16 bytes sent)\n" \
    "${3:+ + $3}" "$stalled"
jq -r '"stalled connections: \(.closed) of \(.stalled) closed by the server; answers \(.statuses | tojson)",
       "  seconds until closed: min \(.close_s.min * 1000 | round / 1000), median \(.close_s.median * 1000 | round / 1000), max \(.close_s.max * 1000 | round / 1000); slowest by answer \(.close_s_by_status | map_values(. * 100 | round / 100) | tojson)",
       "/healthz from 127.0.0.1 during the stall: \(.healthz_ms.n) requests, p50 \(.healthz_ms.p50 * 100 | round / 100) ms, p99 \(.healthz_ms.p99 * 100 | round / 100) ms, max \(.healthz_ms.max * 100 | round / 100) ms"' \
    "$tmp/stall.json"
printf "job from 127.0.0.1 (cornell-box 64x64, 16 spp): %s after %.2f s\n" "$state" "$job_seconds"
jq -e --arg state "$state" '.closed == .stalled and .close_s.max <= 30 and .healthz_ms.p99 <= 100 and $state == "done"' \
    "$tmp/stall.json" > /dev/null && echo "targets met" || { echo "targets missed" >&2; exit 1; }
