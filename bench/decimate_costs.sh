#!/usr/bin/env bash
# Deterministic cost counts of `meshstream decimate`, for speed work on a machine whose timings
# drift (this one's do, by up to ±20 % within the hour): instructions, simulated last-level
# cache misses and simulated branch mispredictions per input triangle, from valgrind's
# cachegrind, with the functions they come from. The same build on the same mesh gives the same
# counts, so a change can be judged without timing it. First it prints this machine's memory
# latency (bench/memory_latency), which turns misses into time.
#
#   bench/decimate_costs.sh                    # the 1 M generated mesh at 10 %
#   SIZE=1000000 RATIO=0.01 bench/decimate_costs.sh
#
# Environment:
#   BENCH_DIR, BUILD_DIR  as bench/decimate.sh (the generated mesh is shared with it)
#   SIZE       generated mesh size in triangles (default 1000000)
#   RATIO      decimation ratio (default 0.1)
#   LL         simulated last-level cache as "bytes,ways,line" (default: one core's L2 from
#              getconf, else 2097152,16,64). The L2, not the L3: on this VM a random line
#              outside the L2 costs as much as DRAM (see the latency table).
#   TOP        functions listed per counter (default 8)
#   DECIMATE_ARGS  extra options for `meshstream decimate`
# Needs: cmake, g++, libmeshoptimizer-dev (the bench configuration), valgrind, python3.
# Runs the decimator about 40× slower than native: a few minutes for the 1 M mesh.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)

BENCH_DIR=${BENCH_DIR:-/tmp/meshstream-bench}
BUILD_DIR=${BUILD_DIR:-$BENCH_DIR/build}
SIZE=${SIZE:-1000000}
RATIO=${RATIO:-0.1}
TOP=${TOP:-8}
DECIMATE_ARGS=${DECIMATE_ARGS:-}

die() { echo "bench/decimate_costs.sh: $*" >&2; exit 1; }
command -v valgrind >/dev/null || die "valgrind is missing: apt-get install valgrind"
command -v python3 >/dev/null || die "python3 is missing"
if [ -z "${LL:-}" ]; then
  l2=$(getconf LEVEL2_CACHE_SIZE 2>/dev/null || echo 0)
  ways=$(getconf LEVEL2_CACHE_ASSOC 2>/dev/null || echo 0)
  line=$(getconf LEVEL2_CACHE_LINESIZE 2>/dev/null || echo 0)
  if [ "${l2:-0}" -gt 0 ] && [ "${ways:-0}" -gt 0 ] && [ "${line:-0}" -gt 0 ]; then
    LL="$l2,$ways,$line"
  else
    LL="2097152,16,64"
  fi
fi
mkdir -p "$BENCH_DIR"

echo "== building in $BUILD_DIR" >&2
cmake -S "$src" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DMESHSTREAM_BUILD_BENCH=ON -DMESHSTREAM_BUILD_TESTS=OFF >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target meshstream meshstream-gen memory_latency >/dev/null ||
  die "build failed (run: cmake --build $BUILD_DIR)"
ms=$BUILD_DIR/tools/meshstream

mesh=$BENCH_DIR/gen_$SIZE.stl
if [ ! -s "$mesh" ]; then
  echo "== generating $mesh" >&2
  "$BUILD_DIR/tools/meshstream-gen" --triangles "$SIZE" "$mesh"
fi

echo "== memory latency (random 64-byte lines, 2 MiB pages)"
"$BUILD_DIR/bench/memory_latency"

out=$BENCH_DIR/costs.cachegrind
echo "== cachegrind: decimate $(basename "$mesh") -r $RATIO $DECIMATE_ARGS (LL $LL)" >&2
# shellcheck disable=SC2086  # DECIMATE_ARGS is a list of options
valgrind --tool=cachegrind --cache-sim=yes --branch-sim=yes --LL="$LL" --cachegrind-out-file="$out" \
  "$ms" decimate "$mesh" "$BENCH_DIR/costs_out.stl" -r "$RATIO" $DECIMATE_ARGS \
  >"$BENCH_DIR/costs.log" 2>&1 || { cat "$BENCH_DIR/costs.log" >&2; die "decimate failed under valgrind"; }

python3 - "$out" "$BENCH_DIR/costs.log" "$TOP" <<'EOF'
import re, sys
path, log, top = sys.argv[1], sys.argv[2], int(sys.argv[3])
events, per_fn, summary, fn = [], {}, None, None
for line in open(path):
    if line.startswith("events:"):
        events = line.split()[1:]
    elif line.startswith("fn="):
        fn = line[3:].strip()
    elif line.startswith("summary:"):
        summary = [int(x) for x in line.split()[1:]]
    elif line[:1].isdigit() and fn is not None:
        counts = [int(x) for x in line.split()[1:]]
        acc = per_fn.setdefault(fn, [0] * len(events))
        for i, c in enumerate(counts):
            acc[i] += c
m = re.search(r"triangles in (\d+)", open(log).read())
if not m or summary is None:
    sys.exit("bench/decimate_costs.sh: no triangle count or summary in the valgrind output")
tris = int(m.group(1))
idx = {e: i for i, e in enumerate(events)}
def total(fields, counts):
    return sum(counts[idx[f]] for f in fields if f in idx)
counters = [("instructions", ["Ir"]), ("LL misses (read + write)", ["DLmr", "DLmw"]),
            ("branch mispredictions", ["Bcm", "Bim"])]
print(f"== per input triangle ({tris} triangles in)")
for name, fields in counters:
    print(f"  {name:28s} {total(fields, summary) / tris:10.1f}")
short = lambda f: re.sub(r"\(.*", "", f.replace("(anonymous namespace)::", "")).replace("meshstream::", "")
for name, fields in counters:
    print(f"== {name}: top {top} functions (share, per input triangle)")
    whole = total(fields, summary) or 1
    ranked = sorted(per_fn.items(), key=lambda kv: -total(fields, kv[1]))[:top]
    for f, c in ranked:
        n = total(fields, c)
        print(f"  {100 * n / whole:5.1f} %  {n / tris:9.1f}  {short(f)}")
EOF
