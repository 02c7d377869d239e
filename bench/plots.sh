#!/usr/bin/env bash
# The plots of the README and docs/results.md, drawn from docs/images/plots.tsv (the data of
# docs/results.md's "Plots" section: one row a figure, each with the commit and the machine it
# was measured on):
#   error_bunny.svg, error_1m.svg  RMS surface error (meshstream compare, % of the input's bounding-box
#                                  diagonal) against output triangle count for meshstream decimate,
#                                  meshoptimizer 1.2 simplifyWithUpdate and CGAL Garland-Heckbert
#                                  (bench/decimate.sh's references), on the bunny fixture and the
#                                  generated 1 M mesh;
#   scaling.svg                    decimate to 1 % (time and peak RSS; meshstream with each thread
#                                  count of the file, meshoptimizer 1.2; file to file) and
#                                  sort --memory 1G against input size.
# By default it measures every row here and now first, and rewrites plots.tsv with this commit
# and this machine; DRAW_ONLY=1 draws from plots.tsv as it is.
#
#   bench/plots.sh
#   DRAW_ONLY=1 bench/plots.sh
# Environment:
#   BENCH_DIR  work dir (default /tmp/meshstream-plots; about 6 GB with the 100 M mesh)
#   SIZES      input sizes of the scaling plot (default "1000000 10000000 100000000")
#   RATIOS     ratios of the error plots (default "0.5 0.2 0.1 0.05 0.02 0.01")
#   RUNS       runs per scaling point, median plotted (default 3)
#   LARGE_RUNS runs per scaling point above LARGE input triangles (default RUNS; LARGE default 20 M)
#   THREADS    decimate --threads of the scaling plot, one line each (default "1 2": one core, as
#              the in-core references, and two); the error plots use the first
#   OUT_DIR    where the SVGs go (default docs/images)
#   DATA       the data file (default docs/images/plots.tsv)
#   REUSE      1: keep the measurements an earlier run left in BENCH_DIR (the error rows; the
#              scaling rows of each size and thread count, the sort rows of each size), measuring
#              only what is missing (default 0)
#   DRAW_ONLY  1: measure nothing, draw from DATA (default 0)
# Needs what bench/decimate.sh needs, and gnuplot (Debian: gnuplot-nox).
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
BENCH_DIR=${BENCH_DIR:-/tmp/meshstream-plots}
SIZES=${SIZES:-"1000000 10000000 100000000"}
RATIOS=${RATIOS:-"0.5 0.2 0.1 0.05 0.02 0.01"}
RUNS=${RUNS:-3}
THREADS=${THREADS:-"1 2"}
LARGE=${LARGE:-20000000}
LARGE_RUNS=${LARGE_RUNS:-$RUNS}
runs_for() { if [ "$1" -gt "$LARGE" ]; then echo "$LARGE_RUNS"; else echo "$RUNS"; fi; }
REUSE=${REUSE:-0}
DRAW_ONLY=${DRAW_ONLY:-0}
OUT_DIR=${OUT_DIR:-docs/images}
DATA=${DATA:-docs/images/plots.tsv}
command -v gnuplot >/dev/null || { echo "bench/plots.sh: gnuplot is missing: apt-get install gnuplot-nox" >&2; exit 1; }
mkdir -p "$BENCH_DIR" "$OUT_DIR"

measure_all() {
  # shellcheck source=bench/lib.sh
  source "$src/bench/lib.sh"  # measure
  MEASURE_DIR=$BENCH_DIR
  local first_threads
  first_threads=$(echo "$THREADS" | cut -d' ' -f1)

  # 1. Error against triangle count: one run each (the error is deterministic, time is not plotted).
  local error_rows=$BENCH_DIR/error/results.tsv
  if [ "$REUSE" != 1 ] || [ ! -s "$error_rows" ]; then
    BUILD_DIR=$BENCH_DIR/build BENCH_DIR=$BENCH_DIR/error SIZES=1000000 RATIOS=$RATIOS RUNS=1 CORPUS=0 \
      THREADS=$first_threads bash bench/decimate.sh >"$BENCH_DIR/error.txt"
  fi

  # 2. Decimate to 1 % against input size, medians of RUNS (LARGE_RUNS), no compare (speed and
  # memory only), one size at a time: bench/decimate.sh with the first thread count (meshstream
  # and meshoptimizer; it generates the mesh), then meshstream alone with each further one.
  # Rows: name, triangles, ratio, tool, threads, output triangles, seconds, rss kB.
  local scaling_rows=$BENCH_DIR/scaling.tsv
  [ "$REUSE" = 1 ] && [ -s "$scaling_rows" ] || : >"$scaling_rows"
  local ms=$BENCH_DIR/build/tools/meshstream
  for n in $SIZES; do
    local runs
    runs=$(runs_for "$n")
    if ! grep -q "^gen_$n	" "$scaling_rows"; then
      BUILD_DIR=$BENCH_DIR/build BENCH_DIR=$BENCH_DIR/scaling SIZES=$n RATIOS=0.01 RUNS=$runs CGAL_MAX=0 \
        COMPARE=0 CORPUS=0 THREADS=$first_threads bash bench/decimate.sh >>"$BENCH_DIR/scaling.txt"
      awk -F'\t' -v OFS='\t' -v t="$first_threads" '$1 ~ /^gen_/ {
          print $1, $2, $3, $4, ($4 == "meshstream" ? t : 1), $5, $6, $7 }' \
        "$BENCH_DIR/scaling/results.tsv" >>"$scaling_rows"
    fi
    local in=$BENCH_DIR/scaling/gen_$n.stl out=$BENCH_DIR/scaling/threads_out.stl
    local triangles
    triangles=$(awk -F'\t' -v n="gen_$n" '$1 == n { print $2; exit }' "$scaling_rows")
    for t in $THREADS; do
      [ "$t" = "$first_threads" ] && continue
      grep -q "^gen_$n	[^	]*	[^	]*	meshstream	$t	" "$scaling_rows" && continue
      for ((r = 0; r < runs; r++)); do
        measure "$ms" -q decimate --threads "$t" "$in" "$out" --ratio 0.01
      done | sort -n | awk -v runs="$runs" 'NR == int((runs + 1) / 2)' >"$BENCH_DIR/threads_median.txt"
      local out_n
      out_n=$("$ms" -q info --json "$out" | python3 -c 'import json,sys; print(json.load(sys.stdin)["triangles"])')
      awk -F'\t' -v OFS='\t' -v n="gen_$n" -v tri="$triangles" -v t="$t" -v o="$out_n" \
        '{ print n, tri, 0.01, "meshstream", t, o, $1, $3 }' "$BENCH_DIR/threads_median.txt" >>"$scaling_rows"
      rm -f "$out"
    done
  done

  # 3. Sort throughput on the same generated meshes (written in generator order; sort along the
  # longest axis), median of RUNS by wall time.
  local sort_rows=$BENCH_DIR/sort.tsv
  [ "$REUSE" = 1 ] && [ -s "$sort_rows" ] || : >"$sort_rows"
  for n in $SIZES; do
    grep -q "^$n " "$sort_rows" && continue
    local in=$BENCH_DIR/scaling/gen_$n.stl runs
    runs=$(runs_for "$n")
    for ((r = 0; r < runs; r++)); do
      rm -f "$BENCH_DIR/sorted.stl"
      /usr/bin/time -f "%e %M" -o "$BENCH_DIR/time.txt" "$ms" -q sort --memory 1G "$in" "$BENCH_DIR/sorted.stl"
      echo "$n $(cat "$BENCH_DIR/time.txt")"
    done | sort -k2 -n | awk -v runs="$runs" 'NR == int((runs + 1) / 2)' >>"$sort_rows"
    rm -f "$BENCH_DIR/sorted.stl"
  done

  # The data file. Columns of decimate.sh's results.tsv: name, triangles, ratio, tool, out
  # triangles, seconds, rss kB, rms %, max %, rms, max.
  local commit machine median_note
  commit=$(git describe --always --dirty 2>/dev/null || echo '?')
  machine="$(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores, $(free -g | awk '/^Mem:/ { print $2 }') GiB"
  median_note="median of $RUNS runs"
  [ "$LARGE_RUNS" = "$RUNS" ] || median_note="median of $RUNS runs, $LARGE_RUNS above $((LARGE / 1000000)) M"
  {
    echo "# bench/plots.sh THREADS=\"$THREADS\" RUNS=$RUNS LARGE_RUNS=$LARGE_RUNS at $commit, $(date -u +%F); load average at the end $(load)"
    echo "# plot	input	input triangles	ratio	tool	threads	output triangles	seconds	peak RSS MiB	RMS % of diagonal	Hausdorff % of diagonal	commit	machine	note"
    awk -F'\t' -v OFS='\t' -v c="$commit" -v m="$machine" -v t="$first_threads" '{
        print "error", $1, $2, $3, $4, ($4 == "meshstream" ? t : 1), $5, $6, sprintf("%.1f", $7 / 1024), $8, $9, c, m, "one run" }' \
      "$error_rows"
    awk -F'\t' -v OFS='\t' -v c="$commit" -v m="$machine" -v note="wall, $median_note" '{
        print "scaling", $1, $2, $3, $4, $5, $6, $7, sprintf("%.1f", $8 / 1024), "-", "-", c, m, note }' "$scaling_rows"
    awk -v OFS='\t' -v c="$commit" -v m="$machine" -v note="wall, $median_note" '{
        print "sort", "gen_" $1, $1, "-", "meshstream sort --memory 1G", 1, $1, $2, sprintf("%.1f", $3 / 1024), "-", "-", c, m, note }' \
      "$sort_rows"
  } >"$DATA"
}

[ "$DRAW_ONLY" = 1 ] || measure_all
[ -s "$DATA" ] || { echo "bench/plots.sh: no data in $DATA" >&2; exit 1; }

# gnuplot input: one block per line of a plot. Rows whose figure is "-" are left out (a row may
# give only the time or only the memory of a point).
rows() {  # PLOT TOOL THREADS(or *) INPUT(or *) COLUMN_X COLUMN_Y
  awk -F'\t' -v p="$1" -v t="$2" -v th="$3" -v input="$4" -v x="$5" -v y="$6" \
    '!/^#/ && $1 == p && $5 == t && (th == "*" || $6 == th) && (input == "*" || $2 == input) && $y != "-" { print $x, $y }' \
    "$DATA" | sort -n
}
commits() {  # PLOT TOOL THREADS: the commits of a line's rows, in order of first appearance
  awk -F'\t' -v p="$1" -v t="$2" -v th="$3" '!/^#/ && $1 == p && $5 == t && (th == "*" || $6 == th) && !seen[$12]++ {
      printf "%s%s", (n++ ? ", " : ""), $12 }' "$DATA"
}
for tool in meshstream meshopt cgal; do
  rows error "$tool" "*" bunny_from_draco.bin 7 10 >"$BENCH_DIR/err_bunny_$tool.dat"
  rows error "$tool" "*" gen_1000000 7 10 >"$BENCH_DIR/err_1m_$tool.dat"
done

error_plot() {  # NAME TITLE
  local note="meshstream --threads $(awk -F'\t' '!/^#/ && $1 == "error" && $5 == "meshstream" { print $6; exit }' "$DATA");"
  note="$note measured at $(commits error meshstream "*") (docs/results.md)"
  gnuplot <<EOF
set terminal svg size 640,440 dynamic font "sans,12"
set output "$OUT_DIR/error_$1.svg"
set title "$2"
set logscale xy
set xlabel "output triangles"
set ylabel "RMS error, % of bounding-box diagonal"
set key top right
set grid
set label 1 "$note" at screen 0.02, 0.02 font "sans,10"
set bmargin 5
plot "$BENCH_DIR/err_$1_meshstream.dat" with linespoints lw 2 pt 7 title "meshstream decimate", \
     "$BENCH_DIR/err_$1_meshopt.dat" with linespoints lw 2 pt 5 title "meshoptimizer 1.2 simplifyWithUpdate", \
     "$BENCH_DIR/err_$1_cgal.dat" with linespoints lw 2 pt 9 title "CGAL Garland-Heckbert"
EOF
}
error_plot bunny "Stanford bunny (69 451 triangles)"
error_plot 1m "generated surface (1 M triangles)"

# The scaling plot: one line per thread count of meshstream's rows, meshoptimizer, sort; the
# legend below both panels, each line with the commits its points were measured at.
plots_time=() plots_rss=()
add_line() {  # PLOT TOOL THREADS TITLE POINT_TYPE
  local f=$BENCH_DIR/scale_${1}_${2// /_}_$3
  rows "$1" "$2" "$3" "*" 3 8 >"$f.time"
  rows "$1" "$2" "$3" "*" 3 9 >"$f.rss"
  local title="$4 ($(commits "$1" "$2" "$3"))"
  plots_time+=("\"$f.time\" using 1:2 with linespoints lw 2 pt $5 title \"$title\"")
  plots_rss+=("\"$f.rss\" using 1:2 with linespoints lw 2 pt $5 notitle")
}
pt=7
for t in $(awk -F'\t' '!/^#/ && $1 == "scaling" && $5 == "meshstream" { print $6 }' "$DATA" | sort -un); do
  # The default is every core: say so on the line whose thread count is its machine's core count.
  cores=$(awk -F'\t' -v t="$t" '!/^#/ && $1 == "scaling" && $5 == "meshstream" && $6 == t {
      if (match($13, /[0-9]+ cores/)) { print substr($13, RSTART, RLENGTH - 6); exit } }' "$DATA")
  title="meshstream decimate -r 0.01 --threads $t"
  [ "$t" = "$cores" ] && title="$title (the default: every core)"
  add_line scaling meshstream "$t" "$title" "$pt"
  pt=$((pt == 7 ? 13 : pt + 2))
done
add_line scaling meshopt 1 "meshoptimizer 1.2, 1 %" 5
add_line sort "meshstream sort --memory 1G" 1 "meshstream sort --memory 1G" 9
join_plots() { local IFS=','; echo "$*"; }
lines=${#plots_time[@]}
gnuplot <<EOF
set terminal svg size 960,$((400 + 22 * lines)) dynamic font "sans,12"
set output "$OUT_DIR/scaling.svg"
set multiplot
set logscale xy
set grid
set xlabel "input triangles"
set xrange [5e5:2e8]
set xtics ("1 M" 1e6, "10 M" 1e7, "100 M" 1e8)
set bmargin at screen $(awk -v l="$lines" 'BEGIN { printf "%.3f", (40 + 22 * l) / (400 + 22 * l) + 0.07 }')
set tmargin at screen 0.93
set key at screen 0.5, 0.01 center bottom vertical maxrows $lines Left reverse samplen 3
set lmargin at screen 0.08
set rmargin at screen 0.48
set title "time, file to file (docs/results.md)"
set ylabel "seconds"
plot $(join_plots "${plots_time[@]}")
unset key
set lmargin at screen 0.58
set rmargin at screen 0.98
set title "peak resident memory"
set ylabel "MiB"
plot $(join_plots "${plots_rss[@]}")
unset multiplot
EOF
echo "wrote $OUT_DIR/error_bunny.svg, error_1m.svg, scaling.svg from $DATA" >&2
