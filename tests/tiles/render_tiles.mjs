// Loads a 3D Tiles tileset the way a web page shows it — three.js with 3d-tiles-renderer (a
// GLTFLoader with MeshoptDecoder and DRACOLoader as its glTF handler) in headless Chromium — and
// prints what it fetched and drew as JSON:
//   node render_tiles.mjs OUT_DIR TILESET_JSON REFERENCE_GLB [--modules NODE_MODULES_DIR]
// REFERENCE_GLB is the full-resolution mesh in the tileset's coordinates (`meshstream convert IN
// ref.glb`: glTF's y-up, which the renderer's turn of the tiles' y-up content into 3D Tiles' z-up
// matches; the tileset without --origin). Four scenes on a 512 × 512 canvas, each with a new
// TilesRenderer with its default loading policy (disposed after the scene, so nothing is cached
// between scenes), updated once per requestAnimationFrame — the renderer runs its parse queue
// in those callbacks — until nothing is queued, downloading or parsing for 5 frames in a row (at
// most 20 s a scene; `settled` says whether it did), then drawn once:
//   far     the whole model from far away (about 40 pixels across), error target 16 px
//   close   a point of the surface (the first hit of a ray from the whole view) from a twentieth
//           of the model's radius, the far plane a quarter of the radius away, error target 16 px
//   match   the whole model filling the view, error target 1 px, unlit (basic materials with
//           the tiles' colours), beside the reference drawn the same way
//   whole   the same whole view, error target 16 px (the renderer's default)
//   levels  the same whole view, error target 1 px, each tile lit and coloured by its level
//           (red, orange, yellow, green, cyan, blue, ... from the root down)
// Every file the page fetches below the tileset (its JSON too) is counted by the server, scene by
// scene. Report:
//   {tiles: {count, levels, leaves, bytes, leaf_bytes, external_tilesets}, // the whole tileset
//    far|close|match|whole|levels: {settled, frames, ms, fetched_bytes, fetched_by_level (content
//                       bytes), drawn_by_level (tiles), drawn_max_error (the largest
//                       geometricError of the tiles drawn), fetched_leaves, leaves_in_view,
//                       fetched_leaves_out_of_view, fetched_leaf_bytes_out_of_view,
//                       out_of_view_parent_out_of_view, fetched_external_tilesets, failed},
//    match: {..., covered_reference, covered_tiles, missing, extra, colour_difference, colour_differs},
//    error (when the page threw)}
// A tile is in view when its box meets the camera's frustum (as the renderer culls);
// out_of_view_parent_out_of_view counts the fetched leaves out of view whose parent is out of view
// too (the renderer loads all the children of a tile it refines, `loadSiblings`, so leaves out of
// view under a parent in view are expected). missing (extra) is the share of the reference's
// covered pixels the tiles leave uncovered (cover beyond it); colour_difference the mean absolute
// difference (0–255, over r, g, b) on pixels both cover, colour_differs the share of those pixels
// with a channel more than 32 apart. OUT_DIR receives far.png, close.png, match_tiles.png,
// match_reference.png, whole.png and levels.png.
// RENDER_TILES_SCENES (e.g. "far,close,whole,levels") runs only those scenes (match loads the
// leaves in view and the reference whole).
// Exit status: 0 when the report was written, 2 when Chromium, three.js or 3d-tiles-renderer
// cannot be found or the page does not report within 120 s.
import fs from 'node:fs';
import path from 'node:path';
import { below, modulesDir, requireTools, runPage } from '../tools/headless.mjs';

const args = process.argv.slice(2);
const modules = modulesDir(args);
const [outDir, tilesetJson, referenceGlb] = args;
if (!outDir || !tilesetJson || !referenceGlb) {
    console.error('usage: node render_tiles.mjs OUT_DIR TILESET_JSON REFERENCE_GLB [--modules NODE_MODULES_DIR]');
    process.exit(2);
}
const chromium = requireTools('render_tiles', modules, [
    ['three', 'build/three.module.js'], ['3d-tiles-renderer', 'build/index.js']]);
const tilesetDir = path.dirname(path.resolve(tilesetJson));
const scenes = (process.env.RENDER_TILES_SCENES || 'far,close,match,whole,levels').split(',');
fs.mkdirSync(outDir, { recursive: true });

// 4 × 4 column-major matrices, as 3D Tiles writes `transform`.
const identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
function multiply(a, b) {
    const r = new Array(16).fill(0);
    for (let c = 0; c < 4; ++c)
        for (let row = 0; row < 4; ++row)
            for (let k = 0; k < 4; ++k) r[c * 4 + row] += a[k * 4 + row] * b[c * 4 + k];
    return r;
}
function apply(m, p) {
    return [0, 1, 2].map((i) => m[i] * p[0] + m[4 + i] * p[1] + m[8 + i] * p[2] + m[12 + i]);
}
function boxCorners(box, m) {
    const c = box.slice(0, 3), axes = [box.slice(3, 6), box.slice(6, 9), box.slice(9, 12)];
    const corners = [];
    for (const sx of [-1, 1])
        for (const sy of [-1, 1])
            for (const sz of [-1, 1])
                corners.push(apply(m, [0, 1, 2].map((i) => c[i] + sx * axes[0][i] + sy * axes[1][i] + sz * axes[2][i])));
    return corners;
}

// Every tile with content, from the tileset's JSON files (external tilesets followed): its path,
// level (how many ancestors have content), whether it is a leaf, its parent's path, its bytes
// and its box's corners in the tileset's coordinates.
const inventory = [];
const externalTilesets = new Set();  // their paths, relative to the tileset's directory
function walk(file, tile, parentMatrix, level, parentPath) {
    const m = tile.transform ? multiply(parentMatrix, tile.transform) : parentMatrix;
    const uri = tile.content && (tile.content.uri || tile.content.url);
    let childLevel = level, childParent = parentPath;
    if (uri) {
        const target = path.join(path.dirname(file), decodeURIComponent(uri));
        if (target.endsWith('.json')) {
            externalTilesets.add(path.relative(tilesetDir, target));
            walk(target, JSON.parse(fs.readFileSync(target, 'utf8')).root, m, level, parentPath);
        } else {
            const p = path.relative(tilesetDir, target);
            inventory.push({
                path: p, level, leaf: !(tile.children && tile.children.length), parent: parentPath,
                bytes: fs.statSync(target).size, error: tile.geometricError,
                corners: tile.boundingVolume.box ? boxCorners(tile.boundingVolume.box, m) : null,
            });
            childLevel = level + 1;
            childParent = p;
        }
    }
    for (const child of tile.children || []) walk(file, child, m, childLevel, childParent);
}
walk(path.resolve(tilesetJson), JSON.parse(fs.readFileSync(tilesetJson, 'utf8')).root, identity, 0, null);
const byPath = new Map(inventory.map((t) => [t.path, t]));
let tilesetBytes = 0;
for (const f of fs.readdirSync(tilesetDir, { recursive: true })) {
    const p = path.join(tilesetDir, f);
    if (fs.statSync(p).isFile()) tilesetBytes += fs.statSync(p).size;
}

const page = `<!doctype html><html><head><meta charset="utf-8">
<script type="importmap">{"imports": {
  "three": "/three/build/three.module.js", "three/addons/": "/three/examples/jsm/",
  "3d-tiles-renderer": "/renderer/build/index.js"}}</script>
</head><body style="margin:0;background:#000">
<script type="module">
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { TilesRenderer } from '3d-tiles-renderer';
const boxes = ${JSON.stringify(inventory.filter((t) => t.corners).map((t) => ({ path: t.path, corners: t.corners })))};
const size = 512;
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(size, size);
renderer.setClearColor(0x000000, 1);
document.body.appendChild(renderer.domElement);
const draco = new DRACOLoader();
draco.setDecoderPath('/three/examples/jsm/libs/draco/');
draco.setDecoderConfig({ type: 'js' });
const post = (url, body) => fetch(url, { method: 'POST', body: JSON.stringify(body) });
const palette = [0xe6194b, 0xf58231, 0xffe119, 0x3cb44b, 0x42d4f4, 0x4363d8, 0x911eb4, 0xf032e6, 0xa9a9a9, 0xffffff];
const frame = () => new Promise((resolve) => requestAnimationFrame(resolve));

function basic(object) {
    object.traverse((o) => {
        if (!o.isMesh) return;
        const old = o.material;
        o.material = new THREE.MeshBasicMaterial({ color: old.color ? old.color.clone() : 0xffffff, map: old.map || null,
            vertexColors: !!o.geometry.attributes.color, side: THREE.DoubleSide });
    });
}
function pixels() {
    const gl = renderer.getContext();
    const p = new Uint8Array(size * size * 4);
    gl.readPixels(0, 0, size, size, gl.RGBA, gl.UNSIGNED_BYTE, p);
    return p;
}
async function save(name) {
    await post('/png/' + name, renderer.domElement.toDataURL('image/png'));
}

// A scene: a new TilesRenderer updated frame by frame until it has nothing left to load, then
// drawn, its picture saved and what it drew reported; the renderer is disposed.
async function show(name, camera, errorTarget, dress) {
    await post('/phase/' + name, {});
    const tiles = new TilesRenderer('/tiles/' + ${JSON.stringify(path.basename(tilesetJson))});
    const gltf = new GLTFLoader(tiles.manager);
    gltf.setDRACOLoader(draco);
    gltf.setMeshoptDecoder(MeshoptDecoder);
    tiles.manager.addHandler(/\\.(gltf|glb)$/g, gltf);
    tiles.errorTarget = errorTarget;
    const urls = new Map();
    tiles.addEventListener('load-model', ({ scene, tile, url }) => {
        urls.set(tile, decodeURIComponent(new URL(url, location.href).pathname).replace(/^\\/tiles\\//, ''));
        if (dress) dress(scene, tile);
    });
    const scene = new THREE.Scene();
    scene.add(tiles.group);
    scene.add(new THREE.AmbientLight(0xffffff, 0.7));
    const sun = new THREE.DirectionalLight(0xffffff, 2.0);
    sun.position.copy(camera.position);
    scene.add(sun);
    tiles.setCamera(camera);
    tiles.setResolutionFromRenderer(camera, renderer);
    const start = performance.now();
    let idle = 0, frames = 0;
    while (idle < 5 && performance.now() - start < 20000) {
        await frame();
        tiles.update();
        ++frames;
        const s = tiles.stats;
        idle = tiles.root && s.queued + s.downloading + s.parsing === 0 ? idle + 1 : 0;
    }
    const ms = performance.now() - start;
    renderer.render(scene, camera);
    const drawn = [];
    for (const t of tiles.visibleTiles) if (urls.has(t)) drawn.push(urls.get(t));
    const frustum = new THREE.Frustum().setFromProjectionMatrix(
        new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse));
    const inView = boxes.filter((l) => frustum.intersectsBox(new THREE.Box3().setFromPoints(
        l.corners.map((c) => new THREE.Vector3(...c).applyMatrix4(tiles.group.matrixWorld))))).map((l) => l.path);
    const result = { drawn, inView, failed: tiles.stats.failed, settled: idle >= 5, frames, ms: Math.round(ms),
        pixels: name === 'match' ? pixels() : null };
    await save(name === 'match' ? 'match_tiles' : name);
    await post('/drawn/' + name, { drawn, inView, failed: result.failed, settled: result.settled, frames, ms: result.ms });
    tiles.dispose();
    return result;
}

try {
    await post('/phase/reference', {});
    const loader = new GLTFLoader();
    loader.setDRACOLoader(draco);
    loader.setMeshoptDecoder(MeshoptDecoder);
    const reference = (await loader.loadAsync('/reference.glb')).scene;
    reference.updateMatrixWorld(true);
    const box = new THREE.Box3().setFromObject(reference);
    const center = box.getCenter(new THREE.Vector3());
    const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-9);
    const direction = new THREE.Vector3(1, 0.8, 1.6).normalize();
    const camera = (distance, target, far) => {
        const c = new THREE.PerspectiveCamera(40, 1, distance / 1000, far);
        c.position.copy(target).addScaledVector(direction, distance);
        c.lookAt(target);
        c.updateMatrixWorld();
        return c;
    };
    const whole = camera(radius * 2.6, center, radius * 5);

    // far: the model about 40 pixels across.
    const farDistance = radius * 2.6 * size / 40;
    await show('far', camera(farDistance, center, farDistance + 2 * radius), 16);

    // close: a point of the surface from a twentieth of the radius.
    const ray = new THREE.Raycaster(whole.position.clone(), center.clone().sub(whole.position).normalize());
    const hit = ray.intersectObject(reference, true)[0];
    await show('close', camera(radius / 20, hit ? hit.point : center, radius / 4), 16);

    // match: the tiles at a 1-pixel error target against the reference, both unlit.
    if (${JSON.stringify(scenes)}.includes('match')) {
        const tilePixels = (await show('match', whole, 1, (scene) => basic(scene))).pixels;
        basic(reference);
        const refScene = new THREE.Scene();
        refScene.add(reference);
        renderer.render(refScene, whole);
        const refPixels = pixels();
        await save('match_reference');
        let coveredRef = 0, coveredTiles = 0, missing = 0, extra = 0, both = 0, difference = 0, differs = 0;
        for (let i = 0; i < refPixels.length; i += 4) {
            const a = refPixels[i] + refPixels[i + 1] + refPixels[i + 2] > 0;
            const b = tilePixels[i] + tilePixels[i + 1] + tilePixels[i + 2] > 0;
            coveredRef += a; coveredTiles += b;
            if (a && !b) ++missing;
            if (b && !a) ++extra;
            if (a && b) {
                ++both;
                let most = 0;
                for (let k = 0; k < 3; ++k) {
                    const d = Math.abs(refPixels[i + k] - tilePixels[i + k]);
                    difference += d;
                    most = Math.max(most, d);
                }
                if (most > 32) ++differs;
            }
        }
        await post('/match', { covered_reference: coveredRef / (size * size), covered_tiles: coveredTiles / (size * size),
            missing: coveredRef ? missing / coveredRef : 0, extra: coveredRef ? extra / coveredRef : 0,
            colour_difference: both ? difference / (3 * both) : 0, colour_differs: both ? differs / both : 0 });
    }

    // whole: the whole view at the renderer's default error target.
    if (${JSON.stringify(scenes)}.includes('whole')) await show('whole', whole, 16);

    // levels: the whole view at a 1-pixel error target, each tile lit and coloured by its level.
    await show('levels', whole, 1, (scene, tile) => {
        const colour = palette[Math.min(tile.internal.depth, palette.length - 1)];
        scene.traverse((o) => {
            if (!o.isMesh) return;
            if (!o.geometry.attributes.normal) o.geometry.computeVertexNormals();
            o.material = new THREE.MeshLambertMaterial({ color: colour, side: THREE.DoubleSide });
        });
    });
    await post('/done', {});
} catch (e) {
    await post('/error', { error: String(e && e.stack ? e.stack : e) });
}
</script></body></html>`;

const report = {
    tiles: {
        count: inventory.length, levels: Math.max(0, ...inventory.map((t) => t.level)) + 1,
        leaves: inventory.filter((t) => t.leaf).length, bytes: tilesetBytes,
        leaf_bytes: inventory.filter((t) => t.leaf).reduce((s, t) => s + t.bytes, 0),
        external_tilesets: externalTilesets.size,
    },
};
let phase = null;
const fetched = {};
const outcome = await runPage({
    chromium, name: 'render_tiles', timeoutMs: Number(process.env.RENDER_TILES_TIMEOUT || 120000), page,
    serve(url) {
        if (url === '/reference.glb') return path.resolve(referenceGlb);
        if (url.startsWith('/tiles/')) return below(tilesetDir, url.slice(7));
        if (url.startsWith('/three/')) return below(path.join(modules, 'three'), url.slice(7));
        if (url.startsWith('/renderer/')) return below(path.join(modules, '3d-tiles-renderer'), url.slice(10));
        return undefined;
    },
    onGet(url, bytes) {
        if (phase && url.startsWith('/tiles/')) fetched[phase].push({ path: url.slice(7), bytes });
    },
    post(url, body, finish) {
        const value = JSON.parse(body);
        if (url.startsWith('/phase/')) {
            phase = url.slice(7);
            fetched[phase] = [];
        } else if (url.startsWith('/png/')) {
            fs.writeFileSync(path.join(outDir, `${url.slice(5)}.png`), Buffer.from(value.split(',')[1], 'base64'));
        } else if (url.startsWith('/drawn/')) {
            const name = url.slice(7);
            const files = fetched[name];
            const fetchedBytesByLevel = {};
            for (const f of files) {
                const t = byPath.get(f.path);
                if (t) fetchedBytesByLevel[t.level] = (fetchedBytesByLevel[t.level] || 0) + f.bytes;
            }
            const drawnByLevel = {};
            let drawnMaxError = 0;
            for (const p of value.drawn) {
                const t = byPath.get(p);
                if (t) drawnByLevel[t.level] = (drawnByLevel[t.level] || 0) + 1;
                if (t) drawnMaxError = Math.max(drawnMaxError, t.error);
            }
            const fetchedLeaves = [...new Set(files.filter((f) => byPath.get(f.path)?.leaf).map((f) => f.path))];
            const inView = new Set(value.inView);
            const outOfView = fetchedLeaves.filter((p) => !inView.has(p));
            report[name] = {
                ...report[name],
                settled: value.settled, frames: value.frames, ms: value.ms,
                fetched_bytes: files.reduce((s, f) => s + f.bytes, 0),
                fetched_by_level: fetchedBytesByLevel,
                drawn_by_level: drawnByLevel,
                drawn_max_error: drawnMaxError,
                fetched_leaves: fetchedLeaves.length,
                fetched_external_tilesets: new Set(files.filter((f) => externalTilesets.has(f.path)).map((f) => f.path)).size,
                leaves_in_view: [...inView].filter((p) => byPath.get(p).leaf).length,
                fetched_leaves_out_of_view: outOfView.length,
                fetched_leaf_bytes_out_of_view: outOfView.reduce((s, p) => s + byPath.get(p).bytes, 0),
                out_of_view_parent_out_of_view: outOfView.filter((p) => !inView.has(byPath.get(p).parent)).length,
                failed: value.failed,
            };
        } else if (url === '/match') {
            report.match = { ...report.match, ...value };
        } else if (url === '/error') {
            report.error = value.error;
            finish('done');
        } else if (url === '/done') {
            finish('done');
        }
    },
});
if (outcome === 'timeout') process.exit(2);
console.log(JSON.stringify(report, null, 2));
process.exit(0);
