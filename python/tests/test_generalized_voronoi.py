"""Generalized Voronoi diagrams (seed §5.3.3): power, farthest-point and k-th order,
against brute-force assignment of sample points; the CLI flags."""
import json
import subprocess

import numpy as np
import pytest

import geods


def polygon_area(poly):
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def inside(poly, q):
    """Points q (m, 2) strictly inside the convex counter-clockwise polygon."""
    a, b = poly, np.roll(poly, -1, axis=0)
    cross = (b[:, 0] - a[:, 0])[None, :] * (q[:, 1:2] - a[:, 1][None, :]) - (b[:, 1] - a[:, 1])[None, :] * (q[:, 0:1] - a[:, 0][None, :])
    return np.all(cross > 1e-12, axis=1)


def samples(box, n, seed):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(box[0], box[2], n), rng.uniform(box[1], box[3], n)])


def box_area(box):
    return (box[2] - box[0]) * (box[3] - box[1])


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_power_diagram_cells_hold_the_least_power(seed):
    rng = np.random.default_rng(seed)
    p = rng.random((120, 2))
    w = rng.random(120) * 0.02
    d = geods.power_diagram(p, w)
    d.validate()
    cells = d.cells
    assert sum(polygon_area(c) for c in cells if len(c)) == pytest.approx(box_area(d.box), rel=1e-9)
    q = samples(d.box, 400, seed)
    power = ((q[:, None, :] - p[None, :, :]) ** 2).sum(-1) - w[None, :]
    best = power.argmin(1)
    for i, c in enumerate(cells):
        if len(c):
            hit = inside(c, q)
            assert np.allclose(power[hit, i], power[hit, best[hit]], atol=1e-12)
    assert all(len(cells[r]) == 0 for r in d.redundant)
    assert d.triangles.shape[1] == 3


def test_power_diagram_with_equal_weights_is_the_voronoi_diagram_and_reports_redundant_points():
    rng = np.random.default_rng(4)
    p = rng.random((80, 2))
    d = geods.power_diagram(p, np.full(80, 0.3))
    v = geods.MetricVoronoi(p, "l2", box=d.box)
    for a, b in zip(d.cells, v.cells):
        assert polygon_area(a) == pytest.approx(polygon_area(b), abs=1e-9)
    heavy = geods.power_diagram(p, rng.random(80) * 0.3)
    assert heavy.stats()["redundant"] == len(heavy.redundant) > 0


def test_farthest_voronoi_cells_hold_the_farthest_site():
    rng = np.random.default_rng(5)
    p = rng.random((150, 2))
    d = geods.farthest_voronoi(p)
    d.validate()
    q = samples(d.box, 500, 5)
    dist = np.linalg.norm(q[:, None, :] - p[None, :, :], axis=-1)
    far = dist.max(1)
    total = 0.0
    for i, c in enumerate(d.cells):
        if len(c):
            assert i in set(d.corners.tolist())
            hit = inside(c, q)
            assert np.allclose(dist[hit, i], far[hit])
            total += polygon_area(c)
    assert total == pytest.approx(box_area(d.box), rel=1e-9)


@pytest.mark.parametrize("k", [1, 2, 3])
def test_kth_order_regions_hold_the_k_nearest(k):
    rng = np.random.default_rng(10 + k)
    p = rng.random((50, 2))
    d = geods.kth_order_voronoi(p, k)
    d.validate()
    assert d.sites.shape == (len(d.cells), k)
    q = samples(d.box, 400, k)
    order = np.argsort(np.linalg.norm(q[:, None, :] - p[None, :, :], axis=-1), axis=1)
    nearest = np.sort(order[:, :k], axis=1)
    found = np.zeros(len(q), dtype=bool)
    for sites, c in zip(d.sites, d.cells):
        hit = inside(c, q)
        assert (nearest[hit] == sites).all()
        found |= hit
    assert found.mean() > 0.95  # the rest lie on boundaries
    assert sum(polygon_area(c) for c in d.cells) == pytest.approx(box_area(d.box), rel=1e-9)


def test_bad_input_raises():
    p = np.random.default_rng(0).random((5, 2))
    with pytest.raises(geods.Error, match="weights"):
        geods.power_diagram(p, np.zeros(4))
    with pytest.raises(geods.Error, match="non-finite"):
        geods.power_diagram(p, np.array([0, 0, np.nan, 0, 0.0]))
    with pytest.raises(geods.Error, match="k = 6"):
        geods.kth_order_voronoi(p, 6)
    with pytest.raises(geods.Error):
        geods.kth_order_voronoi(p, 0)
    with pytest.raises(geods.Error, match="non-finite"):
        geods.farthest_voronoi(np.array([[0.0, np.nan], [1, 1]]))


def test_cli_flags(cli, tmp_path):
    rng = np.random.default_rng(6)
    np.save(tmp_path / "p.npy", rng.random((40, 2)))
    np.save(tmp_path / "w.npy", rng.random(40) * 0.01)
    out = subprocess.run([cli, "voronoi", str(tmp_path / "p.npy"), "--weights", str(tmp_path / "w.npy"), "--json",
                          "-o", str(tmp_path / "v.json")], capture_output=True, text=True, check=True)
    report = json.loads(out.stdout)
    assert report["diagram"] == "power" and report["vertices"] + report["redundant"] == 40
    assert len(json.loads((tmp_path / "v.json").read_text())["cells"]) == 40
    out = subprocess.run([cli, "voronoi", str(tmp_path / "p.npy"), "--order", "2", "--json"], capture_output=True,
                         text=True, check=True)
    assert json.loads(out.stdout)["k"] == 2
    out = subprocess.run([cli, "voronoi", str(tmp_path / "p.npy"), "--farthest", "--json"], capture_output=True,
                         text=True, check=True)
    assert json.loads(out.stdout)["corners"] >= 3
    bad = subprocess.run([cli, "voronoi", str(tmp_path / "p.npy"), "--farthest", "--order", "2"], capture_output=True, text=True)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1
    bad = subprocess.run([cli, "voronoi", str(tmp_path / "p.npy"), "--order", "41"], capture_output=True, text=True)
    assert bad.returncode == 2 and "k = 41" in bad.stderr


def brute_color_spanning(p, colors):
    m = len(set(colors.tolist()))
    best = np.inf
    n = len(p)

    def spans(c, r):
        return len(set(colors[np.linalg.norm(p - c, axis=1) <= r * (1 + 1e-12) + 1e-15].tolist())) == m

    for i in range(n):
        for j in range(i + 1, n):
            c, r = (p[i] + p[j]) / 2, np.linalg.norm(p[i] - p[j]) / 2
            if r < best and spans(c, r):
                best = r
            for k in range(j + 1, n):
                a, b = p[j] - p[i], p[k] - p[i]
                d = 2 * (a[0] * b[1] - a[1] * b[0])
                if d == 0:
                    continue
                c = p[i] + np.array([b[1] * (a @ a) - a[1] * (b @ b), a[0] * (b @ b) - b[0] * (a @ a)]) / d
                r = np.linalg.norm(c - p[i])
                if r < best and spans(c, r):
                    best = r
    return best


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_smallest_color_spanning_circle_matches_brute_force(seed):
    rng = np.random.default_rng(seed)
    p = rng.random((18, 2))
    colors = rng.integers(0, 2 + seed % 3, 18)
    center, radius, support = geods.smallest_color_spanning_circle(p, colors)
    assert radius == pytest.approx(brute_color_spanning(p, colors), rel=1e-12)
    assert np.allclose(np.linalg.norm(p[support] - center, axis=1), radius)
    with pytest.raises(geods.Error):
        geods.smallest_color_spanning_circle(p, colors[:-1])
    with pytest.raises(geods.Error, match="non-negative"):
        geods.smallest_color_spanning_circle(p, -colors - 1)


def test_cli_circles(cli, tmp_path):
    rng = np.random.default_rng(8)
    np.save(tmp_path / "p.npy", rng.random((30, 2)))
    np.save(tmp_path / "c.npy", rng.integers(0, 3, 30))
    out = subprocess.run([cli, "circles", str(tmp_path / "p.npy"), "--colors", str(tmp_path / "c.npy"), "--json",
                          "--svg", str(tmp_path / "c.svg")], capture_output=True, text=True, check=True)
    report = json.loads(out.stdout)
    center, radius, _ = geods.smallest_color_spanning_circle(np.load(tmp_path / "p.npy"), np.load(tmp_path / "c.npy"))
    assert report["color_spanning"]["radius"] == pytest.approx(radius)
    assert report["enclosing"]["radius"] >= report["color_spanning"]["radius"]
    assert (tmp_path / "c.svg").stat().st_size > 0


def crosses(x, q, a, b):
    def orient(p, r, s):
        return (r[0] - p[0]) * (s[1] - p[1]) - (r[1] - p[1]) * (s[0] - p[0])
    return orient(a, b, x) * orient(a, b, q) < 0 and orient(x, q, a) * orient(x, q, b) < 0


def test_constrained_voronoi_pieces_hold_the_nearest_visible_site(cli, tmp_path):
    # A room (square walls) with a wall inside it, sites inside and outside.
    p = np.array([[0, 0], [4, 0], [4, 4], [0, 4], [2, 1], [2, 3], [1, 2], [3, 2], [2, 5], [5, 2], [-1, 2], [2, -1],
                  [0.5, 0.7], [3.4, 3.1]], dtype=float)
    seg = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [4, 5]])
    d = geods.constrained_voronoi(p, seg)
    d.validate()
    assert len(d.cells) == len(d.sites)
    assert sum(polygon_area(c) for c in d.cells) == pytest.approx(box_area(d.box), rel=1e-9)
    q = samples(d.box, 300, 9)
    best = []
    for x in q:
        visible = [i for i in range(len(p)) if not any(crosses(x, p[i], p[a], p[b]) for a, b in seg)]
        best.append(min(np.linalg.norm(p[visible] - x, axis=1)))
    best = np.array(best)
    found = np.zeros(len(q), dtype=bool)
    for s, c in zip(d.sites, d.cells):
        hit = inside(c, q)
        found |= hit
        assert np.allclose(np.linalg.norm(q[hit] - p[s], axis=1), best[hit], atol=1e-9)
        for x in q[hit][:3]:
            assert d.visible(x, int(s))
    assert found.mean() > 0.97
    with pytest.raises(geods.Error, match="cross"):
        geods.constrained_voronoi(p, np.array([[0, 2], [1, 3]]))
    np.savetxt(tmp_path / "p.csv", p, delimiter=",")
    np.savetxt(tmp_path / "s.csv", seg, delimiter=",", fmt="%d")
    out = subprocess.run([cli, "voronoi", str(tmp_path / "p.csv"), "--constraints", str(tmp_path / "s.csv"), "--json"],
                         capture_output=True, text=True, check=True)
    report = json.loads(out.stdout)
    assert report["diagram"] == "constrained" and report["pieces"] == len(d.cells)
