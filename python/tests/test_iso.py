"""geods.isosurface and geods.MinMaxOctree: closed oriented surfaces (checked here
with numpy), axis order, dtypes, the octree against the scan, and the iso command."""
import json
import subprocess

import numpy as np
import pytest

import geods

ERRORS = (geods.Error,)


def grid(shape):
    """Index arrays (z, y, x) of a volume of shape (nz, ny, nx)."""
    return np.mgrid[0 : shape[0], 0 : shape[1], 0 : shape[2]].astype(np.float64)


def sphere(shape, center_xyz, radius):
    z, y, x = grid(shape)
    cx, cy, cz = center_xyz
    return (radius - np.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2)).astype(np.float32)


def check_closed(V, F):
    """Every directed edge appears once and its reverse once: closed and consistently oriented."""
    assert len(F) > 0
    edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]).astype(np.int64)
    n = len(V)
    directed = edges[:, 0] * n + edges[:, 1]
    reverse = edges[:, 1] * n + edges[:, 0]
    assert len(np.unique(directed)) == len(directed), "an edge is used twice in one direction"
    assert np.isin(reverse, directed).all(), "open or inconsistently oriented edge"
    assert len(np.unique(V, axis=0)) == len(V), "coincident vertices"
    a, b, c = V[F[:, 0]].astype(np.float64), V[F[:, 1]].astype(np.float64), V[F[:, 2]].astype(np.float64)
    cross = np.cross(b - a, c - a)
    assert (np.linalg.norm(cross, axis=1) > 0).all(), "zero-area triangle"
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6
    assert volume > 0, "not oriented outwards"
    return len(V) - len(F) // 2  # Euler characteristic


def canonical(V, F):
    tris = V[F]  # (m, 3, 3)
    out = []
    for t in tris:
        first = min(range(3), key=lambda k: tuple(t[k]))
        out.append(tuple(np.roll(t, -first, axis=0).ravel()))
    return sorted(out)


def test_sphere_is_closed_with_radial_normals_and_axis_order():
    vol = sphere((30, 34, 40), (20.3, 16.1, 14.2), 9.5)  # numpy (nz, ny, nx): x is the last axis
    V, F, N = geods.isosurface(vol, 0.0, spacing=(1.0, 0.5, 2.0), origin=(1.0, 2.0, 3.0))
    assert V.dtype == np.float32 and N.dtype == np.float32 and F.shape[1] == 3
    assert check_closed(V, F) == 2
    # World = origin + (i, j, k) * spacing with i along the last numpy axis.
    center = np.array([1.0 + 20.3 * 1.0, 2.0 + 16.1 * 0.5, 3.0 + 14.2 * 2.0])
    extent = V.max(0) - V.min(0)
    assert extent == pytest.approx([19.0, 9.5, 38.0], rel=0.03)
    assert (V.min(0) + V.max(0)) / 2 == pytest.approx(center, abs=0.1)
    assert np.allclose(np.linalg.norm(N, axis=1), 1, atol=1e-5)
    # Normals point away from the sphere's centre in index space.
    radial = (V - center) / np.array([1.0, 0.5, 2.0])
    assert (np.einsum("ij,ij->i", N * np.array([1.0, 0.5, 2.0]), radial) > 0).all()
    V2, F2, N2 = geods.isosurface(vol, 0.0, normals=False)
    assert N2.shape == (0, 3) and len(V2) == len(V)


def test_torus_euler_characteristic_zero():
    z, y, x = grid((24, 40, 44))
    q = np.hypot(x - 21.5, y - 19.7) - 12
    vol = 4.5 - np.hypot(q, z - 11.6)
    V, F, _ = geods.isosurface(vol, 0.0)
    assert check_closed(V, F) == 0


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.int16, np.float32, np.float64, np.int32, np.bool_])
def test_integer_and_other_dtypes_at_sample_values(dtype):
    rng = np.random.default_rng(5)
    vol = np.zeros((12, 13, 14), dtype=np.int64)
    vol[1:-1, 1:-1, 1:-1] = rng.integers(0, 2 if dtype == np.bool_ else 4, size=(10, 11, 12))
    vol = vol.astype(dtype)
    for t in [1.0] if dtype == np.bool_ else [1.0, 2.0, 1.5]:
        V, F, N = geods.isosurface(vol, t)
        check_closed(V, F)


def test_random_noise_is_closed():
    rng = np.random.default_rng(11)
    for _ in range(10):
        vol = np.full((14, 12, 13), -1.0, dtype=np.float32)
        vol[1:-1, 1:-1, 1:-1] = rng.uniform(-1, 1, size=(12, 10, 11))
        V, F, _ = geods.isosurface(vol, 0.1)
        check_closed(V, F)


def test_octree_gives_the_scan_triangles_and_visits_few_cells():
    vol = sphere((60, 64, 70), (30.2, 31.7, 29.9), 2.6)
    tree = geods.MinMaxOctree(vol)
    assert tree.cells_visited is None
    tree.validate()
    V, F, N = tree.isosurface(0.0)
    Vs, Fs, Ns = geods.isosurface(vol, 0.0)
    assert len(V) == len(Vs) and canonical(V, F) == canonical(Vs, Fs)
    cells = 59 * 63 * 69
    assert 0 < tree.cells_visited < 0.01 * cells
    assert tree.nodes_visited > 0
    stats = tree.stats()
    assert stats["cells"] == cells and stats["leaf_cells"] == 4
    # Many iso-values from one build; one cell per leaf.
    fine = geods.MinMaxOctree(vol, leaf_cells=1)
    for t in (-5.0, -1.0, 1.0, 2.5):
        V, F, _ = fine.isosurface(t)
        Vs, Fs, _ = geods.isosurface(vol, t)
        assert canonical(V, F) == canonical(Vs, Fs)


def test_octree_sharing_modes_give_the_same_surface():
    rng = np.random.default_rng(4)
    vol = rng.integers(0, 5, size=(13, 17, 19)).astype(np.uint8)  # samples equal to the iso-value
    tree = geods.MinMaxOctree(vol, leaf_cells=3)
    for t in (1.0, 2.0, 2.5):
        Vs, Fs, Ns = geods.isosurface(vol, t)
        for sharing in ("blocks", "hash"):
            V, F, N = tree.isosurface(t, sharing=sharing)
            assert len(V) == len(Vs) and canonical(V, F) == canonical(Vs, Fs)
            assert sorted(map(tuple, np.hstack([V, N]))) == sorted(map(tuple, np.hstack([Vs, Ns])))
    with pytest.raises(ERRORS):
        tree.isosurface(1.0, sharing="octree")
    with pytest.raises(ERRORS):
        geods.MinMaxOctree(vol, leaf_cells=33)


def test_curvilinear_coords():
    vol = sphere((20, 21, 22), (10.1, 9.8, 10.4), 6.0)
    z, y, x = grid(vol.shape)
    coords = np.stack([x * 0.5, y * 2.0 + 0.1 * x, z], axis=-1).astype(np.float32)
    V, F, N = geods.isosurface(vol, 0.0, coords=coords)
    check_closed(V, F)
    Vi, Fi, _ = geods.isosurface(vol, 0.0)
    assert np.array_equal(F, Fi)
    expected = np.stack([Vi[:, 0] * 0.5, Vi[:, 1] * 2.0 + 0.1 * Vi[:, 0], Vi[:, 2]], axis=-1)
    assert np.allclose(V, expected, atol=1e-4)
    with pytest.raises(ERRORS):
        geods.isosurface(vol, 0.0, coords=coords[:, :, :-1])


def test_bad_input_raises():
    with pytest.raises(ERRORS):
        geods.isosurface(np.zeros((4, 4)), 0.5)
    with pytest.raises(ERRORS):
        geods.isosurface(np.zeros((4, 4, 4)), float("nan"))
    vol = np.zeros((4, 4, 4), dtype=np.float32)
    vol[1, 2, 3] = np.nan
    with pytest.raises(ERRORS):
        geods.isosurface(vol, 0.5)
    with pytest.raises(ERRORS):
        geods.MinMaxOctree(vol)
    with pytest.raises(ERRORS):
        geods.isosurface(np.zeros((4, 4, 4)), 0.5, spacing=(1, 0, 1))


def run(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.int16, np.float32, np.float64])
def test_octree_save_load(tmp_path, dtype):
    vol = (sphere((12, 13, 14), (6, 6.5, 7), 4.5) * 10 + 50).astype(dtype)
    tree = geods.MinMaxOctree(vol, leaf_cells=2, spacing=(0.5, 1, 2), origin=(1, 2, 3))
    tree.save(tmp_path / "o.geods")
    loaded = geods.MinMaxOctree.load(tmp_path / "o.geods")
    assert loaded.stats() == tree.stats()
    loaded.validate()
    for t in (45.5, 50.0, 60.0):
        for sharing in ("block_masks", "hash_table"):
            for a, b in zip(tree.isosurface(t, sharing=sharing), loaded.isosurface(t, sharing=sharing)):
                np.testing.assert_array_equal(a, b)
    data = (tmp_path / "o.geods").read_bytes()
    (tmp_path / "bad.geods").write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match="truncated"):
        geods.MinMaxOctree.load(tmp_path / "bad.geods")


def test_iso_command(cli, tmp_path):
    vol = sphere((20, 22, 24), (11.5, 10.2, 9.8), 6.3)
    geods.write_volume(tmp_path / "ball.npy", vol)
    out = tmp_path / "ball.ply"
    r = run(cli, "iso", tmp_path / "ball.npy", "--iso", 0, "-o", out, "--json")
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    V, F, _ = geods.isosurface(vol, 0.0)
    assert report["vertices"] == len(V) and report["triangles"] == len(F)
    assert 0 < report["cells_visited"] <= report["cells"] and report["compute_s"] >= 0
    Vr, Fr = geods.read_mesh(out)
    assert canonical(Vr, Fr) == canonical(V, F)
    octree = json.loads(run(cli, "iso", tmp_path / "ball.npy", "--iso", 0, "--octree", "--json").stdout)
    assert octree["triangles"] == len(F) and octree["cells_visited"] < report["cells"]
    # --save writes the octree it built, which then gives the same surface from Python
    saved = run(cli, "iso", tmp_path / "ball.npy", "--iso", 0, "--octree", "--save", tmp_path / "ball.geods")
    assert saved.returncode == 0, saved.stderr
    Vs, Fs, _ = geods.MinMaxOctree.load(tmp_path / "ball.geods").isosurface(0.0)
    assert canonical(Vs, Fs) == canonical(V, F)
    assert run(cli, "iso", tmp_path / "ball.npy", "--iso", 0, "--save", tmp_path / "x.geods").returncode != 0
    # Raw input and a curvilinear grid.
    vol.tofile(tmp_path / "ball.raw")
    raw = json.loads(run(cli, "iso", tmp_path / "ball.raw", "--dims", "24,22,20", "--dtype", "f32", "--iso", 0,
                         "--json").stdout)
    assert raw["triangles"] == len(F)
    z, y, x = grid(vol.shape)
    np.save(tmp_path / "coords.npy", np.stack([2 * x, y, z], axis=-1).astype(np.float32))
    curv = json.loads(run(cli, "iso", tmp_path / "ball.npy", "--iso", 0, "--coords", tmp_path / "coords.npy",
                          "--json").stdout)
    assert curv["triangles"] == len(F) and curv["curvilinear"]
    bad = run(cli, "iso", tmp_path / "ball.npy", "--iso", 0, "--coords", tmp_path / "ball.npy")
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1


def test_isosurface_of_an_unpickled_volume():
    # An array that crossed a process boundary (pickle protocol 5, as Dask workers receive
    # chunks) has a dtype equal to, but not the same object as, numpy's builtin one.
    import pickle

    vol = np.random.default_rng(3).random((6, 7, 8))
    copy = pickle.loads(pickle.dumps(vol, protocol=5))
    V0, F0, _ = geods.isosurface(vol, 0.5)
    V1, F1, _ = geods.isosurface(copy, 0.5)
    assert np.array_equal(V0, V1) and np.array_equal(F0, F1)
