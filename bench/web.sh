#!/usr/bin/env bash
# Web-ready output figures (issue 6). For the bunny fixture (69451 triangles) and a generated
# 1-million-triangle mesh (meshstream-gen), each decimated to 10 % with `meshstream decimate -r 0.1`:
#   - file sizes of the same decimated mesh as binary STL, binary PLY, plain GLB, Draco GLB, .drc;
#   - encode time of `meshstream convert M.ply M.glb` (Draco) and `... M.drc` from that PLY;
#   - the Hausdorff error quantization adds: `meshstream compare M.ply M.glb` (symmetric max,
#     absolute and % of the bounding-box diagonal) next to the bound qp implies (half a step);
#   - Debian's draco_encoder on the same PLY at the same settings (-qp 14 -cl 7), in the same
#     run: size ratio (target: within 2 %) and time ratio (target: within 1.5x);
#   - `--compress meshopt` against gltfpack -cc (npm gltfpack 0.18, the same libmeshoptimizer
#     version as Debian's, same 14-bit position quantization) on the same mesh as a plain GLB:
#     size ratio (target: within 10 %) and time ratio, on the full bunny and each decimated mesh.
# Times are wall clock of the whole process (read + index + encode + write), best of 3.
#
# Usage: bench/web.sh [build dir (default: build)] [work dir (default: $TMPDIR or /tmp)]
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
ms=$build/tools/meshstream
gen=$build/tools/meshstream-gen
work=$(mktemp -d "${2:-${TMPDIR:-/tmp}}/web_bench.XXXXXX")
trap 'rm -rf "$work"' EXIT
qp=14
cl=7
[ -x "$ms" ] || { echo "no meshstream binary at $ms" >&2; exit 2; }
command -v draco_encoder >/dev/null || { echo "needs Debian's draco_encoder (package 'draco')" >&2; exit 2; }
command -v node >/dev/null || { echo "needs node (JSON parsing of compare's report)" >&2; exit 2; }
command -v /usr/bin/time >/dev/null || { echo "needs GNU time (/usr/bin/time)" >&2; exit 2; }
gltfpack=${MESHSTREAM_TOOLS_DIR:-/opt/meshstream-tools}/node_modules/gltfpack/cli.js
[ -f "$gltfpack" ] || { echo "needs npm gltfpack in \$MESHSTREAM_TOOLS_DIR (tools/bootstrap.sh installs it)" >&2; exit 2; }

# best_of3 CMD...: prints the fastest wall time of 3 runs, in seconds.
best_of3() {
    local best="" t
    for _ in 1 2 3; do
        /usr/bin/time -f "%e" -o "$work/time" "$@" >/dev/null 2>"$work/stderr" || { cat "$work/stderr" >&2; exit 1; }
        t=$(cat "$work/time")
        if [ -z "$best" ] || awk "BEGIN{exit !($t < $best)}"; then best=$t; fi
    done
    echo "$best"
}

size() { stat -c %s "$1"; }
ratio() { awk "BEGIN{printf \"%.3f\", $1 / $2}"; }

decimate_ok=1
"$ms" decimate --help >/dev/null 2>&1 || decimate_ok=0

# meshopt_vs_gltfpack LABEL PLY: meshstream --compress meshopt against gltfpack -cc from the same
# mesh written as a plain GLB (gltfpack reads glTF, OBJ only).
meshopt_vs_gltfpack() {
    local label=$1 m=$work/$1.mo
    "$ms" -q convert --compress none "$2" "$m.plain.glb"
    local t_ms t_gp
    t_ms=$(best_of3 "$ms" -q convert --memory 4G --compress meshopt "$m.plain.glb" "$m.glb")
    t_gp=$(best_of3 node "$gltfpack" -i "$m.plain.glb" -o "$m.gltfpack.glb" -cc)
    echo "== $label: --compress meshopt against gltfpack 0.18 -cc (14-bit positions)"
    printf "  %-26s %12s bytes\n" "GLB (--compress meshopt)" "$(size "$m.glb")"
    printf "  %-26s %12s bytes  (ours / theirs: %s)\n" "GLB (gltfpack -cc)" "$(size "$m.gltfpack.glb")" \
        "$(ratio "$(size "$m.glb")" "$(size "$m.gltfpack.glb")")"
    printf "  %-26s %8s s  (ours / theirs: %s; gltfpack runs as WebAssembly in node)\n" "encode" "$t_ms" \
        "$(ratio "$t_ms" "$t_gp")"
}

run_mesh() {
    local label=$1 input=$2 m=$work/$1
    if [ "$decimate_ok" = 1 ]; then
        "$ms" -q decimate --memory 2G "$input" "$m.ply" -r 0.1 >"$work/decimate.log" 2>&1 || { cat "$work/decimate.log" >&2; exit 1; }
    else
        echo "note: 'meshstream decimate' is missing: benchmarking the undecimated mesh" >&2
        "$ms" -q convert "$input" "$m.ply"
    fi
    "$ms" -q convert "$m.ply" "$m.stl"
    "$ms" -q convert --no-draco "$m.ply" "$m.plain.glb"
    local t_glb t_drc t_ref
    t_glb=$(best_of3 "$ms" -q convert --memory 4G --draco-qp $qp --draco-cl $cl "$m.ply" "$m.glb")
    t_drc=$(best_of3 "$ms" -q convert --memory 4G --draco-qp $qp --draco-cl $cl "$m.ply" "$m.drc")
    t_ref=$(best_of3 draco_encoder -i "$m.ply" -o "$m.ref.drc" -qp $qp -cl $cl)
    local tris
    tris=$("$ms" info --json "$m.ply" | node -e 'let s="";process.stdin.on("data",d=>s+=d).on("end",()=>console.log(JSON.parse(s).triangles))')
    "$ms" compare --json "$m.ply" "$m.glb" > "$work/compare.json"
    local err
    err=$(node -e '
        const r = JSON.parse(require("fs").readFileSync(process.argv[1]));
        const b = r.a, ext = Math.max(...[0,1,2].map(i => b.bbox_max[i] - b.bbox_min[i]));
        const bound = 0.5 * ext / (2 ** Number(process.argv[2]) - 1);
        console.log(`${r.symmetric.max.toExponential(3)} (${r.symmetric.max_pct.toFixed(4)} % of diagonal; ` +
                    `per-axis bound ${bound.toExponential(3)}, 3-D bound ${(bound * Math.sqrt(3)).toExponential(3)})`);
    ' "$work/compare.json" $qp)

    echo "== $label: $tris triangles after decimation (qp $qp, cl $cl)"
    printf "  %-26s %12s bytes\n" "binary STL" "$(size "$m.stl")"
    printf "  %-26s %12s bytes\n" "binary PLY" "$(size "$m.ply")"
    printf "  %-26s %12s bytes\n" "GLB (--no-draco)" "$(size "$m.plain.glb")"
    printf "  %-26s %12s bytes  (%s x STL, %s x PLY)\n" "GLB (Draco)" "$(size "$m.glb")" \
        "$(ratio "$(size "$m.glb")" "$(size "$m.stl")")" "$(ratio "$(size "$m.glb")" "$(size "$m.ply")")"
    printf "  %-26s %12s bytes\n" ".drc (meshstream)" "$(size "$m.drc")"
    printf "  %-26s %12s bytes  (ours / theirs: %s)\n" ".drc (draco_encoder)" "$(size "$m.ref.drc")" \
        "$(ratio "$(size "$m.drc")" "$(size "$m.ref.drc")")"
    if cmp -s "$m.drc" "$m.ref.drc"; then echo "  .drc bytes identical to draco_encoder's"; fi
    printf "  %-26s %8s s\n" "encode PLY -> GLB" "$t_glb"
    printf "  %-26s %8s s\n" "encode PLY -> .drc" "$t_drc"
    printf "  %-26s %8s s  (ours / theirs: %s)\n" "draco_encoder PLY -> .drc" "$t_ref" "$(ratio "$t_drc" "$t_ref")"
    echo "  Hausdorff(decimated, GLB): $err"
    meshopt_vs_gltfpack "$label" "$m.ply"
}

meshopt_vs_gltfpack bunny_full "$here/../fixtures/bunny_from_draco.bin.stl"
run_mesh bunny "$here/../fixtures/bunny_from_draco.bin.stl"
if [ -x "$gen" ]; then
    "$gen" -q -n 1000000 "$work/gen1m.stl"
    run_mesh generated_1M "$work/gen1m.stl"
else
    echo "note: meshstream-gen is missing: no 1 M triangle run" >&2
fi
