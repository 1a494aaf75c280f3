"""geods.dask on a real dask.distributed LocalCluster (2 worker processes): every
result equals the single-process one (EDT bit for bit against scipy, meshes up
to vertex order, terrain tiles crack-free)."""
import functools
import subprocess
import sys

import numpy as np
import pytest

import geods

dask = pytest.importorskip("dask")
distributed = pytest.importorskip("dask.distributed")
ndimage = pytest.importorskip("scipy.ndimage")
da = pytest.importorskip("dask.array")
gd = pytest.importorskip("geods.dask")

# Debian 12's dask.distributed (2022.12) starts tornado's (6.2) IO loop the
# way tornado deprecated: a warning about those two packages, not about geods.
pytestmark = pytest.mark.filterwarnings("ignore:make_current is deprecated:DeprecationWarning:tornado")


@pytest.fixture(scope="module")
def client():
    """One cluster for the whole module (starting worker processes is slow)."""
    cluster = distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                       dashboard_address=None, silence_logs=40)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def test_import_geods_does_not_import_dask():
    code = "import sys, geods; assert 'dask' not in sys.modules and 'geods.dask' not in sys.modules"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_edt_equals_scipy_bit_for_bit(client):
    rng = np.random.default_rng(7)
    random = rng.random((13, 15, 11)) < 0.85
    sparse = rng.random((13, 15, 11)) < 0.995  # long distances across chunks
    one = np.ones((13, 15, 11), bool)
    one[3, 14, 1] = False  # a single background sample
    # (mask, chunks, spacing in geods order (x first; scipy's sampling is the reverse)):
    # cubes, chunks of 1 along each axis, one chunk, uneven; unit, binary-fraction and other spacings.
    # chunk_samples: the passes' chunks too are cut across the lines (a few hundred samples each).
    cases = [
        (random, (4, 5, 3), None, 400), (random, (1, 15, 11), (0.5, 2.0, 1.25), None),
        (random, (13, 1, 4), (1.3, 0.7, 1.1), 150), (sparse, (6, 4, 1), (3.0, 1.0, 2.0), 300),
        (one, (5, 2, 11), (1.3, 0.7, 1.1), None),
    ]
    results = dask.compute(*[gd.edt(da.from_array(m, chunks=c), s, chunk_samples=n) for m, c, s, n in cases])
    for (m, chunks, spacing, _), got in zip(cases, results):
        want = ndimage.distance_transform_edt(m, sampling=None if spacing is None else spacing[::-1])
        assert got.dtype == np.float64
        assert np.array_equal(got, want), (chunks, spacing)


def test_edt_with_the_passes_on_disk(client, tmp_path):
    # store=: the intermediates written between passes (one file per chunk) and read back memory-mapped.
    rng = np.random.default_rng(11)
    m3 = rng.random((12, 14, 9)) < 0.9
    m2 = rng.random((20, 17)) < 0.9
    a = gd.edt(da.from_array(m3, chunks=(5, 1, 4)), (1.3, 0.7, 1.1), chunk_samples=150, store=tmp_path / "a")
    b = gd.edt(da.from_array(m2, chunks=(3, 17)), (2.0, 0.5), chunk_samples=40, store=tmp_path / "b")
    got3, got2 = dask.compute(a, b)
    assert np.array_equal(got3, ndimage.distance_transform_edt(m3, sampling=(1.1, 0.7, 1.3)))
    assert np.array_equal(got2, ndimage.distance_transform_edt(m2, sampling=(0.5, 2.0)))
    assert len(list((tmp_path / "a").iterdir())) > 2  # two passes' files went through the directory


def test_edt_1d_2d_numeric_and_degenerate(client):
    rng = np.random.default_rng(8)
    m2 = rng.integers(0, 4, (31, 26)).astype(np.int16)  # numeric: nonzero = foreground
    got = gd.edt(da.from_array(m2, chunks=(4, 1)), (2.0, 0.75)).compute()
    assert np.array_equal(got, ndimage.distance_transform_edt(m2, sampling=(0.75, 2.0)))
    m1 = rng.random(50) < 0.9
    got = gd.edt(da.from_array(m1, chunks=7)).compute()
    assert np.array_equal(got, ndimage.distance_transform_edt(m1))
    # No background: inf everywhere (as geods.edt); all background: zeros.
    assert np.all(np.isinf(gd.edt(da.ones((4, 5, 6), chunks=2)).compute()))
    assert np.all(gd.edt(da.zeros((4, 5, 6), chunks=2)).compute() == 0)
    # The result's chunks: whole along the last axis, about chunk_samples samples each.
    x = da.from_array(rng.random((9, 8, 7)) < 0.5, chunks=(2, 3, 4))
    y = gd.edt(x, chunk_samples=30)
    assert y.shape == x.shape and y.chunks[2] == (7,) and max(y.chunks[0]) * max(y.chunks[1]) * 7 <= 30


def test_edt_bad_input(client):
    with pytest.raises(geods.Error):
        gd.edt(da.zeros((2, 2, 2, 2)))
    with pytest.raises(geods.Error):
        gd.edt(da.zeros((4, 4)), spacing=(1.0, 0.0))
    with pytest.raises(geods.Error):
        gd.edt(da.zeros((4, 4)), spacing=(1.0, 2.0, 3.0))
    with pytest.raises(geods.Error):
        gd.edt(da.from_array(np.array([1.0, np.nan, 0.0]), chunks=1)).compute()
    with pytest.raises(geods.Error):
        geods.edt_pass(np.zeros((3, 3)), 2, 1.0)


def canonical(V, F):
    """Vertices sorted, triangles over the sorted ids rotated to start at their
    smallest id (orientation kept) and sorted: equal meshes up to order compare equal."""
    order = np.lexsort(V.T[::-1])
    rank = np.empty(len(V), np.int64)
    rank[order] = np.arange(len(V))
    f = rank[np.asarray(F, np.int64)].reshape(-1, 3)
    shift = np.argmin(f, axis=1)
    f = np.stack([np.roll(row, -k) for row, k in zip(f, shift)]) if len(f) else f
    return V[order], f[np.lexsort(f.T[::-1])] if len(f) else f


def assert_same_mesh(a, b):
    va, fa = canonical(*a)
    vb, fb = canonical(*b)
    assert va.shape == vb.shape and np.array_equal(va, vb)
    assert fa.shape == fb.shape and np.array_equal(fa, fb)


def closed(F):
    """Every edge used once in each direction (a closed, oriented 2-manifold's edges)."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    fwd = {tuple(x) for x in e}
    return len(fwd) == len(e) and all((b, a) in fwd for a, b in fwd)


def test_isosurface_equals_single_process(client):
    rng = np.random.default_rng(9)
    zz, yy, xx = np.mgrid[0:24, 0:21, 0:26]
    blob = (np.sqrt((xx - 12.3) ** 2 + (yy - 10.1) ** 2 + (zz - 11.7) ** 2)).astype(np.float32)
    volumes = {
        "sphere": (blob, 8.2),  # closed: away from the border
        "noise": (rng.random((10, 11, 9)), 0.5),  # ambiguous cells, centre vertices, the border
        "labels": (rng.integers(0, 3, (8, 9, 7)).astype(np.uint8), 1),  # samples equal to t
    }
    for name, (vol, t) in volumes.items():
        V0, F0, _ = geods.isosurface(vol, t, normals=False)
        if name == "noise":  # some cell-centre vertices (off the grid edges) are among them
            assert ((V0 == np.floor(V0)).sum(axis=1) < 2).any()
        for chunks in [(5, 6, 7), (1, 21, 26), (24, 4, 1)]:
            V, F = gd.isosurface(da.from_array(vol, chunks=chunks), t)
            assert_same_mesh((V, F), (V0, F0))
            assert len(np.unique(V, axis=0)) == len(V), (name, chunks)  # no duplicate on the seams
        if name == "sphere":
            assert closed(F0) and closed(F)
    # spacing and origin place vertices as the single-process call does.
    V0, F0, _ = geods.isosurface(blob, 8.2, spacing=(0.5, 1.5, 2.0), origin=(-3.0, 1.0, 7.5), normals=False)
    V, F = gd.isosurface(da.from_array(blob, chunks=(7, 8, 9)), 8.2, spacing=(0.5, 1.5, 2.0), origin=(-3.0, 1.0, 7.5))
    assert_same_mesh((V, F), (V0, F0))
    # Nothing crossed: an empty mesh.
    V, F = gd.isosurface(da.zeros((6, 6, 6), chunks=3), 1.0)
    assert V.shape == (0, 3) and F.shape == (0, 3)
    with pytest.raises(geods.Error):
        gd.isosurface(da.zeros((6, 6)), 1.0)
    with pytest.raises(geods.Error):
        gd.isosurface(da.zeros((6, 6, 6)), float("nan"))


def descriptor(V, F, kind):
    return geods.shape_distribution(V, F, kind=kind, samples=2000, bins=16)


def test_map_meshes_and_shape_database(client, data_dir, tmp_path):
    paths = [data_dir / "bunny.ply", data_dir / "teapot.obj"]
    paths = [p for p in paths if p.exists()]
    assert paths, "data/ meshes"
    # A few meshes of our own too (boxes of different proportions).
    for k, (a, b, c) in enumerate([(1, 1, 1), (1, 2, 3), (4, 1, 1)]):
        x, y, z = np.meshgrid([0, a], [0, b], [0, c], indexing="ij")
        V = np.stack([x.ravel(), y.ravel(), z.ravel()], 1).astype(np.float32)
        F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
        p = tmp_path / f"box{k}.obj"
        p.write_text("".join(f"v {v[0]} {v[1]} {v[2]}\n" for v in V) + "".join(f"f {f[0]+1} {f[1]+1} {f[2]+1}\n" for f in F))
        paths.append(p)
    bag = gd.map_meshes(paths, functools.partial(descriptor, kind="d2"))
    got = bag.compute()
    assert len(got) == len(paths)
    for p, g in zip(paths, got):
        V, F = geods.read_mesh(str(p))
        assert np.array_equal(g, descriptor(V, F, "d2"))
    # The database from the workers' descriptors answers as one built in process.
    db = gd.shape_database(paths, descriptor="d2", samples=2000, bins=16)
    ref = geods.ShapeDatabase(descriptor="d2", samples=2000, bins=16)
    for p in paths:
        ref.add(str(p), *geods.read_mesh(str(p)))
    assert len(db) == len(ref) == len(paths)
    for k in range(len(paths)):
        assert np.array_equal(db.descriptor(k), ref.descriptor(k))
    V, F = geods.read_mesh(str(paths[-1]))
    assert db.query(V, F, k=3) == ref.query(V, F, k=3)
    with pytest.raises(geods.Error):
        gd.map_meshes([tmp_path / "missing.ply"], len).compute()


def test_terrain_tiles_equal_single_process_and_crack_free(client, data_dir):
    rng = np.random.default_rng(10)
    dem = np.load(data_dir / "jacksboro_dem.npy").astype(np.float32)[:97, :130]
    noise = (rng.random((41, 57)) * 5).astype(np.float32)
    for name, h in {"real": dem, "noise": noise}.items():
        for tiles, e in ([(3, 1.0)] if name == "real" else [(1, 2.0), (4, 0.5)]):
            V0, F0 = geods.Terrain(h).tin(e, tiles=tiles)
            V, F = gd.terrain_tiles(da.from_array(h, chunks=(32, 32)), tiles, e)
            assert_same_mesh((V, F), (V0, F0))
            # Crack-free: the triangles tile the rectangle, every inner edge shared by two of them in
            # opposite directions, no vertex left alone on a border edge of a neighbour.
            e2 = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
            fwd = {tuple(x) for x in e2}
            boundary = [(a, b) for a, b in fwd if (b, a) not in fwd]
            pts = V[:, :2]
            for a, b in boundary:  # boundary edges lie on the field's border
                on_x = pts[a, 0] == pts[b, 0] and pts[a, 0] in (0, h.shape[1] - 1)
                on_y = pts[a, 1] == pts[b, 1] and pts[a, 1] in (0, h.shape[0] - 1)
                assert on_x or on_y, (name, tiles)
            area = np.cross(pts[F[:, 1]] - pts[F[:, 0]], pts[F[:, 2]] - pts[F[:, 0]]).sum() / 2
            assert area == (h.shape[0] - 1) * (h.shape[1] - 1)
    with pytest.raises(geods.Error):
        gd.terrain_tiles(np.array([[0, np.nan], [1, 2]], np.float32), 1, 1.0)
    with pytest.raises(geods.Error):
        gd.terrain_tiles(noise, 0, 1.0)
