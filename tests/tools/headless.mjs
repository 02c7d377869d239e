// Runs one page in headless Chromium (Debian's package, WebGL through SwiftShader) against a
// local HTTP server, for the scripts that check what the files meshstream writes look like in a
// browser (render_gltf.mjs: three.js's GLTFLoader; render_tiles.mjs: 3d-tiles-renderer).
//
//   const outcome = await runPage({ page, serve, post, name, timeoutMs });
//
// The server (127.0.0.1, a free port) answers GET /index.html with `page`, other GETs with the
// file `serve(url)` names (404 when it names none or one that does not exist), sent with
// `Cache-Control: no-store` so that every fetch of the page reaches it, and hands each POST's
// body to `post(url, body, done)`; the page reports by POSTing, and the script calls
// `done(value)` when it has all it needs. runPage resolves to that value, or to 'timeout' when the
// page did not finish within timeoutMs (Chromium's last words are then printed). Chromium runs
// in its own process group with a throw-away profile, both removed before runPage returns.
// `onGet(url, bytes)` (optional) sees every file served and its size.
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { spawn, spawnSync } from 'node:child_process';

// The node_modules folder holding the npm tools (tools/bootstrap.sh installs them): --modules DIR
// taken out of `args` when given, else $MESHSTREAM_TOOLS_DIR/node_modules, else
// /opt/meshstream-tools/node_modules.
export function modulesDir(args) {
    const m = args.indexOf('--modules');
    if (m >= 0) {
        const dir = args[m + 1];
        args.splice(m, 2);
        return dir;
    }
    return path.join(process.env.MESHSTREAM_TOOLS_DIR || '/opt/meshstream-tools', 'node_modules');
}

// Exits with status 2 and a message naming `script` when a package or Chromium is missing.
export function requireTools(script, modules, packages) {
    for (const [name, file] of packages) {
        if (!fs.existsSync(path.join(modules, name, file))) {
            console.error(`${script}: ${name} not found in ${modules} (run tools/bootstrap.sh)`);
            process.exit(2);
        }
    }
    const chromium = process.env.CHROMIUM || 'chromium';
    if (spawnSync(chromium, ['--version']).status !== 0) {
        console.error(`${script}: cannot run ${chromium} (Debian package 'chromium'; run tools/bootstrap.sh)`);
        process.exit(2);
    }
    return chromium;
}

// The file below `root` that a URL's `rest` names, or undefined when it would leave `root`.
export function below(root, rest) {
    const p = path.normalize(rest);
    return p.startsWith('..') || path.isAbsolute(p) ? undefined : path.join(root, p);
}

const types = { '.js': 'text/javascript', '.mjs': 'text/javascript', '.wasm': 'application/wasm', '.html': 'text/html',
    '.json': 'application/json', '.glb': 'model/gltf-binary', '.png': 'image/png', '.jpg': 'image/jpeg' };

export async function runPage({ chromium, page, serve, post, onGet, name, timeoutMs }) {
    let finish;
    const finished = new Promise((resolve) => (finish = resolve));
    const server = http.createServer((req, res) => {
        const url = decodeURIComponent(req.url.split('?')[0]);
        if (req.method === 'POST') {
            const parts = [];
            req.on('data', (d) => parts.push(d));
            req.on('end', () => {
                res.end('ok');
                post(url, Buffer.concat(parts).toString('utf8'), finish);
            });
            return;
        }
        res.setHeader('Cache-Control', 'no-store');
        if (url === '/' || url === '/index.html') {
            res.setHeader('Content-Type', 'text/html');
            res.end(page);
            return;
        }
        const file = serve(url);
        if (!file || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
            res.statusCode = 404;
            res.end();
            return;
        }
        if (onGet) onGet(url, fs.statSync(file).size);
        res.setHeader('Content-Type', types[path.extname(file)] || 'application/octet-stream');
        fs.createReadStream(file).pipe(res);
    });
    await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
    const port = server.address().port;

    const profile = fs.mkdtempSync(path.join(os.tmpdir(), `${name}-`));
    const browser = spawn(chromium, [
        '--headless=new', '--no-sandbox', '--no-first-run', '--disable-extensions', '--mute-audio',
        '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
        `--user-data-dir=${profile}`, `http://127.0.0.1:${port}/index.html`,
    ], { stdio: ['ignore', 'ignore', 'pipe'], detached: true });  // its own process group, ended whole below
    const exited = new Promise((resolve) => browser.on('exit', resolve));
    let browserLog = '';
    browser.stderr.on('data', (d) => (browserLog = (browserLog + d).slice(-4000)));
    const timer = setTimeout(() => finish('timeout'), timeoutMs);
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
    if (outcome === 'timeout') console.error(`${name}: no report from the page within ${timeoutMs / 1000} s; chromium said:\n${browserLog}`);
    return outcome;
}
