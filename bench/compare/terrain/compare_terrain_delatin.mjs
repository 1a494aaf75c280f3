// npm delatin (greedy Delaunay TIN, Garland-Heckbert) on the field of field.mjs: run(T) to
// each target max error; reported: triangles, the error measured against every sample,
// query_s = construction + run.
import Delatin from 'delatin';
import { field1025, parseArgs, medianTime, measureError, record, targets } from './field.mjs';

const args = parseArgs(process.argv);
const { n, z } = field1025();
for (const T of targets) {
  const variant = `tin_e${T}`;
  if (!args.wants(variant)) continue;
  let cpu_s = Infinity;  // the least process CPU time (user + system, every thread of node) of a construction
  const [query_s, tin] = medianTime(args.reps, () => {
    const c0 = process.cpuUsage();
    const d = new Delatin(z, n, n);
    d.run(T);
    const c = process.cpuUsage(c0);
    cpu_s = Math.min(cpu_s, (c.user + c.system) / 1e6);
    return d;
  });
  const triangles = tin.triangles.length / 3, err = measureError(z, n, tin.coords, tin.triangles);
  record('delatin', variant, args.threads, 0, query_s, triangles, args.reps, err <= T + 1e-9, { cpu_s, triangles, max_error: err });
}
