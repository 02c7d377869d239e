#!/usr/bin/env bash
# Attribute-aware decimation benchmark: `meshstream decimate --threads 1` next to meshoptimizer
# 1.2 (`bench/ref_meshopt --attributes`: whole mesh in memory, corners welded by position,
# colour and normal, `simplifyWithUpdate` with colour RGB (0..1) and normals as attributes of
# weight 1) at the same triangle count, on the same inputs in the same run:
#   - a generated coloured mesh (`meshstream-gen --color`, PLY) at 10 % and 1 %;
#   - the corpus's normal-carrying scans at 10 %: elephant_normals (5558 triangles) and the
#     bunny with normals (bunny_from_draco.binary_le.ply, 69451 triangles);
# with meshoptimizer's positions-only `simplifyWithUpdate` (`ref_meshopt`, tool meshopt-geo) as
# the geometric reference of the decimator's own bound. Per case and tool: the median of RUNS
# runs (tools alternated run by run, so that a change in the machine's load reaches all alike)
# of wall time and peak RSS, and the error of the output against the input from `meshstream
# compare --json` (deterministic, run once): geometric symmetric RMS in % of the bbox diagonal
# and, where compare has --attributes, the symmetric colour error (Euclidean RGB distance, 0..1;
# RMS and max) and normal error (degrees; RMS and max). A second table gives meshstream /
# meshoptimizer for each error (the targets: colour and normal RMS at most 1.1×) and the
# geometric RMS over meshopt-geo's.
# Then the cost of the colour channel: a generated coloured mesh of N10M triangles decimated to
# 1 % by meshstream with its colours and with `--drop colors` (positions only), alternated,
# medians of RUNS: wall time, CPU time, peak RSS and coloured / positions-only (target: at most
# 1.5× for time and memory). The load average before and after is printed: the machine may be
# shared, and wall times mean little when it is busy.
#
#   bench/attributes.sh                           # 1 M and 10 M coloured meshes, 3 runs
#   N1M=100000 N10M=1000000 RUNS=1 bench/attributes.sh   # a quick check
#
# Environment:
#   BENCH_DIR  work dir for meshes and outputs (default /tmp/meshstream-bench; about 0.5 GB)
#   BUILD_DIR  build dir, configured here with -DMESHSTREAM_BUILD_BENCH=ON (default $BENCH_DIR/build)
#   SHARED     the shared directory with peers/meshoptimizer-1.2 and corpus/ (default ../shared)
#   N1M        triangles of the coloured mesh compared with meshoptimizer (default 1000000)
#   RATIOS     its decimation ratios (default "0.1 0.01")
#   N10M       triangles of the coloured mesh of the cost rows (default 10000000; 0: no cost rows)
#   COST_RATIO decimation ratio of the cost rows (default 0.01)
#   SCANS      1 (default) for the elephant and bunny rows, 0 to leave them out
#   RUNS       runs per measurement, median reported (default 3)
#   DECIMATE_ARGS  extra options for `meshstream decimate` (e.g. "--weights color=2")
# Needs: cmake, g++, the meshoptimizer 1.2 source in $SHARED/peers, GNU time (/usr/bin/time,
# Debian package `time`) and python3.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)

BENCH_DIR=${BENCH_DIR:-/tmp/meshstream-bench}
BUILD_DIR=${BUILD_DIR:-$BENCH_DIR/build}
SHARED=${SHARED:-$src/../shared}
N1M=${N1M:-1000000}
RATIOS=${RATIOS:-"0.1 0.01"}
N10M=${N10M:-10000000}
COST_RATIO=${COST_RATIO:-0.01}
SCANS=${SCANS:-1}
RUNS=${RUNS:-3}
DECIMATE_ARGS=${DECIMATE_ARGS:-}

# shellcheck source=bench/lib.sh
source "$src/bench/lib.sh"  # die, measure, load; checks for GNU time and python3
SHARED=$(cd "$SHARED" 2>/dev/null && pwd) || die "no shared directory (set SHARED)"
mkdir -p "$BENCH_DIR"

echo "== building in $BUILD_DIR" >&2
cmake -S "$src" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DMESHSTREAM_BUILD_BENCH=ON -DMESHSTREAM_BUILD_TESTS=OFF \
  -DMESHSTREAM_SHARED="$SHARED" >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target meshstream meshstream-gen ref_meshopt >/dev/null ||
  die "build failed (run: cmake --build $BUILD_DIR --target meshstream meshstream-gen ref_meshopt)"
ms=$BUILD_DIR/tools/meshstream
gen=$BUILD_DIR/tools/meshstream-gen
ref_meshopt=$BUILD_DIR/bench/ref_meshopt
"$ms" decimate --help | grep -q -- --weights || die "'meshstream decimate' has no --weights: it carries no attributes"
if "$ms" compare --help | grep -q -- --attributes; then
  attributes=1
else
  attributes=0
  echo "bench/attributes.sh: 'meshstream compare' has no --attributes in this build: geometric error only" >&2
fi

triangles_of() { "$ms" -q info --json "$1" | python3 -c 'import json,sys; print(json.load(sys.stdin)["triangles"])'; }

coloured_mesh() {  # N: prints the path of a coloured generated mesh of about N triangles (made once)
  local f=$BENCH_DIR/attr_color_$1.ply
  if [ ! -s "$f" ]; then
    echo "== generating $f" >&2
    "$gen" -q --color -n "$1" "$f"
  fi
  echo "$f"
}

# Cases: name, input, ratio.
cases=()
if [ "$N1M" != 0 ]; then
  for ratio in $RATIOS; do cases+=("color_$N1M $(coloured_mesh "$N1M") $ratio"); done
fi
if [ "$SCANS" = 1 ]; then
  for scan in elephant_normals.binary_be bunny_from_draco.binary_le; do
    f=$SHARED/corpus/ply/$scan.ply
    [ -s "$f" ] || die "no $f (set SHARED)"
    cases+=("${scan%%.*} $f 0.1")
  done
fi

MEASURE_DIR=$BENCH_DIR
runs=$BENCH_DIR/attr_runs.tsv.$$
results=$BENCH_DIR/attributes.tsv
warnings=$BENCH_DIR/attr_warnings.txt
: >"$runs"
: >"$results"
: >"$warnings"
trap 'rm -f "$runs"' EXIT
load_before=$(load)

# keep_warnings LABEL: the measured command's stderr (meshstream -q prints only warnings), once per label.
keep_warnings() {
  if [ -s "$BENCH_DIR/cmd.err" ] && ! grep -q "^$1:" "$warnings"; then sed "s|^|$1: |" "$BENCH_DIR/cmd.err" >>"$warnings"; fi
}

# errors_of INPUT OUTPUT ATTRIBUTES: prints "rms_pct<TAB>color_rms<TAB>color_max<TAB>normal_rms<TAB>normal_max"
# ("-": not measured); ATTRIBUTES 0 for a positions-only output (compare refuses --attributes there).
errors_of() {
  local flag=()
  if [ "$attributes" = 1 ] && [ "$3" = 1 ]; then flag=(--attributes); fi
  "$ms" -q compare --json "${flag[@]}" "$1" "$2" >"$BENCH_DIR/attr_compare.json" 2>"$BENCH_DIR/attr_compare.err" ||
    { cat "$BENCH_DIR/attr_compare.err" >&2; die "compare failed: $1 $2"; }
  python3 - "$BENCH_DIR/attr_compare.json" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))["symmetric"]
def fig(channel, key):
    c = s.get(channel)
    return "-" if not c or c.get(key) is None else "%.6g" % c[key]
print("\t".join(["%.6f" % s["rms_pct"], fig("color", "rms"), fig("color", "max"),
                 fig("normal_degrees", "rms"), fig("normal_degrees", "max")]))
EOF
}

for c in "${cases[@]}"; do
  read -r name in ratio <<<"$c"
  n=$(triangles_of "$in")
  target=$(python3 -c "print(round($ratio * $n))")
  for ((r = 0; r < RUNS; r++)); do
    for tool in meshstream meshopt meshopt-geo; do
      out=$BENCH_DIR/attr_${name}_${ratio}_$tool.ply
      case $tool in
        meshstream) m=$(measure "$ms" -q decimate $DECIMATE_ARGS --threads 1 "$in" "$out" --target "$target") ;;
        meshopt) m=$(measure "$ref_meshopt" "$in" "$out" --target "$target" --attributes) ;;
        meshopt-geo) m=$(measure "$ref_meshopt" "$in" "$out" --target "$target") ;;
      esac
      [ "$tool" = meshstream ] && keep_warnings "$name $ratio meshstream decimate"
      echo "== $tool $name ratio $ratio run $((r + 1)): $m" >&2
      printf '%s\t%s\t%s\t%s\n' "$name" "$ratio" "$tool" "$m" >>"$runs"
    done
  done
  for tool in meshstream meshopt meshopt-geo; do
    out=$BENCH_DIR/attr_${name}_${ratio}_$tool.ply
    echo "== compare $name ratio $ratio $tool" >&2
    e=$(errors_of "$in" "$out" "$([ "$tool" = meshopt-geo ] && echo 0 || echo 1)")
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$name" "$n" "$ratio" "$tool" "$target" "$(triangles_of "$out")" "$e" >>"$results"
  done
done

cost=$BENCH_DIR/attr_cost.tsv
: >"$cost"
if [ "$N10M" != 0 ]; then
  in=$(coloured_mesh "$N10M")
  n=$(triangles_of "$in")
  for ((r = 0; r < RUNS; r++)); do
    for variant in coloured positions; do
      out=$BENCH_DIR/attr_cost_$variant.ply
      drop=()
      if [ "$variant" = positions ]; then drop=(--drop colors); fi
      m=$(measure "$ms" -q decimate $DECIMATE_ARGS --threads 1 "${drop[@]}" "$in" "$out" --ratio "$COST_RATIO")
      keep_warnings "cost $variant meshstream decimate"
      echo "== cost $variant $n ratio $COST_RATIO run $((r + 1)): $m" >&2
      printf '%s\t%s\t%s\t%s\n' "$n" "$COST_RATIO" "$variant" "$m" >>"$cost"
    done
  done
fi
load_after=$(load)

python3 - "$results" "$runs" "$cost" "$RUNS" "$load_before" "$load_after" "$attributes" <<'EOF'
import statistics, sys
results, runs_file, cost_file, runs, before, after, attributes = sys.argv[1:]
def medians(rows):
    out = {}
    for *key, wall, cpu, rss in rows:
        out.setdefault(tuple(key), []).append((float(wall), float(cpu), float(rss)))
    return {k: tuple(statistics.median(x[i] for x in v) for i in range(3)) for k, v in out.items()}
def table(head, rows):
    widths = [max(len(str(r[i])) for r in rows + [head]) for i in range(len(head))]
    print("| " + " | ".join(h.ljust(w) for h, w in zip(head, widths)) + " |")
    print("|-" + "-|-".join("-" * w for w in widths) + "-|")
    for r in rows:
        print("| " + " | ".join(str(c).ljust(w) for c, w in zip(r, widths)) + " |")
    print()
read = lambda f: [l.rstrip("\n").split("\t") for l in open(f) if l.strip()]
med = medians(read(runs_file))
rows = read(results)
print(f"median of {runs} runs (alternated); load average (1/5/15 min) before: {before}, after: {after}")
print("meshstream: decimate --threads 1 --target T; meshopt: ref_meshopt --attributes (simplifyWithUpdate, "
      "colour RGB 0..1 and normals, weight 1) --target T; meshopt-geo: ref_meshopt (positions only)")
print("errors: meshstream compare [--attributes] --json against the input, symmetric; geometric RMS in % of the "
      "bbox diagonal, colour: Euclidean RGB distance (0..1), normal: angle in degrees")
if attributes != "1":
    print("(this build's compare has no --attributes: no colour or normal error)")
print()
out = []
for name, n, ratio, tool, target, out_n, rms, crms, cmax, nrms, nmax in rows:
    wall, cpu, rss = med[(name, ratio, tool)]
    out.append([name, n, ratio, tool, target, out_n, f"{wall:.3f}", f"{rss / 1024:.0f}", rms, crms, cmax, nrms, nmax])
table(["input", "triangles", "ratio", "tool", "target", "out", "wall s", "peak RSS MB", "geo RMS %",
       "colour RMS", "colour max", "normal RMS °", "normal max °"], out)
by = {(r[0], r[2], r[3]): r for r in rows}
ratio_rows = []
def q(a, b):
    return "-" if a == "-" or b == "-" or float(b) == 0 else f"{float(a) / float(b):.3f}"
for name, n, ratio, tool, *_ in rows:
    if tool != "meshstream" or (name, ratio, "meshopt") not in by:
        continue
    a, b = by[(name, ratio, "meshstream")], by[(name, ratio, "meshopt")]
    g = by.get((name, ratio, "meshopt-geo"))
    wa, wb = med[(name, ratio, "meshstream")], med[(name, ratio, "meshopt")]
    ratio_rows.append([name, ratio, q(a[6], b[6]), q(a[7], b[7]), q(a[8], b[8]), q(a[9], b[9]), q(a[10], b[10]),
                       f"{wa[0] / wb[0]:.2f}", f"{wa[2] / wb[2]:.2f}", q(a[6], g[6]) if g else "-"])
print("meshstream / meshopt (colour and normal RMS target: at most 1.1); last column: meshstream's geometric RMS "
      "over meshopt-geo's")
table(["input", "ratio", "geo RMS", "colour RMS", "colour max", "normal RMS", "normal max", "wall", "peak RSS",
       "geo RMS / meshopt-geo"], ratio_rows)
cost = read(cost_file)
if cost:
    cm = medians(cost)
    print("cost of the colour channel: meshstream decimate --threads 1, coloured input, with its colours and with "
          "--drop colors (target: at most 1.5 for time and memory)")
    crows = []
    for (n, ratio, variant), (wall, cpu, rss) in cm.items():
        crows.append([n, ratio, variant, f"{wall:.2f}", f"{cpu:.2f}", f"{rss / 1024:.0f}"])
    pw, pc, pr = cm[(cost[0][0], cost[0][1], "positions")]
    cw, cc, cr = cm[(cost[0][0], cost[0][1], "coloured")]
    crows.append(["", "", "coloured / positions", f"{cw / pw:.2f}", f"{cc / pc:.2f}", f"{cr / pr:.2f}"])
    table(["triangles", "ratio", "variant", "wall s", "CPU s", "peak RSS MB"], crows)
EOF
if [ -s "$warnings" ]; then
  echo "meshstream printed (first run of each case):"
  cat "$warnings"
fi
echo "(raw rows: $results, $cost)" >&2
