#!/usr/bin/env bash
# Parallel decimation benchmark: `meshstream decimate --threads 1` against `--threads 2` (and any
# THREADS given) on the generated meshes, with meshoptimizer 1.2 (`bench/ref_meshopt`, whole mesh
# in memory, exact weld, `simplifyWithUpdate` to the same count) in the same run. Prints per row
# the median of RUNS runs of wall time, CPU time (user + system) and peak RSS, the speed-up over
# one thread, and the symmetric RMS error against the input (meshstream compare, % of the bbox
# diagonal) with its ratio to one thread's. The load average before and after the runs is printed
# too: the machine may be shared, and wall times mean little when it is busy. Where meshstream-mpi
# is built (MPI found) and mpirun is there, `mpirun -n K meshstream-mpi decimate` is measured too
# (rows mpi-K; its peak RSS is the largest rank's, its CPU time every rank's and mpirun's).
#
#   bench/threads.sh                        # 10 M generated mesh at 10 % and 1 %, 1 and 2 threads
#   SIZES=1000000 RUNS=1 THREADS="1 2 4" bench/threads.sh
#
# Environment:
#   BENCH_DIR  work dir for meshes and outputs (default /tmp/meshstream-bench)
#   BUILD_DIR  build dir, configured here with -DMESHSTREAM_BUILD_BENCH=ON (default $BENCH_DIR/build)
#   SIZES      generated mesh sizes in triangles (default 10000000)
#   RATIOS     decimation ratios (default "0.1 0.01")
#   THREADS    --threads values (default "1 2"; the first is the reference of the ratios)
#   RUNS       runs per measurement, median reported (default 3)
#   MESHOPT    0 to leave out meshoptimizer (default 1)
#   MPI_RANKS  ranks of the meshstream-mpi rows (default 2; empty: none)
#   RMS        0 to leave out the error measurement (a compare of each output; default 1)
#   DECIMATE_ARGS  extra options for `meshstream decimate`
# Needs: cmake, g++, libmeshoptimizer-dev, GNU time (/usr/bin/time) and python3.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)

BENCH_DIR=${BENCH_DIR:-/tmp/meshstream-bench}
BUILD_DIR=${BUILD_DIR:-$BENCH_DIR/build}
SIZES=${SIZES:-10000000}
RATIOS=${RATIOS:-"0.1 0.01"}
THREADS=${THREADS:-"1 2"}
RUNS=${RUNS:-3}
MESHOPT=${MESHOPT:-1}
MPI_RANKS=${MPI_RANKS-2}
RMS=${RMS:-1}
DECIMATE_ARGS=${DECIMATE_ARGS:-}

# shellcheck source=bench/lib.sh
source "$src/bench/lib.sh"  # die, measure, load; checks for GNU time and python3
mkdir -p "$BENCH_DIR"

echo "== building in $BUILD_DIR" >&2
cmake -S "$src" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DMESHSTREAM_BUILD_BENCH=ON -DMESHSTREAM_BUILD_TESTS=OFF >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" >/dev/null || die "build failed (run: cmake --build $BUILD_DIR)"
ms=$BUILD_DIR/tools/meshstream
gen=$BUILD_DIR/tools/meshstream-gen
ref_meshopt=$BUILD_DIR/bench/ref_meshopt
ms_mpi=$BUILD_DIR/tools/meshstream-mpi
"$ms" decimate --help | grep -q -- --threads || die "'meshstream decimate' has no --threads in this build"
if [ "$MESHOPT" = 1 ] && [ ! -x "$ref_meshopt" ]; then
  echo "bench/threads.sh: no ref_meshopt (apt-get install libmeshoptimizer-dev): meshoptimizer rows skipped" >&2
  MESHOPT=0
fi

if [ -n "$MPI_RANKS" ] && { [ ! -x "$ms_mpi" ] || ! command -v mpirun >/dev/null; }; then
  echo "bench/threads.sh: no meshstream-mpi or mpirun (apt-get install libopenmpi-dev openmpi-bin): MPI rows skipped" >&2
  MPI_RANKS=""
fi

results=$BENCH_DIR/threads.tsv
: >"$results"
load_before=$(load)

MEASURE_DIR=$BENCH_DIR

rms_of() {  # INPUT OUTPUT: prints the symmetric RMS error in % of the bbox diagonal
  "$ms" -q compare --json "$1" "$2" >"$BENCH_DIR/compare.json" || die "compare failed: $1 $2"
  python3 -c 'import json, sys; print("%.6f" % json.load(open(sys.argv[1]))["symmetric"]["rms_pct"])' "$BENCH_DIR/compare.json"
}

for n in $SIZES; do
  in=$BENCH_DIR/gen_$n.stl
  if [ ! -s "$in" ]; then
    echo "== generating $in" >&2
    "$gen" -q --triangles "$n" "$in"
  fi
  count=$("$ms" -q info --json "$in" | python3 -c 'import json,sys; print(json.load(sys.stdin)["triangles"])')
  for ratio in $RATIOS; do
    target=$(python3 -c "print(round($ratio * $count))")
    tools=""
    for t in $THREADS; do tools="$tools threads-$t"; done
    for k in $MPI_RANKS; do tools="$tools mpi-$k"; done
    if [ "$MESHOPT" = 1 ]; then tools="$tools meshopt"; fi
    # Alternated run by run, so that a change in the machine's load reaches every tool alike.
    for ((r = 0; r < RUNS; r++)); do
      for tool in $tools; do
        out=$BENCH_DIR/threads_${n}_${ratio}_$tool.stl
        case $tool in
          threads-*) m=$(measure "$ms" -q decimate $DECIMATE_ARGS --threads "${tool#threads-}" "$in" "$out" --ratio "$ratio") ;;
          mpi-*) m=$(measure env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe \
                       -n "${tool#mpi-}" "$ms_mpi" -q decimate $DECIMATE_ARGS "$in" "$out" --ratio "$ratio") ;;
          meshopt) m=$(measure "$ref_meshopt" "$in" "$out" --target "$target") ;;
        esac
        echo "== $tool $n ratio $ratio run $((r + 1)): $m" >&2
        printf '%s\t%s\t%s\t%s\n' "$n" "$ratio" "$tool" "$m" >>"$BENCH_DIR/threads_runs.tsv.$$"
      done
    done
    for tool in $tools; do
      out=$BENCH_DIR/threads_${n}_${ratio}_$tool.stl
      out_n=$("$ms" -q info --json "$out" | python3 -c 'import json,sys; print(json.load(sys.stdin)["triangles"])')
      rms=-
      if [ "$RMS" = 1 ]; then rms=$(rms_of "$in" "$out"); fi
      printf '%s\t%s\t%s\t%s\t%s\n' "$n" "$ratio" "$tool" "$out_n" "$rms" >>"$results"
    done
  done
done
load_after=$(load)

python3 - "$results" "$BENCH_DIR/threads_runs.tsv.$$" "$RUNS" "$load_before" "$load_after" <<'EOF'
import statistics, sys
results, runs_file, runs, before, after = sys.argv[1:]
runs_rows = [l.rstrip("\n").split("\t") for l in open(runs_file) if l.strip()]
med = {}
for n, ratio, tool, wall, cpu, rss in runs_rows:
    med.setdefault((n, ratio, tool), []).append((float(wall), float(cpu), float(rss)))
rows = [l.rstrip("\n").split("\t") for l in open(results) if l.strip()]
print(f"median of {runs} runs (alternated); load average (1/5/15 min) before: {before}, after: {after}")
print("RMS = meshstream compare against the input (symmetric, % of bbox diagonal); x1 = ratio to --threads of the first row")
head = ["triangles", "ratio", "tool", "out", "wall s", "CPU s", "peak RSS MB", "speed-up x1", "RMS %", "RMS x1"]
table, ref = [], {}
for n, ratio, tool, out, rms in rows:
    m = med[(n, ratio, tool)]
    wall, cpu, rss = (statistics.median(x[i] for x in m) for i in range(3))
    value = None if rms == "-" else float(rms)
    if (n, ratio) not in ref: ref[(n, ratio)] = (wall, value)
    w1, r1 = ref[(n, ratio)]
    table.append([n, ratio, tool, out, f"{wall:.2f}", f"{cpu:.2f}", f"{rss / 1024:.0f}", f"{w1 / wall:.2f}", rms,
                  "-" if value is None or not r1 else f"{value / r1:.3f}"])
widths = [max(len(str(r[i])) for r in table + [head]) for i in range(len(head))]
print(" | ".join(h.ljust(w) for h, w in zip(head, widths)))
print("-|-".join("-" * w for w in widths))
for r in table:
    print(" | ".join(str(c).ljust(w) for c, w in zip(r, widths)))
EOF
rm -f "$BENCH_DIR/threads_runs.tsv.$$"
echo "(raw rows: $results)" >&2
