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
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { spawn, spawnSync } from 'node:child_process';

const args = process.argv.slice(2);
let modules = path.join(process.env.MESHSTREAM_TOOLS_DIR || '/opt/meshstream-tools', 'node_modules');
const m = args.indexOf('--modules');
if (m >= 0) {
    modules = args[m + 1];
    args.splice(m, 2);
}
const [outDir, ...files] = args;
if (!outDir || files.length === 0) {
    console.error('usage: node render_gltf.mjs OUT_DIR FILE... [--modules NODE_MODULES_DIR]');
    process.exit(2);
}
const three = path.join(modules, 'three');
if (!fs.existsSync(path.join(three, 'build', 'three.module.js'))) {
    console.error(`render_gltf: three.js not found in ${modules} (run tools/bootstrap.sh)`);
    process.exit(2);
}
const chromium = process.env.CHROMIUM || 'chromium';
if (spawnSync(chromium, ['--version']).status !== 0) {
    console.error(`render_gltf: cannot run ${chromium} (Debian package 'chromium'; run tools/bootstrap.sh)`);
    process.exit(2);
}
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

const types = { '.js': 'text/javascript', '.mjs': 'text/javascript', '.wasm': 'application/wasm', '.html': 'text/html' };
const results = new Array(files.length).fill(null);
let done = 0;
let finish;
const finished = new Promise((resolve) => (finish = resolve));

const server = http.createServer((req, res) => {
    const url = decodeURIComponent(req.url.split('?')[0]);
    if (req.method === 'POST' && url.startsWith('/result/')) {
        let body = '';
        req.on('data', (d) => (body += d));
        req.on('end', () => {
            const n = Number(url.slice(8));
            const r = JSON.parse(body);
            if (r.png) {
                fs.writeFileSync(path.join(outDir, `${n}.png`), Buffer.from(r.png.split(',')[1], 'base64'));
                delete r.png;
            }
            results[n] = { file: files[n], ...r };
            res.end('ok');
            if (++done === files.length) finish();
        });
        return;
    }
    let file;
    if (url === '/' || url === '/index.html') {
        res.setHeader('Content-Type', 'text/html');
        res.end(page);
        return;
    } else if (url.startsWith('/file/')) {
        // /file/<n>/<path>: file n's directory (its own name, or what its URIs name).
        const slash = url.indexOf('/', 6);
        const n = Number(url.slice(6, slash));
        const rest = path.normalize(url.slice(slash + 1));
        if (slash > 6 && n >= 0 && n < files.length && !rest.startsWith('..')) file = path.join(path.dirname(files[n]), rest);
    } else if (url.startsWith('/three/')) {
        const rest = path.normalize(url.slice(7));
        if (!rest.startsWith('..')) file = path.join(three, rest);
    }
    if (!file || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
        res.statusCode = 404;
        res.end();
        return;
    }
    res.setHeader('Content-Type', types[path.extname(file)] || 'application/octet-stream');
    fs.createReadStream(file).pipe(res);
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const port = server.address().port;

const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'render-gltf-'));
const browser = spawn(chromium, [
    '--headless=new', '--no-sandbox', '--no-first-run', '--disable-extensions', '--mute-audio',
    '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
    `--user-data-dir=${profile}`, `http://127.0.0.1:${port}/index.html`,
], { stdio: ['ignore', 'ignore', 'pipe'], detached: true });  // its own process group, ended whole below
const exited = new Promise((resolve) => browser.on('exit', resolve));
let browserLog = '';
browser.stderr.on('data', (d) => (browserLog = (browserLog + d).slice(-4000)));
const timer = setTimeout(() => finish('timeout'), 90000);
const outcome = await finished;
clearTimeout(timer);
try {
    process.kill(-browser.pid, 'SIGKILL');  // Chromium's renderer and GPU processes too
} catch (e) {
    // already gone
}
await exited;
server.close();
fs.rmSync(profile, { recursive: true, force: true, maxRetries: 5, retryDelay: 200 });
if (outcome === 'timeout') {
    console.error(`render_gltf: no report from the page within 90 s (${done} of ${files.length}); chromium said:\n${browserLog}`);
    process.exit(2);
}
console.log(JSON.stringify(results, null, 2));
process.exit(0);
