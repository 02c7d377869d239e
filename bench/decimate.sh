#!/usr/bin/env bash
# Decimation benchmark: `meshstream decimate` next to two in-core references on the same inputs
# in the same run, printing end-to-end speed (input triangles/s, file to file), peak RSS and
# the compare error against the input. Medians of RUNS runs (compare runs once: it is
# deterministic).
#
#   bench/decimate.sh                  # 1 M, 10 M, 50 M generated meshes, the bunny, the corpus rows
#   SIZES="1000000" RUNS=1 CORPUS=0 bench/decimate.sh
#
# Environment:
#   BENCH_DIR  work dir for meshes and outputs (default /tmp/meshstream-bench; about 4 GB with 50 M)
#   BUILD_DIR  build dir, configured here with -DMESHSTREAM_BUILD_BENCH=ON (default $BENCH_DIR/build)
#   SIZES      generated mesh sizes in triangles (default "1000000 10000000 50000000"; "" for none)
#   RATIOS     decimation ratios (default "0.1 0.01")
#   RUNS       runs per measurement, median reported (default 3)
#   CGAL_MAX   largest input given to the (slow) CGAL reference (default 1500000: the 1 M mesh)
#   THREADS    meshstream's --threads (default 1: the references run on one core)
#   CORPUS     1 (default) adds, at 10 %, the low-poly models of $SHARED/corpus (Spider,
#              gearwheel, elephant, WusonOBJ; positions only: their normals and uvs dropped by
#              meshstream, not read by the references), and the generated 1 M mesh with 40
#              holes (meshstream-gen --holes) at 1 % through `--buffer 50000`; 0 leaves them out
#   SHARED     the shared directory with corpus/ (default ../shared)
#   COMPARE    0 to skip the error columns (default 1)
#   DECIMATE_ARGS  extra options for `meshstream decimate` (e.g. "--buffer 200000")
# Needs: cmake, g++, libmeshoptimizer-dev, libcgal-dev + libeigen3-dev (else no CGAL rows),
# GNU time (/usr/bin/time, Debian package `time`) and python3 (table).
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)

BENCH_DIR=${BENCH_DIR:-/tmp/meshstream-bench}
BUILD_DIR=${BUILD_DIR:-$BENCH_DIR/build}
SIZES=${SIZES-"1000000 10000000 50000000"}
RATIOS=${RATIOS:-"0.1 0.01"}
RUNS=${RUNS:-3}
CGAL_MAX=${CGAL_MAX:-1500000}
THREADS=${THREADS:-1}
CORPUS=${CORPUS:-1}
SHARED=${SHARED:-$src/../shared}
COMPARE=${COMPARE:-1}
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
ref_cgal=$BUILD_DIR/bench/ref_cgal
"$ms" decimate --help >/dev/null 2>&1 || die "'meshstream decimate' does not exist in this build: nothing to benchmark"
[ -x "$ref_cgal" ] || echo "bench/decimate.sh: no ref_cgal (apt-get install libcgal-dev libeigen3-dev): CGAL rows skipped" >&2

# Cases, one a line: input, its ratios (comma-separated), meshstream's extra options. Generated
# meshes are made once and kept in BENCH_DIR.
generated() {  # N [--holes]: prints the path of a generated mesh of about N triangles
  local f=$BENCH_DIR/gen_$1${2:+_holes}.stl
  if [ ! -s "$f" ]; then
    echo "== generating $f" >&2
    "$gen" --triangles "$1" ${2:-} "$f" >&2
  fi
  echo "$f"
}
all_ratios=$(echo "$RATIOS" | tr ' ' ',')
cases=()
for n in $SIZES; do cases+=("$(generated "$n")|$all_ratios|"); done
cases+=("$src/fixtures/bunny_from_draco.bin.stl|$all_ratios|")
if [ "$CORPUS" = 1 ]; then
  positions_only="--drop normals,colors,uvs,extra,materials"
  for f in stl/Spider_binary.stl stl/gearwheel.bin.stl ply/elephant_normals.binary_be.ply obj/WusonOBJ.obj; do
    [ -s "$SHARED/corpus/$f" ] || die "no $SHARED/corpus/$f (set SHARED)"
    cases+=("$SHARED/corpus/$f|0.1|$positions_only")
  done
  cases+=("$(generated 1000000 --holes)|0.01|--buffer 50000")
fi

results=$BENCH_DIR/results.tsv
: >"$results"

# time_run LABEL CMD...: runs CMD under GNU time; appends "seconds<TAB>rss_kb" lines to $BENCH_DIR/runs.txt
MEASURE_DIR=$BENCH_DIR

median_of_runs() {  # CMD...: prints "median_seconds<TAB>median_rss_kb"
  local lines=()
  for ((r = 0; r < RUNS; r++)); do lines+=("$(measure "$@")"); done
  printf '%s\n' "${lines[@]}" | python3 -c '
import sys, statistics
rows = [l.split("\t") for l in sys.stdin.read().split("\n") if l]
print(f"{statistics.median(float(r[0]) for r in rows)}\t{int(statistics.median(int(r[2]) for r in rows))}")'
}

error_of() {  # INPUT OUTPUT: prints "rms_pct<TAB>max_pct<TAB>rms<TAB>max"
  if [ "$COMPARE" = 0 ]; then printf -- '-\t-\t-\t-\n'; return; fi
  "$ms" -q compare --json "$1" "$2" >"$BENCH_DIR/compare.json" || die "compare failed: $1 $2"
  python3 - "$BENCH_DIR/compare.json" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))["symmetric"]
print("%.5f\t%.4f\t%.6g\t%.6g" % (s["rms_pct"], s["max_pct"], s["rms"], s["max"]))
EOF
}

for case in "${cases[@]}"; do
  IFS='|' read -r in ratios extra <<<"$case"
  n=$("$ms" -q info --json "$in" | python3 -c 'import json,sys; print(json.load(sys.stdin)["triangles"])')
  name=$(basename "$in")
  name=${name%.*}
  for ratio in ${ratios//,/ }; do
    target=$(python3 -c "print(round($ratio * $n))")
    tools="meshstream meshopt"
    if [ -x "$ref_cgal" ] && [ "$n" -le "$CGAL_MAX" ]; then tools="$tools cgal"; fi
    for tool in $tools; do
      out=$BENCH_DIR/out_${name}_${ratio}_$tool.stl
      echo "== $tool $name ratio $ratio ($RUNS runs)" >&2
      case $tool in
        # shellcheck disable=SC2086  # option lists
        meshstream) m=$(median_of_runs "$ms" -q decimate --threads "$THREADS" $extra $DECIMATE_ARGS "$in" "$out" --ratio "$ratio") ;;
        meshopt) m=$(median_of_runs "$ref_meshopt" "$in" "$out" --target "$target") ;;
        cgal) m=$(median_of_runs "$ref_cgal" "$in" "$out" --target "$target") ;;
      esac
      out_n=$("$ms" -q info --json "$out" | python3 -c 'import json,sys; print(json.load(sys.stdin)["triangles"])')
      e=$(error_of "$in" "$out")
      printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$name" "$n" "$ratio" "$tool" "$out_n" "$m" "$e" >>"$results"
    done
  done
done

python3 - "$results" "$RUNS" <<'EOF'
import sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
print(f"median of {sys.argv[2]} runs; error = meshstream compare against the input (symmetric, % of input bbox diagonal)")
head = ["input", "triangles", "ratio", "tool", "out", "seconds", "M in-tri/s", "peak RSS MB", "RMS %", "Hausdorff %"]
table = []
for name, n, ratio, tool, out, sec, rss, rms_pct, max_pct, rms, mx in rows:
    sec = float(sec)
    table.append([name, n, ratio, tool, out, f"{sec:.2f}", f"{int(n) / sec / 1e6:.2f}", f"{int(rss) / 1024:.0f}",
                  rms_pct, max_pct])
widths = [max(len(str(r[i])) for r in table + [head]) for i in range(len(head))]
print(" | ".join(h.ljust(w) for h, w in zip(head, widths)))
print("-|-".join("-" * w for w in widths))
for r in table:
    print(" | ".join(str(c).ljust(w) for c, w in zip(r, widths)))
EOF
echo "(raw rows: $results)" >&2
