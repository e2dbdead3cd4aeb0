# Shared by the scripts that time two builds of tessera against each other on the shared scenes
# (scene_load.sh, sample_cost.sh); sourced, not run. Sets `old`, `new`, `shared` and `tmp` (removed
# on exit) from the script's two arguments, the build directories, and checks that both binaries
# and every scene of the array `scenes` exist: a missing one is an error, never a skip.
#
# Usage: compare_builds_setup SCRIPT_NAME "$@"

compare_builds_setup() {
  local name=$1
  [ $# -eq 3 ] || { echo "usage: bench/$name OLD_BUILD_DIR NEW_BUILD_DIR" >&2; exit 2; }
  old=$2/cli/tessera
  new=$3/cli/tessera
  shared=../shared
  for t in "$old" "$new"; do [ -x "$t" ] || { echo "$name: no tessera binary at $t" >&2; exit 1; }; done
  for s in "${scenes[@]}"; do
    [ -f "$shared/scenes/$s/scene.xml" ] || { echo "$name: missing $shared/scenes/$s/scene.xml" >&2; exit 1; }
  done
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
}

# Median of the numbers on stdin, one per line.
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
