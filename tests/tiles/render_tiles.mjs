// Loads a 3D Tiles tileset the way a web page shows it — three.js with 3d-tiles-renderer (its
// GLTFExtensionsPlugin decoding meshopt and Draco content) in headless Chromium — and prints
// what it fetched and drew as JSON:
//   node render_tiles.mjs OUT_DIR TILESET_JSON REFERENCE_GLB [--modules NODE_MODULES_DIR]
// REFERENCE_GLB is the full-resolution mesh in the tileset's coordinates (e.g. `meshstream
// convert IN ref.glb`; the tileset is expected without --origin). Four scenes, each with a new
// TilesRenderer (so nothing is cached between them) on a 512 × 512 canvas:
//   far     the whole model from far away (about 40 pixels across), default error target (16 px)
//   close   a point of the surface from close up (found by a ray from the whole view), 16 px
//   match   the whole model filling the view, error target 1 px, unlit (basic materials with
//           the tiles' colours and textures), beside the reference drawn the same way
//   levels  an oblique view, error target 4 px, each tile lit and coloured by its level
// The tileset's tiles are listed first, from its JSON files (external tilesets followed):
// each content's path, level (how many ancestors have content), whether it is a leaf, its
// bytes and its bounding box's corners in the tileset's coordinates. Report:
//   {tiles: {count, levels, leaves, bytes},                       // the whole tileset
//    far|close|levels: {fetched_bytes, fetched_by_level, drawn_by_level, fetched_leaves,
//                       leaves_in_view, fetched_leaves_out_of_view, failed},
//    match: {covered_reference, covered_tiles, missing, extra, colour_difference}}
// fetched_bytes counts every file the scene fetched (JSON and content); leaves_in_view counts
// the leaves whose box meets the camera's frustum; missing (extra) is the share of the
// reference's covered pixels the tiles leave uncovered (cover beyond it); colour_difference
// the mean absolute difference (0–255) over pixels both cover. OUT_DIR receives
// far.png, close.png, match_tiles.png, match_reference.png and levels.png.
// Exit status: 0 when the report was written, 2 when Chromium, three.js or 3d-tiles-renderer
// cannot be found or the page does not report within 180 s.
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

// Every tile with content, from the tileset's JSON files.
const inventory = [];
function walk(file, tile, parentMatrix, level) {
    const m = tile.transform ? multiply(parentMatrix, tile.transform) : parentMatrix;
    const uri = tile.content && (tile.content.uri || tile.content.url);
    let childLevel = level;
    let external = null;
    if (uri) {
        const target = path.join(path.dirname(file), decodeURIComponent(uri));
        if (target.endsWith('.json')) {
            external = target;
        } else {
            inventory.push({
                path: path.relative(tilesetDir, target), level, leaf: !(tile.children && tile.children.length),
                bytes: fs.statSync(target).size,
                corners: tile.boundingVolume.box ? boxCorners(tile.boundingVolume.box, m) : null,
            });
            childLevel = level + 1;
        }
    }
    if (external) {
        const json = JSON.parse(fs.readFileSync(external, 'utf8'));
        walk(external, json.root, m, level);
    }
    for (const child of tile.children || []) walk(file, child, m, childLevel);
}
const rootJson = JSON.parse(fs.readFileSync(tilesetJson, 'utf8'));
walk(path.resolve(tilesetJson), rootJson.root, identity, 0);
const byPath = new Map(inventory.map((t) => [t.path, t]));
let tilesetBytes = 0;
for (const f of fs.readdirSync(tilesetDir, { recursive: true })) {
    const p = path.join(tilesetDir, f);
    if (fs.statSync(p).isFile()) tilesetBytes += fs.statSync(p).size;
}

const page = `<!doctype html><html><head><meta charset="utf-8">
<script type="importmap">{"imports": {
  "three": "/three/build/three.module.js", "three/addons/": "/three/examples/jsm/",
  "3d-tiles-renderer": "/renderer/build/index.js", "3d-tiles-renderer/plugins": "/renderer/build/index.plugins.js"}}</script>
</head><body style="margin:0;background:#000">
<script type="module">
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { TilesRenderer } from '3d-tiles-renderer';
import { GLTFExtensionsPlugin } from '3d-tiles-renderer/plugins';
const leaves = ${JSON.stringify(inventory.filter((t) => t.leaf && t.corners).map((t) => ({ path: t.path, corners: t.corners })))};
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

// A scene: a new TilesRenderer drawn until nothing is queued, downloading or parsing.
async function show(name, camera, errorTarget, dress) {
    await post('/phase/' + name, {});
    const tiles = new TilesRenderer('/tiles/' + ${JSON.stringify(path.basename(tilesetJson))});
    tiles.registerPlugin(new GLTFExtensionsPlugin({ dracoLoader: draco, meshoptDecoder: MeshoptDecoder }));
    tiles.errorTarget = errorTarget;
    tiles.lruCache.minSize = 100000;
    tiles.lruCache.maxSize = 100000;
    tiles.lruCache.maxBytesSize = 4e9;
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
    camera.updateMatrixWorld();
    let idle = 0;
    const until = performance.now() + 20000;
    for (let frame = 0; idle < 10 && performance.now() < until; ++frame) {
        tiles.update();
        renderer.render(scene, camera);
        await new Promise((r) => setTimeout(r, 5));
        const s = tiles.stats;
        idle = frame > 3 && s.queued + s.downloading + s.parsing === 0 ? idle + 1 : 0;
    }
    const drawn = [];
    for (const t of tiles.visibleTiles) if (urls.has(t)) drawn.push(urls.get(t));
    const frustum = new THREE.Frustum().setFromProjectionMatrix(
        new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse));
    const inView = leaves.filter((l) => frustum.intersectsBox(new THREE.Box3().setFromPoints(
        l.corners.map((c) => new THREE.Vector3(...c).applyMatrix4(tiles.group.matrixWorld))))).map((l) => l.path);
    await post('/drawn/' + name, { drawn, inView, failed: tiles.stats.failed || 0, settled: idle >= 10, stats: { ...tiles.stats } });
    return { tiles, scene };
}

const loader = new GLTFLoader();
loader.setDRACOLoader(draco);
loader.setMeshoptDecoder(MeshoptDecoder);
try {
    await post('/phase/reference', {});
    const reference = (await loader.loadAsync('/reference.glb')).scene;
    reference.updateMatrixWorld(true);
    const box = new THREE.Box3().setFromObject(reference);
    const center = box.getCenter(new THREE.Vector3());
    const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-9);
    const direction = new THREE.Vector3(1, 0.8, 1.6).normalize();
    const camera = (distance, target, fov = 40) => {
        const c = new THREE.PerspectiveCamera(fov, 1, distance / 1000, distance + 4 * radius);
        c.position.copy(target).addScaledVector(direction, distance);
        c.lookAt(target);
        c.updateMatrixWorld();
        return c;
    };
    const whole = camera(radius * 2.6, center);

    // far: the model about 40 pixels across.
    await show('far', camera(radius * 2.6 * 512 / 40, center), 16);
    await save('far');

    // close: a point of the surface, seen from a twentieth of the model's radius.
    const ray = new THREE.Raycaster(whole.position.clone(), center.clone().sub(whole.position).normalize());
    const hit = ray.intersectObject(reference, true)[0];
    const target = hit ? hit.point : center;
    await show('close', camera(radius / 20, target), 16);
    await save('close');

    // match: the tiles at a 1-pixel error target against the reference, unlit.
    const { scene: tileScene } = await show('match', whole, 1, (scene) => basic(scene));
    const tilePixels = pixels();
    await save('match_tiles');
    basic(reference);
    const refScene = new THREE.Scene();
    refScene.add(reference);
    renderer.render(refScene, whole);
    const refPixels = pixels();
    await save('match_reference');
    let coveredRef = 0, coveredTiles = 0, missing = 0, extra = 0, both = 0, difference = 0;
    for (let i = 0; i < refPixels.length; i += 4) {
        const a = refPixels[i] + refPixels[i + 1] + refPixels[i + 2] > 0;
        const b = tilePixels[i] + tilePixels[i + 1] + tilePixels[i + 2] > 0;
        coveredRef += a; coveredTiles += b;
        if (a && !b) ++missing;
        if (b && !a) ++extra;
        if (a && b) {
            ++both;
            for (let k = 0; k < 3; ++k) difference += Math.abs(refPixels[i + k] - tilePixels[i + k]);
        }
    }
    await post('/match', { covered_reference: coveredRef / (size * size), covered_tiles: coveredTiles / (size * size),
        missing: coveredRef ? missing / coveredRef : 0, extra: coveredRef ? extra / coveredRef : 0,
        colour_difference: both ? difference / (3 * both) : 0 });

    // levels: oblique, each tile coloured by its level.
    const oblique = new THREE.PerspectiveCamera(50, 1, radius / 1000, radius * 10);
    oblique.position.copy(center).add(new THREE.Vector3(radius * 1.2, radius * 0.5, radius * 1.2));
    oblique.lookAt(center);
    oblique.updateMatrixWorld();
    await show('levels', oblique, 4, (scene, tile) => {
        const colour = palette[Math.min(tile.internal.depth, palette.length - 1)];
        scene.traverse((o) => {
            if (!o.isMesh) return;
            if (!o.geometry.attributes.normal) o.geometry.computeVertexNormals();
            o.material = new THREE.MeshLambertMaterial({ color: colour, side: THREE.DoubleSide });
        });
    });
    await save('levels');
    await post('/done', {});
} catch (e) {
    await post('/error', { error: String(e && e.stack ? e.stack : e) });
}
</script></body></html>`;

const report = {
    tiles: {
        count: inventory.length, levels: Math.max(0, ...inventory.map((t) => t.level)) + 1,
        leaves: inventory.filter((t) => t.leaf).length, bytes: tilesetBytes,
    },
};
let phase = null;
const fetched = {};
const outcome = await runPage({
    chromium, name: 'render_tiles', timeoutMs: Number(process.env.RENDER_TILES_TIMEOUT || 180000), page,
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
            if (process.env.RENDER_TILES_TRACE) console.error('render_tiles: phase ' + phase);
            fetched[phase] = [];
        } else if (url.startsWith('/png/')) {
            fs.writeFileSync(path.join(outDir, `${url.slice(5)}.png`), Buffer.from(value.split(',')[1], 'base64'));
        } else if (url.startsWith('/drawn/')) {
            const name = url.slice(7);
            const byLevel = (list) => {
                const counts = {};
                for (const p of list) {
                    const t = byPath.get(p);
                    if (t) counts[t.level] = (counts[t.level] || 0) + t.bytes;
                }
                return counts;
            };
            const files = fetched[name];
            const fetchedLeaves = files.filter((f) => byPath.get(f.path)?.leaf).map((f) => f.path);
            const inView = new Set(value.inView);
            const drawnLevels = {};
            for (const p of value.drawn) {
                const t = byPath.get(p);
                if (t) drawnLevels[t.level] = (drawnLevels[t.level] || 0) + 1;
            }
            report[name] = {
                fetched_bytes: files.reduce((s, f) => s + f.bytes, 0),
                fetched_by_level: byLevel(files.map((f) => f.path)),
                drawn_by_level: drawnLevels,
                fetched_leaves: fetchedLeaves.length,
                leaves_in_view: inView.size,
                fetched_leaves_out_of_view: fetchedLeaves.filter((p) => !inView.has(p)).length,
                failed: value.failed,
                settled: value.settled,
                stats: value.stats,
            };
        } else if (url === '/match') {
            report.match = value;
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
