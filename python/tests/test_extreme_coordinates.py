"""Points scaled far out or far in (issue "No silently wrong answer"): every
binding and command either answers exactly what it answers at unit scale
(scaled by the same power of two, which is exact in floating point) or
refuses with a clear error; none answers wrongly with exit 0."""
import json
import subprocess

import numpy as np
import pytest

import geods

UNIT = np.random.default_rng(31).random((80, 2))
QUERIES = np.random.default_rng(32).random((25, 2))
REFUSED = [1e300, 1e-300, 1e160, 1e-160]


def run(cli, *args, cwd=None):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=120, cwd=cwd)


def brute_nearest(points, queries):
    d = ((queries[:, None, :] - points[None, :, :]) ** 2).sum(-1)
    return d.min(1), d


@pytest.mark.parametrize("exponent", [-250, 300])
def test_bindings_at_power_of_two_scales_equal_unit_scale(exponent):
    s = 2.0 ** exponent
    p, q = UNIT * s, QUERIES * s
    assert geods.closest_pair(p)[:2] == geods.closest_pair(UNIT)[:2]
    np.testing.assert_array_equal(geods.all_nearest_neighbors(p), geods.all_nearest_neighbors(UNIT))
    np.testing.assert_array_equal(geods.emst(p)[0], geods.emst(UNIT)[0])
    dist, idx = geods.KdTree(p).query(q, k=3)
    want_d, want_i = geods.KdTree(UNIT).query(QUERIES, k=3)
    np.testing.assert_array_equal(idx, want_i)
    np.testing.assert_array_equal(dist, want_d * s)
    c, r = geods.smallest_enclosing_circle(p)
    c1, r1 = geods.smallest_enclosing_circle(UNIT)
    assert r == r1 * s and np.array_equal(c, c1 * s)
    # The k-d tree's squared distances reach further in than circumcentres.
    t = 2.0 ** -440
    np.testing.assert_array_equal(geods.KdTree(UNIT * t).query(QUERIES * t, k=3)[1], want_i)


@pytest.mark.parametrize("scale", REFUSED)
def test_bindings_refuse_what_they_cannot_compute(scale):
    p = UNIT * scale
    for f in (geods.closest_pair, geods.all_nearest_neighbors, geods.emst, geods.smallest_enclosing_circle,
              geods.largest_empty_circle, geods.Voronoi2):
        if scale in (1e160, 1e-160) and f in (geods.closest_pair, geods.all_nearest_neighbors, geods.emst):
            continue  # 1e160 is inside the distance range; these build a Voronoi2 first, which refuses 1e160
        with pytest.raises(ValueError, match="scale the input"):
            f(p)
    if scale in (1e300, 1e-300):
        with pytest.raises(ValueError, match="scale the input"):
            geods.KdTree(p)
    with pytest.raises(ValueError):
        geods.KdTree(UNIT).query(np.array([1e300, 0.0]), k=1)
    with pytest.raises(ValueError):
        geods.KdTree(UNIT.astype(np.float32) * np.float32(1e20))


def test_constrained_delaunay_far_out_and_far_in():
    segments = np.array([[2 * k, 2 * k + 40] for k in range(8)])
    ref = geods.Delaunay2(UNIT, segments)
    for s in (2.0 ** 1000, 2.0 ** -1000):
        dt = geods.Delaunay2(UNIT * s, segments)
        dt.validate()
        np.testing.assert_array_equal(np.asarray(dt.triangles), np.asarray(ref.triangles))


@pytest.mark.parametrize("method", ["slab", "walk", "kd_tree"])
def test_cli_nearest_exact_or_refused(cli, tmp_path, method):
    for exponent in (-280, 300):
        s = 2.0 ** exponent
        np.save(tmp_path / "p.npy", UNIT * s)
        np.save(tmp_path / "q.npy", QUERIES * s)
        r = run(cli, "nearest", "p.npy", "--queries", "q.npy", "--method", method, "-o", "i.npy", cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        best, d = brute_nearest(UNIT, QUERIES)
        idx = np.load(tmp_path / "i.npy")
        np.testing.assert_array_equal(d[np.arange(len(QUERIES)), idx], best)
    for scale in (1e300, 1e-300):
        np.save(tmp_path / "p.npy", UNIT * scale)
        np.save(tmp_path / "q.npy", QUERIES * scale)
        r = run(cli, "nearest", "p.npy", "--queries", "q.npy", "--method", method, "-o", "i.npy", cwd=tmp_path)
        assert r.returncode == 2, r.stdout
        assert len(r.stderr.strip().splitlines()) == 1 and "scale the input" in r.stderr
        assert len(r.stderr) < 300  # short numbers, not 300 digits


def test_cli_knn_voronoi_delaunay(cli, tmp_path):
    np.save(tmp_path / "big.npy", UNIT * 1e300)
    np.save(tmp_path / "q.npy", QUERIES * 1e300)
    for args in (["knn", "big.npy", "--queries", "q.npy", "--k", "2", "--indices", "k.npy"],
                 ["voronoi", "big.npy", "-o", "cells.json"]):
        r = run(cli, *args, cwd=tmp_path)
        assert r.returncode == 2 and "scale the input" in r.stderr, (args, r.stdout, r.stderr)
    np.save(tmp_path / "seg.npy", np.array([[2 * k, 2 * k + 40] for k in range(8)]))
    np.save(tmp_path / "far.npy", UNIT * 2.0 ** 997)  # a power of two: the same triangulation
    r = run(cli, "delaunay", "far.npy", "--segments", "seg.npy", "-o", "t.npy", "--json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    ref = geods.Delaunay2(UNIT, np.load(tmp_path / "seg.npy"))
    assert json.loads(r.stdout)["triangles"] == len(np.asarray(ref.triangles))
    np.testing.assert_array_equal(np.load(tmp_path / "t.npy"), np.asarray(ref.triangles))
