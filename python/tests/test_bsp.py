"""geods.BspTree, geods.csg and `geods bsp` / `geods csg` against independent oracles."""
import json
import os
import subprocess

import numpy as np
import pytest

import geods
from test_bvh import brute_intersect  # Moller-Trumbore over all triangles, float64


def box(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    V = np.array([[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]] for i in range(8)])
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    F = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], dtype=np.int64)
    return V, F


def torus(R=1.0, r=0.4, n=16, m=8):
    u, v = np.meshgrid(2 * np.pi * np.arange(n) / n, 2 * np.pi * np.arange(m) / m, indexing="ij")
    V = np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], -1).reshape(-1, 3)
    idx = lambda i, j: (i % n) * m + (j % m)  # noqa: E731
    F = []
    for i in range(n):
        for j in range(m):
            F += [(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)), (idx(i, j), idx(i + 1, j + 1), idx(i, j + 1))]
    return V, np.array(F, dtype=np.int64)


def volume(V, F):
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6


def winding(V, F, p):
    """Generalized winding number (solid angles): the oracle of inside/outside."""
    a, b, c = V[F[:, 0]] - p, V[F[:, 1]] - p, V[F[:, 2]] - p
    la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
    num = np.einsum("ij,ij->i", a, np.cross(b, c))
    den = la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la + np.einsum("ij,ij->i", c, a) * lb
    return (2 * np.arctan2(num, den)).sum() / (4 * np.pi)


def closed(F):
    """Every directed edge is used as often as its opposite (closed and consistently oriented;
    xor of overlapping solids has edges where four faces meet)."""
    from collections import Counter

    e = Counter(map(tuple, np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]).tolist()))
    return all(e[(b, a)] == n for (a, b), n in e.items()) and np.all(F[:, 0] != F[:, 1]) and np.all(F[:, 1] != F[:, 2])


@pytest.mark.parametrize("heuristic", ["cost", "random", "balanced"])
def test_classify_matches_winding_number(heuristic):
    V, F = torus()
    t = geods.BspTree(V, F, heuristic=heuristic)
    t.validate()
    s = t.stats()
    assert s["polygons"] == len(F) and s["fragments"] >= len(F) and s["nodes"] == 2 * s["leaves"] - 1
    rng = np.random.default_rng(1)
    P = rng.uniform(-1.6, 1.6, (300, 3))
    w = np.array([winding(V, F, p) for p in P])
    ok = np.abs(w - np.round(w)) < 1e-3
    c = t.classify(P)
    assert c.dtype == np.int8 and c.shape == (300,)
    np.testing.assert_array_equal(c[ok], np.where(np.round(w[ok]) > 0.5, -1, 1))
    assert t.classify([0, 0, 0]) == 1 and t.classify([1, 0, 0]) == -1


def test_visibility_order_lists_every_fragment():
    V, F = box([0, 0, 0], [1, 1, 1])
    V2, F2 = box([3, 0, 0], [4, 1, 1])
    t = geods.BspTree(np.vstack([V, V2]), np.vstack([F, F2 + 8]))
    order = t.visibility_order([10, 0.5, 0.5])
    assert order.dtype == np.int64 and sorted(set(order.tolist())) == list(range(24))
    # Seen from +x, the +x face of the first box (triangles 10, 11) is hidden by the two
    # x faces of the second (20 to 23): it comes before them back to front, after them front to back.
    pos = {t: i for i, t in enumerate(order.tolist())}
    assert max(pos[10], pos[11]) < min(pos[t] for t in (20, 21, 22, 23))
    assert max(pos[20], pos[21]) < min(pos[22], pos[23])
    f2b = t.visibility_order([10, 0.5, 0.5], back_to_front=False).tolist()
    assert f2b == order.tolist()[::-1] or max(f2b.index(t) for t in (22, 23)) < min(f2b.index(10), f2b.index(11))


@pytest.mark.parametrize("method", ["local", "bsp_merge"])
@pytest.mark.parametrize("shift", [(1.0, 1.0, 1.0), (1e-9, 0, 0), (1.0, 0, 0), (0.5, 0.25, 0)])
def test_csg_volume_identities(shift, method):
    VA, FA = box([0, 0, 0], [2, 2, 2])
    VB, FB = box(np.array([0, 0, 0]) + shift, np.array([2, 2, 2]) + shift)
    res = {op: geods.csg(VA, FA, VB, FB, op, stats=True, method=method)
           for op in ["union", "intersection", "difference", "xor"]}
    for op, (V, F, s) in res.items():
        assert V.dtype == np.float64 and F.dtype == np.int64
        assert s["closed"] and (len(F) == 0 or closed(F)), op
        assert abs(volume(V, F) - s["volume"]) < 1e-9
    va, vb = res["union"][2]["volume_a"], res["union"][2]["volume_b"]
    u, i, d, x = (res[op][2]["volume"] for op in ["union", "intersection", "difference", "xor"])
    assert abs(u + i - va - vb) < 1e-9 and abs(d - (va - i)) < 1e-9 and abs(x - (u - i)) < 1e-9


def test_csg_membership():
    VA, FA = torus()
    VB, FB = box([0.5, -0.5, -0.2], [1.6, 0.7, 0.9])
    rng = np.random.default_rng(2)
    P = rng.uniform(-1.6, 1.6, (120, 3))
    wa = np.array([winding(VA, FA, p) for p in P])
    wb = np.array([winding(VB, FB, p) for p in P])
    for op, f in [("union", np.logical_or), ("intersection", np.logical_and), ("difference", lambda a, b: a & ~b),
                  ("xor", np.logical_xor)]:
        V, F = geods.csg(VA, FA, VB, FB, op)
        assert closed(F)
        w = np.array([winding(V, F, p) for p in P])
        ok = (np.abs(wa - np.round(wa)) < 1e-3) & (np.abs(wb - np.round(wb)) < 1e-3) & (np.abs(w - np.round(w)) < 1e-3)
        assert ok.sum() > 100
        np.testing.assert_array_equal(np.round(w[ok]) > 0.5, f(np.round(wa[ok]) > 0.5, np.round(wb[ok]) > 0.5))


def test_bad_input():
    V, F = box([0, 0, 0], [1, 1, 1])
    with pytest.raises(ValueError):
        geods.BspTree(V, F, heuristic="best")
    with pytest.raises(ValueError):
        geods.BspTree(np.full((3, 3), np.nan), np.array([[0, 1, 2]]))
    with pytest.raises(ValueError):
        geods.BspTree(V, np.array([[0, 1, 9]]))
    with pytest.raises(ValueError):
        geods.csg(V, F, V, F, "plus")
    with pytest.raises(ValueError):
        geods.csg(V, F, V, F, "union", method="fast")
    with pytest.raises(ValueError):
        geods.csg(V, F, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), "union")


def run_cli(*args):
    cli = os.environ.get("GEODS_CLI", "geods")
    return subprocess.run([cli, *args], capture_output=True, text=True)


def test_cli(tmp_path, data_dir):
    r = run_cli("bsp", str(data_dir / "bunny.ply"), "--heuristic", "random", "--k", "5", "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    for key in ["nodes", "depth", "fragments", "expected_cost", "build_s"]:
        assert key in j
    assert j["polygons"] == 3674 and j["fragments"] >= 3674
    V, F = box([0, 0, 0], [1, 1, 1])
    a, b = tmp_path / "a.ply", tmp_path / "b.ply"
    geods.write_mesh(str(a), V.astype(np.float32), F)
    geods.write_mesh(str(b), (V + 0.5).astype(np.float32), F)
    out = tmp_path / "u.ply"
    r = run_cli("csg", str(a), "union", str(b), "-o", str(out), "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["closed"] and abs(j["volume"] - (2 - 0.125)) < 1e-6 and j["bsp_nodes"] > 0 and j["triangles"] > 0
    for key in ["vertices", "triangles", "closed", "volume", "bsp_nodes", "compute_s"]:
        assert key in j
    r = run_cli("csg", str(a), "union", str(b), "-o", str(out), "--method", "bsp_merge", "--json")
    assert r.returncode == 0, r.stderr
    j2 = json.loads(r.stdout)
    assert j2["method"] == "bsp_merge" and j2["closed"] and abs(j2["volume"] - j["volume"]) < 1e-9
    r = run_cli("csg", str(a), "plus", str(b), "-o", str(out))
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    r = run_cli("csg", str(a), "union", str(b), "-o", str(out), "--method", "fast")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


def skewed_rays(V, n, seed):
    """Rays from a small patch in front (+z) of a spot of the box, aimed at it through a narrow cone."""
    lo, hi = V.min(0), V.max(0)
    e = (hi - lo).max()
    spot = lo + np.array([0.3, 0.75, 0.5]) * (hi - lo)
    rng = np.random.default_rng(seed)
    o = spot + np.c_[0.05 * e * rng.standard_normal((n, 2)), np.full(n, 2 * e)]
    return o, spot + 0.15 * e * rng.standard_normal((n, 3)) - o


def test_custom_first_hits_match_oblivious_and_brute_force():
    V, F = torus(n=24, m=12)
    sample, rays = skewed_rays(V, 300, 1), skewed_rays(V, 400, 2)
    c = geods.BspTree(V, F, heuristic="custom", rays=sample, k=4)
    o = geods.BspTree(V, F)
    c.validate()
    tc, ic, sc = c.first_hits(*rays, stats=True)
    to, io_ = o.first_hits(*rays)
    assert tc.dtype == np.float64 and ic.dtype == np.int64 and tc.shape == (400,)
    np.testing.assert_array_equal(np.isinf(tc), np.isinf(to))
    np.testing.assert_allclose(tc[np.isfinite(tc)], to[np.isfinite(to)], rtol=1e-9)
    assert ((ic == -1) == np.isinf(tc)).all() and 50 < sc["hits"] < 400
    for key in ["rays", "hits", "nodes_per_ray", "tests_per_ray", "query_s"]:
        assert key in sc
    # The snapped surface is within a grid step of the input: brute force on the input mesh.
    tb = brute_intersect(V, F, rays[0][:100], rays[1][:100])
    same = np.isinf(tb) == np.isinf(tc[:100])
    assert same.sum() >= 98
    both = same & np.isfinite(tb)
    np.testing.assert_allclose(tc[:100][both], tb[both], atol=1e-4)
    with pytest.raises(ValueError):
        geods.BspTree(V, F, heuristic="custom")
    with pytest.raises(ValueError):
        c.first_hits(rays[0], rays[1][:10])


def test_save_load(tmp_path):
    V, F = torus()
    t = geods.BspTree(V, F, heuristic="balanced")
    path = tmp_path / "t.geods"
    t.save(str(path))
    u = geods.BspTree.load(str(path))
    u.validate()
    assert u.stats() == {**t.stats()}
    P = np.random.default_rng(4).uniform(-2, 2, (200, 3))
    np.testing.assert_array_equal(u.classify(P), t.classify(P))
    np.testing.assert_array_equal(u.visibility_order([3, 2, 1]), t.visibility_order([3, 2, 1]))
    np.testing.assert_array_equal(u.first_hits(P, -P)[1], t.first_hits(P, -P)[1])
    data = path.read_bytes()
    cut = tmp_path / "cut.geods"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError):
        geods.BspTree.load(str(cut))
    with pytest.raises(ValueError):
        geods.BspTree.load(str(tmp_path / "missing.geods"))


def test_cli_custom_rays_and_save(tmp_path, data_dir):
    V, F = geods.read_mesh(str(data_dir / "bunny.ply"))
    rays = tmp_path / "rays.npy"
    np.save(rays, np.hstack(skewed_rays(V.astype(np.float64), 500, 3)))
    out = tmp_path / "t.geods"
    r = run_cli("bsp", str(data_dir / "bunny.ply"), "--heuristic", "custom", "--rays", str(rays), "--save", str(out),
                "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["first_hits"]["rays"] == 500 and j["first_hits"]["hits"] > 100
    u = geods.BspTree.load(str(out))
    assert u.stats()["nodes"] == j["nodes"]
    r = run_cli("bsp", str(data_dir / "bunny.ply"), "--heuristic", "custom")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    np.save(rays, np.zeros((4, 5)))
    r = run_cli("bsp", str(data_dir / "bunny.ply"), "--rays", str(rays))
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
