// A plain command-line boolean on npm manifold-3d (Manifold's WASM build, one
// thread), the peer of `ldc boolean` in bench_boolean_process:
//
//   node manifold_boolean.mjs A.obj B.obj --op subtract|union|intersect -o out.obj
//
// Loads both OBJs (v and f lines; polygons fanned), constructs a Manifold of
// each (Mesh with numProp 3, merge()), computes the boolean, takes getMesh()
// and writes a plain OBJ. Prints the phase times in ms as one JSON line on
// stdout: module (WASM instantiation), load, construct, boolean (the op plus
// numTri(), which forces Manifold's lazy evaluation), export (getMesh + OBJ
// text + write). Exit code 1 with a message on failure, 2 for bad arguments.
// Benchmark only: `npm ci` in bench/js installs manifold-3d (package-lock.json).
import { readFileSync, writeFileSync } from 'node:fs';
import { performance } from 'node:perf_hooks';
import Module from 'manifold-3d';

function usage() {
  process.stderr.write('usage: node manifold_boolean.mjs A.obj B.obj --op subtract|union|intersect -o out.obj\n');
  process.exit(2);
}

const inputs = [];
let op = '';
let out = '';
const args = process.argv.slice(2);
for (let i = 0; i < args.length; ++i) {
  if (args[i] === '--op' && i + 1 < args.length) op = args[++i];
  else if ((args[i] === '-o' || args[i] === '--output') && i + 1 < args.length) out = args[++i];
  else if (!args[i].startsWith('-') && inputs.length < 2) inputs.push(args[i]);
  else usage();
}
if (inputs.length !== 2 || !out || !['subtract', 'union', 'intersect'].includes(op)) usage();

function fail(message) {
  process.stderr.write(`manifold_boolean.mjs: ${message}\n`);
  process.exit(1);
}

// OBJ positions and triangles (fan of each polygon; v/vt/vn face indices; negative indices relative).
function loadObj(path) {
  const text = readFileSync(path, 'latin1');
  const pos = [];
  const tri = [];
  let start = 0;
  while (start < text.length) {
    let end = text.indexOf('\n', start);
    if (end < 0) end = text.length;
    const line = text.slice(start, end).trim();
    start = end + 1;
    if (line.startsWith('v ')) {
      const f = line.split(/\s+/);
      pos.push(+f[1], +f[2], +f[3]);
    } else if (line.startsWith('f ')) {
      const f = line.split(/\s+/).slice(1);
      const nv = pos.length / 3;
      const idx = f.map((s) => {
        const k = parseInt(s, 10);
        return k < 0 ? nv + k : k - 1;
      });
      for (let k = 1; k + 1 < idx.length; ++k) tri.push(idx[0], idx[k], idx[k + 1]);
    }
  }
  if (tri.length === 0) fail(`${path}: no triangles`);
  return { vertProperties: new Float32Array(pos), triVerts: new Uint32Array(tri) };
}

const t0 = performance.now();
const wasm = await Module();
wasm.setup();
const { Manifold, Mesh } = wasm;
const t1 = performance.now();
const meshes = inputs.map(loadObj);
const t2 = performance.now();
const solids = meshes.map((m, i) => {
  const mesh = new Mesh({ numProp: 3, vertProperties: m.vertProperties, triVerts: m.triVerts });
  mesh.merge();
  let s;
  try {
    s = new Manifold(mesh);
  } catch (e) {
    fail(`${inputs[i]}: not a manifold (${e.message ?? e})`);
  }
  return s;
});
const t3 = performance.now();
const [a, b] = solids;
const r = op === 'subtract' ? a.subtract(b) : op === 'union' ? a.add(b) : a.intersect(b);
const triangles = r.numTri();
if (r.status() !== 'NoError') fail(`the boolean failed: ${r.status()}`);
const t4 = performance.now();
const mesh = r.getMesh();
const np = mesh.numProp;
const nv = mesh.vertProperties.length / np;
const parts = [];
for (let v = 0; v < nv; ++v)
  parts.push(`v ${mesh.vertProperties[v * np]} ${mesh.vertProperties[v * np + 1]} ${mesh.vertProperties[v * np + 2]}\n`);
for (let t = 0; t < mesh.triVerts.length; t += 3)
  parts.push(`f ${mesh.triVerts[t] + 1} ${mesh.triVerts[t + 1] + 1} ${mesh.triVerts[t + 2] + 1}\n`);
writeFileSync(out, parts.join(''));
const t5 = performance.now();
const ms = (x) => Math.round(x * 1000) / 1000;
process.stdout.write(JSON.stringify({
  module_ms: ms(t1 - t0), load_ms: ms(t2 - t1), construct_ms: ms(t3 - t2), boolean_ms: ms(t4 - t3),
  export_ms: ms(t5 - t4), triangles,
}) + '\n');
