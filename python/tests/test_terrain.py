"""geods.Terrain and `geods terrain` against numpy oracles: every sample within the
error bound (linear interpolation on the mesh, located by brute force), the mesh
tiles the domain, the strip is the triangle list, the mapped file gives the same mesh."""
import json
import subprocess

import numpy as np
import pytest

import geods


def grid_xy(V):
    """The mesh's vertices as integer sample coordinates (spacing 1, origin 0)."""
    xy = np.rint(V[:, :2]).astype(np.int64)
    np.testing.assert_array_equal(xy, V[:, :2])
    return xy


def oracle_error(heights, V, F):
    """Largest |height - mesh| over all samples, each located in a triangle by
    exact integer orientation tests; also checks the areas tile the domain."""
    h, w = heights.shape
    xy = grid_xy(V)
    a, b, c = xy[F[:, 0]], xy[F[:, 1]], xy[F[:, 2]]
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert (cross > 0).all()
    assert cross.sum() == 2 * (w - 1) * (h - 1)
    ys, xs = np.mgrid[0:h, 0:w]
    p = np.stack([xs.ravel(), ys.ravel()], 1)
    worst = 0.0
    found = np.zeros(len(p), bool)
    for t in range(len(F)):
        A, B, C = a[t], b[t], c[t]
        lo, hi = np.minimum(np.minimum(A, B), C), np.maximum(np.maximum(A, B), C)
        sel = np.flatnonzero((p[:, 0] >= lo[0]) & (p[:, 0] <= hi[0]) & (p[:, 1] >= lo[1]) & (p[:, 1] <= hi[1]))
        q = p[sel]
        wa = (B[0] - q[:, 0]) * (C[1] - q[:, 1]) - (B[1] - q[:, 1]) * (C[0] - q[:, 0])
        wb = (C[0] - q[:, 0]) * (A[1] - q[:, 1]) - (C[1] - q[:, 1]) * (A[0] - q[:, 0])
        wc = cross[t] - wa - wb
        inside = (wa >= 0) & (wb >= 0) & (wc >= 0)
        q, idx = q[inside], sel[inside]
        z = (wa[inside] * V[F[t, 0], 2] + wb[inside] * V[F[t, 1], 2] + wc[inside] * V[F[t, 2], 2]) / cross[t]
        found[idx] = True
        if len(q):
            worst = max(worst, float(np.abs(z - heights[q[:, 1], q[:, 0]]).max()))
    assert found.all()
    return worst


def expect_closed(V, F, w, h):
    """Every edge is used at most once per direction, and an edge used once lies on the border (no cracks)."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    directed = {tuple(x) for x in e}
    assert len(directed) == len(e)
    xy = grid_xy(V)
    for (u, v) in directed:
        if (v, u) not in directed:
            a, b = xy[u], xy[v]
            assert (a[0] == b[0] and a[0] in (0, w - 1)) or (a[1] == b[1] and a[1] in (0, h - 1))


@pytest.fixture
def dem(data_dir):
    return np.load(data_dir / "jacksboro_dem.npy")[:24, :33].astype(np.float64)


@pytest.mark.parametrize("kind", ["noise", "cliff", "constant", "real"])
@pytest.mark.parametrize("max_error", [0.0, 2.0, 25.0])
def test_refine_within_the_bound(kind, max_error, dem):
    rng = np.random.default_rng(3)
    heights = {
        "noise": rng.normal(0, 5, (21, 30)),
        "cliff": np.where(np.add.outer(np.arange(25) * 0.4, np.arange(33)) > 15, 60.0, 0.0),
        "constant": np.full((9, 6), 7.0),
        "real": dem,
    }[kind].astype(np.float32)
    t = geods.Terrain(heights)
    V, F = t.refine(max_error=max_error)
    assert V.dtype == np.float32 and F.shape[1] == 3
    assert oracle_error(heights, V, F) <= max_error + 1e-4 * (1 + max_error)
    h, w = heights.shape
    expect_closed(V, F, w, h)
    # The strip is the same mesh.
    S = t.strip(max_error=max_error)
    tris = {tuple(sorted(S[k:k + 3])) for k in range(len(S) - 2) if len(set(S[k:k + 3])) == 3}
    assert tris == {tuple(sorted(f)) for f in F}
    # TIN: within the bound too, closed, also in tiles.
    for tiles in (1, 2):
        Vt, Ft = t.tin(max_error, tiles=tiles)
        assert oracle_error(heights, Vt, Ft) <= max_error + 1e-4 * (1 + max_error)
        expect_closed(Vt, Ft, w, h)


def test_view_dependent_refinement_and_stats():
    y, x = np.mgrid[0:33, 0:33]
    heights = (6 * np.sin(x * 0.3) * np.cos(y * 0.25)).astype(np.float32)
    t = geods.Terrain(heights, spacing=(1, 1), z_scale=1)
    cam = {"eye": (16, -3, 7), "target": (16, 20, 0), "up": (0, 0, 1), "fov": 50, "size": (320, 240)}
    sizes = []
    for tau in (8, 2, 0.5):
        V, F = t.refine(camera=cam, pixel_error=tau)
        oracle_error(heights, V, F)  # tiles the domain
        expect_closed(V, F, 33, 33)
        sizes.append(len(F))
    assert sizes == sorted(sizes) and sizes[0] < sizes[-1]
    s = t.stats()
    assert s["grid"] == 33 and s["unused_slots_pct"] <= 33
    with pytest.raises(ValueError):
        t.refine()
    with pytest.raises(ValueError):
        t.refine(camera={"eye": (0, 0, 0)})
    with pytest.raises(ValueError):
        geods.Terrain(np.zeros((1, 5)))
    with pytest.raises(ValueError):
        geods.Terrain(np.full((3, 3), np.nan))


def test_save_load_is_mapped_and_equal(tmp_path, dem):
    t = geods.Terrain(dem, spacing=(30, 30), z_scale=2, layout="matrix")
    t.save(tmp_path / "d.geodsterrain")
    u = geods.Terrain.load(tmp_path / "d.geodsterrain")
    assert u.stats()["mapped"] and not t.stats()["mapped"]
    for e in (1.0, 20.0):
        for a, b in zip(t.refine(max_error=e), u.refine(max_error=e)):
            np.testing.assert_array_equal(a, b)
    V, F = u.refine(max_error=0.0)
    assert np.isclose(V[:, 0].max(), 30 * (dem.shape[1] - 1)) and np.isclose(V[:, 2].max(), 2 * dem.max())
    (tmp_path / "bad.geodsterrain").write_bytes(b"junk")
    with pytest.raises(ValueError):
        geods.Terrain.load(tmp_path / "bad.geodsterrain")


def test_cli(tmp_path, data_dir, cli):
    out = tmp_path / "m.ply"
    r = subprocess.run([cli, "terrain", str(data_dir / "terra_lux_elev.tif"), "-o", str(out), "--max-error", "5",
                        "--strip", str(tmp_path / "s.npy"), "--save", str(tmp_path / "t.geodsterrain"), "--json"],
                       capture_output=True, text=True, check=True)
    j = json.loads(r.stdout)
    for key in ("vertices", "triangles", "strip_length", "max_error", "unused_slots_pct", "build_s", "refine_s",
                "compute_s"):
        assert key in j
    assert j["max_error"] <= 5 + 1e-4 and j["triangles"] > 0
    assert len(np.load(tmp_path / "s.npy")) == j["strip_length"]
    r2 = subprocess.run([cli, "terrain", str(tmp_path / "t.geodsterrain"), "-o", str(out), "--max-error", "5",
                         "--tin", "--tiles", "2", "--json"], capture_output=True, text=True, check=True)
    j2 = json.loads(r2.stdout)
    assert j2["max_error"] <= 5 + 1e-4 and j2["triangles"] < j["triangles"] and j2["strip_length"] == 0
    bad = subprocess.run([cli, "terrain", str(tmp_path / "missing.png"), "-o", str(out), "--max-error", "1"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1
