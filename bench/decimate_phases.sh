#!/usr/bin/env bash
# Where the decimator's time goes on this machine: a build with MESHSTREAM_PHASE_TIMERS (time-
# stamp counter scopes around READ, queue upkeep, rating, validation, applying and writing) run on a
# generated mesh, in alternation with the normal bench build, so the timers' own cost shows as
# the difference of the two median wall times. Prints the median share and ticks per call of
# each phase. bench/decimate_costs.sh counts instructions and cache misses exactly; this shows
# what they cost in time.
#
#   bench/decimate_phases.sh                   # the 1 M generated mesh at 10 %, 5 runs each
#   RUNS=3 RATIO=0.01 bench/decimate_phases.sh
#
# Environment:
#   BENCH_DIR, BUILD_DIR  as bench/decimate.sh (the generated mesh is shared with it); the timed
#              build goes to $BENCH_DIR/build-phases
#   SIZE       generated mesh size in triangles (default 1000000)
#   RATIO      decimation ratio (default 0.1)
#   RUNS       runs of each build (default 5)
#   DECIMATE_ARGS  extra options for `meshstream decimate`
# Needs: cmake, g++, libmeshoptimizer-dev (the bench configuration), python3.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)

BENCH_DIR=${BENCH_DIR:-/tmp/meshstream-bench}
BUILD_DIR=${BUILD_DIR:-$BENCH_DIR/build}
PHASE_DIR=$BENCH_DIR/build-phases
SIZE=${SIZE:-1000000}
RATIO=${RATIO:-0.1}
RUNS=${RUNS:-5}
DECIMATE_ARGS=${DECIMATE_ARGS:-}

die() { echo "bench/decimate_phases.sh: $*" >&2; exit 1; }
command -v python3 >/dev/null || die "python3 is missing"
[[ "$RUNS" =~ ^[1-9][0-9]*$ ]] || die "RUNS must be a positive integer, not '$RUNS'"
mkdir -p "$BENCH_DIR"

echo "== building $BUILD_DIR and $PHASE_DIR" >&2
for dir in "$BUILD_DIR" "$PHASE_DIR"; do
  timers=OFF
  [ "$dir" = "$PHASE_DIR" ] && timers=ON
  cmake -S "$src" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DMESHSTREAM_BUILD_BENCH=ON -DMESHSTREAM_BUILD_TESTS=OFF \
    -DMESHSTREAM_PHASE_TIMERS=$timers >/dev/null
  cmake --build "$dir" -j"$(nproc)" --target meshstream meshstream-gen >/dev/null ||
    die "build failed (run: cmake --build $dir)"
done

mesh=$BENCH_DIR/gen_$SIZE.stl
if [ ! -s "$mesh" ]; then
  echo "== generating $mesh" >&2
  "$BUILD_DIR/tools/meshstream-gen" --triangles "$SIZE" "$mesh"
fi

logs=$BENCH_DIR/phases
rm -rf "$logs"
mkdir -p "$logs"
for i in $(seq "$RUNS"); do
  for kind in plain timed; do
    bin=$BUILD_DIR/tools/meshstream
    [ $kind = timed ] && bin=$PHASE_DIR/tools/meshstream
    echo "== run $i/$RUNS ($kind): decimate --threads 1 $(basename "$mesh") -r $RATIO $DECIMATE_ARGS" >&2
    # One decimator: the phase timers are one set for the process, which ranges on several
    # threads would mix.
    # shellcheck disable=SC2086  # DECIMATE_ARGS is a list of options
    "$bin" decimate --threads 1 "$mesh" "$BENCH_DIR/phases_out.stl" -r "$RATIO" $DECIMATE_ARGS 2>"$logs/$kind.$i" >/dev/null ||
      { cat "$logs/$kind.$i" >&2; die "decimate failed"; }
  done
done

python3 - "$logs" "$RUNS" <<'EOF'
import glob, re, statistics as st, sys
logs, runs = sys.argv[1], int(sys.argv[2])
def wall(kind):
    out = []
    for path in glob.glob(f"{logs}/{kind}.*"):
        m = re.search(r"time ([0-9.]+) s", open(path).read())
        if not m:
            sys.exit(f"bench/decimate_phases.sh: no time in {path}")
        out.append(float(m.group(1)))
    return out
plain, timed = wall("plain"), wall("timed")
print(f"== wall time, median of {runs}: without timers {st.median(plain):.3f} s, "
      f"with timers {st.median(timed):.3f} s ({st.median(timed) / st.median(plain):.2f}x)")
rows = {}
for path in glob.glob(f"{logs}/timed.*"):
    for line in open(path):
        m = re.match(r"\s+(\w+)\s+(\d+) calls\s+([0-9.]+) ticks/call\s+([0-9.]+) %", line)
        if m:
            rows.setdefault(m.group(1), []).append((int(m.group(2)), float(m.group(3)), float(m.group(4))))
        m = re.match(r"\s+other\s+([0-9.-]+) %", line)
        if m:
            rows.setdefault("other", []).append((0, 0.0, float(m.group(1))))
if not rows:
    sys.exit("bench/decimate_phases.sh: the timed build printed no phase report")
print("== phases of the timed build, medians (queue excludes the rating, validation and applying it contains)")
print(f"  {'phase':9s} {'calls':>11s} {'ticks/call':>11s} {'share':>7s}")
for name in ["read", "queue", "rate", "validate", "apply", "write", "other"]:
    r = rows.get(name, [])
    if r:
        print(f"  {name:9s} {st.median(x[0] for x in r):11.0f} {st.median(x[1] for x in r):11.0f} "
              f"{st.median(x[2] for x in r):6.1f} %")
EOF
