#!/usr/bin/env bash
# Reader and writer threads benchmark: `meshstream convert` and `meshstream sort` with
# `--threads 1` (everything on one thread) against `--threads 2` (reading on a thread of its own,
# writing on another: io/pipeline.hpp), on a generated mesh converted to and from ASCII PLY,
# gzipped binary PLY and OBJ, and sorted from a gzipped STL. Prints per row the median of RUNS
# runs of wall time, CPU time (user + system) and peak RSS, and the speed-up over the first
# THREADS value; each output is checked to be byte-identical across THREADS. The load average
# before and after the runs is printed too: the machine may be shared, and wall times mean little
# when it is busy.
#
#   bench/pipeline.sh                         # 10 M generated mesh, --threads 1 and 2
#   SIZE=1000000 RUNS=1 bench/pipeline.sh
#
# Environment:
#   BENCH_DIR  work dir for meshes and outputs (default /tmp/meshstream-bench)
#   BUILD_DIR  build dir, configured here (default $BENCH_DIR/build)
#   SIZE       generated mesh size in triangles (default 10000000)
#   THREADS    --threads values (default "1 2"; the first is the reference of the speed-ups)
#   RUNS       runs per measurement, median reported (default 3)
#   CASES      which rows (default: all of those below, by name)
# Needs: cmake, g++, GNU time (/usr/bin/time) and python3.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)

BENCH_DIR=${BENCH_DIR:-/tmp/meshstream-bench}
BUILD_DIR=${BUILD_DIR:-$BENCH_DIR/build}
SIZE=${SIZE:-10000000}
THREADS=${THREADS:-"1 2"}
RUNS=${RUNS:-3}
# name: command, input, output (the inputs are made from the generated binary STL first).
ALL_CASES="stl-to-ply-ascii ply-ascii-to-stl stl-to-ply-gz ply-gz-to-stl stl-to-obj obj-to-stl ply-gz-to-obj sort-stl-gz"
CASES=${CASES:-$ALL_CASES}

# shellcheck source=bench/lib.sh
source "$src/bench/lib.sh"  # die, measure, load; checks for GNU time and python3
mkdir -p "$BENCH_DIR"

echo "== building in $BUILD_DIR" >&2
cmake -S "$src" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DMESHSTREAM_BUILD_TESTS=OFF >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target meshstream meshstream-gen >/dev/null ||
  die "build failed (run: cmake --build $BUILD_DIR)"
ms=$BUILD_DIR/tools/meshstream
gen=$BUILD_DIR/tools/meshstream-gen
"$ms" convert --help | grep -q -- --threads || die "'meshstream convert' has no --threads in this build"

d=$BENCH_DIR
stl=$d/gen_$SIZE.stl
if [ ! -s "$stl" ]; then
  echo "== generating $stl" >&2
  "$gen" -q --triangles "$SIZE" "$stl"
fi
# The inputs in each format, made once (with one thread).
make_input() {  # PATH ARGS...
  local path=$1
  shift
  if [ ! -s "$path" ]; then
    echo "== making $path" >&2
    "$ms" -q convert --threads 1 "$@" "$stl" "$path"
  fi
}
make_input "$d/pipe_$SIZE.ply" --to ply-ascii
make_input "$d/pipe_$SIZE.ply.gz"
make_input "$d/pipe_$SIZE.obj"
make_input "$d/pipe_$SIZE.stl.gz"

args_of() {  # CASE THREADS: the command line's arguments after `meshstream -q`
  local o=$d/pipe_out_$1_t$2
  case $1 in
    stl-to-ply-ascii) echo "convert --threads $2 --to ply-ascii $stl $o.ply" ;;
    ply-ascii-to-stl) echo "convert --threads $2 $d/pipe_$SIZE.ply $o.stl" ;;
    stl-to-ply-gz) echo "convert --threads $2 $stl $o.ply.gz" ;;
    ply-gz-to-stl) echo "convert --threads $2 $d/pipe_$SIZE.ply.gz $o.stl" ;;
    stl-to-obj) echo "convert --threads $2 $stl $o.obj" ;;
    obj-to-stl) echo "convert --threads $2 $d/pipe_$SIZE.obj $o.stl" ;;
    ply-gz-to-obj) echo "convert --threads $2 $d/pipe_$SIZE.ply.gz $o.obj" ;;
    sort-stl-gz) echo "sort --threads $2 --axis x $d/pipe_$SIZE.stl.gz $o.stl" ;;
    *) die "unknown case $1 (one of: $ALL_CASES)" ;;
  esac
}
output_of() { args_of "$1" "$2" | awk '{print $NF}'; }

load_before=$(load)
runs_file=$d/pipeline_runs.tsv
: >"$runs_file"

MEASURE_DIR=$d

for c in $CASES; do
  # Alternated run by run, so that a change in the machine's load reaches every setting alike.
  for ((r = 0; r < RUNS; r++)); do
    for t in $THREADS; do
      # shellcheck disable=SC2046
      m=$(measure "$ms" -q $(args_of "$c" "$t"))
      echo "== $c --threads $t run $((r + 1)): $m" >&2
      printf '%s\t%s\t%s\n' "$c" "$t" "$m" >>"$runs_file"
    done
  done
  first=""
  for t in $THREADS; do
    out=$(output_of "$c" "$t")
    if [ -z "$first" ]; then first=$out; else cmp -s "$first" "$out" || die "$c: $out differs from $first"; fi
  done
done
load_after=$(load)

python3 - "$runs_file" "$RUNS" "$SIZE" "$load_before" "$load_after" <<'EOF'
import statistics, sys
runs_file, runs, size, before, after = sys.argv[1:]
med, order = {}, []
for line in open(runs_file):
    case, threads, wall, cpu, rss = line.rstrip("\n").split("\t")
    if (case, threads) not in med: order.append((case, threads))
    med.setdefault((case, threads), []).append((float(wall), float(cpu), float(rss)))
print(f"{size} triangles; median of {runs} runs (alternated); load average (1/5/15 min) before: {before}, after: {after}")
print("outputs byte-identical across --threads; x1 = wall time of the first --threads over this row's")
head = ["case", "threads", "wall s", "CPU s", "peak RSS MB", "speed-up x1"]
table, ref = [], {}
for case, threads in order:
    wall, cpu, rss = (statistics.median(x[i] for x in med[(case, threads)]) for i in range(3))
    ref.setdefault(case, wall)
    table.append([case, threads, f"{wall:.2f}", f"{cpu:.2f}", f"{rss / 1024:.0f}", f"{ref[case] / wall:.2f}"])
widths = [max(len(str(r[i])) for r in table + [head]) for i in range(len(head))]
print(" | ".join(h.ljust(w) for h, w in zip(head, widths)))
print("-|-".join("-" * w for w in widths))
for r in table:
    print(" | ".join(str(c).ljust(w) for c, w in zip(r, widths)))
EOF
echo "(raw runs: $runs_file)" >&2
