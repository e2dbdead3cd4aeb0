#!/usr/bin/env python3
"""Every long flag of every program the build makes is documented: named in README.md or a
Markdown page under docs/.

The programs are the build's executables named tessera* (tessera-server, tessera-worker, tessera,
tessera-farm-load, ...), found in BUILD_DIR and its folders two levels down, as
`find BUILD_DIR -maxdepth 3 -type f -executable -name 'tessera*'` finds them. Each one's --help is
read, and each subcommand's (`tessera submit --help`, `tessera bench rays --help`, ...); a flag is
documented when `--flag` appears as a whole word (not as the start of a longer flag) in the docs'
text. --help itself is every program's and is not asked for. A flag added without a word in the
docs fails the test, which names the program, the flag and its help line.

usage: flags_docs_test.py --build BUILD_DIR [--root REPO]
Exit status: 0 passed, 1 failed.
"""
import argparse
import os
import re
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
OPTION = re.compile(r"^  (-\S+)")            # CLI11: "  -o,--output TEXT ...", "  --no-speculation{false}"
SUBCOMMAND = re.compile(r"^  ([a-z][\w-]*)\s")
SECTION = re.compile(r"^\S.*:$")              # "Options:", "Security:", "Subcommands:", "Positionals:"
LONG = re.compile(r"--[A-Za-z0-9][\w-]*")
IGNORED = {"--help"}


def programs(build):
    """The build's tessera* executables, at most three levels down (CMake's own files aside)."""
    found = []
    for root, dirs, files in os.walk(build):
        depth = len(Path(root).relative_to(build).parts)
        dirs[:] = [d for d in dirs if d != "CMakeFiles" and depth < 2]
        for name in files:
            path = Path(root, name)
            if name.startswith("tessera") and os.access(path, os.X_OK) and path.is_file():
                found.append(path)
    return sorted(found)


def parse_help(text):
    """The long flags (with their help line) and the subcommands of one --help text."""
    flags, subcommands, section = {}, [], ""
    for line in text.splitlines():
        if SECTION.match(line):
            section = line
            continue
        if section.startswith("Subcommands"):
            m = SUBCOMMAND.match(line)
            if m:
                subcommands.append(m.group(1))
            continue
        m = OPTION.match(line)
        if m:
            for flag in LONG.findall(m.group(1)):
                flags.setdefault(flag, line.strip())
    return flags, subcommands


def read_help(command):
    out = subprocess.run(command + ["--help"], capture_output=True, text=True, timeout=30)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} --help exited {out.returncode}: {out.stderr.strip()}")
    return out.stdout


def walk(command, name, found):
    """found[name] = flags, for the program or subcommand and every subcommand below it."""
    flags, subcommands = parse_help(read_help(command))
    found[name] = flags
    for sub in subcommands:
        walk(command + [sub], f"{name} {sub}", found)


def documented_text(root):
    pages = [root / "README.md"] + sorted((root / "docs").rglob("*.md"))
    return {p.relative_to(root).as_posix(): p.read_text(errors="replace") for p in pages if p.is_file()}


def is_named(flag, text):
    return re.search(r"(?<![\w-])" + re.escape(flag) + r"(?![\w-])", text) is not None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", required=True, help="the build folder")
    parser.add_argument("--root", default=str(REPO), help="the repository (README.md, docs/)")
    args = parser.parse_args()
    build, root = Path(args.build).resolve(), Path(args.root).resolve()

    bins = programs(build)
    names = {p.name for p in bins}
    lacking = {"tessera-server", "tessera-worker", "tessera"} - names
    if lacking:
        print(f"FAIL: {build} has no {', '.join(sorted(lacking))} (build them first)")
        return 1
    found = {}
    for path in bins:
        walk([str(path)], path.name, found)
    pages = documented_text(root)
    text = "\n".join(pages.values())

    missing, total = [], 0
    for name, flags in found.items():
        for flag, help_line in flags.items():
            if flag in IGNORED:
                continue
            total += 1
            if not is_named(flag, text):
                missing.append(f"{name} {flag}: not in README.md or docs/*.md  ({help_line})")
    for m in missing:
        print(m)
    print(f"{len(bins)} programs ({', '.join(sorted(names))}), {len(found)} --help texts, {total} flags, "
          f"{len(missing)} undocumented; searched {len(pages)} pages")
    if total < 50:
        print("FAIL: too few flags parsed: has the --help format changed?")
        return 1
    print("FAIL" if missing else "PASS")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
