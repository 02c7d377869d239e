#!/usr/bin/env bash
# Indexed conversion in bounded memory: a >= 10-million-triangle binary STL (meshstream-gen's
# marching-cubes surface, approximately sorted along z) converted to binary PLY and back, with
# --memory 64M (welding takes the external-sort path; the PLY reader maps the file's vertex
# block with resident-page accounting), with the default 256M, and with 2G (welding fully in
# the hash table). Reports wall time, throughput and peak RSS (GNU time's %M), checks that the
# STL coming back holds the same triangles, and fails if peak RSS at --memory 64M reaches
# 150 MB (the issue's bound).
#
# Usage: bench/convert_indexed.sh [path/to/meshstream] [work dir (default: $TMPDIR or /tmp)]
# Needs GNU time (/usr/bin/time, Debian package `time`) and meshstream-gen next to meshstream.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
meshstream=${1:-$here/../build/tools/meshstream}
gen=$(dirname "$meshstream")/meshstream-gen
work=$(mktemp -d "${2:-${TMPDIR:-/tmp}}/convert_indexed.XXXXXX")
trap 'rm -rf "$work"' EXIT
[ -x "$meshstream" ] || { echo "no meshstream binary at $meshstream" >&2; exit 2; }
[ -x "$gen" ] || { echo "no meshstream-gen next to $meshstream" >&2; exit 2; }
command -v /usr/bin/time >/dev/null || { echo "needs GNU time (/usr/bin/time): apt-get install time" >&2; exit 2; }

"$gen" -q -n 10200000 "$work/big.stl"
triangles=$("$meshstream" -q info --json "$work/big.stl" | sed -n 's/.*"triangles": \([0-9]*\).*/\1/p')
[ "$triangles" -ge 10000000 ] || { echo "generator made only $triangles triangles" >&2; exit 1; }
stl_mb=$(( $(stat -c %s "$work/big.stl") >> 20 ))
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
echo "input: $triangles triangles, binary STL $stl_mb MB ($work/big.stl)"
cat "$work/big.stl" > /dev/null  # warm the page cache

# run LABEL CMD...: one timed run; prints wall and CPU (user + sys) time, throughput against
# wall time, and peak RSS; sets $peak_mb. CPU time is the figure to compare on a busy machine.
run() {
    local label=$1
    shift
    /usr/bin/time -f "%e %U %S %M" -o "$work/time" "$@"
    read -r secs user sys peak_kb < <(tail -1 "$work/time")
    peak_mb=$(( peak_kb / 1024 ))
    awk -v l="$label" -v s="$secs" -v c="$user" -v k="$sys" -v n="$triangles" -v p="$peak_mb" \
        'BEGIN { printf "%-30s %6.2f s wall (%5.2f s CPU)  %5.2f M triangles/s  peak RSS %4d MB\n", l, s, c + k, n / s / 1e6, p }'
}

status=0
for memory in 64M 256M 2G; do
    run "STL -> PLY  --memory $memory" "$meshstream" -q convert --memory "$memory" "$work/big.stl" "$work/big.ply"
    to_ply_peak=$peak_mb
    run "PLY -> STL  --memory $memory" "$meshstream" -q convert --memory "$memory" "$work/big.ply" "$work/back.stl"
    from_ply_peak=$peak_mb
    # Same triangles in the same order: the facet bodies match (normals are recomputed the same way).
    if ! cmp -s <(tail -c +81 "$work/big.stl") <(tail -c +81 "$work/back.stl"); then
        echo "  MISMATCH: STL -> PLY -> STL changed the triangles" >&2
        status=1
    fi
    if [ "$memory" = 64M ] && { [ "$to_ply_peak" -ge 150 ] || [ "$from_ply_peak" -ge 150 ]; }; then
        echo "  FAIL: peak RSS at --memory 64M must stay under 150 MB" >&2
        status=1
    fi
done
echo "PLY: $(( $(stat -c %s "$work/big.ply") >> 20 )) MB, $("$meshstream" -q info --json "$work/big.ply" | sed -n 's/.*"vertices": \([0-9]*\).*/\1/p') vertices"
exit $status
