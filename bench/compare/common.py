"""Python counterpart of common.hpp, for anchors that are Python libraries (e.g. scipy's EDT).

    import os, sys; sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    from common import parse_args, median_time, record
    args = parse_args()
    t = median_time(args.reps, lambda: scipy.ndimage.distance_transform_edt(mask))
    record("edt", "scipy", "256", args.threads, 0.0, t, mask.size, args.reps, ok=True, checksum=...)

Same command line (--data --threads --reps --scale --only) and the same JSON line as the C++
programs; times with time.perf_counter. Standard library only (the caller imports numpy/scipy).
"""
import argparse
import json
import os
import statistics
import sys
import time


def parse_args(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=os.environ.get("ANCHORS_DATA", "build/anchors-data"))
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--reps", type=int, default=int(os.environ.get("ANCHORS_REPS", 3)))
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--only", default="")
    return ap.parse_args(argv)


def median_time(reps, fn):
    """Runs fn() reps times; median seconds."""
    t = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        t.append(time.perf_counter() - t0)
    return statistics.median(t)


def record(workload, anchor, variant, threads, build_s, query_s, count, median_of, ok, **extra):
    """Prints one JSON line: the mandatory keys, then extra, then "ok"."""
    r = {"workload": workload, "anchor": anchor, "variant": variant, "threads": threads,
         "build_s": build_s, "query_s": query_s, "count": count, "median_of": median_of}
    r.update(extra)
    r["ok"] = bool(ok)
    sys.stdout.write(json.dumps(r) + "\n")
    sys.stdout.flush()
