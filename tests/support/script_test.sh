# What the shell test scripts share (sourced): skip (exit 77; a failure under CI=true) and fail.
skip() {
  if [ "${CI:-}" = "true" ]; then
    echo "FAIL: $* (CI=true: a missing tool is a failure)"
    exit 1
  fi
  echo "SKIP: $*"
  exit 77
}
fail() {
  echo "FAIL: $*"
  exit 1
}
