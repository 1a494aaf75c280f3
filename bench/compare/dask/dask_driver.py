"""The dask comparison: geods.dask on a dask.distributed LocalCluster of 1 and of 2 worker
processes (one thread each, geods limited to one thread per worker) against the single-process
geods call on one thread, on the workloads of the edt and mc comparisons; plus the largest volume
processed with a worker memory limit below its size (variant "edt_512_limited").

    compare_dask_geods.py     geods.edt / geods.isosurface in this process (the baseline)
    compare_dask_workers1.py  geods.dask.edt / isosurface on 1 worker
    compare_dask_workers2.py  the same on 2 workers

Every program prints the JSON lines of bench/compare (common.py); `checksum` must agree.
"""
import math
import os
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, os.environ.get("GEODS_PYTHONPATH", os.path.join(REPO, "build", "release", "python")))
from common import median_time, parse_args, record  # noqa: E402

import geods  # noqa: E402

# The big variant: a 512^3 float32 volume (512 MiB) made on the workers chunk by chunk, each of
# them limited to LIMIT bytes, below the volume's size (the EDT's float64 passes need 1 GiB more).
BIG = 512
LIMIT = 384 << 20


def edt_checksum(d):
    """Sum of the squared distances (integers with unit spacing, so exact) / the largest distance."""
    return f"{int(np.rint(d * d).astype(np.int64).sum())} / {float(d.max()):.3f}"


def mesh_checksum(V, F):
    return f"{len(V)} vertices / {len(F)} triangles / {math.fsum(V.astype(np.float64).ravel().tolist()):.3f}"


def big_block(block_info=None):
    """Chunk of the big volume: a sum of waves (deterministic, the same on every worker)."""
    loc = block_info[None]["array-location"]
    z, y, x = np.meshgrid(*[np.arange(a, b, dtype=np.float32) for a, b in loc], indexing="ij", sparse=True)
    s = np.float32(2 * np.pi / BIG)
    return (np.sin(3 * s * x) * np.cos(5 * s * y) + np.sin(4 * s * z + 1)).astype(np.float32)


def main(workers):
    args = parse_args()
    data = args.data
    mask = np.fromfile(os.path.join(data, "edt_256.u8"), dtype=np.uint8).reshape(256, 256, 256)
    volume = np.fromfile(os.path.join(data, "volume_256.f32"), dtype=np.float32).reshape(256, 256, 256)
    iso = 0.3
    anchor = "geods" if workers == 0 else f"dask_{workers}w"
    want = lambda v: not args.only or args.only in v  # noqa: E731
    if workers == 0:
        geods.set_num_threads(1)
        if want("edt_256"):
            out = {}
            t = median_time(args.reps, lambda: out.setdefault("d", geods.edt(mask)))
            record("dask", anchor, "edt_256", args.threads, 0.0, t, mask.size, args.reps, ok=True,
                   checksum=edt_checksum(out["d"]))
        if want("mc_256"):
            out = {}
            t = median_time(args.reps, lambda: out.setdefault("m", geods.isosurface(volume, iso, normals=False)))
            V, F, _ = out["m"]
            record("dask", anchor, "mc_256", args.threads, 0.0, t, volume.size, args.reps, ok=True,
                   checksum=mesh_checksum(V, F))
        if want("edt_512_limited"):
            import dask.array as da
            big = da.map_blocks(big_block, chunks=((128,) * 4,) * 3, dtype=np.float32).compute(scheduler="sync")
            t0 = time.perf_counter()
            d = geods.edt(big > 0.5)
            t = time.perf_counter() - t0
            record("dask", anchor, "edt_512_limited", args.threads, 0.0, t, big.size, 1, ok=True,
                   checksum=edt_checksum(d), volume_bytes=big.nbytes)
        return
    import dask.array as da
    from dask.distributed import Client, LocalCluster

    import geods.dask as gd
    with LocalCluster(n_workers=workers, processes=True, threads_per_worker=1, dashboard_address=None,
                      silence_logs=40) as cluster, Client(cluster) as client:
        client.run(lambda: __import__("geods").set_num_threads(1))
        if want("edt_256"):
            x = da.from_array(mask, chunks=(64, 256, 256))
            x = client.persist(x)
            out = {}
            t = median_time(args.reps, lambda: out.__setitem__("d", gd.edt(x).compute()))
            record("dask", anchor, "edt_256", args.threads, 0.0, t, mask.size, args.reps, ok=True,
                   checksum=edt_checksum(out["d"]))
        if want("mc_256"):
            x = client.persist(da.from_array(volume, chunks=(64, 256, 256)))
            out = {}
            t = median_time(args.reps, lambda: out.__setitem__("m", gd.isosurface(x, iso)))
            record("dask", anchor, "mc_256", args.threads, 0.0, t, volume.size, args.reps, ok=True,
                   checksum=mesh_checksum(*out["m"]))
    if want("edt_512_limited"):
        # Workers limited below the volume's size; the volume is made on them, the passes' float64
        # intermediates (1 GiB) go through a scratch directory (store=), only the checksum comes back.
        with LocalCluster(n_workers=workers, processes=True, threads_per_worker=1, dashboard_address=None,
                          memory_limit=LIMIT, silence_logs=50) as cluster, Client(cluster) as client:
            client.run(lambda: __import__("geods").set_num_threads(1))
            big = da.map_blocks(big_block, chunks=((128,) * 4,) * 3, dtype=np.float32)
            with tempfile.TemporaryDirectory(prefix="geods-dask-") as store:
                t0 = time.perf_counter()
                d = gd.edt(big > 0.5, chunk_samples=128 ** 3, store=store)
                sq = da.rint(d * d).astype(np.int64).sum()
                total, top = client.compute([sq, d.max()], sync=True)
                t = time.perf_counter() - t0
            # VmHWM: the worker's peak resident memory since it started (mapped file pages included).
            peak = max(client.run(lambda: int(open("/proc/self/status").read().split("VmHWM:")[1].split()[0]) * 1024)
                       .values())
            record("dask", anchor, "edt_512_limited", args.threads, 0.0, t, BIG ** 3, 1, ok=True,
                   checksum=f"{int(total)} / {float(top):.3f}", volume_bytes=BIG ** 3 * 4,
                   worker_memory_limit=LIMIT, worker_peak_rss=peak)
