#!/usr/bin/env bash
# Renders the coloured generated mesh (meshstream-gen --color, 1 M triangles) at 100 %, and at 10 %
# and 1 % decimated by `meshstream decimate` and by meshoptimizer 1.2 simplifyWithUpdate with the
# colours as attributes (bench/ref_meshopt --attributes), with bench/render_mesh, all framed by the
# full mesh and cropped to the same close-up, side by side in one PNG for docs/decimation.md.
#   bench/render_colour.sh [OUT.png]     (default docs/images/colour_gen.png)
# Environment: BUILD_DIR (default /tmp/meshstream-bench/build, configured with the bench on),
# N (triangles, default 1000000). Needs ImageMagick (convert, montage).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-docs/images/colour_gen.png}
BUILD_DIR=${BUILD_DIR:-/tmp/meshstream-bench/build}
N=${N:-1000000}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DMESHSTREAM_BUILD_BENCH=ON -DMESHSTREAM_BUILD_TESTS=OFF >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target meshstream meshstream-gen render_mesh ref_meshopt >/dev/null
ms=$BUILD_DIR/tools/meshstream
render=$BUILD_DIR/bench/render_mesh
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$BUILD_DIR/tools/meshstream-gen" -q --color -n "$N" "$tmp/in.ply"
in_count=$("$ms" info --json "$tmp/in.ply" | sed -n 's/.*"triangles": *\([0-9]*\).*/\1/p' | head -1)
shot() {  # mesh, label
  "$render" "$1" "$tmp/full.png" --size 1200 --frame "$tmp/in.ply" --view 0.3,0.4,1
  convert "$tmp/full.png" -gravity center -crop 300x300+60-40 +repage "$tmp/$2.png"
}
shot "$tmp/in.ply" "input"
labels=("$tmp/input.png")
for p in 10 1; do
  target=$(( (in_count * p + 50) / 100 ))
  "$ms" -q decimate "$tmp/in.ply" "$tmp/ms_$p.ply" --target "$target"
  "$BUILD_DIR/bench/ref_meshopt" "$tmp/in.ply" "$tmp/mo_$p.ply" --target "$target" --attributes 2>/dev/null
  shot "$tmp/ms_$p.ply" "ms_$p"
  shot "$tmp/mo_$p.ply" "mo_$p"
done
montage -font DejaVu-Sans -pointsize 15 \
  -label "input ($in_count)" "$tmp/input.png" \
  -label "meshstream 10 %" "$tmp/ms_10.png" -label "meshoptimizer 10 %" "$tmp/mo_10.png" \
  -label "meshstream 1 %" "$tmp/ms_1.png" -label "meshoptimizer 1 %" "$tmp/mo_1.png" \
  -tile 5x1 -geometry +3+3 "$out"
echo "wrote $out" >&2
