#!/usr/bin/env python3
"""`tessera submit`, `jobs` and `cancel` as a user runs them against a coordinator with a client token.

- A coordinator that does not answer is named by its URL; a 401 names the token that was sent (or
  that none was) and how to give one (TESSERA_CLIENT_TOKEN, --token-file).
- `-q` prints nothing at all on success, and still prints errors.
- `--wait` without `-o` writes JOBNAME.exr, the job named after the scene's folder (scenes are all
  called scene.xml), and will not overwrite it again without `--force`.

    python3 tests/cli/submit_cli_test.py --cli TESSERA --server TESSERA_SERVER --worker TESSERA_WORKER
"""
import argparse
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "support"))
from script_test import Failure, run_in_temp_dir  # noqa: E402

TOKEN = "cli-client-7d21"
SCENE = """<scene version="0.6.0">
  <sensor type="perspective"><float name="fov" value="45"/>
    <sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="20"/><integer name="height" value="12"/></film>
  </sensor>
  <shape type="sphere"><point name="center" x="0" y="0" z="4"/></shape>
  <emitter type="constant"/>
</scene>
"""


def check(condition, message):
    if not condition:
        raise Failure(message)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Coordinator:
    def __init__(self, args, tmp):
        port_file = tmp / "port"
        self.log = open(tmp / "server.log", "wb")
        self.proc = subprocess.Popen(
            [args.server, "--listen", "127.0.0.1:0", "--port-file", str(port_file), "--data-dir", str(tmp / "data"),
             "--local-workers", "1", "--worker-binary", args.worker, "--client-token", TOKEN,
             "--worker-token", "cli-worker-1b9e"],
            stdout=self.log, stderr=subprocess.STDOUT, start_new_session=True)
        end = time.monotonic() + 30
        while time.monotonic() < end and not (port_file.exists() and port_file.read_text().strip()):
            check(self.proc.poll() is None, f"tessera-server exited with {self.proc.returncode}")
            time.sleep(0.05)
        check(port_file.exists(), "tessera-server wrote no port file")
        self.url = f"http://127.0.0.1:{int(port_file.read_text())}"

    def stop(self):
        self.proc.terminate()
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        self.log.close()


def tessera(args, cwd, *argv, token=None):
    env = dict(os.environ)
    env.pop("TESSERA_CLIENT_TOKEN", None)
    env.pop("TESSERA_SERVER", None)
    if token:
        env["TESSERA_CLIENT_TOKEN"] = token
    r = subprocess.run([args.cli, *argv], cwd=cwd, env=env, capture_output=True, text=True, timeout=120)
    print(f"$ tessera {' '.join(argv)} -> {r.returncode}\n{r.stdout}{r.stderr}", end="")
    return r


def check_unanswered(args, tmp, scene):
    url = f"http://127.0.0.1:{free_port()}"
    for argv in (["submit", str(scene)], ["jobs"], ["cancel", "1"]):
        r = tessera(args, tmp, *argv, "--server", url, token=TOKEN)
        check(r.returncode != 0, f"tessera {argv[0]} succeeded with nothing at {url}")
        check(f"no answer from {url}" in r.stderr, f"tessera {argv[0]} does not name {url}: {r.stderr!r}")


def check_refused_tokens(args, tmp, scene, url):
    r = tessera(args, tmp, "submit", str(scene), "--server", url)
    check(r.returncode != 0 and "401" in r.stderr, f"submit without a token: {r.stderr!r}")
    for needed in ("none was sent", "TESSERA_CLIENT_TOKEN", "--token-file"):
        check(needed in r.stderr, f"a 401 without a token does not say '{needed}': {r.stderr!r}")
    bad = tmp / "wrong.token"
    bad.write_text("not-the-token\n")
    r = tessera(args, tmp, "jobs", "--server", url, "--token-file", str(bad))
    check(r.returncode != 0 and f"--token-file {bad}" in r.stderr, f"a refused token file is not named: {r.stderr!r}")
    r = tessera(args, tmp, "jobs", "--server", url, token="not-the-token")
    check(r.returncode != 0 and "$TESSERA_CLIENT_TOKEN" in r.stderr, f"a refused $TESSERA_CLIENT_TOKEN: {r.stderr!r}")


def check_quiet(args, tmp, scene, url):
    r = tessera(args, tmp, "submit", str(scene), "--server", url, "-q", "-o", str(tmp / "quiet.exr"), token=TOKEN)
    check(r.returncode == 0, f"submit -q -o failed: {r.stderr!r}")
    check(r.stdout == "" and r.stderr == "", f"submit -q printed {r.stdout + r.stderr!r}")
    check((tmp / "quiet.exr").is_file(), "submit -q -o wrote no image")
    # Quiet still reports an error: a refused job.
    r = tessera(args, tmp, "submit", str(scene), "--server", url, "-q", "--spp", "999999999", token=TOKEN)
    check(r.returncode != 0 and "spp" in r.stderr, f"submit -q hid a refusal: {r.stderr!r}")


def check_default_output(args, tmp, scene, url):
    work = tmp / "work"
    work.mkdir()
    r = tessera(args, work, "submit", str(scene), "--server", url, "--wait", token=TOKEN)
    check(r.returncode == 0, f"submit --wait failed: {r.stderr!r}")
    out = work / "tiny-box.exr"
    check(out.is_file() and out.stat().st_size > 100, f"--wait without -o did not write {out.name}: {os.listdir(work)}")
    r = tessera(args, work, "jobs", "--server", url, token=TOKEN)
    check(r.returncode == 0 and "tiny-box" in r.stdout, f"the job is not named after its folder: {r.stdout!r}")
    before = out.stat().st_mtime_ns
    r = tessera(args, work, "submit", str(scene), "--server", url, "--wait", token=TOKEN)
    check(r.returncode == 2, f"submit --wait over an existing tiny-box.exr exited {r.returncode}")
    check("tiny-box.exr" in r.stderr and "--force" in r.stderr, f"the refusal names neither file nor flag: {r.stderr!r}")
    check(out.stat().st_mtime_ns == before, "tiny-box.exr was overwritten without --force")
    r = tessera(args, work, "submit", str(scene), "--server", url, "--wait", "--force", token=TOKEN)
    check(r.returncode == 0 and out.stat().st_mtime_ns != before, f"submit --wait --force: {r.stderr!r}")


def run(args, tmp):
    scene = tmp / "tiny-box" / "scene.xml"
    scene.parent.mkdir()
    scene.write_text(SCENE)
    failed = []

    def part(check_fn, *extra):  # each part runs, so one run reports every broken promise
        try:
            check_fn(args, tmp, scene, *extra)
        except Failure as e:
            print(f"FAIL {check_fn.__name__}: {e}")
            failed.append(check_fn.__name__)

    part(check_unanswered)
    coordinator = Coordinator(args, tmp)
    try:
        part(check_refused_tokens, coordinator.url)
        part(check_quiet, coordinator.url)
        part(check_default_output, coordinator.url)
    finally:
        coordinator.stop()
    if failed:
        print((tmp / "server.log").read_text(errors="replace")[-2000:], file=sys.stderr)
        raise Failure(", ".join(failed))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", required=True)
    parser.add_argument("--server", required=True)
    parser.add_argument("--worker", required=True)
    args = parser.parse_args()
    for name in ("cli", "server", "worker"):
        setattr(args, name, os.path.abspath(getattr(args, name)))
    return run_in_temp_dir("tessera-submit-cli-", run, args)


if __name__ == "__main__":
    sys.exit(main())
