#!/usr/bin/env bash
# What OBJ's channels cost: meshstream-gen's marching-cubes surface (2 M triangles unless given)
# written as OBJ three ways: positions only (the reference), with a vt and a vn per vertex
# ("smooth": one corner per position), and with one vn per face ("flat": every corner of a
# position is a different vertex, the worst case for the corner-id table). Each is converted
# OBJ -> OBJ (every channel kept) and OBJ -> STL (none kept), at the default --memory and at
# 32M; reports the median wall and CPU time of 3 runs and the largest peak RSS (GNU time's
# %M), and checks that every output holds the input's triangle count.
#
# Usage: bench/obj_channels.sh [path/to/meshstream] [triangles] [work dir (default: $TMPDIR or /tmp)]
# Needs GNU time (/usr/bin/time, Debian package `time`) and meshstream-gen next to meshstream.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
meshstream=${1:-$here/../build/tools/meshstream}
want=${2:-2000000}
gen=$(dirname "$meshstream")/meshstream-gen
work=$(mktemp -d "${3:-${TMPDIR:-/tmp}}/obj_channels.XXXXXX")
trap 'rm -rf "$work"' EXIT
[ -x "$meshstream" ] || { echo "no meshstream binary at $meshstream" >&2; exit 2; }
[ -x "$gen" ] || { echo "no meshstream-gen next to $meshstream" >&2; exit 2; }
command -v /usr/bin/time >/dev/null || { echo "needs GNU time (/usr/bin/time): apt-get install time" >&2; exit 2; }

count() { "$meshstream" -q info --json "$1" | sed -n 's/.*"triangles": \([0-9]*\).*/\1/p'; }

"$gen" -q -n "$want" "$work/mesh.stl"
"$meshstream" -q convert "$work/mesh.stl" "$work/plain.obj"
triangles=$(count "$work/plain.obj")
# smooth: vertex i gets vt i and vn i (texture coordinates from x, y; the normal from the
# position's direction); flat: face f gets vn f, its corners v//f.
awk '/^v / { print; printf "vt %.6f %.6f\n", $2 - int($2), $3 - int($3);
             l = sqrt($2 * $2 + $3 * $3 + $4 * $4) + 1e-9; printf "vn %.6f %.6f %.6f\n", $2 / l, $3 / l, $4 / l; next }
     /^f / { printf "f %d/%d/%d %d/%d/%d %d/%d/%d\n", $2, $2, $2, $3, $3, $3, $4, $4, $4; next }
     { print }' "$work/plain.obj" > "$work/smooth.obj"
awk '/^f / { f++; printf "vn 0 0 1\nf %d//%d %d//%d %d//%d\n", $2, f, $3, f, $4, f; next }
     { print }' "$work/plain.obj" > "$work/flat.obj"
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
for f in plain smooth flat; do
    echo "input $f.obj: $triangles triangles, $(( $(stat -c %s "$work/$f.obj") >> 20 )) MB"
    cat "$work/$f.obj" > /dev/null  # warm the page cache
done

# run LABEL OUT CMD...: 3 timed runs; prints the median wall and CPU (user + sys) time and
# the largest peak RSS; checks the output's triangle count.
status=0
run() {
    local label=$1 out=$2
    shift 2
    : > "$work/times"
    for _ in 1 2 3; do
        rm -f "$out"
        /usr/bin/time -f "%e %U %S %M" -o "$work/time" "$@"
        tail -1 "$work/time" >> "$work/times"
    done
    local wall cpu peak
    wall=$(cut -d' ' -f1 "$work/times" | sort -g | sed -n 2p)
    cpu=$(awk '{ print $2 + $3 }' "$work/times" | sort -g | sed -n 2p)
    peak=$(cut -d' ' -f4 "$work/times" | sort -g | tail -1)
    awk -v l="$label" -v s="$wall" -v c="$cpu" -v p="$peak" -v n="$triangles" \
        'BEGIN { printf "%-34s %6.2f s wall (%5.2f s CPU)  %5.2f M triangles/s  peak RSS %4d MB\n", l, s, c, n / s / 1e6, p / 1024 }'
    local got
    got=$(count "$out")
    if [ "$got" != "$triangles" ]; then
        echo "  MISMATCH: $out holds $got triangles, not $triangles" >&2
        status=1
    fi
}

for memory in 256M 32M; do
    for f in plain smooth flat; do
        run "$f OBJ -> OBJ  --memory $memory" "$work/out.obj" \
            "$meshstream" -q convert --memory "$memory" "$work/$f.obj" "$work/out.obj"
    done
    run "smooth OBJ -> STL  --memory $memory" "$work/out.stl" \
        "$meshstream" -q convert --memory "$memory" "$work/smooth.obj" "$work/out.stl"
done
exit $status
