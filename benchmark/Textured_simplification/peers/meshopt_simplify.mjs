// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// meshoptimizer 1.3.0 (npm package, WebAssembly) as a peer of CMGeom's textured simplification,
// run by run_textured_peers.py:
//
//   node meshopt_simplify.mjs IN.obj OUT.obj --faces N --variant attr|permissive-protected|permissive
//                             [--mtl PATH] [--aggressive]
//
// The OBJ (v, vt, f with v/vt or v/vt/vn corners, polygons split into fans, 1-based or negative
// indices) becomes an indexed vertex buffer in which a vertex is a unique (position, uv) pair (and
// material, when the file uses several), so a UV seam is a set of vertices sharing a position.
// MeshoptSimplifier then runs to a target of 3N indices with an unlimited error (1e30), without
// LockBorder nor Prune:
//   attr                  simplifyWithAttributes, UV as two attributes of weight
//                         w = 1 / sqrt(mean |UV triangle area|) each (meshoptimizer's README), no flag
//   permissive-protected  the same with the Permissive flag, every vertex whose position belongs to
//                         more than one vertex tagged Protect (bit 2) in vertex_lock, as gltfpack does:
//                         collapses may slide along a seam but not cross it
//   permissive            Permissive flag, nothing protected: collapses may cross seams
// --aggressive does what gltfpack's -sa does when the simplifier stops above the target (seams and
// protected vertices left no collapse): for a target above 50 faces it runs simplifySloppy on the
// result, positions only, down to the target (it then crosses seams: a kept vertex keeps its UV).
// The output keeps the original positions and UVs of the kept vertices (meshoptimizer only picks
// vertices), drops the unused ones, repeats the input's usemtl statements and names its material
// library by absolute path (or the MTL given by --mtl), so the output wears the original texture.
// It is written atomically (temporary file + rename). One JSON line on stdout:
//   {"variant":..,"faces_in":..,"target_faces":..,"faces_out":..,"seconds":.., "sloppy":.., ...}
// (seconds: the simplification call alone). Errors: one line on stderr, exit code 1 for bad input,
// 2 for bad usage; no partial output file is left.
import { readFileSync, writeFileSync, renameSync, rmSync, existsSync, statSync } from 'node:fs';
import { dirname, resolve, isAbsolute, join, basename } from 'node:path';
import { fileURLToPath } from 'node:url';
import { performance } from 'node:perf_hooks';
import { MeshoptSimplifier } from 'meshoptimizer';

const VARIANTS = ['attr', 'permissive-protected', 'permissive'];
const REQUIRED_VERSION = '1.3.0';
const PROTECT = 2; // meshopt_SimplifyVertex_Protect
const UNLIMITED_ERROR = 1e30;

class UsageError extends Error {}
class InputError extends Error {}

function usage(msg) {
  throw new UsageError(
    `${msg}\nusage: node meshopt_simplify.mjs IN.obj OUT.obj --faces N --variant ${VARIANTS.join('|')} [--mtl PATH] [--aggressive]`
  );
}

function parseArgs(argv) {
  const pos = [];
  const opt = { faces: null, variant: null, mtl: null, aggressive: false };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    if (a === '--faces' || a === '--variant' || a === '--mtl') {
      if (i + 1 >= argv.length) usage(`${a} needs a value`);
      opt[a.slice(2)] = argv[++i];
    } else if (a === '--aggressive') {
      opt.aggressive = true;
    } else if (a.startsWith('--')) {
      usage(`unknown option ${a}`);
    } else {
      pos.push(a);
    }
  }
  if (pos.length !== 2) usage('expected IN.obj and OUT.obj');
  if (opt.faces === null) usage('--faces is required');
  if (!/^[0-9]+$/.test(opt.faces) || Number(opt.faces) < 1) usage(`--faces needs a positive integer, got '${opt.faces}'`);
  if (!VARIANTS.includes(opt.variant)) usage(`--variant must be one of ${VARIANTS.join(', ')}, got '${opt.variant}'`);
  return {
    input: pos[0],
    output: pos[1],
    faces: Number(opt.faces),
    variant: opt.variant,
    mtl: opt.mtl,
    aggressive: opt.aggressive,
  };
}

// ---- OBJ reader -----------------------------------------------------------------------------------

function parseNumber(tok, path, lineNo, what) {
  const x = Number(tok);
  if (tok === undefined || tok === '' || !Number.isFinite(x)) throw new InputError(`${path}:${lineNo}: ${what} needs finite numbers, got '${tok ?? ''}'`);
  return x;
}

function parseIndex(tok, count, path, lineNo, what) {
  if (!/^[+-]?[0-9]+$/.test(tok)) throw new InputError(`${path}:${lineNo}: bad ${what} index '${tok}'`);
  const i = Number(tok);
  const r = i > 0 ? i - 1 : count + i;
  if (i === 0 || r < 0 || r >= count) throw new InputError(`${path}:${lineNo}: ${what} index ${i} out of range (${count} defined so far)`);
  return r;
}

function readObj(path) {
  let text;
  try {
    text = readFileSync(path, 'utf8');
  } catch (e) {
    throw new InputError(`${path}: cannot read (${e.code ?? e.message})`);
  }
  const positions = []; // [x, y, z]
  const uvs = []; // [u, v]
  const tris = []; // [p0, t0, p1, t1, p2, t2, material]
  const materials = []; // names in order of first use ('' = before any usemtl)
  const materialIndex = new Map();
  const mtllibs = []; // as written
  let current = -1;
  const useMaterial = (name) => {
    if (!materialIndex.has(name)) {
      materialIndex.set(name, materials.length);
      materials.push(name);
    }
    return materialIndex.get(name);
  };
  const lines = text.split(/\r?\n/);
  for (let n = 0; n < lines.length; ++n) {
    const lineNo = n + 1;
    const line = lines[n].trim();
    if (line === '' || line[0] === '#') continue;
    const sp = line.search(/\s/);
    const key = sp < 0 ? line : line.slice(0, sp);
    const rest = sp < 0 ? '' : line.slice(sp + 1).trim();
    if (key === 'v') {
      const t = rest.split(/\s+/);
      positions.push([0, 1, 2].map((k) => parseNumber(t[k], path, lineNo, 'vertex')));
    } else if (key === 'vt') {
      const t = rest.split(/\s+/);
      uvs.push([parseNumber(t[0], path, lineNo, 'texture coordinate'), t.length > 1 ? parseNumber(t[1], path, lineNo, 'texture coordinate') : 0]);
    } else if (key === 'f') {
      const corners = rest.split(/\s+/).filter((s) => s !== '');
      if (corners.length < 3) throw new InputError(`${path}:${lineNo}: face with ${corners.length} corner(s); at least 3 needed`);
      const c = corners.map((s) => {
        const parts = s.split('/');
        if (parts.length < 2 || parts[1] === '') throw new InputError(`${path}:${lineNo}: face corner '${s}' has no texture coordinate (v/vt or v/vt/vn needed)`);
        return [parseIndex(parts[0], positions.length, path, lineNo, 'vertex'), parseIndex(parts[1], uvs.length, path, lineNo, 'texture coordinate')];
      });
      if (current < 0) current = useMaterial('');
      for (let k = 1; k + 1 < c.length; ++k) tris.push([c[0][0], c[0][1], c[k][0], c[k][1], c[k + 1][0], c[k + 1][1], current]);
    } else if (key === 'usemtl') {
      if (rest === '') throw new InputError(`${path}:${lineNo}: usemtl without a material name`);
      current = useMaterial(rest);
    } else if (key === 'mtllib') {
      if (rest === '') throw new InputError(`${path}:${lineNo}: mtllib without a file name`);
      mtllibs.push(rest);
    }
  }
  if (tris.length === 0) throw new InputError(`${path}: no faces`);
  return { positions, uvs, tris, materials, mtllibs };
}

// mtllib names resolved as CMGeom's reader does: the whole rest of the line if it names a file,
// else each whitespace-separated name.
function resolveMtllibs(objPath, mtllibs) {
  const dir = dirname(resolve(objPath));
  const out = [];
  for (const raw of mtllibs) {
    const whole = raw.replace(/\\/g, '/');
    const abs = (n) => (isAbsolute(n) ? n : join(dir, n));
    const names = existsSync(abs(whole)) ? [whole] : whole.split(/\s+/);
    for (const n of names) {
      const p = resolve(abs(n));
      if (!existsSync(p)) process.stderr.write(`meshopt_simplify: warning: ${objPath}: material library '${n}' not found (looked for ${p})\n`);
      out.push(p);
    }
  }
  return out;
}

function firstMaterialName(mtlPath) {
  const m = readFileSync(mtlPath, 'utf8').match(/^\s*newmtl\s+(.+?)\s*$/m);
  if (!m) throw new InputError(`${mtlPath}: no newmtl statement`);
  return m[1];
}

// ---- simplification -------------------------------------------------------------------------------

function buildVertexBuffer(obj) {
  // Positions and UVs are identified by value (an OBJ may repeat a value under two indices).
  const posId = new Map();
  const uvId = new Map();
  const canonPos = obj.positions.map((p) => {
    const k = `${p[0]} ${p[1]} ${p[2]}`;
    if (!posId.has(k)) posId.set(k, posId.size);
    return posId.get(k);
  });
  const canonUv = obj.uvs.map((t) => {
    const k = `${t[0]} ${t[1]}`;
    if (!uvId.has(k)) uvId.set(k, uvId.size);
    return uvId.get(k);
  });
  const multiMaterial = obj.materials.length > 1;
  const vertexId = new Map();
  const vPos = []; // vertex -> obj position index (first of its value)
  const vUv = []; // vertex -> obj uv index
  const vMat = [];
  const indices = new Uint32Array(obj.tris.length * 3);
  obj.tris.forEach((t, f) => {
    for (let c = 0; c < 3; ++c) {
      const p = t[2 * c];
      const q = t[2 * c + 1];
      const key = multiMaterial ? `${canonPos[p]}/${canonUv[q]}/${t[6]}` : `${canonPos[p]}/${canonUv[q]}`;
      let v = vertexId.get(key);
      if (v === undefined) {
        v = vPos.length;
        vertexId.set(key, v);
        vPos.push(p);
        vUv.push(q);
        vMat.push(t[6]);
      }
      indices[3 * f + c] = v;
    }
  });
  const n = vPos.length;
  const xyz = new Float32Array(3 * n);
  const uv = new Float32Array(2 * n);
  const vCanonPos = new Uint32Array(n);
  for (let v = 0; v < n; ++v) {
    const p = obj.positions[vPos[v]];
    xyz.set(p, 3 * v);
    uv.set(obj.uvs[vUv[v]], 2 * v);
    vCanonPos[v] = canonPos[vPos[v]];
  }
  return { indices, xyz, uv, vPos, vUv, vMat, vCanonPos, count: n };
}

function uvWeight(obj) {
  let sum = 0;
  for (const t of obj.tris) {
    const a = obj.uvs[t[1]];
    const b = obj.uvs[t[3]];
    const c = obj.uvs[t[5]];
    sum += Math.abs((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])) / 2;
  }
  const mean = sum / obj.tris.length;
  if (!(mean > 0)) throw new InputError('all UV triangles have zero area: no UV weight');
  return 1 / Math.sqrt(mean);
}

// ---- OBJ writer -----------------------------------------------------------------------------------

function writeAtomically(path, content) {
  const tmp = join(dirname(resolve(path)), `.${basename(path)}.tmp-${process.pid}`);
  try {
    writeFileSync(tmp, content);
    renameSync(tmp, path);
  } catch (e) {
    rmSync(tmp, { force: true });
    throw new InputError(`${path}: cannot write (${e.code ?? e.message})`);
  }
}

function objText(obj, vb, result, header, mtlPaths, materialNames) {
  const outPos = new Map(); // obj position index -> output index (1-based)
  const outUv = new Map();
  const vLines = [];
  const vtLines = [];
  const fLines = [];
  let current = null;
  for (let i = 0; i < result.length; i += 3) {
    const m = vb.vMat[result[i]];
    const name = materialNames[m];
    if (name !== current && name !== '') fLines.push(`usemtl ${name}`);
    current = name;
    const c = [];
    for (let k = 0; k < 3; ++k) {
      const v = result[i + k];
      let p = outPos.get(vb.vPos[v]);
      if (p === undefined) {
        p = outPos.size + 1;
        outPos.set(vb.vPos[v], p);
        const x = obj.positions[vb.vPos[v]];
        vLines.push(`v ${x[0]} ${x[1]} ${x[2]}`);
      }
      let t = outUv.get(vb.vUv[v]);
      if (t === undefined) {
        t = outUv.size + 1;
        outUv.set(vb.vUv[v], t);
        const u = obj.uvs[vb.vUv[v]];
        vtLines.push(`vt ${u[0]} ${u[1]}`);
      }
      c.push(`${p}/${t}`);
    }
    fLines.push(`f ${c.join(' ')}`);
  }
  const lines = [...header.map((h) => `# ${h}`), ...mtlPaths.map((m) => `mtllib ${m}`), ...vLines, ...vtLines, ...fLines];
  return lines.join('\n') + '\n';
}

// ---- main -----------------------------------------------------------------------------------------

async function main() {
  const args = parseArgs(process.argv.slice(2));
  let mtlOverride = null;
  if (args.mtl !== null) {
    mtlOverride = resolve(args.mtl);
    if (!existsSync(mtlOverride) || !statSync(mtlOverride).isFile()) usage(`--mtl: no file ${mtlOverride}`);
  }
  const obj = readObj(args.input);
  const vb = buildVertexBuffer(obj);
  const facesIn = obj.tris.length;
  const targetFaces = args.faces;
  const targetIndexCount = 3 * Math.min(targetFaces, facesIn);

  const pkg = join(dirname(fileURLToPath(import.meta.resolve('meshoptimizer'))), 'package.json');
  const version = JSON.parse(readFileSync(pkg, 'utf8')).version;
  if (version !== REQUIRED_VERSION)
    throw new InputError(`meshoptimizer ${version} installed (${pkg}), ${REQUIRED_VERSION} expected: npm install in ${dirname(fileURLToPath(import.meta.url))}`);
  await MeshoptSimplifier.ready;
  if (!MeshoptSimplifier.supported) throw new InputError('MeshoptSimplifier is not supported (no WebAssembly)');

  const w = uvWeight(obj);
  const flags = args.variant === 'attr' ? [] : ['Permissive'];
  let lock = null;
  let protectedCount = 0;
  if (args.variant === 'permissive-protected') {
    // a position carried by more than one (position, uv) vertex lies on a UV seam
    const copies = new Map();
    for (let v = 0; v < vb.count; ++v) copies.set(vb.vCanonPos[v], (copies.get(vb.vCanonPos[v]) ?? 0) + 1);
    lock = new Uint8Array(vb.count);
    for (let v = 0; v < vb.count; ++v)
      if (copies.get(vb.vCanonPos[v]) > 1) {
        lock[v] = PROTECT;
        ++protectedCount;
      }
  }
  const t0 = performance.now();
  let [result, error] = MeshoptSimplifier.simplifyWithAttributes(
    vb.indices, vb.xyz, 3, vb.uv, 2, [w, w], lock, targetIndexCount, UNLIMITED_ERROR, flags
  );
  let sloppy = false;
  if (args.aggressive && targetIndexCount > 50 * 3 && result.length > targetIndexCount) {
    [result, error] = MeshoptSimplifier.simplifySloppy(result, vb.xyz, 3, null, targetIndexCount, UNLIMITED_ERROR);
    sloppy = true;
  }
  const seconds = (performance.now() - t0) / 1000;

  // materials: the input's mtllib (absolute) or --mtl; an input without usemtl gets the MTL's first
  // material when --mtl names one
  const mtlPaths = mtlOverride !== null ? [mtlOverride] : resolveMtllibs(args.input, obj.mtllibs);
  const names = obj.materials.slice();
  if (names.length === 1 && names[0] === '' && mtlOverride !== null) names[0] = firstMaterialName(mtlOverride);
  const header = [
    `meshoptimizer ${version} (npm) MeshoptSimplifier.simplifyWithAttributes, variant ${args.variant}` +
      (sloppy ? ', then simplifySloppy (--aggressive)' : ''),
    `input ${resolve(args.input)}: ${facesIn} faces, target ${targetFaces}, output ${result.length / 3}`,
  ];
  writeAtomically(args.output, objText(obj, vb, result, header, mtlPaths, names));

  process.stdout.write(
    JSON.stringify({
      variant: args.variant,
      faces_in: facesIn,
      target_faces: targetFaces,
      faces_out: result.length / 3,
      seconds,
      sloppy,
      vertices_in: vb.count,
      protected_vertices: protectedCount,
      uv_weight: w,
      result_error: error,
      meshoptimizer: version,
    }) + '\n'
  );
}

main().catch((e) => {
  process.stderr.write(`meshopt_simplify: error: ${e.message}\n`);
  process.exit(e instanceof UsageError ? 2 : 1);
});
