#!/usr/bin/env python3
"""Instancing at scale, as a user runs it: scripts/gen_forest.py makes 10,000 instances of a
100,000-triangle tree (a billion instanced triangles); the farm renders it on one worker
(tessera-server without local workers, one tessera-worker, tessera submit --wait) to the same bits
as `tessera render`, with no NaN or Inf, trees in view, and the worker's peak memory under 4 GB.
The worker's heartbeats report the scene's memory, which the coordinator shows. Prints the load
and BVH build times the CLI reports."""
import argparse
import json
import os
import re
import resource
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request

MAX_WORKER_BYTES = 4 << 30


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def read_pfm(path):
    with open(path, "rb") as f:
        data = f.read()
    header = data.split(b"\n", 3)
    if header[0] != b"PF":
        fail("%s is not an RGB PFM" % path)
    w, h = map(int, header[1].split())
    scale = float(header[2])
    fmt = ("<" if scale < 0 else ">") + "%df" % (3 * w * h)
    return w, h, struct.unpack(fmt, header[3][: 12 * w * h])


def start_farm(args, tmp):
    port_file = os.path.join(tmp, "port")
    server = subprocess.Popen([args.server, "--listen", "127.0.0.1:0", "--port-file", port_file, "--data-dir",
                               os.path.join(tmp, "state"), "--local-workers", "0"],
                              stdout=open(os.path.join(tmp, "server.log"), "w"), stderr=subprocess.STDOUT)
    for _ in range(200):
        if os.path.exists(port_file) and os.path.getsize(port_file) > 0:
            break
        time.sleep(0.05)
    else:
        server.kill()
        fail("the coordinator did not start: " + open(os.path.join(tmp, "server.log")).read())
    url = "http://127.0.0.1:" + open(port_file).read().strip()
    worker = subprocess.Popen([args.worker, "--server", url, "--threads", "2", "--cache-dir",
                               os.path.join(tmp, "cache"), "--poll-wait", "1"],
                              stdout=open(os.path.join(tmp, "worker.log"), "w"), stderr=subprocess.STDOUT)
    return server, worker, url


def reported_scene_memory(url):
    """The worker's scene memory as GET /api/v1/workers shows it, once a heartbeat reported it."""
    for _ in range(150):
        with urllib.request.urlopen(url + "/api/v1/workers", timeout=10) as r:
            workers = json.load(r)["workers"]
        if workers and workers[0].get("scene_memory_bytes", 0) > 0:
            return workers[0]
        time.sleep(0.1)
    fail("no worker reported its scene memory: %s" % workers)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--server", required=True)
    ap.add_argument("--worker", required=True)
    ap.add_argument("--source", required=True)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        forest = os.path.join(tmp, "forest")
        subprocess.run([sys.executable, os.path.join(args.source, "scripts", "gen_forest.py"), "--out", forest],
                       check=True, timeout=120)
        scene = os.path.join(forest, "scene.xml")
        size = ["--width", "96", "--height", "54", "--spp", "2"]
        local = os.path.join(tmp, "local.pfm")
        r = subprocess.run([args.cli, "render", scene, "-o", local, "--threads", "2"] + size,
                           capture_output=True, text=True, timeout=300)
        if r.returncode != 0:
            fail("tessera render exited %d: %s" % (r.returncode, r.stderr[-2000:]))
        m = re.search(r"(\d+) triangles \((\d+) with instances\), \d+ shapes, (\d+) instances", r.stderr)
        if not m or int(m.group(2)) < 10**9 or int(m.group(3)) < 10000 or int(m.group(1)) > 200000:
            fail("the CLI did not report a billion instanced triangles from one stored tree: " + r.stderr[-2000:])
        times = re.search(r"times: parse ([0-9.]+) s, load ([0-9.]+) s \(BVH build ([0-9.]+) s\)", r.stderr)
        print("forest: %s stored triangles, %s instanced, %s instances; parse %s s, load %s s, BVH build %s s"
              % (m.group(1), m.group(2), m.group(3), times.group(1), times.group(2), times.group(3)))

        w, h, pixels = read_pfm(local)
        if any(v != v or v in (float("inf"), float("-inf")) for v in pixels):
            fail("NaN or Inf in the forest image")
        green = sum(1 for i in range(w * h) if pixels[3 * i + 1] > 1.2 * pixels[3 * i] and pixels[3 * i + 1] > 0.01)
        if green < w * h // 10:
            fail("only %d of %d pixels are leaves: the trees are not in view" % (green, w * h))

        server, worker, url = start_farm(args, tmp)
        try:
            farm = os.path.join(tmp, "farm.pfm")
            r = subprocess.run([args.cli, "submit", scene, "--server", url, "--wait", "-o", farm] + size,
                               capture_output=True, text=True, timeout=600)
            if r.returncode != 0:
                fail("tessera submit exited %d: %s%s" % (r.returncode, r.stdout[-2000:], r.stderr[-2000:]))
            worker_status = reported_scene_memory(url)
        finally:
            worker.terminate()
            _, status, usage = os.wait4(worker.pid, 0)
            server.terminate()
            server.wait(timeout=30)
        if open(farm, "rb").read() != open(local, "rb").read():
            fail("the farm's image differs from tessera render's")
        peak = usage.ru_maxrss * 1024  # kilobytes on Linux
        reported = worker_status["scene_memory_bytes"]
        print("forest on one worker: peak resident memory %.0f MB; the worker reports %.1f MB of scene in %d scene(s)"
              % (peak / 2**20, reported / 2**20, worker_status["scenes_loaded"]))
        if worker_status["scenes_loaded"] != 1 or not (2**20 < reported < peak):
            fail("the reported scene memory (%d bytes) is not within the worker's footprint (%d)" % (reported, peak))
        if peak > MAX_WORKER_BYTES:
            fail("the worker peaked at %.1f GB, over 4 GB" % (peak / 2**30))
    print("PASS")


if __name__ == "__main__":
    main()
