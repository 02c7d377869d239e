#!/usr/bin/env bash
# Renders the plots in docs/images/ from measurements made here and now:
#   error_bunny.svg, error_1m.svg  RMS surface error (meshstream compare, % of the input's bounding-box
#                                  diagonal) against output triangle count for meshstream decimate,
#                                  meshoptimizer 1.2 simplifyWithUpdate and CGAL Garland-Heckbert
#                                  (bench/decimate.sh's references), on the bunny fixture and the
#                                  generated 1 M mesh;
#   scaling.svg                    decimate to 1 % (time and peak RSS, meshstream and meshoptimizer 1.2,
#                                  file to file) and sort --memory 1G (time) against input size;
# and writes the numbers beside them (docs/images/plots.tsv).
#
#   bench/plots.sh
# Environment:
#   BENCH_DIR  work dir (default /tmp/meshstream-plots; about 6 GB with the 100 M mesh)
#   SIZES      input sizes of the scaling plot (default "1000000 10000000 100000000")
#   RATIOS     ratios of the error plots (default "0.5 0.2 0.1 0.05 0.02 0.01")
#   RUNS       runs per scaling point, median plotted (default 3)
#   LARGE_RUNS runs per scaling point above LARGE input triangles (default RUNS; LARGE default 20 M)
#   THREADS    decimate --threads of both plots (default 1: one core, as the in-core references)
#   OUT_DIR    where the SVGs go (default docs/images)
#   REUSE      1: keep the measurements an earlier run left in BENCH_DIR (the error rows; the
#              scaling and sort rows of each size), measuring only what is missing (default 0)
# Needs what bench/decimate.sh needs, and gnuplot (Debian: gnuplot-nox).
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
BENCH_DIR=${BENCH_DIR:-/tmp/meshstream-plots}
SIZES=${SIZES:-"1000000 10000000 100000000"}
RATIOS=${RATIOS:-"0.5 0.2 0.1 0.05 0.02 0.01"}
RUNS=${RUNS:-3}
THREADS=${THREADS:-1}
LARGE=${LARGE:-20000000}
LARGE_RUNS=${LARGE_RUNS:-$RUNS}
runs_for() { if [ "$1" -gt "$LARGE" ]; then echo "$LARGE_RUNS"; else echo "$RUNS"; fi; }
REUSE=${REUSE:-0}
OUT_DIR=${OUT_DIR:-docs/images}
command -v gnuplot >/dev/null || { echo "bench/plots.sh: gnuplot is missing: apt-get install gnuplot-nox" >&2; exit 1; }
mkdir -p "$BENCH_DIR" "$OUT_DIR"

# 1. Error against triangle count: one run each (the error is deterministic, time is not plotted).
error_rows=$BENCH_DIR/error/results.tsv
if [ "$REUSE" != 1 ] || [ ! -s "$error_rows" ]; then
  BUILD_DIR=$BENCH_DIR/build BENCH_DIR=$BENCH_DIR/error SIZES=1000000 RATIOS=$RATIOS RUNS=1 CORPUS=0 \
    THREADS=$THREADS bash bench/decimate.sh >"$BENCH_DIR/error.txt"
fi

# 2. Decimate to 1 % against input size, medians of RUNS (LARGE_RUNS), no compare (speed and
# memory only), one size at a time.
scaling_rows=$BENCH_DIR/scaling.tsv
[ "$REUSE" = 1 ] && [ -s "$scaling_rows" ] || : >"$scaling_rows"
for n in $SIZES; do
  grep -q "^gen_$n	" "$scaling_rows" && continue
  BUILD_DIR=$BENCH_DIR/build BENCH_DIR=$BENCH_DIR/scaling SIZES=$n RATIOS=0.01 RUNS=$(runs_for "$n") CGAL_MAX=0 \
    COMPARE=0 CORPUS=0 THREADS=$THREADS bash bench/decimate.sh >>"$BENCH_DIR/scaling.txt"
  grep "^gen_" "$BENCH_DIR/scaling/results.tsv" >>"$scaling_rows"
done

# 3. Sort throughput on the same generated meshes (written in generator order; sort along the
# longest axis), median of RUNS by wall time.
ms=$BENCH_DIR/build/tools/meshstream
sort_rows=$BENCH_DIR/sort.tsv
[ "$REUSE" = 1 ] && [ -s "$sort_rows" ] || : >"$sort_rows"
for n in $SIZES; do
  grep -q "^$n " "$sort_rows" && continue
  in=$BENCH_DIR/scaling/gen_$n.stl
  runs=$(runs_for "$n")
  for ((r = 0; r < runs; r++)); do
    rm -f "$BENCH_DIR/sorted.stl"
    /usr/bin/time -f "%e %M" -o "$BENCH_DIR/time.txt" "$ms" -q sort --memory 1G "$in" "$BENCH_DIR/sorted.stl"
    echo "$n $(cat "$BENCH_DIR/time.txt")"
  done | sort -k2 -n | awk -v runs="$runs" 'NR == int((runs + 1) / 2)' >>"$sort_rows"
  rm -f "$BENCH_DIR/sorted.stl"
done

# Columns of results.tsv: name, triangles, ratio, tool, out triangles, seconds, rss kB, rms %, max %, rms, max.
table=$OUT_DIR/plots.tsv
{
  echo "# meshstream $(git describe --always --dirty 2>/dev/null || echo '?'), $(nproc) cores, load average at the end $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "# plot	input	input triangles	ratio	tool	output triangles	seconds	peak RSS kB	RMS % of diagonal	Hausdorff % of diagonal"
  awk -F'\t' -v OFS='\t' '{ print "error", $1, $2, $3, $4, $5, $6, $7, $8, $9 }' "$error_rows"
  awk -F'\t' -v OFS='\t' '{ print "scaling", $1, $2, $3, $4, $5, $6, $7, "-", "-" }' "$scaling_rows"
  awk -v OFS='\t' '{ print "sort", "gen_" $1, $1, "-", "meshstream sort --memory 1G", $1, $2, $3, "-", "-" }' "$sort_rows"
} >"$table"

# gnuplot input: one block per tool.
series() {  # FILE INPUT_NAME TOOL COLUMN_X COLUMN_Y
  awk -F'\t' -v n="$2" -v t="$3" -v x="$4" -v y="$5" '$1 == n && $4 == t { print $x, $y }' "$1" | sort -n
}
for tool in meshstream meshopt cgal; do
  series "$error_rows" bunny_from_draco.bin "$tool" 5 8 >"$BENCH_DIR/err_bunny_$tool.dat"
  series "$error_rows" gen_1000000 "$tool" 5 8 >"$BENCH_DIR/err_1m_$tool.dat"
done
for tool in meshstream meshopt; do
  awk -F'\t' -v t="$tool" '$4 == t && $1 ~ /^gen_/ { print $2, $6, $7 / 1024 }' "$scaling_rows" | sort -n \
    >"$BENCH_DIR/scale_$tool.dat"
done
awk '{ print $1, $2, $3 / 1024 }' "$sort_rows" >"$BENCH_DIR/scale_sort.dat"

error_plot() {  # NAME TITLE
  gnuplot <<EOF
set terminal svg size 640,420 dynamic font "sans,12"
set output "$OUT_DIR/error_$1.svg"
set title "$2"
set logscale xy
set xlabel "output triangles"
set ylabel "RMS error, % of bounding-box diagonal"
set key top right
set grid
plot "$BENCH_DIR/err_$1_meshstream.dat" with linespoints lw 2 pt 7 title "meshstream decimate", \
     "$BENCH_DIR/err_$1_meshopt.dat" with linespoints lw 2 pt 5 title "meshoptimizer 1.2 simplifyWithUpdate", \
     "$BENCH_DIR/err_$1_cgal.dat" with linespoints lw 2 pt 9 title "CGAL Garland-Heckbert"
EOF
}
error_plot bunny "Stanford bunny (69 451 triangles)"
error_plot 1m "generated surface (1 M triangles)"

median_note="$RUNS runs"
[ "$LARGE_RUNS" = "$RUNS" ] || median_note="$RUNS runs, $LARGE_RUNS above $((LARGE / 1000000)) M"
gnuplot <<EOF
set terminal svg size 960,420 dynamic font "sans,12"
set output "$OUT_DIR/scaling.svg"
set multiplot layout 1,2
set logscale xy
set grid
set xlabel "input triangles"
set key top left
set title "time, file to file (median of $median_note)"
set ylabel "seconds"
plot "$BENCH_DIR/scale_meshstream.dat" using 1:2 with linespoints lw 2 pt 7 title "meshstream decimate -r 0.01 --threads $THREADS", \
     "$BENCH_DIR/scale_meshopt.dat" using 1:2 with linespoints lw 2 pt 5 title "meshoptimizer 1.2, 1 %", \
     "$BENCH_DIR/scale_sort.dat" using 1:2 with linespoints lw 2 pt 9 title "meshstream sort --memory 1G"
set title "peak resident memory"
set ylabel "MB"
plot "$BENCH_DIR/scale_meshstream.dat" using 1:3 with linespoints lw 2 pt 7 title "meshstream decimate -r 0.01 --threads $THREADS", \
     "$BENCH_DIR/scale_meshopt.dat" using 1:3 with linespoints lw 2 pt 5 title "meshoptimizer 1.2, 1 %", \
     "$BENCH_DIR/scale_sort.dat" using 1:3 with linespoints lw 2 pt 9 title "meshstream sort --memory 1G"
unset multiplot
EOF
echo "wrote $OUT_DIR/error_bunny.svg, error_1m.svg, scaling.svg and plots.tsv (load average during the run: $(cut -d' ' -f1-3 /proc/loadavg))" >&2
