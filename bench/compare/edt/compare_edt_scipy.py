"""scipy.ndimage.distance_transform_edt on the edt workload (single-threaded by design):
the same input, checksum and JSON line as compare_edt_geods.cpp."""
import math
import os
import sys

import numpy as np
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from common import median_time, parse_args, record  # noqa: E402

args = parse_args()
if args.only and args.only not in "256":
    sys.exit(0)
mask = np.fromfile(os.path.join(args.data, "edt_256.u8"), dtype=np.uint8).reshape(256, 256, 256)
out = {}
t = median_time(args.reps, lambda: out.setdefault("d", ndimage.distance_transform_edt(mask)))
d = out["d"]
total = math.fsum(d.ravel().tolist())  # exact: the checksum does not depend on the summation order
record("edt", "scipy", "256", args.threads, 0.0, t, mask.size, args.reps, ok=True,
       checksum=f"{total:.2f} / {d.max():.3f}")
