// Runs the Khronos glTF validator (npm package gltf-validator) on one .glb/.gltf file and prints
// its JSON report. Exit status: 0 when the report has no errors, 1 when it has errors, 2 when
// the validator or the file cannot be loaded.
//   node validate_gltf.mjs FILE [NODE_MODULES_DIR]
// The validator is looked up in NODE_MODULES_DIR, else $MESHSTREAM_TOOLS_DIR/node_modules,
// else /opt/meshstream-tools/node_modules (where the set-up script installs it).
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';

const [file, modulesArg] = process.argv.slice(2);
if (!file) {
    console.error('usage: node validate_gltf.mjs FILE [NODE_MODULES_DIR]');
    process.exit(2);
}
const modules = modulesArg || path.join(process.env.MESHSTREAM_TOOLS_DIR || '/opt/meshstream-tools', 'node_modules');
let validator;
try {
    validator = createRequire(path.join(modules, 'noop.js'))('gltf-validator');
} catch (e) {
    console.error(`validate_gltf: cannot load gltf-validator from ${modules}: ${e.message}`);
    process.exit(2);
}

let bytes;
try {
    bytes = fs.readFileSync(file);
} catch (e) {
    console.error(`validate_gltf: ${e.message}`);
    process.exit(2);
}
const dir = path.dirname(path.resolve(file));
const report = await validator.validateBytes(new Uint8Array(bytes), {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: (uri) => new Promise((resolve, reject) => {
        fs.readFile(path.resolve(dir, decodeURIComponent(uri)), (err, data) => (err ? reject(err.toString()) : resolve(data)));
    }),
});
console.log(JSON.stringify(report, null, 2));
process.exit(report.issues.numErrors > 0 ? 1 : 0);
