#!/usr/bin/env python3
"""Runs the ```sh blocks of docs/api.md, in order, in one bash session, against a real coordinator.

The coordinator has a client and a worker token (read from client.token and worker.token in the
session's folder, as the docs say) and one local worker, so jobs finish. The session's folder
stands in for the repository's root: ../shared beside it, and the build's programs in
build/server, build/worker and build/cli. The session starts from a clean shell (`env -i`): PATH
holds only /usr/bin and /bin, HOME an empty folder, and nothing else is set, so every variable
and PATH entry a command uses must be set by the docs themselves (their "Before you start"
block), and `set -u` makes a variable they never set an error. The one change to the docs' text:
the coordinator listens on a free port, so the line that sets S=URL sets that port's URL.

Every curl answer must be 2xx, unless the command carries a `# expect: NNN` comment, which makes
NNN the one answer accepted. Any other answer, a failing command, a curl example that never ran or
a session that does not finish fails the test, naming the line of docs/api.md, the command and
the answer. ```text blocks are synopses and are not run.

Exit status: 0 passed, 1 failed, 77 skipped (a tool or ../shared missing; under CI=true that fails).
"""
import argparse
import base64
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "support"))
from script_test import SKIP, Failure, run_in_temp_dir  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
TOOLS = ("bash", "curl", "jq", "tar", "openssl")
CLIENT_TOKEN = "docs-client-7f3a"
WORKER_TOKEN = "docs-worker-21c9"
EXPECT = re.compile(r"#\s*expect:\s*(\d{3})\b")
DOCS_NAME = "docs/api.md"  # in messages; set from --docs
SYSTEM_PATH = "/usr/bin:/bin"  # a clean shell's PATH; /usr/local/bin could hold an installed tessera
SETS_S = re.compile(r"^(\s*(?:export\s+)?S=)(https?://[^\s#;]+)")


# ---- reading the docs -----------------------------------------------------------------------

@dataclass
class Command:
    first: int          # lines in the docs, 1-based, inclusive
    last: int
    text: str
    expect: int = None  # the status a `# expect: NNN` comment asks for


@dataclass
class Block:
    line: int                  # the line of the block's first command line (after the fence)
    lines: list
    commands: list = field(default_factory=list)


def sh_blocks(markdown):
    """The ```sh blocks of a Markdown text, with the docs line of their first line."""
    blocks, block, fence = [], None, None
    for number, line in enumerate(markdown.splitlines(), start=1):
        stripped = line.strip()
        if fence is None and stripped.startswith("```"):
            fence = stripped[3:].strip()
            block = Block(number + 1, []) if fence in ("sh", "bash", "shell") else None
        elif fence is not None and stripped == "```":
            if block is not None:
                blocks.append(block)
            fence, block = None, None
        elif block is not None:
            block.lines.append(line)
    if fence is not None:
        raise Failure(f"unclosed ``` fence ({fence or 'no language'})")
    for b in blocks:
        b.commands = split_commands(b.lines, b.line)
    return blocks


def split_commands(lines, first_line):
    """Logical shell commands: lines joined by trailing backslashes and by open quotes. Enough
    shell to find where a command ends and what its comment says, not a shell parser."""
    commands, text, start, quote, comment = [], "", None, None, ""
    for offset, line in enumerate(lines):
        number = first_line + offset
        i, in_comment = 0, False
        while i < len(line):
            c = line[i]
            if in_comment:
                comment += c
            elif quote:
                if c == "\\" and quote == '"':
                    i += 1
                elif c == quote:
                    quote = None
            elif c in "'\"":
                quote = c
            elif c == "\\":
                i += 1
            elif c == "#" and (i == 0 or line[i - 1].isspace()):
                in_comment, comment = True, comment + " #"
            i += 1
        if start is None and line.strip() and not line.strip().startswith("#"):
            start = number
        if start is not None:
            text += line + "\n"
        continued = quote is not None or (line.endswith("\\") and not in_comment)
        if start is not None and not continued:
            m = EXPECT.search(comment)
            commands.append(Command(start, number, text.rstrip("\n"), int(m.group(1)) if m else None))
            text, start = "", None
        if not continued:
            comment = ""
    if start is not None:
        raise Failure(f"docs line {start}: command not finished at the end of its block (open quote or trailing \\)")
    return commands


# ---- the session script ---------------------------------------------------------------------

# Wraps curl: runs it with the docs' arguments, keeps its stdout clean (captures like
# HASH=$(curl ... | jq -r .hash) work), logs the status with the calling line, and fails (as
# curl --fail does) on an answer the docs do not expect, which ends the session (set -e).
PREAMBLE = r'''
set -eEu -o pipefail
__doc_log() { printf '%s\t%s\t%s\t%s\t%s\n' "$1" "$2" "$3" "$4" "$5" >> "$DOC_LOG"; }
__doc_out_file() {  # the file of a -o/--output argument, if any
  local prev=""
  for a in "$@"; do
    if [ "$prev" = "-o" ] || [ "$prev" = "--output" ]; then printf '%s' "$a"; return; fi
    prev=$a
  done
}
curl() {
  local line=${BASH_LINENO[0]} out err status rc=0 expected answer file
  out=$(mktemp) err=$(mktemp)
  command curl -sS -w '%{stderr}__DOC_STATUS__ %{http_code}\n' "$@" > "$out" 2> "$err" || rc=$?
  status=$(sed -n 's/.*__DOC_STATUS__ \([0-9]*\)$/\1/p' "$err" | tail -n 1)
  grep -v '__DOC_STATUS__' "$err" >&2 || true
  cat "$out"
  file=$(__doc_out_file "$@")
  if [ -n "$file" ] && [ -f "$file" ]; then answer=$(head -c 600 "$file" | base64 -w0); else answer=$(head -c 600 "$out" | base64 -w0); fi
  __doc_log curl "$line" "${status:-000}" "$rc" "$answer"
  rm -f "$out" "$err"
  expected=${DOC_EXPECT[$line]:-}
  if [ -n "$expected" ]; then [ "$status" = "$expected" ] || return 22
  else [ "$rc" = 0 ] && [ "${status:-0}" -ge 200 ] && [ "${status:-0}" -lt 300 ] || return 22
  fi
}
trap '__doc_log error "$LINENO" "$?" 0 "$(printf %s "$BASH_COMMAND" | base64 -w0)"' ERR
'''


def build_script(blocks, url, log, done):
    """The session as one bash script, and for each of its lines the docs line it came from. The
    docs' S=URL becomes the coordinator's url; the test's own files are the script's variables,
    not the environment's."""
    lines, origin = [], []

    def emit(text, doc_line=None):
        for t in text.split("\n"):
            lines.append(t)
            origin.append(doc_line)

    sets_s = [(b, i) for b in blocks for i, text in enumerate(b.lines) if SETS_S.match(text)]
    if not sets_s:
        raise Failure(f"{DOCS_NAME} never sets S=URL in a ```sh block: its examples' $S would be unset")
    block, i = sets_s[0]
    block.lines[i] = SETS_S.sub(lambda m: m.group(1) + url, block.lines[i])
    emit(f"DOC_LOG={shlex.quote(str(log))} DOC_DONE={shlex.quote(str(done))}")
    emit(PREAMBLE.strip("\n"))
    expect_at = len(lines)
    emit("")  # the DOC_EXPECT table goes here once every line's place is known
    for block in blocks:
        emit(f"# {DOCS_NAME} line {block.line}")
        first = len(lines) + 1
        for offset, text in enumerate(block.lines):
            emit(text, block.line + offset)
        block.script_first = first
    emit("printf 'session complete\\n' > \"$DOC_DONE\"")
    expects = []
    for block in blocks:
        for cmd in block.commands:
            if cmd.expect is not None:
                for doc_line in range(cmd.first, cmd.last + 1):
                    expects.append(f"[{block.script_first + doc_line - block.line}]={cmd.expect}")
    lines[expect_at] = "declare -A DOC_EXPECT=(" + " ".join(expects) + ")"
    return "\n".join(lines) + "\n", origin


# ---- the coordinator ------------------------------------------------------------------------

class Coordinator:
    def __init__(self, args, folder):
        self.folder = folder
        self.log_path = folder.parent / "server.log"
        port_file = folder.parent / "port"
        self.log = open(self.log_path, "wb")
        self.proc = subprocess.Popen(
            [args.server, "--listen", "127.0.0.1:0", "--port-file", str(port_file), "--data-dir",
             str(folder.parent / "farm-data"), "--local-workers", "1", "--local-worker-threads", "1",
             "--worker-binary", args.worker, "--client-token-file", "client.token",
             "--worker-token-file", "worker.token"],
            cwd=folder, stdout=self.log, stderr=subprocess.STDOUT, start_new_session=True)
        end = time.monotonic() + 30
        self.url = None
        while time.monotonic() < end and self.url is None:
            if self.proc.poll() is not None:
                raise Failure(f"tessera-server exited with {self.proc.returncode}:\n{self.log_tail()}")
            text = port_file.read_text().strip() if port_file.exists() else ""
            if text:
                self.url = f"http://127.0.0.1:{int(text)}"
            time.sleep(0.05)
        if self.url is None:
            raise Failure("tessera-server wrote no port")

    def get(self, path):
        req = urllib.request.Request(self.url + path, headers={"Authorization": f"Bearer {CLIENT_TOKEN}"})
        with urllib.request.urlopen(req, timeout=10) as res:
            return res.read()

    def stop(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                pass
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)  # a local worker left behind
        except ProcessLookupError:
            pass
        self.proc.wait()
        self.log.close()

    def log_tail(self, lines=30):
        try:
            return "\n".join(self.log_path.read_text(errors="replace").splitlines()[-lines:])
        except OSError:
            return "(no log)"


# ---- checking the session -------------------------------------------------------------------

def command_at(blocks, doc_line):
    for block in blocks:
        for cmd in block.commands:
            if cmd.first <= doc_line <= cmd.last:
                return cmd
    return None


def read_log(path):
    records = []
    if path.exists():
        for row in path.read_text().splitlines():
            kind, line, a, b, data = (row.split("\t") + [""] * 5)[:5]
            records.append((kind, int(line), a, b, base64.b64decode(data).decode(errors="replace")))
    return records


def describe(cmd, doc_line):
    shown = cmd.text if cmd else "(not a docs line)"
    return f"{DOCS_NAME} line {cmd.first if cmd else doc_line}:\n    {shown.replace(chr(10), chr(10) + '    ')}"


def check_session(blocks, origin, records):
    """Problems in the session's log: unexpected answers, failed commands, curl examples not run."""
    problems, ran = [], set()
    for kind, script_line, a, b, data in records:
        doc_line = origin[script_line - 1] if 0 < script_line <= len(origin) else None
        cmd = command_at(blocks, doc_line) if doc_line else None
        if kind == "curl":
            ran.add(cmd.first if cmd else None)
            expected = cmd.expect if cmd else None
            good = int(a) == expected if expected else 200 <= int(a) < 300 and b == "0"
            if not good:
                want = f"expected {expected}" if expected else "expected 2xx"
                problems.append(f"{describe(cmd, doc_line)}\n  answered HTTP {a} (curl exit {b}; {want}): {data.strip()[:600]}")
        elif kind == "error" and (cmd is None or "curl" not in cmd.text):
            problems.append(f"{describe(cmd, doc_line)}\n  failed with exit status {a}: {data}")
    for block in blocks:
        for cmd in block.commands:
            if re.search(r"(^|[\s($|])curl\s", cmd.text) and cmd.first not in ran:
                problems.append(f"{describe(cmd, cmd.first)}\n  never ran")
    return problems


def run(args, tmp):
    global DOCS_NAME
    docs = Path(args.docs)
    DOCS_NAME = os.path.relpath(docs.resolve(), REPO) if docs.resolve().is_relative_to(REPO) else str(docs)
    blocks = sh_blocks(docs.read_text())
    if not blocks:
        raise Failure(f"{docs} has no ```sh blocks")
    folder = tmp / "work"  # a stand-in for the repository's root: ../shared sits beside it
    folder.mkdir()
    (tmp / "shared").symlink_to(Path(args.shared).resolve())
    for part, binary in (("server", args.server), ("worker", args.worker), ("cli", args.cli)):
        (folder / "build" / part).mkdir(parents=True)
        (folder / "build" / part / Path(binary).name).symlink_to(binary)
    (folder / "client.token").write_text(CLIENT_TOKEN + "\n")
    (folder / "worker.token").write_text(WORKER_TOKEN + "\n")
    (tmp / "home").mkdir()
    log, done = tmp / "session.log", tmp / "session.done"

    server = Coordinator(args, folder)
    try:
        script, origin = build_script(blocks, server.url, log, done)
        (tmp / "session.sh").write_text(script)
        env = {"PATH": SYSTEM_PATH, "HOME": str(tmp / "home")}  # env -i: what the docs set, nothing else
        t0 = time.monotonic()
        bash = shutil.which("bash", path=SYSTEM_PATH)
        session = subprocess.Popen([bash, str(tmp / "session.sh")], cwd=folder, env=env, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, start_new_session=True)
        try:
            output, _ = session.communicate(timeout=args.timeout)
        except subprocess.TimeoutExpired:
            os.killpg(session.pid, signal.SIGKILL)
            output, _ = session.communicate()
        seconds = time.monotonic() - t0
        records = read_log(log)
        problems = check_session(blocks, origin, records)
        if not done.exists():
            last = records[-1] if records else None
            where = origin[last[1] - 1] if last and 0 < last[1] <= len(origin) else None
            cmd = command_at(blocks, where) if where else None
            problems.append(f"the session stopped (exit {session.returncode}, {seconds:.0f} s) after "
                            f"{describe(cmd, where) if last else 'no curl call'}")
        jobs = server.get("/api/v1/jobs").decode()
        if '"state": "done"' not in jobs:
            problems.append(f"no job of the session finished: {jobs[:800]}")
        if problems:
            tail = output.decode(errors="replace").splitlines()[-25:]
            raise Failure("\n".join(problems) + "\n--- session output (tail) ---\n" + "\n".join(tail) +
                          f"\n--- server log (tail) ---\n{server.log_tail()}")
        calls = sum(1 for r in records if r[0] == "curl")
        expected = sum(1 for b in blocks for c in b.commands if c.expect)
        for kind, line, status, _, _ in records:
            cmd = command_at(blocks, origin[line - 1]) if kind == "curl" and origin[line - 1] else None
            if cmd and cmd.expect:
                print(f"{DOCS_NAME} line {cmd.first}: HTTP {status}, as its '# expect: {cmd.expect}' says")
        print(f"{DOCS_NAME}: {len(blocks)} sh blocks, {sum(len(b.commands) for b in blocks)} commands, "
              f"{calls} curl calls ({expected} commands expect an error status), all as documented, in {seconds:.1f} s")
    finally:
        server.stop()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", required=True, help="the tessera-server binary")
    parser.add_argument("--worker", required=True, help="the tessera-worker binary")
    parser.add_argument("--cli", required=True, help="the tessera binary")
    parser.add_argument("--docs", default=str(REPO / "docs" / "api.md"))
    parser.add_argument("--shared", default=str(REPO.parent / "shared"), help="the shared/ folder beside the checkout")
    parser.add_argument("--timeout", type=float, default=240, help="seconds the whole session may take")
    args = parser.parse_args()
    for name in ("server", "worker", "cli"):  # the session runs elsewhere
        setattr(args, name, str(Path(getattr(args, name)).resolve()))

    ci = os.environ.get("CI") == "true"
    missing = [f"{t} in {SYSTEM_PATH} (scripts/install-deps.sh installs it)" for t in TOOLS
               if shutil.which(t, path=SYSTEM_PATH) is None]
    for name in ("tessera-server", "tessera-worker", "tessera"):
        installed = shutil.which(name, path=SYSTEM_PATH)
        if installed:
            print(f"note: {installed} is installed, so the docs could lack their PATH line unnoticed")
    if not Path(args.shared, "scenes", "cornell-box", "scene.xml").is_file():
        missing.append(f"{args.shared}/scenes/cornell-box (../shared beside the checkout)")
    if missing:
        print(f"{'FAIL' if ci else 'SKIP'}: missing {', '.join(missing)}")
        return 1 if ci else SKIP
    return run_in_temp_dir("tessera-docs-", run, args)


if __name__ == "__main__":
    sys.exit(main())
