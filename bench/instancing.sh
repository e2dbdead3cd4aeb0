#!/usr/bin/env bash
# Instancing at scale (docs/performance.md, "Instancing"): scripts/gen_forest.py's forest of
# COUNT instances of one 100,398-triangle tree, rendered by `tessera render` at 320x180, 4 spp,
# 2 threads; prints the stored and instanced triangles, parse, load and BVH build seconds, the
# BVH and mesh bytes the CLI reports, and the process's peak resident memory (GNU time).
#
# Usage: bench/instancing.sh BUILD_DIR     Environment: IN_COUNTS="1000 10000 100000"
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: bench/instancing.sh BUILD_DIR" >&2; exit 2; }
cli=$(realpath "$1")/cli/tessera
cd "$(dirname "$0")/.."
[ -x "$cli" ] || { echo "instancing.sh: no tessera binary at $cli" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "instancing.sh: needs GNU time (/usr/bin/time, Debian package time)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

echo "| instances | instanced triangles | parse (s) | load (s) | BVH build (s) | BVH (MB) | meshes (MB) | peak memory (MB) |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
for count in ${IN_COUNTS:-1000 10000 100000}; do
  python3 scripts/gen_forest.py --out "$tmp/forest" --count "$count" > /dev/null
  (cd "$tmp/forest" && /usr/bin/time -f "peak %M" "$cli" render scene.xml -o "$tmp/out.exr" --spp 4 --width 320 \
      --height 180 --threads 2 -q) > "$tmp/log" 2>&1
  tris=$(sed -n 's/.*triangles (\([0-9]*\) with instances).*/\1/p' "$tmp/log")
  bvh=$(sed -n 's/.*; BVH \([0-9.]*\) MB$/\1/p' "$tmp/log")
  meshes=$(sed -n 's/^memory: .*meshes \([0-9.]*\) MB.*/\1/p' "$tmp/log")
  read -r parse load build < <(sed -n 's/^times: parse \([0-9.]*\) s, load \([0-9.]*\) s (BVH build \([0-9.]*\) s).*/\1 \2 \3/p' "$tmp/log")
  peak=$(sed -n 's/^peak \([0-9]*\)$/\1/p' "$tmp/log")
  echo "| $count | $tris | $parse | $load | $build | $bvh | $meshes | $((peak / 1024)) |"
done
