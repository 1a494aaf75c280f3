// Shared by the node programs of the terrain comparison: the same 1025^2 field as
// compare_terrain_geods (data/trigger_tropic_h.png, 8-bit, padded by repeating its last row
// and column), the arguments, timing, the error of a mesh against every sample, JSON lines.
import fs from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));

// A non-interlaced 8-bit PNG (grey, grey+alpha, RGB, RGBA): its first channel.
function readPng(file) {
  const b = fs.readFileSync(file);
  let pos = 8, width = 0, height = 0, channels = 0;
  const idat = [];
  while (pos < b.length) {
    const len = b.readUInt32BE(pos), type = b.toString('latin1', pos + 4, pos + 8), data = b.subarray(pos + 8, pos + 8 + len);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0); height = data.readUInt32BE(4);
      if (data[8] !== 8 || data[12] !== 0) throw new Error(`${file}: only 8-bit non-interlaced PNG`);
      channels = { 0: 1, 2: 3, 4: 2, 6: 4 }[data[9]];
    } else if (type === 'IDAT') idat.push(data);
    else if (type === 'IEND') break;
    pos += 12 + len;
  }
  const raw = zlib.inflateSync(Buffer.concat(idat)), stride = width * channels;
  const out = new Uint8Array(stride * height), prev = new Uint8Array(stride);
  for (let y = 0; y < height; y++) {
    const f = raw[y * (stride + 1)], row = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    const cur = out.subarray(y * stride, (y + 1) * stride), up = y ? out.subarray((y - 1) * stride, y * stride) : prev;
    for (let i = 0; i < stride; i++) {
      const a = i >= channels ? cur[i - channels] : 0, u = up[i], c = i >= channels ? up[i - channels] : 0;
      let v = row[i];
      if (f === 1) v += a; else if (f === 2) v += u; else if (f === 3) v += (a + u) >> 1;
      else if (f === 4) { const p = a + u - c, pa = Math.abs(p - a), pb = Math.abs(p - u), pc = Math.abs(p - c); v += pa <= pb && pa <= pc ? a : pb <= pc ? u : c; }
      cur[i] = v & 255;
    }
  }
  const grey = new Float32Array(width * height);
  for (let i = 0; i < width * height; i++) grey[i] = out[i * channels];
  return { width, height, grey };
}

export function field1025() {
  const im = readPng(path.join(here, '..', '..', '..', 'data', 'trigger_tropic_h.png'));
  const n = 1025, z = new Float32Array(n * n);
  for (let y = 0; y < n; y++)
    for (let x = 0; x < n; x++) z[y * n + x] = im.grey[Math.min(y, im.height - 1) * im.width + Math.min(x, im.width - 1)];
  return { n, z };
}

export function parseArgs(argv) {
  const a = { threads: 1, reps: 3, only: '' };
  for (let i = 2; i < argv.length; i++) {
    const k = argv[i], v = argv[i + 1];
    if (k === '--threads') a.threads = Number(v), i++;
    else if (k === '--reps') a.reps = Number(v), i++;
    else if (k === '--only') a.only = v, i++;
    else if (k === '--data' || k === '--scale') i++;
  }
  a.wants = (variant) => !a.only || variant.includes(a.only);
  return a;
}

export function medianTime(reps, fn) {
  const t = [];
  let result;
  for (let r = 0; r < reps; r++) { const t0 = performance.now(); result = fn(); t.push((performance.now() - t0) / 1e3); }
  t.sort((x, y) => x - y);
  return [t[t.length >> 1], result];
}

// The largest |z - mesh| over every sample: each triangle's samples by exact integer edge tests.
export function measureError(z, n, coords, triangles) {
  let worst = 0;
  for (let t = 0; t < triangles.length; t += 3) {
    let ax = coords[2 * triangles[t]], ay = coords[2 * triangles[t] + 1];
    let bx = coords[2 * triangles[t + 1]], by = coords[2 * triangles[t + 1] + 1];
    let cx = coords[2 * triangles[t + 2]], cy = coords[2 * triangles[t + 2] + 1];
    const za = z[ay * n + ax], zb = z[by * n + bx], zc = z[cy * n + cx];
    const ux = bx - ax, uy = by - ay, vx = cx - ax, vy = cy - ay, det = ux * vy - uy * vx;
    if (det === 0) continue;
    const gx = ((zb - za) * vy - (zc - za) * uy) / det, gy = ((zc - za) * ux - (zb - za) * vx) / det;
    if (det < 0) [bx, by, cx, cy] = [cx, cy, bx, by];
    const V = [[ax, ay], [bx, by], [cx, cy]];
    const y0 = Math.min(ay, by, cy), y1 = Math.max(ay, by, cy), x0 = Math.min(ax, bx, cx), x1 = Math.max(ax, bx, cx);
    for (let y = y0; y <= y1; y++) {
      let lo = x0, hi = x1;
      for (let e = 0; e < 3; e++) {
        const [px, py] = V[e], [qx, qy] = V[(e + 1) % 3];
        const A = qy - py, B = (qx - px) * (y - py) + (qy - py) * px;
        if (A > 0) hi = Math.min(hi, Math.floor(B / A));
        else if (A < 0) lo = Math.max(lo, Math.ceil(B / A));
        else if (B < 0) lo = hi + 1;
      }
      const base = za + gy * (y - ay) - gx * ax;
      for (let x = lo; x <= hi; x++) { const d = Math.abs(z[y * n + x] - (base + gx * x)); if (d > worst) worst = d; }
    }
  }
  return worst;
}

export function record(anchor, variant, threads, build_s, query_s, count, median_of, ok, extra = {}) {
  process.stdout.write(JSON.stringify({ workload: 'terrain', anchor, variant, threads, build_s, query_s, count, median_of, ...extra, ok }) + '\n');
}

export const targets = [1, 2, 4, 8, 16];
