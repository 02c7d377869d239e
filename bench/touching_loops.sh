#!/usr/bin/env bash
# Boundary loops that touch at vertices (issue 40): `meshstream decimate --threads 1` beside
# meshoptimizer 1.2 (bench/ref_meshopt) and CGAL (bench/ref_cgal) on meshes whose holes' loops
# meet at shared vertices, at the same target counts. Prints, per input, ratio and tool: output
# triangles, boundary edges left, symmetric RMS and Hausdorff distance (% of the bounding-box
# diagonal, `meshstream compare --json`; deterministic, run once) and the median wall time of
# RUNS runs.
#
#   bench/touching_loops.sh [BUILD_DIR]     # default build/, configured with -DMESHSTREAM_BUILD_BENCH=ON
#
# Environment: RUNS (default 3), RATIOS (default "0.25 0.1 0.01"), WORK (default a temp dir),
# INPUTS (default: meshstream-gen -n 17000 --hole-chains and -n 1000000 --touching-holes).
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
build=$(cd "${1:-build}" && pwd)
RUNS=${RUNS:-3}
RATIOS=${RATIOS:-"0.25 0.1 0.01"}
# shellcheck source=bench/lib.sh
source "$src/bench/lib.sh"
ms=$build/tools/meshstream
gen=$build/tools/meshstream-gen
for x in "$ms" "$gen" "$build/bench/ref_meshopt" "$build/bench/ref_cgal"; do
  [ -x "$x" ] || die "no $x (configure $build with -DMESHSTREAM_BUILD_BENCH=ON and build it)"
done
WORK=${WORK:-$(mktemp -d "${TMPDIR:-/tmp}/touching_loops.XXXXXX")}
MEASURE_DIR=$WORK
mkdir -p "$WORK"
if [ -z "${INPUTS:-}" ]; then
  "$gen" -q -n 17000 --hole-chains "$WORK/chains_17k.stl"
  "$gen" -q -n 1000000 --touching-holes "$WORK/touching_1m.stl"
  INPUTS="$WORK/chains_17k.stl $WORK/touching_1m.stl"
fi
echo "# load before: $(load)"
printf 'input\tratio\ttool\ttriangles\tboundary_edges\trms_pct\thausdorff_pct\twall_s\n'
for in in $INPUTS; do
  n=$("$ms" info --json "$in" | python3 -c 'import json, sys; print(json.load(sys.stdin)["triangles"])')
  for r in $RATIOS; do
    t=$(python3 -c "print(round($r * $n))")
    for tool in meshstream meshopt cgal; do
      out=$WORK/out_${tool}.stl
      case $tool in
        meshstream) cmd=("$ms" decimate -q "$in" "$out" --target "$t" --threads 1) ;;
        meshopt) cmd=("$build/bench/ref_meshopt" "$in" "$out" --target "$t") ;;
        cgal) cmd=("$build/bench/ref_cgal" "$in" "$out" --target "$t") ;;
      esac
      walls=()
      for _ in $(seq "$RUNS"); do walls+=("$(measure "${cmd[@]}" | cut -f1)"); done
      wall=$(printf '%s\n' "${walls[@]}" | sort -g | awk '{ a[NR] = $0 } END { print a[int((NR + 1) / 2)] }')
      "$ms" compare --json "$in" "$out" | python3 -c '
import json, sys
j = json.load(sys.stdin); s = j["symmetric"]
print("\t".join([sys.argv[1], sys.argv[2], sys.argv[3], str(j["b"]["triangles"]), str(j["b"]["boundary_edges"]),
                 "%.5f" % s["rms_pct"], "%.4f" % s["max_pct"], sys.argv[4]]))' "$(basename "$in")" "$r" "$tool" "$wall"
    done
  done
done
echo "# load after: $(load)"
