// npm manifold-3d (Manifold's WebAssembly build, run with node) on the csg workload and the
// fuzz corpus, with the checks of csg_driver.hpp: build_s = Manifold.ofMesh of both inputs,
// query_s = the boolean and getMesh (Manifold evaluates lazily). Manifold's JS meshes hold
// float32 positions: the fuzz corpus's 1e-9 moves round away (its cases become identical
// or touching solids). Fuzz cases run in a child node process each (30 s limit: a loop).
import { readFileSync } from 'node:fs';
import { spawnSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { dirname, join } from 'node:path';
import Module from 'manifold-3d';

const here = dirname(fileURLToPath(import.meta.url));
const args = { threads: 1, reps: 3, only: '', data: 'build/anchors-data', fuzzCase: -1 };
for (let i = 2; i < process.argv.length; i++) {
  const k = process.argv[i], v = process.argv[i + 1];
  if (k === '--threads') args.threads = Number(v), i++;
  else if (k === '--reps') args.reps = Number(v), i++;
  else if (k === '--only') args.only = v, i++;
  else if (k === '--data') args.data = v, i++;
  else if (k === '--scale') i++;
  else if (k === '--case') args.fuzzCase = Number(v), i++;
}
if (process.env.ANCHORS_DATA && !process.argv.includes('--data')) args.data = process.env.ANCHORS_DATA;
const wants = (v) => !args.only || v.includes(args.only);

const wasm = await Module();
wasm.setup();
const { Manifold, Mesh } = wasm;

function readPly(path) {
  const buf = readFileSync(path);
  const end = buf.indexOf('end_header\n') + 'end_header\n'.length;
  const header = buf.subarray(0, end).toString();
  const nv = Number(/element vertex (\d+)/.exec(header)[1]), nf = Number(/element face (\d+)/.exec(header)[1]);
  const xyz = new Float64Array(3 * nv), tri = new Uint32Array(3 * nf);
  const dv = new DataView(buf.buffer, buf.byteOffset + end);
  for (let i = 0; i < 3 * nv; i++) xyz[i] = dv.getFloat32(4 * i, true);
  let o = 12 * nv;
  for (let f = 0; f < nf; f++) {
    o += 1;
    for (let k = 0; k < 3; k++) tri[3 * f + k] = dv.getInt32(o, true), o += 4;
  }
  return { xyz, tri };
}

function readCorpus() {
  const lines = readFileSync(join(here, 'fuzz_corpus.txt'), 'utf8').split('\n');
  const out = [];
  let i = 0;
  while (i < lines.length && lines[i].startsWith('case ')) {
    const c = { name: lines[i++].slice(5) };
    for (const tag of ['a', 'b']) {
      const [, nv, nt] = lines[i++].split(' ').map(Number);
      const xyz = new Float64Array(3 * nv), tri = new Uint32Array(3 * nt);
      for (let v = 0; v < nv; v++) lines[i++].split(' ').forEach((x, k) => { xyz[3 * v + k] = Number(x); });
      for (let t = 0; t < nt; t++) lines[i++].split(' ').forEach((x, k) => { tri[3 * t + k] = Number(x); });
      c[tag] = { xyz, tri };
    }
    out.push(c);
  }
  return out;
}

function volume(m) {
  let v = 0;
  const p = m.xyz, t = m.tri;
  for (let f = 0; f < t.length; f += 3) {
    const a = 3 * t[f], b = 3 * t[f + 1], c = 3 * t[f + 2];
    v += p[a] * (p[b + 1] * p[c + 2] - p[b + 2] * p[c + 1]) - p[a + 1] * (p[b] * p[c + 2] - p[b + 2] * p[c]) +
      p[a + 2] * (p[b] * p[c + 1] - p[b + 1] * p[c]);
  }
  return v / 6;
}

// Every directed edge has its opposite once vertices with equal coordinates are one.
function closed(m) {
  const weld = new Map(), id = new Uint32Array(m.xyz.length / 3);
  for (let v = 0; v < id.length; v++) {
    const key = `${m.xyz[3 * v]},${m.xyz[3 * v + 1]},${m.xyz[3 * v + 2]}`;
    if (!weld.has(key)) weld.set(key, weld.size);
    id[v] = weld.get(key);
  }
  const count = new Map();
  for (let f = 0; f < m.tri.length; f += 3)
    for (let k = 0; k < 3; k++) {
      const u = id[m.tri[f + k]], w = id[m.tri[f + (k + 1) % 3]];
      if (u === w) continue;
      const fwd = `${u},${w}`, bwd = `${w},${u}`;
      count.set(fwd, (count.get(fwd) || 0) + 1);
      count.set(bwd, (count.get(bwd) || 0) - 1);
    }
  for (const c of count.values()) if (c !== 0) return false;
  return true;
}

const opName = ['union', 'intersection', 'difference'];
// One boolean: [build_s, query_s, output mesh].
function boolean(a, b, op) {
  const t0 = performance.now();
  const mk = (m) => Manifold.ofMesh(new Mesh({ numProp: 3, vertProperties: Float32Array.from(m.xyz), triVerts: m.tri }));
  const ma = mk(a), mb = mk(b);
  const t1 = performance.now();
  const r = op === 0 ? ma.add(mb) : op === 1 ? ma.intersect(mb) : ma.subtract(mb);
  const mesh = r.getMesh();
  const t2 = performance.now();
  const status = r.status();
  const out = { xyz: Float64Array.from(mesh.vertProperties.filter((_, i) => i % mesh.numProp < 3)), tri: mesh.triVerts };
  ma.delete(), mb.delete(), r.delete();
  if (status !== 'NoError' && status !== 0) throw new Error(`manifold status ${status}`);
  return [(t1 - t0) / 1e3, (t2 - t1) / 1e3, out];
}

function record(variant, build_s, query_s, count, median_of, ok, extra) {
  process.stdout.write(JSON.stringify({ workload: 'csg', anchor: 'manifold', variant, threads: args.threads, build_s, query_s, count, median_of, ...extra, ok }) + '\n');
}

if (args.fuzzCase >= 0) {
  // Child: "status closed volume triangles" per operation.
  const c = readCorpus()[args.fuzzCase];
  for (let op = 0; op < 3; op++) {
    try {
      const [, , out] = boolean(c.a, c.b, op);
      process.stdout.write(`0 ${closed(out) ? 1 : 0} ${volume(out)} ${out.tri.length / 3}\n`);
    } catch (e) {
      process.stdout.write(`1 0 0 0\n`);
    }
  }
  process.exit(0);
}

if (wants('union') || wants('difference')) {
  const a = readPly(join(args.data, 'csg_a.ply')), b = readPly(join(args.data, 'csg_b.ply'));
  const res = {};
  for (const op of [0, 2]) {
    const bs = [], qs = [];
    let out;
    for (let r = 0; r < args.reps; r++) {
      const [x, y, o] = boolean(a, b, op);
      bs.push(x), qs.push(y), out = o;
    }
    const med = (v) => v.sort((x, y) => x - y)[v.length >> 1];
    res[op] = { build: med(bs), query: med(qs), out };
  }
  const vb = volume(b);
  const err = Math.abs(volume(res[0].out) - volume(res[2].out) - vb) / vb;
  for (const op of [0, 2]) {
    if (!wants(opName[op])) continue;
    const o = res[op].out, cl = closed(o), n = o.tri.length / 3;
    record(opName[op], res[op].build, res[op].query, n, args.reps, cl && err < 1e-5,
      { triangles: n, closed: cl, volume: volume(o), identity_error: err });
  }
}

if (wants('fuzz')) {
  const corpus = readCorpus();
  let failures = 0, loops = 0, cracks = 0, wrong = 0;
  const failed = [];
  const t0 = performance.now();
  corpus.forEach((c, i) => {
    const r = spawnSync(process.execPath, [fileURLToPath(import.meta.url), '--case', String(i)], { timeout: 30000, encoding: 'utf8' });
    let what = '';
    const rows = (r.stdout || '').trim().split('\n').filter((l) => l).map((l) => l.split(' ').map(Number));
    if (r.error && r.error.code === 'ETIMEDOUT') loops++, what = 'loop';
    else if (rows.length < 3 || rows.some((x) => x[0] !== 0)) failures++, what = 'failure';
    else {
      const va = volume(c.a), vb = volume(c.b), tol = 1e-5 * Math.max(Math.abs(va), Math.abs(vb));
      const [u, n, d] = rows;
      if (!u[1] || !n[1] || !d[1]) cracks++, what = 'crack';
      if (Math.abs(u[2] + n[2] - va - vb) > tol || Math.abs(d[2] - (va - n[2])) > tol) wrong++, what += what ? '+wrong volume' : 'wrong volume';
    }
    if (what) failed.push(`${c.name}: ${what}`);
  });
  record('fuzz', 0, (performance.now() - t0) / 1e3, corpus.length, 1, true,
    { failures, loops, cracks, wrong, failed_cases: failed.join('; ') });
}
