#!/usr/bin/env bash
# Benchmark of `meshstream sort` (issue 5): shuffles generated meshes of 10 M and 50 M
# triangles (meshstream-gen --shuffle), sorts each with --memory 64M and 1G, and reports
# triangles/s, peak RSS (GNU time), temporary disk (meshstream's own accounting and a du poll
# of --tmpdir), next to baselines: `cat` of the same file (the I/O floor) and GNU `sort -g` on
# a text file with one line per triangle (key first) given the same memory, on the first
# GNU_SORT_LINES triangles only (GNU sort parses floats at ~0.03 M lines/s; compare rates).
# cpu_s (user + system) is printed too: on a shared, loaded machine wall time overstates.
# Every timed run starts with the page cache's dirty data written back (sync) and writes a
# new output file, like cat: replacing an existing output on ext4 costs an extra ~0.4 s per
# 500 MB in rename() (auto_da_alloc flushes the new file, the old one's pages are freed).
# Then decimates the
# sorted file and the generator's original order and reports both (error and forced writes, from decimate --report).
#
# Usage: bench/sort.sh [BUILD_DIR]   (default: build, as tools/bootstrap.sh makes it)
# Env:   SIZES="10000000 50000000"  WORK=/tmp/meshstream-bench-sort  GNU_SORT_LINES=1000000
#        REPEAT=3: runs of cat and of each meshstream sort; the row shows the run with the median
#        wall time (its CPU, RSS and temp disk beside it).
#        KEEP=1 keeps the generated files.  DECIMATE=0 skips the decimation comparison.
set -euo pipefail

here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
ms="$build/tools/meshstream"
gen="$build/tools/meshstream-gen"
sizes="${SIZES:-10000000 50000000}"
work="${WORK:-${TMPDIR:-/tmp}/meshstream-bench-sort}"
gnu_sort_lines="${GNU_SORT_LINES:-1000000}"
repeat="${REPEAT:-3}"

[[ -x "$ms" ]] || { echo "bench/sort.sh: no meshstream binary at $ms (build first)" >&2; exit 1; }
[[ -x "$gen" ]] || { echo "bench/sort.sh: no meshstream-gen at $gen: the generator (tools/gen_mesh.cpp) is needed" >&2; exit 1; }
"$gen" --help | grep -q -- --shuffle || { echo "bench/sort.sh: meshstream-gen has no --shuffle option" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "bench/sort.sh: needs GNU time (apt-get install time)" >&2; exit 1; }

mkdir -p "$work/tmp"
[[ -n "${KEEP:-}" ]] || trap 'rm -rf "$work"' EXIT

# Polls the disk use of a directory while a command runs; prints the peak in bytes.
du_peak() {
    local dir="$1"
    shift
    "$@" &
    local pid=$! peak=0 now
    while kill -0 "$pid" 2>/dev/null; do
        now=$(du -sb "$dir" 2>/dev/null | cut -f1)
        ((now > peak)) && peak=$now
        sleep 0.05
    done
    wait "$pid"
    echo "$peak"
}

# Keeps one "seconds rss user sys temp_peak" line per run in $work/runs.txt; median_run prints
# the line of the run with the median wall time.
median_run() { sort -n -k1,1 "$work/runs.txt" | awk -v r="$repeat" 'NR == int((r + 1) / 2)'; }

rate() { awk -v n="$1" -v s="$2" 'BEGIN { printf "%.2f M/s", (s > 0 ? n / s / 1e6 : 0) }'; }

printf "%-10s %-26s %8s %12s %10s %12s %8s %12s\n" triangles run seconds rate peak_RSS temp_disk cpu_s rate_by_cpu
for n in $sizes; do
    "$gen" -q -n "$n" --tmpdir "$work/tmp" "$work/orig.stl"
    "$gen" -q -n "$n" --shuffle --tmpdir "$work/tmp" "$work/shuffled.stl"
    tris=$("$ms" -q info --json "$work/shuffled.stl" | sed -n 's/.*"triangles": \([0-9]*\).*/\1/p')
    cat "$work/shuffled.stl" > /dev/null  # warm the page cache like every run after it

    : > "$work/runs.txt"
    for ((i = 0; i < repeat; ++i)); do
        rm -f "$work/cat.stl"
        sync
        /usr/bin/time -f "%e %M %U %S" -o "$work/time.txt" sh -c 'cat "$1" > "$2"' sh "$work/shuffled.stl" "$work/cat.stl"
        echo "$(cat "$work/time.txt") 0" >> "$work/runs.txt"
    done
    read -r s rss us ss _ < <(median_run)
    printf "%-10s %-26s %8s %12s %10s %12s %8s %12s\n" "$tris" "cat (I/O floor)" "$s" "$(rate "$tris" "$s")" "$((rss / 1024)) MB" - "$(awk -v u="$us" -v s="$ss" 'BEGIN{print u+s}')" -
    rm -f "$work/cat.stl"

    for mem in 64M 1G; do
        : > "$work/runs.txt"
        for ((i = 0; i < repeat; ++i)); do
            rm -f "$work/sorted.stl"
            sync
            peak=$(du_peak "$work/tmp" /usr/bin/time -f "%e %M %U %S" -o "$work/time.txt" \
                "$ms" -q sort --stats --axis z --memory "$mem" --tmpdir "$work/tmp" "$work/shuffled.stl" "$work/sorted.stl" \
                2> "$work/stats.txt")
            echo "$(cat "$work/time.txt") $peak" >> "$work/runs.txt"
        done
        read -r s rss us ss peak < <(median_run)
        printf "%-10s %-26s %8s %12s %10s %12s %8s %12s\n" "$tris" "meshstream sort $mem" "$s" "$(rate "$tris" "$s")" \
            "$((rss / 1024)) MB" "$((peak / 1048576)) MB" "$(awk -v u="$us" -v s="$ss" 'BEGIN{print u+s}')" \
            "$(rate "$tris" "$(awk -v u="$us" -v s="$ss" 'BEGIN{print u+s}')")"
        sed 's/^/           /' "$work/stats.txt"
        awk '{ printf "           run: %s s wall, %.2f s cpu\n", $1, $3 + $4 }' "$work/runs.txt"
    done

    if ((gnu_sort_lines > 0)); then
        # GNU sort sees one text line per triangle: the z key, then the 9 coordinates.
        python3 - "$work/shuffled.stl" "$gnu_sort_lines" > "$work/lines.txt" <<'PY'
import struct, sys
with open(sys.argv[1], "rb") as f:
    f.read(80); (n,) = struct.unpack("<I", f.read(4))
    out = sys.stdout
    for _ in range(min(n, int(sys.argv[2]))):
        rec = f.read(50); c = struct.unpack_from("<9f", rec, 12)
        out.write("%.9g %s\n" % (min(c[2], c[5], c[8]), " ".join("%.9g" % v for v in c)))
PY
        for mem in 64M 1G; do
            peak=$(du_peak "$work/tmp" /usr/bin/time -f "%e %M %U %S" -o "$work/time.txt" \
                env LC_ALL=C sort -s -g -k1,1 -S "$mem" -T "$work/tmp" -o "$work/lines.sorted" "$work/lines.txt")
            read -r s rss us ss < "$work/time.txt"
            printf "%-10s %-26s %8s %12s %10s %12s %8s %12s\n" "$(wc -l < "$work/lines.txt")" "GNU sort -S $mem (text)" "$s" "$(rate "$(wc -l < "$work/lines.txt")" "$s")" \
                "$((rss / 1024)) MB" "$((peak / 1048576)) MB" "$(awk -v u="$us" -v s="$ss" 'BEGIN{print u+s}')" \
            "$(rate "$(wc -l < "$work/lines.txt")" "$(awk -v u="$us" -v s="$ss" 'BEGIN{print u+s}')")"
        done
        rm -f "$work/lines.txt" "$work/lines.sorted"
    fi

    "$ms" -q info --order "$work/shuffled.stl" | grep -E "width|buffer" | sed 's/^/           shuffled /'
    "$ms" -q info --order "$work/sorted.stl" | grep -E "width|buffer" | sed 's/^/           sorted   /'
    if [[ "${DECIMATE:-1}" != 0 ]] && "$ms" decimate --help > /dev/null 2>&1; then
        for f in orig sorted; do
            echo "           decimate 10% of $f.stl:"
            "$ms" -q decimate --ratio 0.1 --report "$work/$f.stl" "$work/dec.stl" 2>&1 | sed 's/^/             /' || true
        done
        rm -f "$work/dec.stl"
    fi
    rm -f "$work/orig.stl" "$work/shuffled.stl" "$work/sorted.stl"
done
