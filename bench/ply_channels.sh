#!/usr/bin/env bash
# PLY reading with and without attributes: a >= 10-million-triangle binary PLY (meshstream-gen's
# surface, positions only) and the same PLY with a uchar colour per vertex, read by the
# commands that use positions only (convert to STL, info, decimate) and converted PLY -> PLY and
# PLY -> GLB (which keep the colour). With a second binary given, each positions-only run is timed for
# both in the same invocation (alternating), so "before" and "after" share the machine's load.
# Reports the median of $RUNS (default 3) runs: wall time, CPU time (user + sys; the figure to
# compare on a busy machine) and peak RSS.
#
# Paths covered: the in-place read of a binary PLY's vertex block (a regular file), the copied
# table (the same file on stdin), ascii parsing (a 1 M-triangle ascii PLY).
#
# Usage: bench/ply_channels.sh [meshstream] [reference meshstream] [work dir (default: $TMPDIR or /tmp)]
# Needs GNU time (/usr/bin/time), python3 (to add the colours) and meshstream-gen next to meshstream.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
meshstream=${1:-$here/../build/tools/meshstream}
reference=${2:-}
gen=$(dirname "$meshstream")/meshstream-gen
work=$(mktemp -d "${3:-${TMPDIR:-/tmp}}/ply_channels.XXXXXX")
trap 'rm -rf "$work"' EXIT
[ -x "$meshstream" ] || { echo "no meshstream binary at $meshstream" >&2; exit 2; }
[ -x "$gen" ] || { echo "no meshstream-gen next to $meshstream" >&2; exit 2; }
[ -z "$reference" ] || [ -x "$reference" ] || { echo "no reference binary at $reference" >&2; exit 2; }
command -v /usr/bin/time >/dev/null || { echo "needs GNU time (/usr/bin/time)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "needs python3" >&2; exit 2; }

"$gen" -q -n 10200000 "$work/big.stl"
"$meshstream" -q convert "$work/big.stl" "$work/big.ply"
rm "$work/big.stl"
# The same PLY with "property uchar red/green/blue" after z, colours from the coordinates.
python3 - "$work/big.ply" "$work/colour.ply" <<'EOF'
import sys
src, dst = sys.argv[1], sys.argv[2]
data = open(src, "rb").read()
end = data.index(b"end_header\n") + 11
header = data[:end].decode()
vertices = int(header.split("element vertex ")[1].split()[0])
header = header.replace("property float z\n", "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n")
with open(dst, "wb") as out:
    out.write(header.encode())
    block = memoryview(data)[end:end + 12 * vertices]
    step = 1 << 20
    for first in range(0, vertices, step):
        part = bytearray()
        for i in range(first, min(vertices, first + step)):
            xyz = block[12 * i:12 * i + 12]
            part += xyz
            part += bytes((xyz[1], xyz[5], xyz[9]))
        out.write(part)
    out.write(memoryview(data)[end + 12 * vertices:])
EOF
"$meshstream" -q convert "$work/big.ply" "$work/mid.stl"  # for the ascii PLY: the first 1 M triangles
head -c $((84 + 50 * 1000000)) "$work/mid.stl" > "$work/cut.stl"
printf '\x40\x42\x0f\x00' | dd of="$work/cut.stl" bs=1 seek=80 conv=notrunc status=none  # count = 1000000
"$meshstream" -q convert "$work/cut.stl" "$work/mid.ascii.ply" --to ply-ascii
rm "$work/mid.stl" "$work/cut.stl"
triangles=$("$meshstream" -q info --json "$work/big.ply" | sed -n 's/.*"triangles": \([0-9]*\).*/\1/p')
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
echo "input: $triangles triangles; PLY $(( $(stat -c %s "$work/big.ply") >> 20 )) MB, with colour $(( $(stat -c %s "$work/colour.ply") >> 20 )) MB"
cat "$work/big.ply" "$work/colour.ply" > /dev/null  # warm the page cache

# once BINARY LABEL CMD...: one run of CMD with "$M" standing for BINARY; appends
# "label wall cpu peak_kb" to $work/runs.
once() {
    local binary=$1 label=$2
    shift 2
    M=$binary /usr/bin/time -f "%e %U %S %M" -o "$work/time" sh -c "$*" > /dev/null
    read -r secs user sys peak_kb < <(tail -1 "$work/time")
    echo "$label $secs $(awk -v u="$user" -v s="$sys" 'BEGIN { print u + s }') $peak_kb" >> "$work/runs"
    rm -f "$work"/out.*
}

# timed LABEL CMD: $RUNS runs of CMD with the binary under test and, when given, the reference,
# alternating; prints each one's median.
timed() {
    local label=$1 cmd=$2 i
    : > "$work/runs"
    for i in $(seq "${RUNS:-3}"); do
        once "$meshstream" after "$cmd"
        [ -z "$reference" ] || once "$reference" before "$cmd"
    done
    for who in before after; do
        { grep "^$who " "$work/runs" || true; } | sort -k2 -n | awk -v l="$label" -v w="$who" '{ a[NR] = $0 } END {
            if (NR == 0) exit; split(a[int((NR + 1) / 2)], r, " ");
            printf "%-44s %-6s %7.2f s wall %7.2f s CPU  peak RSS %5d MB\n", l, w, r[2], r[3], r[4] / 1024 }'
    done
}

w=$work
timed "PLY -> STL (vertex block read in place)" "\$M -q convert $w/big.ply $w/out.stl"
timed "PLY on stdin -> STL (table copied)" "cat $w/big.ply | \$M -q convert - $w/out.stl --from ply"
timed "ascii PLY 1 M -> STL" "\$M -q convert $w/mid.ascii.ply $w/out.stl"
timed "info PLY" "\$M -q info $w/big.ply"
timed "info coloured PLY" "\$M -q info $w/colour.ply"
timed "decimate -r 0.1 PLY" "\$M -q decimate -r 0.1 $w/big.ply $w/out.stl"
timed "decimate -r 0.1 coloured PLY" "\$M -q decimate -r 0.1 $w/colour.ply $w/out.stl"
reference=""  # PLY -> PLY with colour: the channel's cost, against the positions-only run
timed "PLY -> PLY" "\$M -q convert $w/big.ply $w/out.ply"
timed "coloured PLY -> PLY (colour kept)" "\$M -q convert $w/colour.ply $w/out.ply"
timed "PLY -> GLB" "\$M -q convert --memory 8G --compress none $w/big.ply $w/out.glb"
timed "coloured PLY -> GLB (COLOR_0 kept)" "\$M -q convert --memory 8G --compress none $w/colour.ply $w/out.glb"
