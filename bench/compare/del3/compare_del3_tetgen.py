"""TetGen 1.5 (Debian's tetgen program, AGPL, so run as a program, never linked) on the del3
workload: the same points written to a .node file before timing, `tetgen -NEFI` (Delaunay only,
no output files), and its own "Delaunay seconds" as build_s (file reading and writing excluded),
median of --reps runs. Single-threaded: nothing is printed for --threads > 1."""
import os
import re
import statistics
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from common import parse_args, record  # noqa: E402

args = parse_args()
if args.threads != 1:
    sys.exit(0)
xyz = np.fromfile(os.path.join(args.data, "del3_uniform.f64"), dtype="<f8").reshape(-1, 3)
for variant, full in (("uniform_200k", 200000), ("uniform_1m", 1000000)):
    if args.only and args.only not in variant:
        continue
    n = min(len(xyz), max(1, int(full * args.scale)))
    with tempfile.TemporaryDirectory() as tmp:
        node = os.path.join(tmp, "points.node")
        with open(node, "w") as f:
            f.write(f"{n} 3 0 0\n")
            np.savetxt(f, np.column_stack([np.arange(n), xyz[:n]]), fmt=["%d", "%.17g", "%.17g", "%.17g"])
        times, stats = [], {}
        for _ in range(args.reps):
            out = subprocess.run(["tetgen", "-NEFI", node], capture_output=True, text=True, check=True).stdout
            times.append(float(re.search(r"Delaunay seconds:\s*([0-9.eE+-]+)", out).group(1)))
            for key in ("Mesh points", "Mesh tetrahedra", "Convex hull faces"):
                stats[key] = int(re.search(key + r":\s*(\d+)", out).group(1))
    record("del3", "tetgen", variant, 1, statistics.median(times), 0.0, n, args.reps,
           ok=stats["Mesh points"] == n, tetrahedra=stats["Mesh tetrahedra"], hull=stats["Convex hull faces"],
           vertices=stats["Mesh points"], all_vertices=stats["Mesh points"] == n)
