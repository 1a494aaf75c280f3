"""geods.edt and `geods edt` against brute force and scipy's distance_transform_edt."""
import json
import subprocess

import numpy as np
import pytest

import geods


def brute_force(mask, spacing):
    """Squared distance and flat index of the nearest zero, numpy axis order; spacing x first."""
    s = np.array(spacing[::-1], dtype=np.float64)
    grid = np.indices(mask.shape).reshape(mask.ndim, -1).T.astype(np.float64)
    zeros = np.flatnonzero(mask.ravel() == 0)
    diff = (grid[:, None, :] - grid[zeros][None, :, :]) * s
    # The library's sum order: x first, then y, then z (the last numpy axis first).
    d = np.zeros(diff.shape[:2])
    for axis in range(mask.ndim - 1, -1, -1):
        d = d + diff[:, :, axis] ** 2
    best = np.argmin(d, axis=1)  # first of equals: the smallest flat index
    return d[np.arange(len(d)), best].reshape(mask.shape), zeros[best].reshape(mask.shape)


@pytest.mark.parametrize("shape", [(40,), (17, 23), (9, 8, 11)])
@pytest.mark.parametrize("foreground", [0.1, 0.6, 0.95])
def test_edt_equals_brute_force(shape, foreground):
    rng = np.random.default_rng(len(shape) * 10 + int(foreground * 10))
    mask = (rng.random(shape) < foreground).astype(np.float32) * rng.integers(1, 5, shape)
    mask.flat[0] = 0  # at least one zero
    for spacing in [None, (1, 2, 3)[: len(shape)]]:
        sq, idx = brute_force(mask, spacing or (1,) * len(shape))
        d, i = geods.edt(mask, spacing=spacing, return_indices=True)
        assert d.dtype == np.float64 and d.shape == shape and i.shape == shape
        np.testing.assert_array_equal(d, np.sqrt(sq))
        np.testing.assert_array_equal(i, idx)
        np.testing.assert_array_equal(geods.edt(mask, spacing=spacing, squared=True), sq)


def test_edt_matches_scipy_on_real_data(data_dir):
    ndimage = pytest.importorskip("scipy.ndimage")
    head = geods.read_volume(str(data_dir / "t1_head.nii.gz"))
    mask = head[::2, ::2, ::2] > np.percentile(head, 60)
    spacing = (0.9, 1.1, 1.3)  # x, y, z: scipy's sampling is in numpy axis order, the reverse
    expected = ndimage.distance_transform_edt(mask, sampling=spacing[::-1])
    np.testing.assert_allclose(geods.edt(mask, spacing=spacing), expected, rtol=1e-12)
    brick = geods.read_image(str(data_dir / "brick.png"))
    stones = brick if brick.ndim == 2 else brick[..., 0]
    stones = stones > 100
    np.testing.assert_array_equal(geods.edt(stones), ndimage.distance_transform_edt(stones))


def test_edt_degenerate_and_bad_input():
    assert np.isinf(geods.edt(np.ones((3, 4)))).all()
    d, i = geods.edt(np.ones(5), return_indices=True)
    assert (i == -1).all()
    d, i = geods.edt(np.zeros((2, 3)), return_indices=True)
    assert (d == 0).all() and (i.ravel() == np.arange(6)).all()
    assert geods.edt(np.array([True, False, True]), spacing=2.5).tolist() == [2.5, 0, 2.5]
    with pytest.raises(geods.Error, match="NaN"):
        geods.edt(np.array([0.0, np.nan]))
    with pytest.raises(geods.Error, match="1-, 2- or 3-D"):
        geods.edt(np.zeros((2, 2, 2, 2)))
    with pytest.raises(geods.Error, match="spacing"):
        geods.edt(np.zeros((2, 2)), spacing=(1, 1, 1))
    with pytest.raises(geods.Error, match="spacing"):
        geods.edt(np.zeros((2, 2)), spacing=(1, 0))
    with pytest.raises(geods.Error, match="numbers"):
        geods.edt(np.array(["a", "b"]))


def run(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=300)


def test_cli_edt_npy_volume_and_image(cli, data_dir, tmp_path):
    rng = np.random.default_rng(3)
    mask = (rng.random((6, 7, 8)) < 0.8).astype(np.uint8)
    mask[0, 0, 0] = 0
    np.save(tmp_path / "m.npy", mask)
    r = run(cli, "edt", tmp_path / "m.npy", "-o", tmp_path / "d.npy", "--spacing", "1,2,3", "--indices",
            tmp_path / "i.npy", "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["dims"] == [8, 7, 6] and j["spacing"] == [1, 2, 3] and j["foreground"] == int(mask.sum())
    d, i = geods.edt(mask, spacing=(1, 2, 3), return_indices=True)
    np.testing.assert_array_equal(np.load(tmp_path / "d.npy"), d)
    np.testing.assert_array_equal(np.load(tmp_path / "i.npy"), i)
    assert j["max_distance"] == d.max()

    # A NIfTI volume keeps its header spacing; an image is 2-D (its first channel).
    r = run(cli, "edt", data_dir / "brick_hole_mask.png", "-o", tmp_path / "h.npy", "--json")
    assert r.returncode == 0, r.stderr
    hole = geods.read_image(str(data_dir / "brick_hole_mask.png"))
    hole = hole if hole.ndim == 2 else hole[..., 0]
    np.testing.assert_array_equal(np.load(tmp_path / "h.npy"), geods.edt(hole))

    bad = [(["--spacing", "1,2"], "3 values"), (["--spacing", "1,-2,3"], "spacing")]
    for args, words in bad:
        r = run(cli, "edt", tmp_path / "m.npy", "-o", tmp_path / "x.npy", *args)
        assert r.returncode == 2 and words in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    np.save(tmp_path / "nan.npy", np.array([[0.0, np.nan]]))
    r = run(cli, "edt", tmp_path / "nan.npy", "-o", tmp_path / "x.npy")
    assert r.returncode == 2 and "NaN" in r.stderr
    r = run(cli, "edt", tmp_path / "m.npy", "-o", tmp_path / "x.png")
    assert r.returncode == 2 and ".npy" in r.stderr
    r = run(cli, "edt", tmp_path / "missing.npy", "-o", tmp_path / "x.npy")
    assert r.returncode == 2 and "missing.npy" in r.stderr


# ---------------------------------------------------------------- signed distance of meshes


def point_triangle_distance(p, a, b, c):
    """Distance from points p (n, 3) to one triangle, float64: the face if the projection is
    inside, else the nearest of the three edges (an oracle independent of the library's)."""
    def segment(s, e):
        d = e - s
        t = np.clip(((p - s) @ d) / max(d @ d, 1e-300), 0, 1)
        return np.linalg.norm(p - (s + t[:, None] * d), axis=1)
    n = np.cross(b - a, c - a)
    nn = n @ n
    edges = np.minimum(np.minimum(segment(a, b), segment(b, c)), segment(c, a))
    if nn == 0:
        return edges
    q = p - ((p - a) @ n / nn)[:, None] * n  # projection on the plane
    inside = np.ones(len(p), bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= (np.cross(v - u, q - u) @ n) >= 0
    return np.where(inside, np.abs((p - a) @ n) / np.sqrt(nn), edges)


def brute_distance(V, F, p):
    V = V.astype(np.float64)
    return np.min([point_triangle_distance(p, V[f[0]], V[f[1]], V[f[2]]) for f in F], axis=0)


def ray_parity(V, F, p, direction=(0.5773, 0.6114, 0.5411)):
    """Inside (odd crossings of a ray) per point, over all triangles (Moeller-Trumbore, float64)."""
    V = V.astype(np.float64)
    d = np.array(direction) / np.linalg.norm(direction)
    a, e1, e2 = V[F[:, 0]], V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]
    h = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, h)
    crossings = np.zeros(len(p), int)
    for i, x in enumerate(p):
        s = x - a
        u = np.einsum("ij,ij->i", s, h) / det
        q = np.cross(s, e1)
        v = (q @ d) / det
        t = np.einsum("ij,ij->i", e2, q) / det
        crossings[i] = np.count_nonzero((u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0))
    return crossings % 2 == 1


@pytest.fixture(scope="module")
def bunny(data_dir):
    V, F = geods.read_mesh(str(data_dir / "bunny.ply"))[:2]
    return V, F


def test_signed_distance_against_brute_force_and_ray_parity(bunny):
    V, F = bunny
    rng = np.random.default_rng(16)
    lo, hi = V.min(0), V.max(0)
    p = (lo - 0.5 + rng.random((120, 3)) * (hi - lo + 1)).astype(np.float32)
    truth = brute_distance(V, F, p.astype(np.float64))
    inside = ray_parity(V, F, p.astype(np.float64))
    for sign in ("winding", "pseudonormal"):
        d, closest, face, feature = geods.signed_distance(V, F, p, sign=sign, return_feature=True)
        assert d.dtype == np.float64 and closest.shape == (120, 3) and face.dtype == np.int64
        np.testing.assert_allclose(np.abs(d), truth, atol=2e-5)
        np.testing.assert_allclose(np.linalg.norm(closest - p, axis=1), truth, atol=2e-5)
        far = truth > 1e-3
        assert ((d < 0) == inside)[far].all()
        assert set(np.unique(feature)) <= {0, 1, 2}
    d, _, _ = geods.signed_distance(V, F, p, sign="none")
    np.testing.assert_allclose(d, truth, atol=2e-5)


def test_sdf_grid_every_sample_and_band(bunny):
    V, F = bunny
    d, origin, spacing, face = geods.sdf_grid(V, F, 14, padding=2, return_faces=True)
    nz, ny, nx = d.shape
    assert d.dtype == np.float32 and nx == 14 and face.shape == d.shape
    z, y, x = np.indices(d.shape).reshape(3, -1)
    p = (np.array(origin) + np.stack([x, y, z], 1) * np.array(spacing)).astype(np.float32).astype(np.float64)
    np.testing.assert_allclose(np.abs(d.ravel()), brute_distance(V, F, p), atol=2e-5)
    np.testing.assert_array_equal(d.ravel() < 0, ray_parity(V, F, p))  # no sample sits on the surface here
    # The reported face is at the sample's distance.
    Vd = V.astype(np.float64)
    for s in range(0, len(p), 97):
        f = F[face.ravel()[s]]
        np.testing.assert_allclose(point_triangle_distance(p[s:s + 1], Vd[f[0]], Vd[f[1]], Vd[f[2]]),
                                   abs(d.ravel()[s]), atol=2e-5)

    # A narrow band: equal inside it, +-inf (the same sign) outside.
    b, _, _ = geods.sdf_grid(V, F, 14, padding=2, band=1.5)
    w = 1.5 * spacing[0]
    near = np.abs(d) <= w
    np.testing.assert_array_equal(b[near], d[near])
    assert np.isinf(b[~near]).all() and ((b < 0) == (d < 0)).all()

    # An explicit grid (x first), anisotropic.
    e, o, s = geods.sdf_grid(V, F, origin=(-1, 0, -2), spacing=(0.5, 0.4, 0.3), dims=(5, 4, 3))
    assert e.shape == (3, 4, 5) and o == (-1, 0, -2) and np.allclose(s, (0.5, 0.4, 0.3))
    q = np.array([[-1 + 0.5 * 4, 0.4 * 3, -2 + 0.3 * 2]], np.float32)
    np.testing.assert_allclose(e[2, 3, 4], geods.signed_distance(V, F, q)[0][0], atol=1e-5)


def test_sdf_open_mesh_and_bad_input(bunny):
    V, F = bunny
    open_f = np.delete(F, np.s_[100:130], axis=0)
    d, _, _ = geods.sdf_grid(V, open_f, 12)
    c, _, _ = geods.sdf_grid(V, F, 12)
    deep = np.abs(c) > 0.1 * (V.max(0) - V.min(0)).max()
    assert ((d < 0) == (c < 0))[deep].all() and (c[deep] < 0).any()

    with pytest.raises(geods.Error, match="no faces"):
        geods.signed_distance(V, np.zeros((0, 3), np.int64), [[0, 0, 0]])
    bad = V.copy()
    bad[3, 1] = np.nan
    with pytest.raises(geods.Error):
        geods.sdf_grid(bad, F, 16)
    with pytest.raises(geods.Error, match="not finite"):
        geods.signed_distance(V, F, [[0, np.inf, 0]])
    with pytest.raises(geods.Error, match="res or spacing"):
        geods.sdf_grid(V, F)
    with pytest.raises(geods.Error, match="GB"):
        geods.sdf_grid(V, F, origin=(0, 0, 0), spacing=1, dims=(100000, 100000, 100000))
    with pytest.raises(geods.Error, match="sign method"):
        geods.sdf_grid(V, F, 8, sign="parity")
    with pytest.raises(geods.Error, match="band"):
        geods.sdf_grid(V, F, 8, band=-1)


def test_cli_sdf(cli, data_dir, tmp_path, bunny):
    V, F = bunny
    r = run(cli, "sdf", data_dir / "bunny.ply", "-o", tmp_path / "d.npy", "--res", 20, "--padding", 2, "--band", 4,
            "--faces", tmp_path / "f.npy", "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    d = np.load(tmp_path / "d.npy")
    assert d.dtype == np.float32 and d.shape == tuple(j["dims"][::-1]) and j["dims"][0] == 20
    assert {"dims", "spacing", "origin", "build_s", "compute_s"} <= set(j)
    e, origin, spacing = geods.sdf_grid(V, F, 20, padding=2, band=4)
    np.testing.assert_array_equal(d, e)
    assert np.allclose(j["origin"], origin) and np.allclose(j["spacing"], spacing)
    faces = np.load(tmp_path / "f.npy")
    assert (faces[np.isinf(d)] == -1).all() and (faces[np.isfinite(d)] >= 0).all()

    r = run(cli, "sdf", data_dir / "bunny.ply", "-o", tmp_path / "p.npy", "--spacing", 0.5, "--sign", "pseudonormal")
    assert r.returncode == 0, r.stderr
    bad = [(["--res", "8", "--spacing", "1"], "excludes"), ([], "--res N or --spacing H"),
           (["--res", "4", "--padding", "2"], "padding"), (["--spacing", "1e-9"], "too many"),
           (["--res", "8", "--sign", "parity"], "sign")]
    for args, words in bad:
        r = run(cli, "sdf", data_dir / "bunny.ply", "-o", tmp_path / "x.npy", *args)
        assert r.returncode == 2 and words in r.stderr and len(r.stderr.strip().splitlines()) == 1, (args, r.stderr)
    r = run(cli, "sdf", tmp_path / "missing.ply", "-o", tmp_path / "x.npy", "--res", 8)
    assert r.returncode == 2 and "missing.ply" in r.stderr


# ---------------------------------------------------------------- chamfer propagation


def dijkstra_chamfer(mask, size, spacing=(1.0, 1.0, 1.0)):
    """Shortest paths of matrix steps from the zeros (3-D mask, numpy order; spacing x first)."""
    import heapq
    import itertools
    import math
    r = size // 2
    steps = [m for m in itertools.product(range(-r, r + 1), repeat=3)
             if math.gcd(math.gcd(abs(m[0]), abs(m[1])), abs(m[2])) == 1]
    sz, sy, sx = spacing[2], spacing[1], spacing[0]
    d = np.full(mask.shape, np.inf)
    heap = [(0.0, idx) for idx in zip(*np.nonzero(mask == 0))]
    for _, idx in heap:
        d[idx] = 0
    heapq.heapify(heap)
    while heap:
        dist, (z, y, x) = heapq.heappop(heap)
        if dist > d[z, y, x]:
            continue
        for dz, dy, dx in steps:
            c = (z + dz, y + dy, x + dx)
            if all(0 <= c[a] < mask.shape[a] for a in range(3)):
                nd = dist + math.sqrt((sz * dz) ** 2 + (sy * dy) ** 2 + (sx * dx) ** 2)
                if nd < d[c]:
                    d[c] = nd
                    heapq.heappush(heap, (nd, c))
    return d


@pytest.mark.parametrize("size", [3, 5])
def test_chamfer_is_the_shortest_path_of_steps_and_within_its_bound(size):
    rng = np.random.default_rng(size)
    mask = rng.random((6, 7, 8)) < 0.93
    mask[0, 0, 0] = False
    np.testing.assert_allclose(geods.chamfer(mask, size=size), dijkstra_chamfer(mask, size), atol=1e-9)
    np.testing.assert_allclose(geods.chamfer(mask, size=size, spacing=(1, 2, 0.5)),
                               dijkstra_chamfer(mask, size, (1, 2, 0.5)), atol=1e-9)
    big = rng.random((30, 40, 50)) < 0.995
    big[0, 0, 0] = False
    exact = geods.edt(big)
    approx = geods.chamfer(big, size=size)
    e = geods.chamfer_max_error(size)
    assert (approx >= exact * (1 - 1e-12)).all() and (approx <= exact * (1 + e) + 1e-12).all()
    assert e < (0.13 if size == 3 else 0.05)


def test_chamfer_2d_and_bad_input():
    stripes = np.ones((8, 9), bool)
    stripes[::4] = False
    assert geods.chamfer(stripes)[:4, 0].tolist() == [0, 1, 2, 1]
    assert np.isinf(geods.chamfer(np.ones((3, 4)))).all()
    with pytest.raises(geods.Error, match="size 3 or 5"):
        geods.chamfer(stripes, size=4)
    with pytest.raises(geods.Error, match="NaN"):
        geods.chamfer(np.array([0.0, np.nan]))
    with pytest.raises(geods.Error, match="spacing"):
        geods.chamfer(stripes, spacing=(1, 0))


def test_sdf_grid_propagation_is_an_upper_bound(bunny, cli, data_dir, tmp_path):
    V, F = bunny
    exact, _, spacing = geods.sdf_grid(V, F, 32, sign="pseudonormal")
    approx, _, _ = geods.sdf_grid(V, F, 32, sign="pseudonormal", method="propagation")
    h = spacing[0]
    assert (np.abs(approx) >= np.abs(exact) - 1e-5).all()
    shell = np.abs(exact) <= 1.7 * h
    np.testing.assert_allclose(approx[shell], exact[shell], atol=1e-5)
    assert ((approx < 0) == (exact < 0))[np.abs(exact) > 1e-5].all()
    assert (np.abs(approx) - np.abs(exact)).max() < 1.5 * h
    with pytest.raises(geods.Error, match="method"):
        geods.sdf_grid(V, F, 8, method="sweep")
    r = run(cli, "sdf", data_dir / "bunny.ply", "-o", tmp_path / "p.npy", "--res", 32, "--sign", "pseudonormal",
            "--method", "propagation", "--json")
    assert r.returncode == 0, r.stderr
    np.testing.assert_array_equal(np.load(tmp_path / "p.npy"), approx)
    assert json.loads(r.stdout)["method"] == "propagation"
