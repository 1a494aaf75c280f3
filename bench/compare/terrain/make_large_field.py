"""A 16385 x 16385 float32 height field (1 GB .npy) for the mapped-terrain memory
measurement of docs/terrain.md: data/trigger_tropic_h.png mirrored into a
periodic 2048^2 block, tiled 8 x 8, padded by one row and column, plus a gentle
slope along y so that no two tiles are equal.
Usage: python3 make_large_field.py OUT.npy"""
import sys
from pathlib import Path

import numpy as np
from PIL import Image

a = np.asarray(Image.open(Path(__file__).resolve().parents[3] / "data" / "trigger_tropic_h.png").convert("L"),
               dtype=np.float32)
m = np.concatenate([a, a[:, ::-1]], axis=1)
m = np.concatenate([m, m[::-1, :]], axis=0)
big = np.pad(np.tile(m, (8, 8)), ((0, 1), (0, 1)), mode="edge")
big += np.arange(big.shape[0], dtype=np.float32)[:, None] * np.float32(0.01)
np.save(sys.argv[1], big)
