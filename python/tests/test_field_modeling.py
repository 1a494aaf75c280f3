"""geods.project_distance, csg_field / blend / offset / field_surface, fit_rigid and morph
against independent oracles: brute force (scipy's cKDTree where it helps), point membership,
analytic spheres, known motions."""
import os
import subprocess

import numpy as np
import pytest

import geods


def test_project_distance_points_match_brute_force():
    rng = np.random.default_rng(3)
    sites = rng.uniform(-3, 60, (35, 2))
    d, ids = geods.project_distance(sites, (50, 40), origin=(0.5, -0.25), spacing=1.25)
    assert d.shape == (40, 50) and ids.shape == (40, 50)
    ys, xs = np.mgrid[0:40, 0:50]
    px, py = 0.5 + xs * 1.25, -0.25 + ys * 1.25
    all_d = np.hypot(px[..., None] - sites[:, 0], py[..., None] - sites[:, 1])
    brute = all_d.min(axis=-1)
    assert np.allclose(d, brute, rtol=0, atol=1e-12)
    # The id is a nearest site (ties within rounding documented).
    own = np.take_along_axis(all_d, ids[..., None], axis=-1)[..., 0]
    assert np.allclose(own, brute, rtol=0, atol=1e-12)
    assert (ids == all_d.argmin(axis=-1)).mean() > 0.999


def test_project_distance_segments_polygons_and_3d():
    seg = np.array([[2.0, 2.0, 12.0, 8.0]])
    square = np.array([[14.0, 2.0], [18.0, 2.0], [18.0, 6.0], [14.0, 6.0]])
    d, ids = geods.project_distance(np.zeros((0, 2)), (20, 10), segments=seg, polygons=[square])
    assert d[4, 16] == 0 and ids[4, 16] == 1  # inside the square: its slab
    assert abs(d[0, 0] - np.hypot(2, 2)) < 1e-12 and ids[0, 0] == 0
    # 3D: hyperboloids of the points on every slice.
    pts = np.array([[1.0, 2.0, 3.5], [6.0, 1.0, 0.0]])
    d3, ids3 = geods.project_distance(pts, (8, 5, 6))
    z, y, x = np.mgrid[0:6, 0:5, 0:8]
    brute = np.minimum(np.sqrt((x - 1) ** 2 + (y - 2) ** 2 + (z - 3.5) ** 2), np.sqrt((x - 6) ** 2 + (y - 1) ** 2 + z ** 2))
    assert d3.shape == (6, 5, 8) and np.allclose(d3, brute, atol=1e-12)
    # Bounded cones.
    d, ids = geods.project_distance([[0, 0]], (10, 1), max_distance=3)
    assert list(ids[0]) == [0] * 4 + [-1] * 6 and np.isinf(d[0, 5])
    with pytest.raises(ValueError):
        geods.project_distance([[np.nan, 0]], (4, 4))
    with pytest.raises(ValueError):
        geods.project_distance(None, (4, 4))


def sphere(shape, centre, r, h=1.0):
    z, y, x = np.indices(shape) * h
    return (np.sqrt((x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2) - r).astype(np.float32)


def test_csg_against_membership():
    a, b = sphere((30, 30, 30), (12, 14, 15), 8), sphere((30, 30, 30), (18, 15, 14), 7)
    ina, inb = a < 0, b < 0
    for op, expected in (("union", ina | inb), ("intersection", ina & inb), ("difference", ina & (b > 0))):
        r = geods.csg_field(a, b, op)
        assert r.dtype == np.float32 and ((r < 0) == expected).all()
    np.testing.assert_array_equal(geods.csg_field(a, b, "difference"), np.maximum(a, -b))
    smooth = geods.blend(a, b, 3.0)
    assert (smooth <= np.minimum(a, b)).all() and (smooth >= np.minimum(a, b) - 0.75 - 1e-6).all()
    with pytest.raises(ValueError):
        geods.csg_field(a, b[:-1], "union")
    with pytest.raises(ValueError):
        geods.csg_field(a, b, "xor")


def test_offset_of_a_sphere_is_a_sphere():
    d = sphere((41, 41, 41), (2, 2, 2), 1, h=0.1)  # radius 1 on a grid of spacing 0.1
    for r in (0.5, -0.3):
        V, F = geods.field_surface(geods.offset(d, r), spacing=(0.1, 0.1, 0.1))
        assert len(F) > 100
        dist = np.linalg.norm(V - 2.0, axis=1)
        assert np.abs(dist - (1 + r)).max() < 0.01


def test_fit_rigid_recovers_a_motion():
    rng = np.random.default_rng(5)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))
    t = np.array([1.0, -2.0, 0.5])
    p = rng.normal(size=(10, 3))
    R, c = geods.fit_rigid(p, p @ q.T + t)
    assert np.allclose(R, q, atol=1e-10) and np.allclose(c, t, atol=1e-10)


def box(lo, hi):
    V = np.array([[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]] for i in range(8)],
                 np.float32)
    F = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7],
                  [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return V, F


def test_morph_endpoints_and_warp():
    VA, FA = box((-1, -0.2, -0.2), (1, 0.2, 0.2))
    VB, FB = box((-0.2, -1, -0.2), (0.2, 1, 0.2))
    steps = geods.morph(VA, FA, VB, FB, 3, res=28)
    assert len(steps) == 3
    # The ends are the inputs: their surfaces lie on the boxes.
    for (V, F), (Vi, Fi) in ((steps[0], (VA, FA)), (steps[-1], (VB, FB))):
        d = geods.signed_distance(Vi, Fi, V)[0]
        assert np.abs(d).max() < 0.1
    corr = np.array([[1, 0, 0, 0, 1, 0], [-1, 0, 0, 0, -1, 0], [0, 0, 0.2, 0, 0, 0.2]], float)
    warped = geods.morph(VA, FA, VB, FB, 3, correspondences=corr, res=28)
    V, F = warped[1]
    assert np.abs(V[:, 0]).max() > 0.6 and np.abs(V[:, 1]).max() > 0.6  # a stick along the diagonal
    with pytest.raises(ValueError):
        geods.morph(VA, FA, VB, FB, 1)
    with pytest.raises(ValueError):
        geods.morph(VA, FA, VB, FB, 3, correspondences=np.zeros((2, 5)))


def test_cli_project_and_morph(tmp_path, cli):
    rng = np.random.default_rng(1)
    np.save(tmp_path / "sites.npy", rng.uniform(0, 30, (12, 2)))
    r = subprocess.run([str(cli), "project", "sites.npy", "-o", "d.npy", "--ids", "ids.npy", "--size", "32,24", "--json"],
                       cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    d, ids = np.load(tmp_path / "d.npy"), np.load(tmp_path / "ids.npy")
    assert d.shape == (24, 32) and ids.shape == (24, 32)
    ref, ref_ids = geods.project_distance(np.load(tmp_path / "sites.npy"), (32, 24))
    np.testing.assert_array_equal(d, ref)
    np.testing.assert_array_equal(ids, ref_ids)
    VA, FA = box((-1, -0.2, -0.2), (1, 0.2, 0.2))
    VB, FB = box((-0.2, -1, -0.2), (0.2, 1, 0.2))
    geods.write_mesh(str(tmp_path / "a.ply"), VA, FA)
    geods.write_mesh(str(tmp_path / "b.ply"), VB, FB)
    (tmp_path / "c.csv").write_text("1,0,0,0,1,0\n-1,0,0,0,-1,0\n0,0,0.2,0,0,0.2\n")
    r = subprocess.run([str(cli), "morph", "a.ply", "b.ply", "--steps", "3", "--res", "20", "--correspondences", "c.csv",
                        "-o", "out_%d.ply", "--json"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    import json
    j = json.loads(r.stdout)
    assert j["steps"] == 3 and len(j["vertices"]) == 3 and j["warped"] and "build_s" in j and "compute_s" in j
    assert all((tmp_path / f"out_{k}.ply").exists() for k in range(3))
    r = subprocess.run([str(cli), "morph", "a.ply", "b.ply", "--steps", "3", "-o", "out.ply"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 2 and "%d" in r.stderr
    # Bad input: one line on stderr, exit code 2.
    for args in (["project", "sites.npy", "-o", "d.npy", "--size", "32"],             # W,H needed
                 ["project", "sites.npy", "-o", "d.npy", "--size", "32,24,8"],        # 2-column sites for a volume
                 ["project", "sites.npy", "-o", "d.npy", "--size", "32,24", "--spacing", "0"],
                 ["project", "missing.npy", "-o", "d.npy", "--size", "32,24"],
                 ["morph", "a.ply", "missing.ply", "--steps", "3", "-o", "o_%d.ply"],
                 ["morph", "a.ply", "b.ply", "--steps", "1", "-o", "o_%d.ply"],
                 ["morph", "a.ply", "b.ply", "--steps", "3", "--correspondences", "sites.npy", "-o", "o_%d.ply"]):
        r = subprocess.run([str(cli), *args], cwd=tmp_path, capture_output=True, text=True)
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, (args, r.stderr)


def test_cone_tessellation_error():
    assert abs(geods.cone_tessellation_error(10, 32) - 10 * (1 / np.cos(np.pi / 32) - 1)) < 1e-12
