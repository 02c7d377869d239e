#!/usr/bin/env bash
# STL streaming throughput: times `meshstream convert` of a 10-million-triangle binary STL to
# binary STL against `cat FILE > OUT` (the STL issue's target: at most 3x cat, aim 1.5x; peak
# RSS under 64 MB), then ASCII -> binary and binary -> ASCII on a 1-million-triangle file.
# The input is fixtures/bunny_from_draco.bin.stl's body repeated (real floats, no generator).
# Each timing is the median of $RUNS (default 5) runs; use a quiet machine, the outputs go to the work dir.
#
# Usage: bench/stl_convert.sh [path/to/meshstream] [work dir (default: $TMPDIR or /tmp)]
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
meshstream=${1:-$here/../build/tools/meshstream}
work=$(mktemp -d "${2:-${TMPDIR:-/tmp}}/stl_convert.XXXXXX")
trap 'rm -rf "$work"' EXIT
bunny=$here/../fixtures/bunny_from_draco.bin.stl
[ -x "$meshstream" ] || { echo "no meshstream binary at $meshstream" >&2; exit 2; }
command -v /usr/bin/time >/dev/null || { echo "needs GNU time (/usr/bin/time)" >&2; exit 2; }

# make_stl COPIES OUT: the bunny's 69451 facets repeated COPIES times, count patched in.
make_stl() {
    local copies=$1 out=$2 n
    n=$((69451 * copies))
    head -c 80 "$bunny" > "$out"
    printf "$(printf '\\x%02x\\x%02x\\x%02x\\x%02x' $((n & 255)) $((n >> 8 & 255)) $((n >> 16 & 255)) $((n >> 24 & 255)))" >> "$out"
    tail -c +85 "$bunny" > "$work/body"
    for _ in $(seq "$copies"); do cat "$work/body"; done >> "$out"
    rm "$work/body"
}

# median_of RUNS CMD...: prints "seconds peak_kb" of the median run (by time) of $RUNS runs
# (default 5); the cat reference runs in the same invocation, just before.
median_of() {
    local i
    for i in $(seq "${RUNS:-5}"); do
        rm -f "$work"/out.*
        /usr/bin/time -f "%e %M" -o "$work/time" "$@" > /dev/null
        tail -1 "$work/time"
    done | sort -n | awk '{ a[NR] = $0 } END { print a[int((NR + 1) / 2)] }'
}

make_stl 144 "$work/big.stl"  # 10,000,944 triangles, 500 MB
cat "$work/big.stl" > /dev/null  # warm the page cache
cat_run=$(median_of sh -c "cat '$work/big.stl' > '$work/out.cat'")
bin_run=$(median_of "$meshstream" -q convert "$work/big.stl" "$work/out.stl")
awk -v c="$cat_run" -v m="$bin_run" 'BEGIN {
    split(c, a, " "); split(m, b, " ");
    printf "binary->binary 10M triangles: cat %.2f s, meshstream %.2f s (%.2fx cat), peak RSS %.1f MB\n",
           a[1], b[1], b[1] / a[1], b[2] / 1024 }'
rm -f "$work/big.stl" "$work"/out.*

make_stl 14 "$work/mid.stl"  # 972,314 triangles
"$meshstream" -q convert "$work/mid.stl" "$work/mid.ascii.stl" --to stl-ascii
to_ascii=$(median_of "$meshstream" -q convert "$work/mid.stl" "$work/out.ascii.stl" --to stl-ascii)
from_ascii=$(median_of "$meshstream" -q convert "$work/mid.ascii.stl" "$work/out.stl")
echo "binary->ascii 972k triangles: ${to_ascii% *} s, peak RSS $(( ${to_ascii#* } / 1024 )) MB"
echo "ascii->binary 972k triangles ($(( $(stat -c %s "$work/mid.ascii.stl") >> 20 )) MB of text): ${from_ascii% *} s, peak RSS $(( ${from_ascii#* } / 1024 )) MB"
