"""geods past one machine: volumes in chunks, mesh collections and terrain tiles on Dask.

``import geods.dask`` needs Dask (Debian's python3-dask and python3-distributed);
``import geods`` never imports it. Every function builds a Dask graph over the
geods bindings and runs on whatever scheduler is active (a
``dask.distributed.Client`` of a cluster, or Dask's local threads); the results
equal the single-process geods ones:

- ``edt(x, spacing=None)``: the exact Euclidean distance transform of a dask
  array, one separable pass per axis across the chunks (``geods.edt_pass``),
  equal to ``scipy.ndimage.distance_transform_edt`` of the whole array.
- ``isosurface(x, t)``: marching cubes per chunk with a one-sample overlap,
  the pieces welded into one mesh by the grid edge of each vertex.
- ``map_meshes(paths, fn)``: ``fn(V, F)`` over meshes read on the workers (a
  dask bag); ``shape_database(paths)`` feeds their descriptors to a
  ``geods.ShapeDatabase``.
- ``terrain_tiles(heights, tiles, max_error)``: the tiled TIN of
  ``geods.Terrain(heights).tin(max_error, tiles)``, one tile per task.
"""
from __future__ import annotations

import os
from typing import Callable, Sequence

import dask
import dask.array as da
import dask.bag as db
import numpy as np

import geods

__all__ = ["edt", "isosurface", "map_meshes", "shape_database", "terrain_tiles"]


# ---------------------------------------------------------------- EDT

def _spacing(spacing, ndim: int, what: str) -> list[float]:
    """Per-axis spacing in geods order (x first) -> per numpy axis (axis 0 first)."""
    if spacing is None:
        return [1.0] * ndim
    if np.isscalar(spacing):
        s = [float(spacing)] * ndim
    else:
        s = [float(v) for v in spacing]
        if len(s) != ndim:
            raise geods.Error(f"{what}: spacing needs one value per axis (x first), {ndim} for this array, "
                              f"got {len(s)}")
    for v in s:
        if not (np.isfinite(v) and v > 0):
            raise geods.Error(f"{what}: spacing must be finite and > 0, got {v}")
    return s[::-1]


def _pass_chunks(sizes, shape: tuple, axis: int, target: int) -> tuple:
    """Chunks whole along `axis`, the other axes starting from `sizes` and halved
    (the largest first) until a chunk holds at most about `target` samples."""
    sizes = list(sizes)
    sizes[axis] = shape[axis]
    others = [a for a in range(len(shape)) if a != axis]
    while int(np.prod(sizes)) > target and any(sizes[a] > 1 for a in others):
        a = max(others, key=lambda a: sizes[a])
        sizes[a] = (sizes[a] + 1) // 2
    return da.core.normalize_chunks(tuple(max(v, 1) for v in sizes), shape)


def _whole_along(x: da.Array, axis: int, target: int) -> da.Array:
    """x rechunked so that `axis` is whole in every chunk (_pass_chunks)."""
    return x.rechunk(_pass_chunks([max(c, default=1) for c in x.chunks], x.shape, axis, target))


def _background(block: np.ndarray) -> np.ndarray:
    if block.dtype.kind == "f" and np.isnan(block).any():
        raise geods.Error("edt: the mask holds NaN")
    return np.where(block != 0, np.inf, 0.0)


def _pass(block: np.ndarray, axis: int, spacing: float, first: bool, last: bool) -> np.ndarray:
    """One pass along numpy axis `axis` of a chunk whole along it; the first pass
    starts from the mask (0 on the background, inf elsewhere), the last takes the
    square root."""
    g = _background(block) if first else block
    # geods.edt_pass counts axes x first: numpy axis a of an n-D block is geods axis n - 1 - a.
    g = geods.edt_pass(g, block.ndim - 1 - axis, spacing)
    return np.sqrt(g, out=g) if last else g


def _regions(chunks: tuple):
    """(block index, tuple of slices) of every block of a chunk grid."""
    starts = [np.concatenate([[0], np.cumsum(c)]) for c in chunks]
    for index in np.ndindex(*[len(c) for c in chunks]):
        yield index, tuple(slice(int(starts[a][i]), int(starts[a][i + 1])) for a, i in enumerate(index))


def _stored_pass(block, region, axis, spacing, first, last, previous, path):
    """One block of a pass with the intermediates on disk: read the block's
    region from the previous pass's files (memory-mapped), run the pass, and
    write it (or return it after the last pass)."""
    if not first:
        block = np.empty(tuple(r.stop - r.start for r in region), np.float64)
        for file, where in previous:
            inter = tuple(slice(max(a.start, b.start), min(a.stop, b.stop)) for a, b in zip(region, where))
            if any(i.start >= i.stop for i in inter):
                continue
            src = np.load(file, mmap_mode="r")
            block[tuple(slice(i.start - r.start, i.stop - r.start) for i, r in zip(inter, region))] = \
                src[tuple(slice(i.start - w.start, i.stop - w.start) for i, w in zip(inter, where))]
            del src
    g = _pass(block, axis, spacing, first, last)
    if last:
        return g
    np.save(path, g)
    return path, region


def _edt_stored(x: da.Array, s: list, chunk_samples: int, store) -> da.Array:
    import uuid
    os.makedirs(store, exist_ok=True)
    token = uuid.uuid4().hex[:12]
    n = x.ndim
    task = dask.delayed(_stored_pass, pure=False)
    first = _whole_along(x, 0, chunk_samples)
    blocks = first.to_delayed()
    previous = None
    for axis in range(n):
        chunks = first.chunks if axis == 0 else _pass_chunks([max(c) for c in chunks], x.shape, axis, chunk_samples)
        last = axis == n - 1
        out = {}
        for index, region in _regions(chunks):
            path = os.path.join(os.fspath(store), f"edt-{token}-{axis}-{'-'.join(map(str, index))}.npy")
            block = blocks[index] if axis == 0 else None
            out[index] = task(block, region, axis, s[axis], axis == 0, last, previous, path)
        if last:
            shape_of = {index: tuple(r.stop - r.start for r in region) for index, region in _regions(chunks)}
            arrays = np.empty([len(c) for c in chunks], dtype=object)
            for index, d in out.items():
                arrays[index] = da.from_delayed(d, shape_of[index], dtype=np.float64)
            return da.block(arrays.tolist())
        previous = list(out.values())


def edt(x, spacing=None, chunk_samples: int | None = None, store=None) -> da.Array:
    """Exact Euclidean distance transform of a 1-, 2- or 3-D dask array (nonzero =
    foreground): per sample the distance to the nearest zero sample, 0 on zeros,
    inf if there is none; float64, in chunks whole along the last axis (of about
    chunk_samples samples; rechunk it as needed).

    The squared distance is separable: one pass per axis (numpy axis 0 first)
    replaces every line along it by the lower envelope of its parabolas
    (``geods.edt_pass``), for which the array is rechunked so that the axis is
    whole in every chunk (the first pass starts from the mask, the last takes
    the square root). No chunk overlap is
    involved, and the result equals ``scipy.ndimage.distance_transform_edt`` of
    the whole array bit for bit (the same sums in the same order; exactly so
    whenever the spacings are integers or binary fractions such as 0.5 or 1.25,
    and with other spacings wherever two nearest samples do not tie in real
    arithmetic). spacing: one number or one per axis in geods order, x first
    ((sx, sy, sz) for an (nz, ny, nx) array, the reverse of scipy's
    ``sampling``), as ``geods.edt``. chunk_samples: samples per chunk during the
    passes (default: those of x's largest chunk, at least 2^20, i.e. 8 MiB of
    float64). The float64 squared distances of a pass are all needed before
    the next pass starts; held by the workers by default (Dask spills them when
    memory runs short), or with store= a directory (on a file system every
    worker sees) written to and read back memory-mapped between passes, one
    file per chunk: a worker then holds a chunk or two at a time, so arrays
    far larger than the cluster's memory work. The files (8 bytes per sample
    per pass but the last) stay there; remove the directory afterwards.
    """
    x = da.asarray(x)
    if x.ndim < 1 or x.ndim > 3:
        raise geods.Error("edt: the mask must be a 1-, 2- or 3-D array")
    if x.dtype.kind not in "biuf":
        raise geods.Error(f"edt: the mask must hold numbers or booleans, got {x.dtype!r}")
    s = _spacing(spacing, x.ndim, "edt")
    if x.size == 0:
        return da.zeros(x.shape, dtype=np.float64)
    if chunk_samples is None:
        chunk_samples = max(int(np.prod([max(c, default=1) for c in x.chunks])), 1 << 20)
    if store is not None:
        return _edt_stored(x, s, int(chunk_samples), store)
    # The first pass reads the mask itself: the rechunk before it moves the mask's bytes, not float64s.
    g = x
    for axis in range(x.ndim):
        g = _whole_along(g, axis, int(chunk_samples)).map_blocks(_pass, axis, s[axis], axis == 0,
                                                                 axis == x.ndim - 1, dtype=np.float64)
    return g


# ---------------------------------------------------------------- isosurface

def _iso_block(block: np.ndarray, first: tuple, shape: tuple, low: tuple, t: float, spacing, origin):
    """One chunk's piece: marching cubes of its cells (the chunk plus one sample
    of overlap on the high side), each vertex keyed by its grid edge."""
    sub = block[tuple(slice(l, None) for l in low)]  # drop the low halo: cells belong to one chunk
    if min(sub.shape) < 2:
        empty = np.zeros((0, 3), np.float32)
        return np.zeros(0, np.int64), empty, empty, np.zeros((0, 3), np.int64)
    V, F, _ = geods.isosurface(np.ascontiguousarray(sub), t, normals=False)
    on = V == np.floor(V)  # local positions: integral along the two axes the edge does not run
    edge = on.sum(axis=1) == 2
    ev = V[edge]
    axis = np.argmin(on[edge], axis=1)  # x = 0, y = 1, z = 2
    ijk = np.floor(ev).astype(np.int64)  # the edge's first sample, local (x, y, z)
    # The position as geods.isosurface places it on the whole grid: same samples, same arithmetic.
    a = sub[ijk[:, 2], ijk[:, 1], ijk[:, 0]].astype(np.float64)
    step = np.eye(3, dtype=np.int64)[axis]
    nb = ijk + step
    b = sub[nb[:, 2], nb[:, 1], nb[:, 0]].astype(np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.clip((t - a) / (b - a), 1e-3, 1.0 - 1e-3)
    g = ijk + np.asarray(first, np.int64)[::-1]  # global (x, y, z)
    idx = g.astype(np.float64)
    idx[np.arange(len(idx)), axis] += s
    pos = (origin + idx * spacing).astype(np.float32)
    keys = ((g[:, 2] * shape[1] + g[:, 1]) * shape[2] + g[:, 0]) * 3 + axis
    # Centre vertices (inside one cell, so in no other chunk): the mean of their edge vertices, as placed.
    local = np.full(len(V), -1, np.int64)
    local[edge] = np.arange(len(ev))
    centres = np.flatnonzero(~edge)
    cpos = np.zeros((len(centres), 3), np.float32)
    for n, c in enumerate(centres):
        around = np.unique(F[(F == c).any(axis=1)])
        around = around[around != c]
        cpos[n] = (pos[local[around]].astype(np.float64).sum(axis=0) / len(around)).astype(np.float32)
    local[~edge] = len(ev) + np.arange(len(centres))
    return keys, pos, cpos, local[F]


def isosurface(x, t: float, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0)):
    """Isosurface {value = t} of a 3-D dask array (indexed [z, y, x]) by marching
    cubes per chunk -> (V float32 (n, 3), F int64 (m, 3)).

    Each chunk runs ``geods.isosurface`` on its samples plus one sample of
    overlap on the high side (``dask.array.overlap``), so every cell belongs to
    exactly one chunk; vertices get a global id from the grid edge they lie on,
    and the pieces are welded on these ids: no duplicate vertex on the seams.
    The result equals ``geods.isosurface(x.compute(), t, spacing, origin)``'s
    (V, F) up to vertex and triangle order (positions bit for bit), closed
    when that one is. spacing and origin as in geods.isosurface (x first).
    """
    x = da.asarray(x)
    if x.ndim != 3:
        raise geods.Error("isosurface: the volume must be a 3-D array")
    t = float(t)
    if not np.isfinite(t):
        raise geods.Error("isosurface: the iso-value must be finite")
    sp = np.asarray(spacing, np.float32).astype(np.float64)
    org = np.asarray(origin, np.float32).astype(np.float64)
    if sp.shape != (3,) or org.shape != (3,) or not np.all(np.isfinite(sp)) or np.any(sp == 0):
        raise geods.Error("isosurface: spacing must be 3 finite, non-zero values and origin 3 finite values")
    xo = da.overlap.overlap(x, depth={0: 1, 1: 1, 2: 1}, boundary="none")
    starts = [np.concatenate([[0], np.cumsum(c)[:-1]]) for c in x.chunks]
    blocks = xo.to_delayed()
    piece = dask.delayed(_iso_block, pure=True)
    parts = []
    for index in np.ndindex(*blocks.shape):
        first = tuple(int(starts[a][index[a]]) for a in range(3))
        low = tuple(1 if first[a] > 0 else 0 for a in range(3))
        parts.append(piece(blocks[index], first, x.shape, low, t, sp, org))
    parts = dask.compute(*parts)
    keys = np.concatenate([p[0] for p in parts])
    pos = np.concatenate([p[1] for p in parts])
    unique, at, inverse = np.unique(keys, return_index=True, return_inverse=True)
    V = [pos[at]]
    F = []
    edge_base, centre_base = 0, len(unique)
    for k, c, f in ((p[0], p[2], p[3]) for p in parts):
        ids = np.concatenate([inverse[edge_base:edge_base + len(k)], centre_base + np.arange(len(c))])
        F.append(ids[f])
        V.append(c)
        edge_base += len(k)
        centre_base += len(c)
    return np.concatenate(V).reshape(-1, 3), np.concatenate(F).reshape(-1, 3).astype(np.int64)


# ---------------------------------------------------------------- collections

def _apply(path, fn):
    V, F = geods.read_mesh(os.fspath(path))
    return fn(V, F)


def map_meshes(paths: Sequence, fn: Callable, npartitions: int | None = None) -> db.Bag:
    """A dask bag of fn(V, F) over the meshes at `paths` (any format of
    geods.read_mesh), read and processed on the workers, in the order of paths.
    fn: shape descriptors, a signed distance field, a collision test...; it must
    be picklable (a module-level function or a functools.partial of one)."""
    paths = [os.fspath(p) for p in paths]
    if npartitions is None:
        npartitions = max(1, min(len(paths), 100))
    return db.from_sequence(paths, npartitions=npartitions).map(_apply, fn)


class _Describe:
    """fn of map_meshes: a mesh's descriptor under a database's options."""

    def __init__(self, **options):
        self.options = options

    def __call__(self, V, F):
        return geods.ShapeDatabase(**self.options).describe(V, F)


def shape_database(paths: Sequence, labels: Sequence[str] | None = None, names: Sequence[str] | None = None,
                   **options) -> "geods.ShapeDatabase":
    """A geods.ShapeDatabase of the meshes at `paths`, their descriptors
    computed on the workers (map_meshes) and added as one batch. options:
    those of geods.ShapeDatabase (descriptor, samples, bins, seed,
    normalization); the descriptors equal those of ShapeDatabase.add."""
    paths = [os.fspath(p) for p in paths]
    database = geods.ShapeDatabase(**options)
    rows = map_meshes(paths, _Describe(**options)).compute()
    if not rows:
        return database
    names = list(names) if names is not None else paths
    database.add_descriptors(names, np.stack(rows).astype(np.float32), list(labels) if labels is not None else None)
    return database


# ---------------------------------------------------------------- terrain tiles

def _tin_tile(block: np.ndarray, x0: int, y0: int, max_error: float, border_limit: float):
    V, F = geods.tin_tile(np.ascontiguousarray(block, np.float32), max_error, border_limit)
    xy = V[:, :2].astype(np.int64) + np.array([x0, y0])
    return xy, V[:, 2].copy(), F


def terrain_tiles(heights, tiles: int, max_error: float, spacing=(1.0, 1.0)):
    """The tiled TIN of a height field (2-D array, rows = y, finite), one tile per
    task -> (V float32 (n, 3), F int64 (m, 3)).

    The field is cut as ``geods.Terrain(heights, spacing).tin(max_error, tiles)``
    cuts it (tiles x tiles blocks sharing their border samples); each task
    triangulates its block with ``geods.tin_tile``, the sides simplified with the
    whole field's tolerance (``geods.tin_border_limit`` of its lowest and highest
    sample), so neighbouring tiles keep the same border vertices: the mesh is
    crack-free, and equal to the single-process one up to vertex order. Vertices
    are welded by their sample.
    """
    h = da.asarray(heights)
    if h.ndim != 2:
        raise geods.Error("terrain_tiles: heights must be a 2-D array (rows = y)")
    H, W = h.shape
    tiles = int(tiles)
    if tiles < 1 or tiles > min(W, H) - 1:
        raise geods.Error(f"terrain_tiles: tiles must be in 1..{min(W, H) - 1}, got {tiles}")
    max_error = float(max_error)
    if not (np.isfinite(max_error) and max_error >= 0):
        raise geods.Error("terrain_tiles: max_error must be finite and >= 0")
    h = h.astype(np.float32)
    lo, hi = dask.compute(h.min(), h.max())
    if not (np.isfinite(lo) and np.isfinite(hi)):
        raise geods.Error("terrain_tiles: the heights hold a NaN or infinite sample (fill them first)")
    border_limit = geods.tin_border_limit(max_error, float(lo), float(hi))
    xs = [k * (W - 1) // tiles for k in range(tiles + 1)]
    ys = [k * (H - 1) // tiles for k in range(tiles + 1)]
    task = dask.delayed(_tin_tile, pure=True)
    parts = dask.compute(*[task(h[ys[ty]:ys[ty + 1] + 1, xs[tx]:xs[tx + 1] + 1], xs[tx], ys[ty], max_error,
                                border_limit)
                           for ty in range(tiles) for tx in range(tiles)])
    xy = np.concatenate([p[0] for p in parts])
    z = np.concatenate([p[1] for p in parts])
    keys = xy[:, 1] * W + xy[:, 0]
    unique, at, inverse = np.unique(keys, return_index=True, return_inverse=True)
    sx, sy = (float(v) for v in spacing)
    V = np.stack([(xy[at, 0] * sx).astype(np.float32), (xy[at, 1] * sy).astype(np.float32), z[at]], axis=1)
    F, base = [], 0
    for p in parts:
        F.append(inverse[base:base + len(p[0])][p[2]])
        base += len(p[0])
    return V, np.concatenate(F).reshape(-1, 3).astype(np.int64)
