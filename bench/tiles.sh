#!/usr/bin/env bash
# `meshstream tiles` against `meshstream decimate -r 0.01` on the same generated mesh with the same
# threads (docs/tiles.md; the figures in docs/results.md): the median wall time and peak memory
# of $RUNS (default 3) runs each, a tiles run just before its decimate run, and the tileset's
# bytes against its leaves' (from the last tiles run's --json).
#
# Usage: bench/tiles.sh [N triangles (default 10000000)] [threads (default: every core)]
#                       [build dir (default build)] [work dir]
# MESH=FILE: tile FILE (a mesh `meshstream-gen -n N --color` wrote before) instead of generating one.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
n=${1:-10000000}
threads=${2:-$(nproc)}
build=$(cd "${3:-$here/../build}" && pwd)
work=$(mktemp -d "${4:-${TMPDIR:-/tmp}}/tiles_bench.XXXXXX")
trap 'rm -rf "$work"' EXIT
MEASURE_DIR=$work
meshstream=$build/tools/meshstream
gen=$build/tools/meshstream-gen
[ -x "$meshstream" ] && [ -x "$gen" ] || die "no meshstream or meshstream-gen in $build/tools"

echo "# bench/tiles.sh: N = $n triangles with colours${MESH:+ ($MESH)}, --threads $threads, $(nproc) cores, load $(load), commit $(git -C "$here" rev-parse --short HEAD)"
mesh=${MESH:-$work/mesh.ply}
[ -n "${MESH:-}" ] || "$gen" -q -n "$n" --color "$mesh"
cat "$mesh" >/dev/null  # the page cache holds it for every run

rows=$work/rows
for i in $(seq "${RUNS:-3}"); do
  rm -rf "$work/tiles"
  echo "tiles $(measure "$meshstream" -q tiles "$mesh" "$work/tiles" --threads "$threads" --json)" >> "$rows"
  cp "$work/cmd.out" "$work/sizes.json"
  echo "decimate $(measure "$meshstream" -q decimate "$mesh" "$work/d.glb" -r 0.01 --threads "$threads")" >> "$rows"
done
python3 - "$rows" "$work/sizes.json" <<'PY'
import json, statistics, sys
rows = [line.split() for line in open(sys.argv[1])]
for r in rows:
    print(f"  run: {r[0]:<10} {float(r[1]):8.2f} s {int(r[3]) / 1024:6.0f} MiB")
med = {}
for tool in ("tiles", "decimate"):
    mine = [r for r in rows if r[0] == tool]
    med[tool] = (statistics.median(float(r[1]) for r in mine), statistics.median(int(r[3]) for r in mine) / 1024)
for tool, (wall, rss) in med.items():
    print(f"{tool:<10} {wall:8.2f} s {rss:8.0f} MiB")
print(f"tiles / decimate: {med['tiles'][0] / med['decimate'][0]:.2f}x time")
t = json.load(open(sys.argv[2]))["tiles"]
print(f"tileset {t['bytes']} bytes, leaves {t['leaf_bytes']} bytes: {t['bytes'] / t['leaf_bytes']:.2f}x")
for l in t["levels"]:
    print(f"  depth {l['depth']}: {l['tiles']} tiles ({l['leaves']} leaves), {l['triangles']} triangles, "
          f"{l['bytes']} bytes, error {l['min_error']:.4g}..{l['max_error']:.4g}")
PY
echo "# load after: $(load)"
