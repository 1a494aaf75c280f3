// Shared by the node programs of the terrain comparison: the same 1025^2 field as
// compare_terrain_geods (the USGS Jacksboro DEM, data/jacksboro_dem.npy, mirrored into 1025^2),
// the arguments, timing, the error of a mesh against every sample, JSON lines.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));

// A little-endian int16 .npy in C order (the Jacksboro DEM): its shape and samples.
function readNpyInt16(file) {
  const b = fs.readFileSync(file);
  const headerLen = b.readUInt16LE(8), header = b.toString('latin1', 10, 10 + headerLen);
  if (!header.includes("'<i2'") || !header.includes("'fortran_order': False")) throw new Error(`${file}: not a C-order <i2 .npy`);
  const [rows, cols] = header.match(/'shape': \((\d+), (\d+)\)/).slice(1).map(Number);
  const data = new Int16Array(rows * cols);
  for (let i = 0; i < rows * cols; i++) data[i] = b.readInt16LE(10 + headerLen + 2 * i);
  return { rows, cols, data };
}

// i reflected into 0..n-1 (period 2n - 2, the border samples not repeated).
const reflect = (i, n) => { const p = 2 * (n - 1), k = i % p; return k < n ? k : p - k; };

export function field1025() {
  const dem = readNpyInt16(path.join(here, '..', '..', '..', 'data', 'jacksboro_dem.npy'));
  const n = 1025, z = new Float32Array(n * n);
  for (let y = 0; y < n; y++)
    for (let x = 0; x < n; x++) z[y * n + x] = dem.data[reflect(y, dem.rows) * dem.cols + reflect(x, dem.cols)];
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

export const targets = [2, 4, 8, 16, 32];
