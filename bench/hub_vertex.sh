#!/usr/bin/env bash
# A vertex in many triangles: depth scanners write invalid points as (0,0,0), so one vertex
# ends up in thousands of triangles. Times `meshstream decimate -r 0.1` of a generated mesh
# with the vertices whose x ends in the digit 7 (one in ten, the same position wherever it is
# a corner) moved to the origin, against the same mesh untouched, in the same run
# (median of $RUNS runs, default 3). Reading used to walk the hub's whole corner list for every
# triangle at it: quadratic (300 k triangles: 27 s against 0.7 s untouched; now 0.34 s against
# 0.29 s).
#
# Usage: bench/hub_vertex.sh [path/to/build dir (default: ../build)] [triangles (default 300000)]
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
triangles=${2:-300000}
meshstream=$build/tools/meshstream
gen=$build/tools/meshstream-gen
[ -x "$meshstream" ] && [ -x "$gen" ] || { echo "no meshstream / meshstream-gen in $build/tools" >&2; exit 2; }
command -v /usr/bin/time >/dev/null || { echo "needs GNU time (/usr/bin/time)" >&2; exit 2; }
work=$(mktemp -d "${TMPDIR:-/tmp}/hub_vertex.XXXXXX")
trap 'rm -rf "$work"' EXIT

"$gen" -q -n "$triangles" "$work/clean.stl"
"$meshstream" -q convert "$work/clean.stl" - --to stl-ascii |
    awk '$1 == "vertex" && $2 ~ /7$/ { print "      vertex 0 0 0"; next } { print }' |
    "$meshstream" -q convert - "$work/hub.stl" --from stl-ascii --to stl 2>/dev/null  # degenerate ones are dropped

median_of() {
    local i
    for i in $(seq "${RUNS:-3}"); do
        /usr/bin/time -f "%e %M" -o "$work/time" "$meshstream" -q decimate "$1" "$work/out.stl" -r 0.1 2>/dev/null
        tail -1 "$work/time"
    done | sort -n | awk '{ a[NR] = $0 } END { print a[int((NR + 1) / 2)] }'
}

for input in clean hub; do
    read -r seconds kb < <(median_of "$work/$input.stl")
    printf '%-6s %s triangles: %6.2f s, peak RSS %d MB\n' "$input" "$triangles" "$seconds" $((kb / 1024))
done
