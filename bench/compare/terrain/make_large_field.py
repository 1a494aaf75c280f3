"""A 16385 x 16385 float32 height field (1 GB .npy) for the mapped-terrain memory
measurement of docs/terrain.md: the USGS Jacksboro DEM (data/jacksboro_dem.npy,
344 x 403 metres, public domain) mirrored into 16385^2 (the bench's 1025^2 field
is its top-left corner), plus a gentle slope along y so that no two periods are
equal.
Usage: python3 make_large_field.py OUT.npy"""
import sys
from pathlib import Path

import numpy as np

n = 16385
a = np.load(Path(__file__).resolve().parents[3] / "data" / "jacksboro_dem.npy").astype(np.float32)
big = np.pad(a, ((0, n - a.shape[0]), (0, n - a.shape[1])), mode="reflect")
big += np.arange(n, dtype=np.float32)[:, None] * np.float32(0.01)
np.save(sys.argv[1], big)
