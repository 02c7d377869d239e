#!/usr/bin/env bash
# What a web viewer fetches from a tileset against a single 1 % GLB of the same generated
# coloured mesh (docs/tiles.md; the figures in docs/results.md): three.js with 3d-tiles-renderer
# in headless Chromium (tests/tiles/render_tiles.mjs, its default 16-pixel error target, a new
# renderer a view, nothing cached) on a 512 × 512 canvas, for the whole model filling the view
# and for a close-up (a point of the surface from a twentieth of the model's radius); the bytes
# it fetched (JSON and tiles) and the largest geometric error of the tiles it drew. The GLB
# (`meshstream decimate -r 0.01`, its default Draco compression) is fetched whole for any view,
# and shows its Hausdorff distance to the input everywhere (`meshstream compare`).
#
# Usage: bench/tiles_view.sh [N triangles (default 10000000)] [threads (default: every core)]
#                            [build dir (default build)] [work dir]
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
n=${1:-10000000}
threads=${2:-$(nproc)}
build=$(cd "${3:-$here/../build}" && pwd)
work=$(mktemp -d "${4:-${TMPDIR:-/tmp}}/tiles_view.XXXXXX")
trap 'rm -rf "$work"' EXIT
meshstream=$build/tools/meshstream
gen=$build/tools/meshstream-gen
modules=${MESHSTREAM_TOOLS_DIR:-/opt/meshstream-tools}/node_modules
[ -x "$meshstream" ] && [ -x "$gen" ] || die "no meshstream or meshstream-gen in $build/tools"
[ -f "$modules/3d-tiles-renderer/build/index.js" ] || die "needs three.js and 3d-tiles-renderer in $modules (tools/bootstrap.sh)"

echo "# bench/tiles_view.sh: N = $n triangles with colours, --threads $threads, commit $(git -C "$here" rev-parse --short HEAD)"
"$gen" -q -n "$n" --color "$work/mesh.ply"
"$meshstream" -q tiles "$work/mesh.ply" "$work/tiles" --threads "$threads"
"$meshstream" -q decimate "$work/mesh.ply" "$work/one.glb" -r 0.01 --threads "$threads"
"$meshstream" compare "$work/mesh.ply" "$work/one.glb" --json > "$work/compare.json" 2>/dev/null
# The 1 % GLB stands in for the reference the script places its cameras by (the match scene,
# which needs the whole mesh, is not run).
RENDER_TILES_SCENES=far,close,levels RENDER_TILES_TIMEOUT=600000 \
  node "$here/../tests/tiles/render_tiles.mjs" "$work/shots" "$work/tiles/tileset.json" "$work/one.glb" \
  --modules "$modules" > "$work/report.json" 2> "$work/render.err" || { tail "$work/render.err" >&2; die "render_tiles.mjs failed"; }
python3 - "$work/report.json" "$work/compare.json" "$(stat -c %s "$work/one.glb")" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
c = json.load(open(sys.argv[2]))
glb = int(sys.argv[3])
t = r["tiles"]
print(f"tileset: {t['count']} tiles, {t['levels']} levels, {t['bytes']} bytes ({t['leaf_bytes']} in the leaves)")
print(f"1 % GLB: {glb} bytes, Hausdorff {c['symmetric']['max']:.4g} ({c['symmetric']['max_pct']:.3f} % of the diagonal {c['diagonal']:.4g})")
print("| view | tileset: bytes fetched | tileset: largest error drawn | settled | 1 % GLB: bytes | 1 % GLB: error |")
print("|---|---|---|---|---|---|")
for name, label in (("levels", "whole model"), ("close", "close-up"), ("far", "far (40 px)")):
    s = r[name]
    print(f"| {label} | {s['fetched_bytes']} ({100 * s['fetched_bytes'] / t['bytes']:.1f} %) | "
          f"{s['drawn_max_error']:.4g} | {s['settled']} | {glb} | {c['symmetric']['max']:.4g} |")
PY
