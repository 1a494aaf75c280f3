// npm @mapbox/martini (RTIN, the same longest-edge bisection family) on the field of
// field.mjs. Its error parameter is not a bound on the mesh's distance to the samples, so for
// each target T the largest parameter whose mesh is measured within T is found by bisection
// (14 steps); reported: that mesh's triangles and measured error, build_s = createTile (the
// errors), query_s = getMesh at that parameter.
import Martini from '@mapbox/martini';
import { field1025, parseArgs, medianTime, measureError, record, targets } from './field.mjs';

const args = parseArgs(process.argv);
const { n, z } = field1025();
const martini = new Martini(n);
const [build_s, tile] = medianTime(args.reps, () => martini.createTile(z));
for (const T of targets) {
  const variant = `e${T}`;
  if (!args.wants(variant)) continue;
  let lo = 0, hi = 2 * T, best = null;
  for (let step = 0; step < 14; step++) {
    const p = step === 0 ? 0 : (lo + hi) / 2;
    const mesh = tile.getMesh(p), err = measureError(z, n, mesh.vertices, mesh.triangles);
    if (err <= T) { if (!best || mesh.triangles.length < best.triangles) best = { p, triangles: mesh.triangles.length, err }; lo = p; }
    else hi = p;
  }
  const [query_s, mesh] = medianTime(args.reps, () => tile.getMesh(best.p));
  const triangles = mesh.triangles.length / 3;
  record('martini', variant, args.threads, build_s, query_s, triangles, args.reps, best.err <= T,
         { triangles, max_error: best.err, parameter: best.p });
}
