// Renders glTF/GLB files with three.js (GLTFLoader with MeshoptDecoder and DRACOLoader) in
// headless Chromium, the way a web page shows them, and prints what the pictures hold as JSON.
//   node render_gltf.mjs OUT_DIR FILE... [--modules NODE_MODULES_DIR]
// A local HTTP server (127.0.0.1, a free port) serves the page, three.js and the files; the page
// loads each file in turn, frames it, lights it, renders 256 × 256 pixels over a black
// background, saves the canvas as OUT_DIR/<n>.png and reports per file:
//   {file, triangles, covered (fraction of pixels not background), saturated (fraction of covered
//    pixels with HSV saturation > 0.25), distinct (colours among covered pixels, 4 bits a
//    channel), mean [r, g, b] of covered pixels, error (when loading failed)}.
// Exit status: 0 when every file was rendered (or failed to load: see its "error"), 2 when
// Chromium or three.js cannot be found or the page does not report within 90 s.
// three.js is looked up in NODE_MODULES_DIR, else $MESHSTREAM_TOOLS_DIR/node_modules, else
// /opt/meshstream-tools/node_modules (tools/bootstrap.sh installs it there); Chromium is
// $CHROMIUM, else `chromium` on the PATH (Debian's package).
import fs from 'node:fs';
import path from 'node:path';
import { below, modulesDir, requireTools, runPage } from './headless.mjs';

const args = process.argv.slice(2);
const modules = modulesDir(args);
const [outDir, ...files] = args;
if (!outDir || files.length === 0) {
    console.error('usage: node render_gltf.mjs OUT_DIR FILE... [--modules NODE_MODULES_DIR]');
    process.exit(2);
}
const chromium = requireTools('render_gltf', modules, [['three', 'build/three.module.js']]);
const three = path.join(modules, 'three');
fs.mkdirSync(outDir, { recursive: true });

const page = `<!doctype html><html><head><meta charset="utf-8">
<script type="importmap">{"imports": {"three": "/three/build/three.module.js", "three/addons/": "/three/examples/jsm/"}}</script>
</head><body style="margin:0;background:#000">
<script type="module">
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
const names = ${JSON.stringify(files.map((f) => encodeURIComponent(path.basename(f))))};
const count = names.length;
const size = 256;
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(size, size);
renderer.setClearColor(0x000000, 1);
document.body.appendChild(renderer.domElement);
const draco = new DRACOLoader();
draco.setDecoderPath('/three/examples/jsm/libs/draco/');
draco.setDecoderConfig({ type: 'js' });
const loader = new GLTFLoader();
loader.setDRACOLoader(draco);
loader.setMeshoptDecoder(MeshoptDecoder);
async function report(n, body) {
    await fetch('/result/' + n, { method: 'POST', body: JSON.stringify(body) });
}
for (let n = 0; n < count; ++n) {
    try {
        // /file/<n>/<name>: a .gltf's relative URIs (its .bin, its images) resolve beside it.
        const gltf = await loader.loadAsync('/file/' + n + '/' + names[n]);
        const scene = new THREE.Scene();
        scene.add(gltf.scene);
        scene.add(new THREE.AmbientLight(0xffffff, 0.6));
        const sun = new THREE.DirectionalLight(0xffffff, 2.0);
        sun.position.set(1, 2, 3);
        scene.add(sun);
        let triangles = 0;
        gltf.scene.traverse((o) => {
            if (!o.isMesh) return;
            const g = o.geometry;
            triangles += (g.index ? g.index.count : g.attributes.position.count) / 3;
        });
        const box = new THREE.Box3().setFromObject(gltf.scene);
        const center = box.getCenter(new THREE.Vector3());
        const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-9);
        const camera = new THREE.PerspectiveCamera(40, 1, radius / 100, radius * 100);
        camera.position.copy(center).add(new THREE.Vector3(1, 0.8, 1.6).normalize().multiplyScalar(radius * 2.6));
        camera.lookAt(center);
        renderer.render(scene, camera);
        const gl = renderer.getContext();
        const pixels = new Uint8Array(size * size * 4);
        gl.readPixels(0, 0, size, size, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
        let covered = 0, saturated = 0;
        const sum = [0, 0, 0], colours = new Set();
        for (let i = 0; i < pixels.length; i += 4) {
            const r = pixels[i], g = pixels[i + 1], b = pixels[i + 2];
            if (r + g + b === 0) continue;
            ++covered;
            sum[0] += r; sum[1] += g; sum[2] += b;
            const max = Math.max(r, g, b), min = Math.min(r, g, b);
            if (max > 0 && (max - min) / max > 0.25) ++saturated;
            colours.add((r >> 4) << 8 | (g >> 4) << 4 | (b >> 4));
        }
        await report(n, {
            triangles,
            covered: covered / (size * size),
            saturated: covered ? saturated / covered : 0,
            distinct: colours.size,
            mean: sum.map((s) => (covered ? s / covered : 0)),
            png: renderer.domElement.toDataURL('image/png'),
        });
    } catch (e) {
        await report(n, { error: String(e && e.stack ? e.stack : e) });
    }
}
</script></body></html>`;

const results = new Array(files.length).fill(null);
let done = 0;
const outcome = await runPage({
    chromium, name: 'render_gltf', timeoutMs: 90000, page,
    serve(url) {
        if (url.startsWith('/file/')) {
            // /file/<n>/<path>: file n's directory (its own name, or what its URIs name).
            const slash = url.indexOf('/', 6);
            const n = Number(url.slice(6, slash));
            if (slash > 6 && n >= 0 && n < files.length) return below(path.dirname(files[n]), url.slice(slash + 1));
        } else if (url.startsWith('/three/')) {
            return below(three, url.slice(7));
        }
        return undefined;
    },
    post(url, body, finish) {
        if (!url.startsWith('/result/')) return;
        const n = Number(url.slice(8));
        const r = JSON.parse(body);
        if (r.png) {
            fs.writeFileSync(path.join(outDir, `${n}.png`), Buffer.from(r.png.split(',')[1], 'base64'));
            delete r.png;
        }
        results[n] = { file: files[n], ...r };
        if (++done === files.length) finish('done');
    },
});
if (outcome === 'timeout') process.exit(2);
console.log(JSON.stringify(results, null, 2));
process.exit(0);
