"""geods.Quadtree / geods.Octree against numpy brute force."""
import numpy as np
import pytest

import geods


def point_sets(d):
    rng = np.random.default_rng(10 + d)
    n = 400
    centers = rng.random((5, d))
    spread = 10.0 ** -np.arange(1, 6)
    labels = rng.integers(5, size=n)
    return {
        "uniform": rng.random((n, d)),
        "clustered": centers[labels] + spread[labels, None] * rng.standard_normal((n, d)),
        "duplicated": rng.random((12, d))[rng.integers(12, size=n)],
        "line": rng.random(d) + np.outer(rng.uniform(-1, 1, n), rng.standard_normal(d)),
        "identical": np.full((n, d), 0.25),
    }.items()


def tree_class(d):
    return geods.Quadtree if d == 2 else geods.Octree


def brute_knn(points, q, k):
    diff = points - q.astype(points.dtype)
    d2 = np.einsum("ij,ij->i", diff, diff) if points.dtype == np.float64 else (diff * diff).sum(1, dtype=np.float32)
    order = np.lexsort((np.arange(len(points)), d2))[:k]
    return np.sqrt(d2[order].astype(np.float64)), order


def cells(tree):
    """Integer cell boxes of every node at the deepest depth: (lo, hi) arrays, depths."""
    depth = np.array([tree.depth(v) for v in range(tree.num_nodes)])
    root_lo, root_hi = tree.node_bounds(0)
    side = (root_hi - root_lo).max()
    deepest = depth.max()
    lo = np.empty((tree.num_nodes, len(root_lo)), dtype=np.int64)
    hi = np.empty_like(lo)
    for v in range(tree.num_nodes):
        a, b = tree.node_bounds(v)
        unit = side / 2.0 ** deepest
        lo[v] = np.rint((a - root_lo) / unit)
        hi[v] = np.rint((b - root_lo) / unit)
    return lo, hi, depth


def neighbor_oracle(lo, hi, depth, v, axis, positive):
    d = lo.shape[1]
    ok = depth <= depth[v]
    ok &= (lo[:, axis] == hi[v, axis]) if positive else (hi[:, axis] == lo[v, axis])
    for a in range(d):
        if a != axis:
            ok &= (lo[:, a] <= lo[v, a]) & (hi[v, a] <= hi[:, a])
    found = np.flatnonzero(ok)
    return -1 if len(found) == 0 else int(found[np.argmax(depth[found])])


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("d", [2, 3])
def test_queries_match_brute_force(d, dtype):
    rng = np.random.default_rng(d)
    for name, pts in point_sets(d):
        pts = pts.astype(dtype)
        for bucket in (1, 4):
            tree = tree_class(d)(pts, bucket=bucket)
            tree.validate()
            assert len(tree) == len(pts) and tree.dtype == dtype, name
            for q in np.vstack([pts[:10], rng.uniform(-0.5, 1.5, (10, d))]):
                dist, idx = tree.query(q, k=7)
                bd, bi = brute_knn(pts, q, 7)
                np.testing.assert_array_equal(idx, bi, err_msg=name)
                np.testing.assert_allclose(dist, bd, rtol=1e-6, err_msg=name)
                r = 0.2
                got = tree.query_radius(q, r)
                diff = (pts - q.astype(dtype)).astype(np.float64)
                assert set(got) == set(np.flatnonzero((diff * diff).sum(1) <= r * r + 1e-6)) or name, name
                lo, hi = np.minimum(q, q[::-1] * 0.5), np.maximum(q, q[::-1] * 0.5)
                inside = np.flatnonzero(np.all((pts >= lo.astype(dtype)) & (pts <= hi.astype(dtype)), axis=1))
                np.testing.assert_array_equal(tree.query_box(lo, hi), inside, err_msg=name)
                assert tree.count_box(lo, hi) == len(inside)
                leaf = tree.locate(q)
                a, b = tree.node_bounds(0)
                if np.all((q >= a) & (q <= b)):
                    assert tree.is_leaf(leaf)
                    la, lb = tree.node_bounds(leaf)
                    assert np.all((q >= la) & (q <= lb))
                else:
                    assert leaf == -1
            # every point is in the leaf that locate() finds
            for i in range(0, len(pts), 37):
                assert i in tree.node_points(tree.locate(pts[i]))
            # batches and padding
            dist, idx = tree.query(pts[:5], k=len(pts) + 2)
            assert dist.shape == (5, len(pts) + 2) and np.all(idx[:, -2:] == -1) and np.all(np.isinf(dist[:, -1]))


@pytest.mark.parametrize("d", [2, 3])
def test_neighbors_and_balancing(d):
    for name, pts in point_sets(d):
        pts = pts[:100]
        tree = tree_class(d)(pts)
        if tree.num_nodes == 1:  # identical points: one leaf without neighbors
            assert all(tree.neighbor(0, k) == -1 for k in range(2 * d)) and tree.balanced().num_nodes == 1
            continue
        for t in (tree, tree.balanced()):
            t.validate()
            lo, hi, depth = cells(t)
            names = ["+x", "-x", "+y", "-y", "+z", "-z"]
            for v in range(t.num_nodes):
                for direction in range(2 * d):
                    expected = neighbor_oracle(lo, hi, depth, v, direction // 2, direction % 2 == 0)
                    assert t.neighbor(v, direction) == expected, (name, v, direction)
                    assert t.neighbor(v, names[direction]) == expected
            # the children of every inner node tile it, one level deeper
            for v in range(t.num_nodes):
                assert t.is_leaf(v) == (t.children(v) == [])
                for c in t.children(v):
                    assert t.parent(c) == v and t.depth(c) == t.depth(v) + 1
        balanced = tree.balanced()
        assert balanced.is_balanced and not tree.is_balanced
        assert balanced.stats()["depth"] == tree.stats()["depth"]
        assert balanced.num_nodes >= tree.num_nodes
        # 2:1: face-adjacent leaves differ by at most one level
        lo, hi, depth = cells(balanced)
        leaves = balanced.leaves()
        for i in leaves:
            touch = ((lo[leaves] == hi[i]) | (hi[leaves] == lo[i])).sum(1)
            overlap = ((lo[leaves] < hi[i]) & (lo[i] < hi[leaves])).sum(1)
            adjacent = leaves[(touch == 1) & (overlap == d - 1)]
            assert np.all(np.abs(depth[adjacent] - depth[i]) <= 1), name


def test_compass_directions_and_morton_build():
    pts = np.array([[0, 0], [4, 4], [2, 2], [3, 1]], dtype=float)
    tree = geods.Quadtree(pts)
    sw, se, nw, ne = tree.children(0)
    assert tree.neighbor(sw, "N") == nw and tree.neighbor(sw, "E") == se
    assert tree.neighbor(ne, "S") == se and tree.neighbor(ne, "W") == nw
    assert tree.neighbor(sw, "S") == -1 and tree.neighbor(0, 2) == -1
    rng = np.random.default_rng(3)
    pts = rng.random((2000, 3)) ** 3
    a, b = geods.Octree(pts, bucket=3), geods.Octree(pts, bucket=3, build="morton")
    assert a.stats() == b.stats()
    for leaf in a.leaves()[::50]:
        np.testing.assert_array_equal(a.node_points(leaf), b.node_points(leaf))
    assert geods.Octree(pts, max_depth=2).stats()["depth"] == 2


def test_bad_input():
    with pytest.raises(geods.Error, match="non-finite"):
        geods.Quadtree(np.array([[0.0, 0.0], [np.nan, 1.0]]))
    with pytest.raises(geods.Error, match="bucket"):
        geods.Quadtree(np.zeros((3, 2)), bucket=0)
    with pytest.raises(geods.Error):
        geods.Quadtree(np.zeros((3, 3)))
    with pytest.raises(geods.Error):
        geods.Octree(np.zeros((3, 3)), max_depth=22)
    tree = geods.Quadtree(np.random.default_rng(0).random((10, 2)))
    with pytest.raises(geods.Error):
        tree.neighbor(0, "+z")
    with pytest.raises(geods.Error):
        tree.neighbor(0, "up")
    with pytest.raises(geods.Error):
        tree.neighbor(tree.num_nodes, "N")
    with pytest.raises(geods.Error):
        tree.query([0.0, 0.0], k=0)


def test_save_load(tmp_path):
    pts = np.random.default_rng(5).random((500, 2)).astype(np.float32)
    tree = geods.Quadtree(pts, bucket=2).balanced()
    tree.save(tmp_path / "t.ort")
    loaded = geods.Quadtree.load(tmp_path / "t.ort")
    assert loaded.stats() == tree.stats() and loaded.is_balanced and loaded.dtype == np.float32
    np.testing.assert_array_equal(loaded.query(pts[:3], 4)[1], tree.query(pts[:3], 4)[1])
    with pytest.raises(geods.Error):
        geods.Octree.load(tmp_path / "t.ort")


@pytest.mark.parametrize("d", [2, 3])
def test_save_load_round_trip(tmp_path, d):
    """Loaded trees answer like the originals (duplicates, one point, no points); bad files raise."""
    rng = np.random.default_rng(d)
    cls = tree_class(d)
    for pts in (rng.random((300, d)), np.repeat(rng.random((5, d)), 20, axis=0), rng.random((1, d)),
                np.zeros((0, d))):
        for dtype in (np.float32, np.float64):
            tree = cls(pts.astype(dtype), bucket=3)
            tree.save(tmp_path / "t.geods")
            loaded = cls.load(tmp_path / "t.geods")
            assert loaded.stats() == tree.stats() and loaded.dtype == dtype
            loaded.validate()
            if len(pts):
                q = rng.random((10, d))
                for a, b in zip(tree.query(q, 4), loaded.query(q, 4)):
                    np.testing.assert_array_equal(a, b)
    data = (tmp_path / "t.geods").read_bytes()
    (tmp_path / "bad.geods").write_bytes(data[:-3])
    with pytest.raises(ValueError, match="truncated"):
        cls.load(tmp_path / "bad.geods")
    geods.KdTree(np.zeros((2, d))).save(tmp_path / "bad.geods")
    with pytest.raises(ValueError, match="of kind spatial.KdTree"):
        cls.load(tmp_path / "bad.geods")
