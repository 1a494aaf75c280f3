"""The time-against-error tables of docs/texture.md, single-threaded.

    PYTHONPATH=build/release/python python3 bench/compare/texture/tradeoff.py table
    PYTHONPATH=build/release/python python3 bench/compare/texture/tradeoff.py seeds

`table`: every search on data/brick.png and data/gravel.png averaged over 8 x 8
and 4 x 4 blocks (64 x 64 and 128 x 128 samples) -> 256 x 256, seed 1, as
markdown rows (time, mean_neighborhood_distance). `seeds`: over seeds 1 to 5,
the approximate search's mean error against the exact one's, and its mean time.
"""
import os
import sys
import time

import numpy as np

import geods

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "data")
ROWS = [("brute", None, None), ("exact", 0, 8), ("approx", 2, 8), ("approx", 4, 8), ("approx", 8, 8),
        ("approx", 16, 8), ("approx", 24, 8), ("approx", 8, 16)]


def sample(name, block):
    """data/NAME.png averaged over block x block pixels, rounded to 8 bits."""
    f = geods.read_image(os.path.join(DATA, name + ".png")).astype(np.float64)
    h, w = f.shape[0] // block, f.shape[1] // block
    s = f[:h * block, :w * block].reshape(h, block, w, block, *f.shape[2:]).mean(axis=(1, 3))
    return np.clip(np.rint(s), 0, 255).astype(np.uint8)


def run(s, search, eps=None, dims=None, seed=1):
    kw = dict(search=search, seed=seed, stats=True)
    if dims is not None:
        kw["reduced_dimension"] = dims
    if search == "approx":
        kw["eps"] = eps
    t = time.perf_counter()
    stats = geods.synthesize_texture(s, (256, 256), **kw)[1]
    return time.perf_counter() - t, stats["mean_neighborhood_distance"]


def table():
    samples = [sample(n, b) for b in (8, 4) for n in ("brick", "gravel")]
    for search, eps, dims in ROWS:
        cells = " | ".join(f"{t:.3f} s | {e:.2f}" for t, e in (run(s, search, eps, dims) for s in samples))
        print(f"| {search} | {'' if eps is None else eps} | {'' if dims is None else dims} | {cells} |", flush=True)


def seeds(configs=((8, (8, 4)), (16, (8,)), (24, (8,)))):
    for eps, blocks in configs:
        for block in blocks:
            for name in ("brick", "gravel"):
                s = sample(name, block)
                exact, approx, seconds = [], [], 0.0
                for seed in range(1, 6):
                    exact.append(run(s, "exact", seed=seed)[1])
                    t, e = run(s, "approx", eps, seed=seed)
                    approx.append(e)
                    seconds += t
                print(f"{name} {s.shape[0]}, eps {eps}: {100 * (np.mean(approx) / np.mean(exact) - 1):+.1f} % "
                      f"({seconds / 5:.3f} s); by seed {np.round(np.array(approx) / np.array(exact), 3)}", flush=True)


if __name__ == "__main__":
    geods.set_num_threads(1)
    {"table": table, "seeds": seeds}[sys.argv[1] if len(sys.argv) > 1 else "table"]()
