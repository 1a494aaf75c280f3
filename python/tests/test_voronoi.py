"""geods.Voronoi2, geods.MetricVoronoi and the Voronoi applications against brute force (numpy)."""
import numpy as np
import pytest

import geods


def uniform(n, seed):
    return np.random.default_rng(seed).random((n, 2))


def brute_nearest(points, queries):
    d = ((queries[:, None, :] - points[None, :, :]) ** 2).sum(-1)
    return d.min(1), d


def polygon_contains(poly, q):
    x, y = poly[:, 0], poly[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    crosses = (y > q[1]) != (yn > q[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        xs = (xn - x) * (q[1] - y) / (yn - y) + x
    return np.count_nonzero(crosses & (q[0] < xs)) % 2 == 1


def area(poly):
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


def test_voronoi2_cells_vertices_edges():
    p = uniform(200, 1)
    v = geods.Voronoi2(p, box=(0, 0, 1, 1))
    v.validate()
    cells = v.cells
    assert len(cells) == 200
    assert sum(area(c) for c in cells) == pytest.approx(1.0, rel=1e-9)
    rng = np.random.default_rng(2)
    for q in rng.random((200, 2)):
        best, d = brute_nearest(p, q[None, :])
        owners = [i for i, c in enumerate(cells) if polygon_contains(c, q)]
        assert owners and all(d[0, i] == pytest.approx(best[0], rel=1e-9) for i in owners)
    vertices, edges = v.vertices, v.edges
    assert vertices.shape[1] == 2 and edges.shape[1] == 4
    assert len(edges) == v.stats()["edges"]
    # Finite edge ends are equidistant from the edge's two sites.
    for left, right, a, b in edges:
        for end in (a, b):
            if end >= 0:
                x = vertices[end]
                assert np.linalg.norm(x - p[left]) == pytest.approx(np.linalg.norm(x - p[right]), rel=1e-9)
    assert np.all(np.isfinite(v.edge_directions))
    assert v.edge_segments.shape == (len(edges), 4)


def test_voronoi2_nearest_both_ways_and_k_nearest():
    p = uniform(500, 3)
    q = np.random.default_rng(4).uniform(-0.5, 1.5, (1000, 2))
    v = geods.Voronoi2(p)
    best, d = brute_nearest(p, q)
    for method in ("slab", "walk"):
        idx = v.nearest(q, method=method)
        assert idx.shape == (1000,) and idx.dtype == np.int64
        np.testing.assert_array_equal(d[np.arange(1000), idx], best)
    assert v.nearest(p[7]) == 7
    knn = v.k_nearest(q[0], 10)
    np.testing.assert_array_equal(np.sort(d[0])[:10], d[0, knn])
    with pytest.raises(ValueError):
        v.nearest(q, method="grid")


def test_degenerate_inputs():
    grid = np.array([[x, y] for x in range(5) for y in range(5)], dtype=float)
    v = geods.Voronoi2(np.vstack([grid, grid[:3]]))
    v.validate()
    assert len(v.vertices) == 16  # co-circular squares: one vertex each
    assert list(v.representatives[25:]) == [0, 1, 2]
    line = geods.Voronoi2([[0, 0], [1, 1], [3, 3]])
    assert len(line.vertices) == 0 and np.all(line.edges[:, 2:] == -1)
    with pytest.raises(ValueError):
        geods.Voronoi2(np.zeros((0, 2)))
    with pytest.raises(ValueError):
        geods.Voronoi2([[0, 0], [np.nan, 1]])
    with pytest.raises(ValueError):
        geods.Voronoi2(uniform(5, 1), box=(1, 0, 0, 1))


@pytest.mark.parametrize("metric", ["l1", "linf", "l2"])
def test_metric_voronoi_against_brute_force(metric):
    p = uniform(80, 5)
    v = geods.MetricVoronoi(p, metric, box=(0, 0, 1, 1))
    v.validate()
    assert v.metric == metric
    order = {"l1": 1, "linf": np.inf, "l2": 2}[metric]
    rng = np.random.default_rng(6)
    for q in rng.random((150, 2)):
        dist = np.linalg.norm(p - q, ord=order, axis=1)
        owners = [i for i, c in enumerate(v.cells) if len(c) and polygon_contains(c, q)]
        assert owners and all(dist[i] == pytest.approx(dist.min(), rel=1e-6) for i in owners)
    sites, segments = v.edges
    assert sites.shape[1] == 2 and segments.shape[1] == 4 and len(sites) == len(segments)


def test_applications_against_brute_force():
    p = uniform(300, 7)
    d = np.sqrt(((p[:, None] - p[None]) ** 2).sum(-1))
    np.fill_diagonal(d, np.inf)
    i, j, dist = geods.closest_pair(p)
    assert i < j and dist == d.min() and d[i, j] == d.min()
    nn = geods.all_nearest_neighbors(p)
    np.testing.assert_array_equal(d[np.arange(300), nn], d.min(1))
    edges, length = geods.emst(p)
    assert edges.shape == (299, 2)
    # Prim on the complete graph.
    key = np.full(300, np.inf)
    key[0] = 0
    done = np.zeros(300, bool)
    total = 0.0
    for _ in range(300):
        u = np.argmin(np.where(done, np.inf, key))
        done[u] = True
        total += key[u]
        key = np.minimum(key, np.where(done, np.inf, d[u]))
    assert length == pytest.approx(total, rel=1e-12)
    center, radius = geods.smallest_enclosing_circle(p)
    assert np.all(np.linalg.norm(p - center, axis=1) <= radius)
    assert np.sum(np.linalg.norm(p - center, axis=1) >= radius * (1 - 1e-12)) >= 2
    center, radius = geods.largest_empty_circle(p)
    assert np.linalg.norm(p - center, axis=1).min() == pytest.approx(radius, rel=1e-9)
    assert radius > 0.03


def test_application_errors():
    with pytest.raises(ValueError):
        geods.closest_pair([[0.0, 0.0]])
    with pytest.raises(ValueError):
        geods.smallest_enclosing_circle(np.zeros((0, 2)))
    with pytest.raises(ValueError):
        geods.emst(np.zeros((3, 4)))  # (n, 3) is the 3D version


def test_cli_voronoi_and_nearest(cli, workdir):
    import json
    import subprocess

    p = uniform(300, 8)
    q = np.random.default_rng(9).random((500, 2))
    np.save(workdir / "p.npy", p)
    np.save(workdir / "q.npy", q)
    for metric in ("l2", "l1", "linf"):
        out = subprocess.run([cli, "voronoi", "p.npy", "--metric", metric, "--box", "0,0,1,1", "--svg", "v.svg",
                              "-o", "cells.json", "--json"], cwd=workdir, capture_output=True, text=True, check=True)
        report = json.loads(out.stdout)
        assert report["metric"] == metric and report["points"] == 300 and report["compute_s"] >= 0
        cells = json.loads((workdir / "cells.json").read_text())
        assert len(cells["cells"]) == 300
        assert sum(area(np.array(c)) for c in cells["cells"]) == pytest.approx(1.0, rel=1e-6)
        assert (workdir / "v.svg").read_text().startswith("<svg") or "<svg" in (workdir / "v.svg").read_text()
    best, d = brute_nearest(p, q)
    for method in ("slab", "walk", "kdtree"):
        out = subprocess.run([cli, "nearest", "--sites", "p.npy", "--queries", "q.npy", "-o", "idx.npy", "--method",
                              method, "--json"], cwd=workdir, capture_output=True, text=True, check=True)
        assert json.loads(out.stdout)["queries"] == 500
        idx = np.load(workdir / "idx.npy")
        np.testing.assert_array_equal(d[np.arange(500), idx], best)
    bad = subprocess.run([cli, "voronoi", "p.npy", "--box", "1,1,0,0"], cwd=workdir, capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1


def test_voronoi2_save_load(cli, workdir):
    import subprocess

    p = uniform(300, 10)
    v = geods.Voronoi2(p)
    v.save(workdir / "v.geods")
    w = geods.Voronoi2.load(workdir / "v.geods", box=v.box)
    w.validate()
    assert np.array_equal(w.vertices, v.vertices) and np.array_equal(w.edges, v.edges)
    q = np.random.default_rng(11).random((100, 2))
    assert np.array_equal(w.nearest(q), v.nearest(q))
    (workdir / "half.geods").write_bytes((workdir / "v.geods").read_bytes()[:500])
    with pytest.raises(ValueError):
        geods.Voronoi2.load(workdir / "half.geods")
    np.save(workdir / "p2.npy", p)
    subprocess.run([cli, "voronoi", "p2.npy", "--save", "cli.geods"], cwd=workdir, check=True, capture_output=True)
    assert np.array_equal(geods.Voronoi2.load(workdir / "cli.geods").edges, v.edges)
    bad = subprocess.run([cli, "voronoi", "p2.npy", "--metric", "l1", "--save", "x.geods"], cwd=workdir,
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1


def test_cli_nearest_default_method_and_no_sites(cli, workdir):
    import json
    import subprocess

    np.save(workdir / "p.npy", uniform(50, 12))
    np.save(workdir / "none.npy", np.zeros((0, 2)))
    out = subprocess.run([cli, "nearest", "p.npy", "--queries", "p.npy", "-o", "i.npy", "--json"], cwd=workdir,
                         capture_output=True, text=True, check=True)
    assert json.loads(out.stdout)["method"] == "walk"  # O(n) memory; slab can take O(n^1.5)
    np.testing.assert_array_equal(np.load(workdir / "i.npy"), np.arange(50))
    assert geods.Voronoi2(uniform(50, 12)).nearest(uniform(50, 12)[:3]).tolist() == [0, 1, 2]
    for method in ("walk", "slab", "kd_tree"):
        bad = subprocess.run([cli, "nearest", "none.npy", "--queries", "p.npy", "-o", "i.npy", "--method", method],
                             cwd=workdir, capture_output=True, text=True)
        assert bad.returncode == 2 and bad.stderr.count("\n") == 1, bad.stderr
