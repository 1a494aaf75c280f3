"""geods.KdTree against numpy brute force, and the knn / range commands."""
import json
import subprocess

import numpy as np
import pytest

import geods

# geods::Error surfaces as geods.Error.
ERRORS = (geods.Error,)  # a ValueError


def point_sets(d, dtype):
    rng = np.random.default_rng(d)
    n = 700
    centers = rng.random((8, d))
    return {
        "uniform": rng.random((n, d)),
        "clustered": centers[rng.integers(8, size=n)] + 0.01 * rng.standard_normal((n, d)),
        "duplicated": rng.random((15, d))[rng.integers(15, size=n)],
        "line": rng.random(d) + np.outer(rng.uniform(-1, 1, n), rng.standard_normal(d)),
        "identical": np.full((n, d), 0.25),
        "grid": rng.integers(0, 6, size=(n, d)).astype(float),
    }.items()


def brute_knn(points, q, k):
    """Sorted by (distance, index), with the distances computed in the points' dtype as the tree does."""
    diff = points - q.astype(points.dtype)
    d2 = np.einsum("ij,ij->i", diff, diff) if points.dtype == np.float64 else (diff * diff).sum(1, dtype=np.float32)
    order = np.lexsort((np.arange(len(points)), d2))[:k]
    return np.sqrt(d2[order].astype(np.float64)), order


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("d", [2, 3, 7])
def test_queries_match_brute_force(d, dtype):
    rng = np.random.default_rng(100 + d)
    for name, pts in point_sets(d, dtype):
        pts = pts.astype(dtype)
        tree = geods.KdTree(pts, leaf_size=8)
        tree.validate()
        assert len(tree) == len(pts) and tree.dim == d and tree.dtype == np.dtype(dtype)
        queries = np.vstack([rng.uniform(-0.5, 1.5, (20, d)), pts[::97]]).astype(dtype)
        dist, idx = tree.query(queries, k=6)
        assert dist.shape == idx.shape == (len(queries), 6)
        assert dist.dtype == np.float64 and idx.dtype == np.int64
        for i, q in enumerate(queries):
            want_d, want_i = brute_knn(pts, q, 6)
            np.testing.assert_array_equal(idx[i], want_i, err_msg=name)
            np.testing.assert_allclose(dist[i], want_d, rtol=1e-6, err_msg=name)
            # (1 + eps)-approximate neighbours
            ad, ai = tree.query(q, k=6, eps=0.5)
            assert ad.shape == (6,) and len(set(ai.tolist())) == 6
            assert np.all(ad <= 1.5 * want_d * (1 + 1e-6) + 1e-9)
            # radius: everything within r, sorted by distance
            r = want_d[3]
            got = tree.query_radius(q, r)
            d_all = np.sqrt(((pts.astype(np.float64) - q.astype(np.float64)) ** 2).sum(1))
            assert set(got.tolist()) >= set(np.flatnonzero(d_all < r * (1 - 1e-5)).tolist())
            assert set(got.tolist()) <= set(np.flatnonzero(d_all <= r * (1 + 1e-5)).tolist())
            assert np.all(np.diff(d_all[got]) >= -1e-6)
            # boxes: report and count
            lo, hi = q - rng.uniform(0, 0.4, d), q + rng.uniform(0, 0.4, d)
            lo, hi = lo.astype(dtype), hi.astype(dtype)
            want = np.flatnonzero(np.all((pts >= lo) & (pts <= hi), axis=1))
            np.testing.assert_array_equal(tree.query_box(lo, hi), want)
            assert tree.count_box(lo, hi) == len(want)


def test_batches_empty_and_missing():
    rng = np.random.default_rng(3)
    pts = rng.random((50, 3))
    tree = geods.KdTree(pts)
    dist, idx = tree.query(pts[:4], k=60)  # more than n: the rest is -1 / inf
    assert np.all(idx[:, 50:] == -1) and np.all(np.isinf(dist[:, 50:]))
    assert idx[0, 0] == 0 and dist[0, 0] == 0
    lists = tree.query_radius(pts[:5], 0.2)
    assert isinstance(lists, list) and len(lists) == 5
    lo = rng.random((10, 3)) * 0.5
    counts = tree.count_box(lo, lo + 0.5)
    assert counts.dtype == np.int64 and counts.shape == (10,)
    for c, l in zip(counts, lo):
        assert c == tree.count_box(l, l + 0.5)
    empty = geods.KdTree(np.zeros((0, 2)))
    d, i = empty.query([0.5, 0.5], k=2)
    assert np.all(i == -1) and np.all(np.isinf(d))
    assert empty.count_box([0, 0], [1, 1]) == 0 and len(empty.query_box([0, 0], [1, 1])) == 0


def test_zero_copy_views_and_strided_input():
    rng = np.random.default_rng(4)
    base = rng.random((400, 5))
    strided = base[:, :3]  # rows are contiguous, not the whole array
    tree = geods.KdTree(strided)
    np.testing.assert_array_equal(tree.query(strided[7], k=1)[1], [7])
    fortran = np.asfortranarray(base[:, :2])  # copied once
    assert geods.KdTree(fortran).query(fortran[9], k=1)[1][0] == 9
    ints = np.arange(20).reshape(10, 2)  # other dtypes become float64
    assert geods.KdTree(ints).dtype == np.float64


def test_layouts_give_identical_answers(tmp_path):
    rng = np.random.default_rng(6)
    pts = rng.random((2000, 3)).astype(np.float32)
    ordered = geods.KdTree(pts)  # default: a copy in leaf order
    plain = geods.KdTree(pts, layout="zero_copy")
    assert ordered.layout == "tree_order" and plain.layout == "zero_copy"
    # float 3D keeps the packed copy: 16 bytes per inner node, and per leaf (7 or 8
    # of these 2000 points) two groups of 4 points (x4 y4 z4 and 4 indices: 64 bytes).
    s = ordered.stats()
    assert s["bytes"] == plain.stats()["bytes"] + 16 * (s["nodes"] - s["leaves"]) + 2 * 64 * s["leaves"]
    q = rng.random((40, 3))
    for a, b in zip(ordered.query(q, 7), plain.query(q, 7)):
        np.testing.assert_array_equal(a, b)
    d, i = ordered.query(q, 7)
    brute = np.sort(np.linalg.norm(pts[None, :, :].astype(np.float64) - q[:, None, :], axis=2), axis=1)[:, :7]
    np.testing.assert_allclose(d, brute, rtol=1e-5)
    for a, b in zip(ordered.query_radius(q, 0.1), plain.query_radius(q, 0.1)):
        np.testing.assert_array_equal(a, b)
    path = tmp_path / "tree.geods"
    ordered.save(path)
    assert geods.KdTree.load(path).layout == "zero_copy"  # mapped points read in place
    copied = geods.KdTree.load(path, layout="tree_order")
    assert copied.layout == "tree_order"
    np.testing.assert_array_equal(copied.query(q, 7)[1], i)
    with pytest.raises(ERRORS, match="point layout"):
        geods.KdTree(pts, layout="sorted")


def test_stats_save_load(tmp_path):
    rng = np.random.default_rng(5)
    pts = rng.random((3000, 3)).astype(np.float32)
    tree = geods.KdTree(pts, leaf_size=12)
    s = tree.stats()
    assert s["points"] == 3000 and s["nodes"] == 2 * s["leaves"] - 1 and s["depth"] <= 8 and s["bytes"] > 0
    path = tmp_path / "tree.kdt"
    tree.save(path)
    loaded = geods.KdTree.load(str(path))
    assert loaded.dtype == np.float32 and loaded.leaf_size == 12 and loaded.dim == 3
    q = rng.random((50, 3))
    for a, b in zip(tree.query(q, 5), loaded.query(q, 5)):
        np.testing.assert_array_equal(a, b)
    path.write_bytes(path.read_bytes()[:-7])
    with pytest.raises(ERRORS, match="truncated"):
        geods.KdTree.load(path)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("d", [2, 3, 5])
def test_save_load_round_trip(tmp_path, d, dtype):
    """Loaded trees (mapped) answer like the originals, also for duplicates, one point and no points."""
    rng = np.random.default_rng(d)
    sets = [rng.random((700, d)), np.repeat(rng.random((20, d)), 30, axis=0), np.ones((50, d)), rng.random((1, d))]
    for pts in sets:
        tree = geods.KdTree(pts.astype(dtype), leaf_size=4)
        tree.save(tmp_path / "t.geods")
        loaded = geods.KdTree.load(tmp_path / "t.geods")
        assert (loaded.dim, loaded.dtype, len(loaded), loaded.stats()["nodes"]) == (d, dtype, len(tree),
                                                                                    tree.stats()["nodes"])
        loaded.validate()
        q = rng.random((30, d))
        for a, b in zip(tree.query(q, 6), loaded.query(q, 6)):
            np.testing.assert_array_equal(a, b)
        for a, b in zip(tree.query_radius(q, 0.3), loaded.query_radius(q, 0.3)):
            np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(tree.count_box(q * 0.5, q), loaded.count_box(q * 0.5, q))


def test_load_errors(tmp_path):
    tree = geods.KdTree(np.random.default_rng(1).random((100, 2)))
    tree.save(tmp_path / "t.geods")
    good = (tmp_path / "t.geods").read_bytes()
    bad = tmp_path / "bad.geods"
    for data, what in ((good[:100], "truncated"), (good + b"\0", "trailing"), (b"x" * 200, "not a geods archive"),
                       (good[:-1] + bytes([good[-1] ^ 1]), "checksum")):
        bad.write_bytes(data)
        with pytest.raises(ValueError, match=what):
            geods.KdTree.load(bad)
    geods.Quadtree(np.zeros((3, 2))).save(bad)
    with pytest.raises(ValueError, match="kind spatial.Orthtree, expected kind spatial.KdTree"):
        geods.KdTree.load(bad)
    with pytest.raises(ValueError):
        geods.KdTree.load(tmp_path / "missing.geods")


def test_bad_input():
    pts = np.random.default_rng(6).random((20, 2))
    with pytest.raises(ERRORS):
        geods.KdTree(pts.ravel())
    bad = pts.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ERRORS, match="non-finite"):
        geods.KdTree(bad)
    tree = geods.KdTree(pts)
    with pytest.raises(ERRORS):
        tree.query([0.5, 0.5, 0.5], k=1)
    with pytest.raises(ERRORS):
        tree.query([0.5, 0.5], k=0)
    with pytest.raises(ERRORS):
        tree.query_radius([0.5, 0.5], -1.0)
    with pytest.raises(ERRORS):
        geods.KdTree(pts, leaf_size=0)


# ----------------------------------------------------------------------------- CLI
def run(cli, *args, cwd=None):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=300, cwd=cwd)


def test_cli_knn(cli, workdir):
    rng = np.random.default_rng(7)
    pts = rng.random((2000, 3)).astype(np.float32)
    q = rng.random((100, 3))
    np.save(workdir / "p.npy", pts)
    np.save(workdir / "q.npy", q)
    r = run(cli, "knn", "--points", "p.npy", "--queries", "q.npy", "--k", 5, "--indices", "i.npy",
            "--distances", "d.npy", "--json", cwd=workdir)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert (report["points"], report["queries"], report["k"], report["dim"]) == (2000, 100, 5, 3)
    assert report["compute_s"] == pytest.approx(report["build_s"] + report["query_s"])
    idx, dist = np.load(workdir / "i.npy"), np.load(workdir / "d.npy")
    assert idx.dtype == np.int64 and dist.dtype == np.float64 and idx.shape == (100, 5)
    p64 = pts.astype(np.float64)
    for i in range(100):
        d_all = np.sqrt(((p64 - q[i]) ** 2).sum(1))
        np.testing.assert_array_equal(idx[i], np.lexsort((np.arange(2000), d_all))[:5])
        np.testing.assert_allclose(dist[i], np.sort(d_all)[:5])
    # --radius: fewer than k, the rest -1 / inf
    r = run(cli, "knn", "--points", "p.npy", "--queries", "q.npy", "--k", 5, "--radius", 0.05, "--indices", "i.npy",
            "--distances", "d.npy", cwd=workdir)
    assert r.returncode == 0, r.stderr
    idx, dist = np.load(workdir / "i.npy"), np.load(workdir / "d.npy")
    assert np.any(idx == -1) and np.all((idx == -1) == np.isinf(dist)) and np.all(dist[idx >= 0] <= 0.05)
    # --save writes the tree; --tree answers from it, and so does geods.KdTree.load
    r = run(cli, "knn", "--points", "p.npy", "--queries", "q.npy", "--k", 5, "--save", "p.geods", cwd=workdir)
    assert r.returncode == 0, r.stderr
    r = run(cli, "knn", "--tree", "p.geods", "--queries", "q.npy", "--k", 5, "--indices", "i2.npy", "--distances",
            "d2.npy", "--json", cwd=workdir)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert (report["points"], report["dim"], report["tree"], report["build_s"]) == (2000, 3, "p.geods", 0)
    r = run(cli, "knn", "--points", "p.npy", "--queries", "q.npy", "--k", 5, "--indices", "i.npy", "--distances",
            "d.npy", cwd=workdir)
    np.testing.assert_array_equal(np.load(workdir / "i2.npy"), np.load(workdir / "i.npy"))
    np.testing.assert_array_equal(np.load(workdir / "d2.npy"), np.load(workdir / "d.npy"))
    saved = geods.KdTree.load(workdir / "p.geods")
    assert saved.dtype == np.float64 and len(saved) == 2000
    np.testing.assert_array_equal(saved.query(q, 5)[1], np.load(workdir / "i.npy"))
    # --tree and --points together, neither, or a file that is not a tree: exit code 2 and one line
    for args in (["--points", "p.npy", "--tree", "p.geods"], [], ["--tree", "p.npy"]):
        r = run(cli, "knn", *args, "--queries", "q.npy", "--k", 3, cwd=workdir)
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    # bad input: exit code 2 and one line
    np.save(workdir / "q2.npy", rng.random((10, 2)))
    for args in (["--queries", "q2.npy", "--k", 3], ["--queries", "q.npy", "--k", 0],
                 ["--queries", "missing.npy", "--k", 3], ["--queries", "q.npy", "--k", 3, "--radius", -1]):
        r = run(cli, "knn", "--points", "p.npy", *args, "--indices", "i.npy", cwd=workdir)
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr


@pytest.mark.parametrize("d", [2, 3, 5])
def test_cli_tree_of_float32_points(cli, workdir, d):
    # A float32 tree saved from Python answers knn --tree and range --tree as
    # the float64 path does on the same points (queries and boxes exact in float32).
    rng = np.random.default_rng(11 + d)
    pts = rng.random((1500, d)).astype(np.float32)
    q = rng.random((60, d)).astype(np.float32).astype(np.float64)
    lo = rng.uniform(0, 0.7, (20, d)).astype(np.float32)
    boxes = np.hstack([lo, lo + np.float32(0.3)]).astype(np.float64)
    np.save(workdir / "p.npy", pts)
    np.save(workdir / "q.npy", q)
    np.save(workdir / "b.npy", boxes)
    tree = geods.KdTree(pts)
    assert tree.dtype == np.float32
    tree.save(workdir / "p32.geods")
    r = run(cli, "knn", "p.npy", "--queries", "q.npy", "--k", 4, "--indices", "i64.npy", "--distances", "d64.npy",
            cwd=workdir)
    assert r.returncode == 0, r.stderr
    r = run(cli, "knn", "--tree", "p32.geods", "--queries", "q.npy", "--k", 4, "--indices", "i32.npy", "--distances",
            "d32.npy", "--json", cwd=workdir)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert (report["points"], report["dim"], report["build_s"]) == (1500, d, 0)
    np.testing.assert_array_equal(np.load(workdir / "i32.npy"), np.load(workdir / "i64.npy"))
    np.testing.assert_allclose(np.load(workdir / "d32.npy"), np.load(workdir / "d64.npy"), rtol=1e-5)
    want = [np.sum(np.all((pts >= b[:d]) & (pts <= b[d:]), axis=1)) for b in boxes]
    for args in (["p.npy"], ["--tree", "p32.geods"]):
        r = run(cli, "range", *args, "--boxes", "b.npy", "-o", "c.npy", cwd=workdir)
        assert r.returncode == 0, r.stderr
        np.testing.assert_array_equal(np.load(workdir / "c.npy"), want)


def test_cli_range(cli, workdir, data_dir):
    pts = np.load(data_dir / "land_points.npy")
    rng = np.random.default_rng(8)
    lo = rng.uniform([-180, -90], [100, 40], (30, 2))
    boxes = np.hstack([lo, lo + rng.uniform(0, 80, (30, 2))])
    np.save(workdir / "b.npy", boxes)
    r = run(cli, "range", "--points", "data/land_points.npy", "--boxes", "b.npy", "-o", "c.npy", "--json",
            cwd=workdir)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert report["boxes"] == 30 and report["points"] == len(pts)
    counts = np.load(workdir / "c.npy")
    want = [np.sum(np.all((pts >= b[:2]) & (pts <= b[2:]), axis=1)) for b in boxes]
    assert counts.dtype == np.int64
    np.testing.assert_array_equal(counts, want)
    # --save writes the tree, --tree answers from it without the points
    r = run(cli, "range", "--points", "data/land_points.npy", "--boxes", "b.npy", "--save", "land.geods", cwd=workdir)
    assert r.returncode == 0, r.stderr
    r = run(cli, "range", "--tree", "land.geods", "--boxes", "b.npy", "-o", "c2.npy", "--json", cwd=workdir)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["points"] == len(pts)
    np.testing.assert_array_equal(np.load(workdir / "c2.npy"), want)
    np.save(workdir / "bad.npy", boxes[:, :3])
    r = run(cli, "range", "--points", "data/land_points.npy", "--boxes", "bad.npy", "-o", "c.npy", cwd=workdir)
    assert r.returncode == 2 and "columns" in r.stderr
