// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// meshoptimizer 1.3.0's codec (npm package, WebAssembly) + zstd, the way a glTF pipeline ships a
// plain mesh (gltfpack: reorder, quantize, encode, then a general-purpose compressor), as a peer
// of the compact CM file in run_rate_distortion.py:
//
//   node meshopt_encode.mjs IN.obj DECODED.obj --bits B
//
// Reads the positions and triangles of an OBJ (v and f lines; polygons split into fans), reorders
// vertices and triangles for the vertex cache and fetch (MeshoptEncoder.reorderMesh), quantizes the
// positions to B bits per axis over their bounding box (uint16 x 4, stride 8), encodes the vertex
// buffer (encodeVertexBuffer) and the index buffer (encodeIndexBuffer), and compresses the two with
// the zstd command (level 19). The counted bytes are the zstd output plus a 36-byte header (counts,
// bounding box origin and scale, bits). DECODED.obj receives the mesh a decoder would rebuild
// (dequantized positions), written atomically. One JSON line on stdout:
//   {"bits":..,"vertices":..,"faces":..,"bytes":..,"vertex_bytes":..,"index_bytes":..}
// Errors: one line on stderr, exit code 1.
import { readFileSync, writeFileSync, renameSync } from 'node:fs';
import { spawnSync } from 'node:child_process';
import { MeshoptEncoder } from 'meshoptimizer';

function fail(msg) {
  process.stderr.write(`meshopt_encode: ${msg}\n`);
  process.exit(1);
}

const args = process.argv.slice(2);
if (args.length !== 4 || args[2] !== '--bits') fail('usage: node meshopt_encode.mjs IN.obj DECODED.obj --bits B');
const [input, output, , bitsText] = args;
const bits = Number(bitsText);
if (!Number.isInteger(bits) || bits < 4 || bits > 16) fail(`--bits must be an integer in [4, 16], got '${bitsText}'`);

const positions = [];
const indices = [];
const lines = readFileSync(input, 'utf8').split('\n');
lines.forEach((line, n) => {
  const t = line.trim().split(/\s+/);
  if (t[0] === 'v') {
    const p = t.slice(1, 4).map(Number);
    if (p.length !== 3 || p.some((x) => !Number.isFinite(x))) fail(`${input}:${n + 1}: bad vertex`);
    positions.push(p);
  } else if (t[0] === 'f') {
    const c = t.slice(1).map((s) => {
      const i = parseInt(s.split('/')[0], 10);
      const k = i < 0 ? positions.length + i : i - 1;
      if (!Number.isInteger(k) || k < 0 || k >= positions.length) fail(`${input}:${n + 1}: bad face index '${s}'`);
      return k;
    });
    if (c.length < 3) fail(`${input}:${n + 1}: face with fewer than 3 corners`);
    for (let i = 1; i + 1 < c.length; ++i) indices.push(c[0], c[i], c[i + 1]);
  }
});
if (indices.length === 0) fail(`${input}: no triangle`);

await MeshoptEncoder.ready;
// reorders the triangles and renumbers the vertices of `reordered` in place
const reordered = Uint32Array.from(indices);
const [remap, unique] = MeshoptEncoder.reorderMesh(reordered, true, false);
const lo = [Infinity, Infinity, Infinity];
const hi = [-Infinity, -Infinity, -Infinity];
for (const p of positions) for (let k = 0; k < 3; ++k) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
const extent = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
const scale = extent / ((1 << bits) - 1);
const q = new Uint16Array(unique * 4);
const decoded = new Array(unique);
positions.forEach((p, i) => {
  const j = remap[i];
  if (j === 0xffffffff) return;  // unused vertex
  const d = [0, 0, 0];
  for (let k = 0; k < 3; ++k) {
    const v = Math.round((p[k] - lo[k]) / scale);
    q[4 * j + k] = v;
    d[k] = lo[k] + v * scale;
  }
  decoded[j] = d;
});
const vertexBytes = MeshoptEncoder.encodeVertexBuffer(new Uint8Array(q.buffer), unique, 8);
const indexBytes = MeshoptEncoder.encodeIndexBuffer(new Uint8Array(reordered.buffer), reordered.length, 4);
const joined = Buffer.concat([Buffer.from(vertexBytes), Buffer.from(indexBytes)]);
const z = spawnSync('zstd', ['-19', '-q', '-c'], { input: joined, maxBuffer: 1 << 30 });
if (z.status !== 0) fail(`zstd failed: ${z.stderr}`);
const bytes = z.stdout.length + 36;

let obj = '';
for (const d of decoded) obj += `v ${d[0]} ${d[1]} ${d[2]}\n`;
for (let i = 0; i < reordered.length; i += 3) obj += `f ${reordered[i] + 1} ${reordered[i + 1] + 1} ${reordered[i + 2] + 1}\n`;
writeFileSync(`${output}.tmp`, obj);
renameSync(`${output}.tmp`, output);
process.stdout.write(JSON.stringify({ bits, vertices: unique, faces: reordered.length / 3, bytes,
  vertex_bytes: vertexBytes.length, index_bytes: indexBytes.length }) + '\n');
