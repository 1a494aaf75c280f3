"""geods.DynamicKdTree against numpy brute force."""
import numpy as np
import pytest

import geods


def brute_knn(points, ids, q, k):
    d2 = ((points - q) ** 2).sum(axis=1)
    order = np.lexsort((ids, d2))[:k]
    return np.sqrt(d2[order]), ids[order]


@pytest.mark.parametrize("variant", ["amortized", "worst_case"])
@pytest.mark.parametrize("dim", [2, 3])
def test_random_sequence_matches_brute_force(variant, dim):
    rng = np.random.default_rng(dim)
    tree = geods.DynamicKdTree(dim=dim, variant=variant)
    live = {}  # id -> point
    for step in range(300):
        op = rng.integers(10)
        if op < 5 or not live:
            pts = rng.integers(0, 30, (int(rng.integers(1, 40)), dim)).astype(np.float64)
            ids = tree.insert(pts)
            assert ids.dtype == np.int64 and ids.shape == (len(pts),)
            for i, p in zip(ids, pts):
                assert int(i) not in live
                live[int(i)] = p
        elif op < 8:
            keys = np.array(sorted(live), dtype=np.int64)
            gone = rng.choice(keys, size=min(len(keys), int(rng.integers(1, 30))), replace=False)
            tree.remove(gone)
            for i in gone:
                del live[int(i)]
        else:
            ids = np.array(sorted(live), dtype=np.int64)
            points = np.array([live[i] for i in ids])
            q = rng.uniform(0, 30, (5, dim))
            k = int(rng.integers(1, 8))
            dist, idx = tree.query(q, k)
            for j in range(len(q)):
                bd, bi = brute_knn(points, ids, q[j], k)
                np.testing.assert_allclose(dist[j, : len(bd)], bd)
                np.testing.assert_array_equal(idx[j, : len(bi)], bi)
                assert (idx[j, len(bi):] == -1).all()
            lo, hi = q[0], q[0] + 8
            inside = ids[((points >= lo) & (points <= hi)).all(axis=1)]
            np.testing.assert_array_equal(tree.query_box(lo, hi), inside)
            near = tree.query_radius(q[1], 5.0)
            assert set(near.tolist()) == set(ids[((points - q[1]) ** 2).sum(axis=1) <= 25.0].tolist())
        assert len(tree) == len(live)
        tree.validate()
    assert tree.stats()["rebuilds"] >= 1


@pytest.mark.parametrize("variant", ["amortized", "worst_case"])
@pytest.mark.parametrize("dim", [1, 5])
def test_any_dimension_eps_and_max_distance(variant, dim):
    # Duplicates on a coarse grid, deletions, then exact, approximate and limited queries against brute force.
    rng = np.random.default_rng(10 + dim)
    tree = geods.DynamicKdTree(dim=dim, variant=variant)
    assert tree.dim == dim
    pts = rng.integers(0, 6, (600, dim)).astype(np.float64)
    ids = np.concatenate([tree.insert(chunk) for chunk in np.array_split(pts, 40)])
    gone = rng.choice(ids, size=250, replace=False)
    tree.remove(gone)
    tree.validate()
    keep = ~np.isin(ids, gone)
    points, live = pts[keep], ids[keep]
    q = rng.uniform(-1, 7, (20, dim))
    dist, idx = tree.query(q, 9)
    approx, approx_idx = tree.query(q, 9, eps=0.5)
    limited, limited_idx = tree.query(q, 9, max_distance=1.5)
    for j in range(len(q)):
        bd, bi = brute_knn(points, live, q[j], 9)
        np.testing.assert_allclose(dist[j], bd)
        np.testing.assert_array_equal(idx[j], bi)
        assert np.isin(approx_idx[j], live).all()
        np.testing.assert_allclose(approx[j], np.sqrt(((pts[approx_idx[j]] - q[j]) ** 2).sum(axis=1)))
        assert (approx[j] <= 1.5 * bd * (1 + 1e-9) + 1e-12).all()
        within = bd <= 1.5
        np.testing.assert_array_equal(limited_idx[j][within], bi[within])
        assert (limited_idx[j][~within] == -1).all() and np.isinf(limited[j][~within]).all()
    near = tree.query_radius(q[0], 2.0)
    assert set(near.tolist()) == set(live[((points - q[0]) ** 2).sum(axis=1) <= 4.0].tolist())
    with pytest.raises(ValueError, match="eps"):
        tree.query(q[0], 1, eps=-1.0)


def test_single_point_and_reinsert():
    tree = geods.DynamicKdTree(dim=2)
    a = tree.insert([1.0, 2.0])
    assert a.shape == () and int(a) == 0
    tree.remove(a)
    assert a not in tree
    b = tree.insert([1.0, 2.0])
    assert int(b) != int(a)
    dist, idx = tree.query([1.0, 2.0], k=2)
    assert idx.tolist() == [int(b), -1] and dist[0] == 0 and np.isinf(dist[1])
    with pytest.raises(ValueError, match="not stored"):
        tree.remove([int(a)])


def test_memory_returns_after_mass_deletion():
    rng = np.random.default_rng(0)
    tree = geods.DynamicKdTree(dim=3, variant="worst_case")
    ids = np.concatenate([tree.insert(rng.uniform(size=(100, 3))) for _ in range(100)])
    full = tree.stats()["bytes"]
    work_before = tree.stats()["work"]
    tree.remove(ids[:9500])
    s = tree.stats()
    assert s["live"] == 500 and s["rebuilds"] >= 1
    # The reconstructions were paid for (work counts element visits) and are finished or under way.
    assert s["work"] > work_before and isinstance(s["reconstructing"], bool)
    assert 0 < s["locator_bytes"] <= s["bytes"]
    assert s["bytes"] < full / 5
    tree.validate()


def test_bad_input():
    tree = geods.DynamicKdTree(dim=3)
    with pytest.raises(ValueError, match="variant"):
        geods.DynamicKdTree(variant="fast")
    with pytest.raises(ValueError, match="dim"):
        geods.DynamicKdTree(dim=0)
    with pytest.raises(ValueError, match="shape"):
        tree.insert(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="non-finite"):
        tree.insert([[0, 0, 0], [np.nan, 0, 0]])
    assert len(tree) == 0
    ids = tree.insert(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="not stored"):
        tree.remove([ids[0], 99])
    with pytest.raises(ValueError, match="twice"):
        tree.remove([ids[1], ids[1]])
    assert len(tree) == 3
    with pytest.raises(ValueError, match="k must be"):
        tree.query([0, 0, 0], k=0)


@pytest.mark.parametrize("variant", ["amortized", "worst_case"])
@pytest.mark.parametrize("dim", [2, 4])
def test_save_load_round_trip(tmp_path, variant, dim):
    rng = np.random.default_rng(dim)
    tree = geods.DynamicKdTree(dim=dim, variant=variant)
    ids = np.concatenate([tree.insert(rng.integers(0, 9, (int(rng.integers(1, 30)), dim)).astype(float))
                          for _ in range(60)])
    tree.remove(ids[::3])
    path = str(tmp_path / "dyn.geods")
    tree.save(path)
    loaded = geods.DynamicKdTree.load(path)
    loaded.validate()
    assert loaded.dim == dim and loaded.variant == variant and len(loaded) == len(tree)
    q = rng.uniform(0, 9, (25, dim))
    for a, b in zip(tree.query(q, 6), loaded.query(q, 6)):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(tree.query_radius(q[0], 3.0), loaded.query_radius(q[0], 3.0))
    assert int(loaded.insert(np.zeros(dim))) == int(tree.insert(np.zeros(dim)))
    with open(path, "rb") as f:
        data = f.read()
    bad = tmp_path / "bad.geods"
    bad.write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError):
        geods.DynamicKdTree.load(str(bad))
    bad.write_bytes(b"not an archive")
    with pytest.raises(ValueError):
        geods.DynamicKdTree.load(str(bad))
