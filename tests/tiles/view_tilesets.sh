#!/bin/bash
# A tileset `meshstream tiles` writes, loaded as a web page shows it: three.js with
# 3d-tiles-renderer in headless Chromium (render_tiles.mjs), on a generated coloured mesh of 200 k
# triangles at 4 000 triangles a tile (4 levels, 288 leaves), against the same mesh converted whole;
# then the bunny at 300 triangles a tile, whose subtrees from depth 3 are external tilesets.
#   view_tilesets.sh MESHSTREAM MESHSTREAM_GEN TOOLS_DIR [KEEP_DIR]
# Checks, from the report:
#   every scene settles (nothing left loading) with no tile failed, and no error in the page;
#   far     no leaf fetched, content of the two coarsest levels only, at most 15 % of the bytes;
#   close   leaves fetched and drawn, at most a quarter of them; every leaf fetched out of the view
#           is the child of a tile in view (the renderer loads a refined tile's children together);
#   match   at a 1-pixel error target, missing and extra coverage each under 0.1 % of the
#           reference's pixels (a leaf of the 288 covers about that much), mean colour difference
#           under 1 (of 255), under 0.1 % of the pixels more than 32 apart in a channel;
#   whole   the whole model at the default 16-pixel target: no leaf fetched;
#   levels  at least two levels drawn at a 1-pixel target.
# The report is printed. KEEP_DIR, when given, receives the pictures and the report.
# Exit 77 (ctest's skip) with the reason when node, Chromium, three.js or 3d-tiles-renderer is
# absent (tools/bootstrap.sh installs them).
set -u
meshstream=$1 gen=$2 tools=$3 keep=${4:-}
here=$(cd "$(dirname "$0")" && pwd)
modules=$tools/node_modules
if ! command -v node >/dev/null; then
  echo "SKIPPED: node is not installed (tools/bootstrap.sh installs it)"
  exit 77
fi
for f in three/build/three.module.js 3d-tiles-renderer/build/index.js; do
  if [ ! -f "$modules/$f" ]; then
    echo "SKIPPED: ${f%%/*} is not in $modules (tools/bootstrap.sh installs it)"
    exit 77
  fi
done
if ! "${CHROMIUM:-chromium}" --version >/dev/null 2>&1; then
  echo "SKIPPED: cannot run ${CHROMIUM:-chromium} (Debian package 'chromium'; tools/bootstrap.sh installs it)"
  exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$gen" -q -n 200000 --color "$work/mesh.ply" || { echo "FAILED: meshstream-gen"; exit 1; }
"$meshstream" -q tiles "$work/mesh.ply" "$work/tiles" --tile-triangles 4000 || { echo "FAILED: meshstream tiles"; exit 1; }
"$meshstream" -q convert "$work/mesh.ply" "$work/reference.glb" --compress none || { echo "FAILED: meshstream convert"; exit 1; }
if ! node "$here/render_tiles.mjs" "$work/shots" "$work/tiles/tileset.json" "$work/reference.glb" \
    --modules "$modules" > "$work/report.json" 2> "$work/render.err"; then
  echo "FAILED: render_tiles.mjs:"
  grep -v -e dbus -e '^\[' "$work/render.err" | tail -20
  exit 1
fi
cat "$work/report.json"
if [ -n "$keep" ]; then
  mkdir -p "$keep" && cp "$work/shots"/*.png "$work/report.json" "$keep/"
fi
node - "$work/report.json" <<'EOF' || exit 1
const r = JSON.parse(require('fs').readFileSync(process.argv[2], 'utf8'));
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); };
const t = r.tiles;
check(!r.error, `the page threw: ${r.error}`);
check(t.levels === 4 && t.leaves > 100, `the tileset has ${t.levels} levels and ${t.leaves} leaves (expected 4 and over 100)`);
for (const name of ['far', 'close', 'match', 'whole', 'levels']) {
  const s = r[name];
  if (!s) { failures.push(`no report of the ${name} scene`); continue; }
  check(s.settled, `${name}: still loading after 20 s`);
  check(s.failed === 0, `${name}: ${s.failed} tiles failed to load`);
}
const share = (bytes) => (100 * bytes / t.bytes).toFixed(1) + ' %';
if (r.far) {
  const levels = Object.keys(r.far.fetched_by_level).map(Number);
  check(r.far.fetched_leaves === 0, `far: ${r.far.fetched_leaves} leaves fetched`);
  check(levels.length > 0 && Math.max(...levels) <= t.levels - 3, `far: content of levels ${levels} fetched`);
  check(r.far.fetched_bytes <= 0.15 * t.bytes, `far: ${share(r.far.fetched_bytes)} of the bytes fetched`);
}
if (r.close) {
  const c = r.close;
  check(c.fetched_leaves > 0 && (c.drawn_by_level[t.levels - 1] || 0) > 0, `close: no leaf fetched or drawn`);
  check(c.fetched_leaves <= t.leaves / 4, `close: ${c.fetched_leaves} of ${t.leaves} leaves fetched`);
  check(c.out_of_view_parent_out_of_view === 0, `close: ${c.out_of_view_parent_out_of_view} leaves fetched out of view under a parent out of view`);
}
if (r.match) {
  const m = r.match;
  check(m.covered_reference > 0.1, `match: the reference covers ${m.covered_reference} of the picture`);
  check(m.missing < 0.001, `match: ${(100 * m.missing).toFixed(3)} % of the reference's pixels missing`);
  check(m.extra < 0.001, `match: ${(100 * m.extra).toFixed(3)} % extra pixels`);
  check(m.colour_difference < 1, `match: mean colour difference ${m.colour_difference}`);
  check(m.colour_differs < 0.001, `match: ${(100 * m.colour_differs).toFixed(3)} % of the pixels' colours more than 32 apart`);
}
if (r.whole) check(r.whole.fetched_leaves === 0, `whole: ${r.whole.fetched_leaves} leaves fetched`);
if (r.levels) check(Object.keys(r.levels.drawn_by_level).length >= 2, `levels: drawn ${JSON.stringify(r.levels.drawn_by_level)}`);
if (failures.length) {
  for (const f of failures) console.log('FAILED: ' + f);
  process.exit(1);
}
console.log(`ok: far ${share(r.far.fetched_bytes)} of ${t.bytes} bytes, whole ${share(r.whole.fetched_bytes)}, close ${share(r.close.fetched_bytes)} (${r.close.fetched_leaves} of ${t.leaves} leaves), ` +
  `match missing ${(100 * r.match.missing).toFixed(4)} % extra ${(100 * r.match.extra).toFixed(4)} % colour ${r.match.colour_difference.toFixed(3)}`);
EOF

# External tilesets: the bunny at 300 triangles a tile has five levels, so the subtrees from
# depth 3 are tileset files of their own. At a 1-pixel target the page follows them and its
# picture matches the bunny drawn whole; from far away it fetches none of them.
bunny=$here/../../fixtures/bunny_from_draco.bin.stl
"$meshstream" -q tiles "$bunny" "$work/bunny_tiles" --tile-triangles 300 || { echo "FAILED: meshstream tiles (bunny)"; exit 1; }
"$meshstream" -q convert "$bunny" "$work/bunny.glb" --compress none || { echo "FAILED: meshstream convert (bunny)"; exit 1; }
if ! RENDER_TILES_SCENES=far,close,match node "$here/render_tiles.mjs" "$work/bunny_shots" "$work/bunny_tiles/tileset.json" \
    "$work/bunny.glb" --modules "$modules" > "$work/bunny_report.json" 2> "$work/bunny_render.err"; then
  echo "FAILED: render_tiles.mjs (bunny):"
  grep -v -e dbus -e '^\[' "$work/bunny_render.err" | tail -20
  exit 1
fi
if [ -n "$keep" ]; then
  mkdir -p "$keep/bunny" && cp "$work/bunny_shots"/*.png "$work/bunny_report.json" "$keep/bunny/"
fi
node - "$work/bunny_report.json" <<'EOF'
const r = JSON.parse(require('fs').readFileSync(process.argv[2], 'utf8'));
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); };
const t = r.tiles;
check(!r.error, `bunny: the page threw: ${r.error}`);
check(t.levels >= 5 && t.external_tilesets > 1, `bunny: ${t.levels} levels, ${t.external_tilesets} external tilesets (expected 5 or more, and more than one)`);
for (const name of ['far', 'match']) {
  const s = r[name];
  if (!s) { failures.push(`bunny: no report of the ${name} scene`); continue; }
  check(s.settled, `bunny ${name}: still loading after 20 s`);
  check(s.failed === 0, `bunny ${name}: ${s.failed} tiles failed to load`);
}
if (r.far) check(r.far.fetched_external_tilesets === 0, `bunny far: ${r.far.fetched_external_tilesets} external tilesets fetched`);
if (r.match) {
  const m = r.match;
  const deep = Object.keys(m.drawn_by_level).map(Number).filter((l) => l >= 3);
  check(m.fetched_external_tilesets > 0 && deep.length > 0,
    `bunny match: ${m.fetched_external_tilesets} external tilesets fetched, levels drawn ${Object.keys(m.drawn_by_level)}`);
  check(m.covered_reference > 0.1, `bunny match: the reference covers ${m.covered_reference} of the picture`);
  check(m.missing < 0.001, `bunny match: ${(100 * m.missing).toFixed(3)} % of the reference's pixels missing`);
  check(m.extra < 0.001, `bunny match: ${(100 * m.extra).toFixed(3)} % extra pixels`);
}
if (failures.length) {
  for (const f of failures) console.log('FAILED: ' + f);
  process.exit(1);
}
console.log(`ok: bunny ${t.levels} levels, ${r.match.fetched_external_tilesets} of ${t.external_tilesets} external tilesets fetched at 1 px, ` +
  `none from far; match missing ${(100 * r.match.missing).toFixed(4)} % extra ${(100 * r.match.extra).toFixed(4)} %`);
EOF
