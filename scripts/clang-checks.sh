#!/usr/bin/env bash
# The clang stage: Clang's thread-safety analysis (core/mutex.h's annotations; any warning is an
# error) and a limit of 80 lines per function (clang-tidy's readability-function-size), on the
# coordinator and the command line, with the flags of BUILD_DIR's compile_commands.json.
# Usage: scripts/clang-checks.sh [BUILD_DIR] [FILE...]     (default: every .cpp of server/ and cli/)
# Exit 0: clean; 1: findings (printed with file and line); 2: no clang-tidy or compile database.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
command -v clang-tidy >/dev/null || { echo "clang-checks: clang-tidy is missing (scripts/install-deps.sh installs it)" >&2; exit 2; }
[ -f "$build/compile_commands.json" ] || { echo "clang-checks: no $build/compile_commands.json (configure with CMake first)" >&2; exit 2; }
if [ $# -eq 0 ]; then
  set -- server/main.cpp server/src/*.cpp cli/main.cpp cli/src/*.cpp
fi
config='{Checks: "-*,readability-function-size,clang-diagnostic-thread-safety*",
         WarningsAsErrors: "*",
         CheckOptions: [{key: readability-function-size.LineThreshold, value: 80}]}'
out=$(mktemp)
trap 'rm -f "$out"' EXIT
status=0
printf '%s\n' "$@" | xargs -P "$(nproc 2>/dev/null || echo 2)" -I{} \
  clang-tidy -p "$build" --quiet --config="$config" --extra-arg=-Wthread-safety --extra-arg=-Wno-unknown-warning-option {} \
  >"$out" 2>&1 || status=1
grep -E "(warning|error):" "$out" | sort -u || true
if [ $status -ne 0 ]; then
  echo "clang-checks: findings in $# file(s) (thread safety, or a function over 80 lines)" >&2
  exit 1
fi
echo "clang-checks: $# file(s) clean (thread-safety analysis, functions of at most 80 lines)"
