#!/usr/bin/env bash
# Benchmark of `decimate --sort` (issue 21 §5): a generated mesh (meshstream-gen) and the same
# mesh shuffled, decimated to RATIO (default 1 %):
#   - shuffled, `--sort never` (as read: forced writes), once;
#   - shuffled, `meshstream sort` then `decimate` (two commands: the reference);
#   - shuffled, `decimate` (--sort auto: sorts at its first forced write), from the file and
#     from stdin (spooled), and `--sort always`;
#   - the generator's order (streaming order: auto must not sort it).
# Each timed command runs REPEAT times, round robin with the others (so that the machine's
# load falls on all alike); the row shows the run with the median wall time, its CPU (user +
# system) and peak RSS (GNU time). Also timed: `info --order` of the shuffled file, the pass
# an order test before decimating would cost. For each output: triangles against the
# target, and the symmetric RMS and Hausdorff error against the original mesh
# (`meshstream compare --json`). cpu_s is printed too: on a shared, loaded machine wall time
# overstates.
#
# Usage: bench/decimate_sort.sh [BUILD_DIR]   (default: build)
# Env:   N=1000000  RATIO=0.01  REPEAT=3  WORK=/tmp/meshstream-bench-decimate-sort  KEEP=1
set -euo pipefail

here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
ms="$build/tools/meshstream"
gen="$build/tools/meshstream-gen"
n="${N:-1000000}"
ratio="${RATIO:-0.01}"
repeat="${REPEAT:-3}"
work="${WORK:-${TMPDIR:-/tmp}/meshstream-bench-decimate-sort}"

[[ -x "$ms" ]] || { echo "bench/decimate_sort.sh: no meshstream binary at $ms (build first)" >&2; exit 1; }
[[ -x "$gen" ]] || { echo "bench/decimate_sort.sh: no meshstream-gen at $gen" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "bench/decimate_sort.sh: needs GNU time (apt-get install time)" >&2; exit 1; }
command -v python3 > /dev/null || { echo "bench/decimate_sort.sh: needs python3 (to read compare's JSON)" >&2; exit 1; }

mkdir -p "$work/tmp"
[[ -n "${KEEP:-}" ]] || trap 'rm -rf "$work"' EXIT

"$gen" -q -n "$n" --tmpdir "$work/tmp" "$work/mesh.stl"
"$gen" -q -n "$n" --shuffle --tmpdir "$work/tmp" "$work/shuffled.stl"
tris=$("$ms" -q info --json "$work/shuffled.stl" | python3 -c 'import json,sys; print(json.load(sys.stdin)["triangles"])')
target=$(python3 -c "print(round($ratio * $tris))")
cat "$work/mesh.stl" "$work/shuffled.stl" > /dev/null  # warm the page cache

# Runs each labelled command line (sh -c) REPEAT times, round robin, so that a change in the
# machine's load falls on all of them alike; keeps "wall rss user sys" per run in
# $work/runs.<label>, and the last run's stderr in $work/stderr.<label>.
round_robin() {
    local label
    for label in "$@"; do : > "$work/runs.$label"; done
    for ((i = 0; i < repeat; ++i)); do
        for label in "$@"; do
            sync
            /usr/bin/time -f "%e %M %U %S" -o "$work/time.txt" sh -c "${cmd[$label]}" > /dev/null 2> "$work/stderr.$label"
            cat "$work/time.txt" >> "$work/runs.$label"
        done
    done
}
# The run with the median wall time: "wall rss user sys".
median() { sort -n -k1,1 "$work/runs.$1" | awk -v r="$repeat" 'NR == int((r + 1) / 2)'; }
cpu() { awk -v u="$1" -v s="$2" 'BEGIN{printf "%.2f", u + s}'; }

# Triangles, and the symmetric RMS / Hausdorff in % of the bbox diagonal, of an output.
quality() {
    local out="$1" count
    count=$("$ms" -q info --json "$out" | python3 -c 'import json,sys; print(json.load(sys.stdin)["triangles"])')
    "$ms" -q compare --json "$work/mesh.stl" "$out" | python3 -c '
import json, sys
j = json.load(sys.stdin)["symmetric"]
print("%s %.5f %.4f" % (sys.argv[1], j["rms_pct"], j["max_pct"]))' "$count"
}

line() {  # label, wall, cpu, rss KB, output or ""
    local count=- rms=- haus=-
    [[ -n "$5" ]] && read -r count rms haus < <(quality "$5")
    printf "%-46s %8s %8s %9s %10s %9s %9s\n" "$1" "$2" "$3" "$(($4 / 1024)) MB" "$count" "$rms" "$haus"
}

d="$ms -q decimate -r $ratio"
declare -A cmd=(
    [never]="$d --sort never '$work/shuffled.stl' '$work/never.stl'"
    [sort]="$ms -q sort '$work/shuffled.stl' '$work/sorted.stl'"
    [sorted]="$d '$work/sorted.stl' '$work/ref.stl'"
    [auto]="$d '$work/shuffled.stl' '$work/auto.stl'"
    [stdin]="$d --tmpdir '$work/tmp' - '$work/stdin.stl' < '$work/shuffled.stl'"
    [always]="$d --sort always '$work/shuffled.stl' '$work/always.stl'"
    [plain]="$d '$work/mesh.stl' '$work/plain.stl'"
    [order]="$ms -q info --order '$work/shuffled.stl'"
)
echo "mesh: $tris triangles, target $target (ratio $ratio), $repeat runs each, round robin (median shown)"
printf "%-46s %8s %8s %9s %10s %9s %9s\n" run wall_s cpu_s peak_RSS triangles rms_pct haus_pct
repeat_all=$repeat
repeat=1 round_robin never
read -r s rss us ss < <(repeat=1 median never)
line "shuffled, --sort never (as read; once)" "$s" "$(cpu "$us" "$ss")" "$rss" "$work/never.stl"
repeat=$repeat_all
round_robin sort sorted auto stdin always plain order
read -r s1 rss1 us1 ss1 < <(median sort)
read -r s2 rss2 us2 ss2 < <(median sorted)
line "  meshstream sort" "$s1" "$(cpu "$us1" "$ss1")" "$rss1" ""
line "  decimate the sorted file" "$s2" "$(cpu "$us2" "$ss2")" "$rss2" ""
line "shuffled, sort then decimate (sum)" "$(awk -v a="$s1" -v b="$s2" 'BEGIN{print a+b}')" \
    "$(cpu "$(cpu "$us1" "$ss1")" "$(cpu "$us2" "$ss2")")" "$((rss1 > rss2 ? rss1 : rss2))" "$work/ref.stl"
for label in auto stdin always plain; do
    read -r s rss us ss < <(median "$label")
    case $label in
        auto) what="shuffled, decimate (--sort auto)" ;;
        stdin) what="shuffled on stdin, decimate (--sort auto)" ;;
        always) what="shuffled, decimate --sort always" ;;
        plain) what="generator order, decimate (--sort auto)" ;;
    esac
    line "$what" "$s" "$(cpu "$us" "$ss")" "$rss" "$work/$label.stl"
    notice=$(grep "sorted along . first" "$work/stderr.$label" | sed 's/^ *//' || true)
    echo "  ${notice:-(not sorted)}"
    if [[ $label != plain ]]; then
        cmp -s "$work/$label.stl" "$work/ref.stl" && echo "  byte-identical to sort then decimate" ||
            echo "  differs from sort then decimate"
    fi
done
read -r s rss us ss < <(median order)
line "  info --order of the shuffled file (a pre-pass)" "$s" "$(cpu "$us" "$ss")" "$rss" ""
