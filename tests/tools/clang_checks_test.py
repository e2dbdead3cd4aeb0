#!/usr/bin/env python3
"""The clang stage (scripts/clang-checks.sh) finds what it is there to find: an access to guarded
state without its lock, and a function over 80 lines; and passes the corrected form.

usage: clang_checks_test.py --build BUILD_DIR        (77: no clang-tidy, outside CI only)
"""
import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "support"))
from script_test import SKIP  # noqa: E402

FIXTURES = Path("tests/tools/clang_fixtures")
CASES = [  # file, must pass, what its findings must say
    ("unguarded_access.cpp", False, "requires holding mutex 'mu'"),
    ("guarded_access.cpp", True, ""),
    ("long_function.cpp", False, "exceeds recommended size"),
]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    args = ap.parse_args()
    if not shutil.which("clang-tidy"):
        print("clang-tidy is missing (scripts/install-deps.sh installs it)")
        return 1 if os.environ.get("CI") == "true" else SKIP
    failures = 0
    for name, clean, finding in CASES:
        run = subprocess.run(["bash", "scripts/clang-checks.sh", args.build, str(FIXTURES / name)],
                             capture_output=True, text=True, timeout=240)
        out = run.stdout + run.stderr
        ok = (run.returncode == 0) if clean else (run.returncode == 1 and finding in out)
        print(f"{'ok' if ok else 'FAIL'}  {name}: exit {run.returncode}" + ("" if ok else "\n" + out))
        failures += not ok
    print("PASS" if failures == 0 else f"FAIL: {failures} case(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
