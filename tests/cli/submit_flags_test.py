#!/usr/bin/env python3
"""`tessera submit` takes every `tessera render` flag that can apply to a job on the farm.

Compares the two commands' `--help`: each flag of render must be a flag of submit, or be listed in
RENDER_ONLY below with the reason it cannot apply to a job. A listed flag that submit has after all,
or that render no longer has, is an error too, so the list stays true.

    python3 tests/cli/submit_flags_test.py TESSERA_BINARY
"""
import re
import subprocess
import sys

# Render flags that cannot apply to a job, each with the reason.
RENDER_ONLY = {
    "threads": "a job's units render on the workers, each with its own cores (tessera-worker --threads)",
    "strategy-images": "a debugging render per strategy, each an image of its own, on this machine",
}


def flags(tessera, command):
    """Every --long (and -D style) option of `tessera COMMAND --help`, without the dashes."""
    text = subprocess.run([tessera, command, "--help"], capture_output=True, text=True, check=True).stdout
    found = set()
    for m in re.finditer(r"^\s+(-[\w-]+(?:,\s*-[\w-]+)*)", text, re.M):
        names = [n.strip().lstrip("-") for n in m.group(1).split(",")]
        found.add(max(names, key=len))  # (-o,--output: "output")
    return found - {"help"}


def problems(tessera):
    render, submit = flags(tessera, "render"), flags(tessera, "submit")
    out = []
    if len(render) < 15:
        out.append(f"only {len(render)} flags found in `tessera render --help`: has its format changed?")
    for name in sorted(render - submit - set(RENDER_ONLY)):
        out.append(f"tessera render --{name} is missing from tessera submit (add it, or list why it cannot apply)")
    for name in sorted(set(RENDER_ONLY) & submit):
        out.append(f"--{name} is listed as render-only, but tessera submit takes it")
    for name in sorted(set(RENDER_ONLY) - render):
        out.append(f"--{name} is listed as render-only, but tessera render no longer takes it")
    return out


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    found = problems(sys.argv[1])
    for p in found:
        print("FAIL", p)
    print(f"{len(found)} problems")
    sys.exit(1 if found else 0)


if __name__ == "__main__":
    main()
