#!/usr/bin/env bash
# Renders the bunny fixture at 100 %, 10 % and 1 % (decimated with `meshstream decimate`) to
# PNG for docs/decimation.md, with bench/render_mesh (z-buffer rasteriser, wireframe overlay),
# all framed by the full mesh so they line up.
#   bench/render_bunny.sh [OUT_DIR]     (default docs/images)
# Environment: BUILD_DIR (default /tmp/meshstream-bench/build, configured with the bench on).
set -euo pipefail
cd "$(dirname "$0")/.."
out_dir=${1:-docs/images}
BUILD_DIR=${BUILD_DIR:-/tmp/meshstream-bench/build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DMESHSTREAM_BUILD_BENCH=ON -DMESHSTREAM_BUILD_TESTS=OFF >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target meshstream render_mesh >/dev/null
ms=$BUILD_DIR/tools/meshstream
render=$BUILD_DIR/bench/render_mesh
bunny=fixtures/bunny_from_draco.bin.stl
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out_dir"
"$render" "$bunny" "$out_dir/bunny_100.png" --wire --size 480
for p in 10 1; do
  "$ms" -q decimate "$bunny" "$tmp/bunny_$p.stl" --ratio "0.$(printf '%02d' "$p")" >/dev/null
  "$render" "$tmp/bunny_$p.stl" "$out_dir/bunny_$p.png" --frame "$bunny" --wire --size 480
done
echo "wrote $out_dir/bunny_100.png bunny_10.png bunny_1.png" >&2
