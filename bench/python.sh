#!/usr/bin/env bash
# The Python package against its yardsticks (docs/python.md; the figures in docs/results.md):
#   - meshstream.read of an N-triangle binary PLY and of the same mesh as OBJ, against
#     open3d.io.read_triangle_mesh and meshio.read of the same files;
#   - iterating meshstream.chunks over an N-triangle binary STL, against `meshstream info` (the
#     C++ read loop) on it;
#   - meshstream.decimate from Python against `meshstream decimate` with the same options, and
#     their outputs compared byte for byte.
# Each figure is a whole process (interpreter start and imports included) under GNU time, the
# median of $RUNS (default 3) runs, a tool's runs just before its yardstick's. The meshes come from
# meshstream-gen (one connected surface, welded in the PLY and OBJ), in the work directory.
#
# Usage: bench/python.sh [N triangles (default 10000000)] [build dir (default build)] [work dir]
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
n=${1:-10000000}
build=$(cd "${2:-$here/../build}" && pwd)
work=$(mktemp -d "${3:-${TMPDIR:-/tmp}}/python_bench.XXXXXX")
trap 'rm -rf "$work"' EXIT
MEASURE_DIR=$work
meshstream=$build/tools/meshstream
gen=$build/tools/meshstream-gen
python=${PYTHON:-/usr/bin/python3}
export PYTHONPATH=$build/python${PYTHONPATH:+:$PYTHONPATH}
[ -x "$meshstream" ] && [ -x "$gen" ] || die "no meshstream or meshstream-gen in $build/tools"
"$python" -c 'import meshstream, open3d, meshio' 2>/dev/null ||
  die "$python cannot import meshstream (built in $build/python), open3d and meshio (apt-get install python3-open3d python3-meshio)"

# median LABEL CMD...: runs CMD $RUNS times; prints LABEL, the median wall seconds and the
# median peak RSS in MiB.
median() {
  local label=$1 i
  shift
  for i in $(seq "${RUNS:-3}"); do measure "$@"; done | python3 -c '
import statistics, sys
rows = [line.split() for line in sys.stdin]
wall = statistics.median(float(r[0]) for r in rows)
rss = statistics.median(int(r[2]) for r in rows)
print(f"{sys.argv[1]:<44} {wall:8.2f} s {rss / 1024:8.0f} MiB")' "$label"
}

echo "# bench/python.sh: N = $n triangles, $(nproc) cores, load $(load), commit $(git -C "$here" rev-parse --short HEAD)"
"$gen" -q -n "$n" "$work/mesh.ply"
"$meshstream" -q convert "$work/mesh.ply" "$work/mesh.obj"
"$meshstream" -q convert "$work/mesh.ply" "$work/mesh.stl"
triangles=$("$python" -c 'import meshstream, sys; print(meshstream.info(sys.argv[1])["triangles"])' "$work/mesh.ply")
echo "# $triangles triangles; PLY $(( $(stat -c %s "$work/mesh.ply") >> 20 )) MiB, OBJ $(( $(stat -c %s "$work/mesh.obj") >> 20 )) MiB, STL $(( $(stat -c %s "$work/mesh.stl") >> 20 )) MiB"
cat "$work"/mesh.* >/dev/null  # the page cache holds them for every run

# What starting the interpreter and importing costs, in every row below.
for module in meshstream open3d meshio; do median "import $module" "$python" -c "import $module"; done
for f in ply obj; do
  median "meshstream.read ($f)" "$python" -c 'import meshstream, sys; m = meshstream.read(sys.argv[1]); assert len(m.faces) == int(sys.argv[2])' "$work/mesh.$f" "$triangles"
  median "open3d.io.read_triangle_mesh ($f)" "$python" -c 'import open3d, sys; m = open3d.io.read_triangle_mesh(sys.argv[1]); assert len(m.triangles) == int(sys.argv[2])' "$work/mesh.$f" "$triangles"
  median "meshio.read ($f)" "$python" -c 'import meshio, sys; m = meshio.read(sys.argv[1]); assert sum(len(c.data) for c in m.cells) == int(sys.argv[2])' "$work/mesh.$f" "$triangles"
done

median "meshstream.chunks (stl)" "$python" -c 'import meshstream, sys; assert sum(len(c) for c in meshstream.chunks(sys.argv[1])) == int(sys.argv[2])' "$work/mesh.stl" "$triangles"
median "meshstream info (stl)" "$meshstream" info "$work/mesh.stl"

median "meshstream.decimate (ply -> ply, 1 %)" "$python" -c 'import meshstream, sys; meshstream.decimate(sys.argv[1], sys.argv[2], ratio=0.01)' "$work/mesh.ply" "$work/py.ply"
median "meshstream decimate (ply -> ply, 1 %)" "$meshstream" -q decimate "$work/mesh.ply" "$work/cmd.ply" --ratio 0.01
cmp "$work/py.ply" "$work/cmd.ply" && echo "# decimate outputs: the same bytes"
echo "# load after: $(load)"
