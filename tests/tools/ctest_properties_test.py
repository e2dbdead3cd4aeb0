#!/usr/bin/env python3
"""Every CTest entry of the build, each discovered GoogleTest case included, has a label and a
timeout, so that a run can be cut by label and no test can hang a run; and every GoogleTest binary
of the build has its cases discovered (a binary linked without its test files has none).

usage: ctest_properties_test.py BUILD_DIR
"""
import json
import subprocess
import sys
from pathlib import Path


def main():
    build = sys.argv[1]
    listed = subprocess.run(["ctest", "--test-dir", build, "--show-only=json-v1"], capture_output=True, text=True,
                            timeout=100)
    if listed.returncode != 0:
        print(listed.stderr)
        print("FAIL: ctest --show-only=json-v1 failed")
        return 1
    tests = json.loads(listed.stdout)["tests"]
    missing = []
    for t in tests:
        props = {p["name"]: p["value"] for p in t.get("properties", [])}
        lacks = [p for p in ("LABELS", "TIMEOUT") if not props.get(p)]
        if lacks:
            missing.append(f"{t['name']}: no {' or '.join(lacks)}")
    # The binaries gtest_discover_tests was asked to list: tests/NAME[1]_include.cmake.
    names = {t["name"] for t in tests}
    for include in sorted(Path(build, "tests").glob("*[[]1[]]_include.cmake")):
        binary = include.name[: -len("[1]_include.cmake")]
        if not Path(build, "tests", binary).exists():
            continue  # (not built in this build)
        if not any(n.startswith(binary + ".") for n in names):
            missing.append(f"{binary}: no test case discovered")
    for m in missing:
        print(m)
    print(f"{len(tests)} tests, {len(missing)} without a label or a timeout")
    if len(tests) < 100:
        print("FAIL: too few tests listed: the GoogleTest cases were not discovered")
        return 1
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
