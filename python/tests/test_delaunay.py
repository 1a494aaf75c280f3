"""geods.Delaunay2 against numpy brute force (empty circles, hull, nearest) and the delaunay command."""
import json
import subprocess

import numpy as np
import pytest

import geods


def incircle_det(a, b, c, d):
    """The in-circle determinant in exact integer arithmetic (inputs are small integers)."""
    rows = []
    for p in (a, b, c):
        dx, dy = int(p[0]) - int(d[0]), int(p[1]) - int(d[1])
        rows.append((dx, dy, dx * dx + dy * dy))
    (a0, a1, a2), (b0, b1, b2), (c0, c1, c2) = rows
    return a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0)


def orient(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def integer_sets():
    rng = np.random.default_rng(3)
    return {
        "random": rng.integers(0, 1000, (300, 2)),
        "grid": np.stack(np.meshgrid(np.arange(15), np.arange(15)), -1).reshape(-1, 2),
        "duplicates": rng.integers(0, 8, (200, 2)),
    }.items()


@pytest.mark.parametrize("name,pts", list(integer_sets()))
def test_empty_circles_exactly(name, pts):
    dt = geods.Delaunay2(pts.astype(float))
    dt.validate()
    tri = dt.triangles
    assert tri.dtype == np.int64 and tri.shape[1] == 3
    distinct = np.unique(pts, axis=0)
    h = len(dt.hull)
    assert len(tri) == 2 * len(distinct) - h - 2  # Euler
    for t in tri:
        a, b, c = pts[t]
        assert orient(a, b, c) > 0
        for d in distinct:
            assert incircle_det(a, b, c, d) <= 0
    # Duplicates map to their first occurrence.
    for i in range(len(pts)):
        first = int(np.flatnonzero((pts == pts[i]).all(axis=1))[0])
        assert dt.representative(i) == first
    assert set(np.unique(tri)) == {dt.representative(i) for i in range(len(pts))}


def test_halfedges_hull_locate_nearest():
    rng = np.random.default_rng(1)
    pts = rng.random((500, 2))
    dt = geods.Delaunay2(pts)
    tri, he = dt.triangles.ravel(), dt.halfedges
    assert he.shape == (len(tri),)
    nxt = lambda e: e - 2 if e % 3 == 2 else e + 1
    for e in range(len(tri)):
        if he[e] >= 0:
            assert he[he[e]] == e and tri[he[e]] == tri[nxt(e)]
    assert (he < 0).sum() == len(dt.hull)
    hull = pts[dt.hull]
    for i in range(len(hull)):
        a, b = hull[i], hull[(i + 1) % len(hull)]
        assert all(orient(a, b, p) >= 0 for p in pts)
    for q in rng.uniform(-0.2, 1.2, (200, 2)):
        t = dt.locate(q)
        inside = all(orient(hull[i], hull[(i + 1) % len(hull)], q) >= 0 for i in range(len(hull)))
        if inside:
            a, b, c = pts[dt.triangles[t]]
            assert orient(a, b, q) >= 0 and orient(b, c, q) >= 0 and orient(c, a, q) >= 0
        else:
            assert t == -1
        d2 = ((pts - q) ** 2).sum(1)
        assert d2[dt.nearest(q)] == d2.min()


def test_insert_remove_keep_delaunay():
    rng = np.random.default_rng(2)
    pts = rng.random((100, 2))
    dt = geods.Delaunay2(pts)
    for p in rng.random((50, 2)):
        i = dt.insert(p)
        assert dt.points[i].tolist() == p.tolist()
    dt.validate()
    for i in rng.permutation(150)[:120]:
        dt.remove(int(i))
    dt.validate()
    assert dt.stats()["vertices"] == 30
    with pytest.raises(ValueError):
        dt.remove(1000)


def test_degenerate_and_bad_input():
    dt = geods.Delaunay2(np.array([[0.0, 0], [2, 2], [1, 1], [1, 1]]))
    assert dt.degenerate and len(dt.triangles) == 0
    assert dt.hull.tolist() == [0, 2, 1]
    assert dt.locate([1, 1]) == -1
    with pytest.raises(ValueError):
        geods.Delaunay2(np.array([[0.0, 0], [np.nan, 1], [1, 0]]))
    with pytest.raises(ValueError):
        geods.Delaunay2(np.zeros((4, 3)))
    with pytest.raises(ValueError):
        geods.Delaunay2(np.array([[0.0, 0], [1, 0], [0, 1]]), segments=np.array([[0, 5]]))


def test_constrained_polygon_with_hole():
    outer = [[0, 0], [10, 0], [10, 10], [0, 10]]
    hole = [[5, 3], [7, 5], [5, 7], [3, 5]]
    rng = np.random.default_rng(4)
    pts = np.vstack([outer, hole, rng.uniform(-1, 11, (150, 2))]).astype(float)
    segs = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4]])
    dt = geods.Delaunay2(pts, segments=segs)
    dt.validate()
    edges = {tuple(sorted(e)) for e in dt.constrained_edges.tolist()}
    assert edges == {tuple(sorted(s)) for s in segs.tolist()}
    a, b, c = (pts[dt.triangles[:, k]] for k in range(3))
    area = 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    assert area[dt.inside].sum() == pytest.approx(100 - 8)
    assert dt.constrained.sum() == 2 * len(segs)  # no constrained edge on the hull here


def test_crossing_segments_by_coordinates():
    pts = np.array([[0.0, 0], [4, 4], [0, 4], [4, 0]])
    dt = geods.Delaunay2(pts, segments=np.array([[0.0, 0, 4, 4], [0, 4, 4, 0]]))
    dt.validate()
    (x,) = dt.intersection_points
    assert dt.points[x].tolist() == [2.0, 2.0]
    assert len(dt.constrained_edges) == 4


def test_cli_delaunay(cli, tmp_path):
    rng = np.random.default_rng(5)
    pts = rng.random((300, 2))
    pts[10] = pts[3]
    np.save(tmp_path / "p.npy", pts)
    out = tmp_path / "tri.npy"
    r = subprocess.run([str(cli), "delaunay", str(tmp_path / "p.npy"), "-o", str(out), "--svg",
                        str(tmp_path / "t.svg"), "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    tri = np.load(out)
    assert tri.dtype == np.int64 and tri.shape == (info["triangles"], 3)
    assert np.array_equal(tri, geods.Delaunay2(pts).triangles)
    assert info["duplicates"] == 1 and info["points"] == 300 and "compute_s" in info
    assert (tmp_path / "t.svg").read_text().startswith("<?xml") or "<svg" in (tmp_path / "t.svg").read_text()
    # Constrained, with index segments.
    np.save(tmp_path / "s.npy", np.array([[0, 1], [2, 3]], dtype=np.int64))
    r = subprocess.run([str(cli), "delaunay", str(tmp_path / "p.npy"), "--segments", str(tmp_path / "s.npy"),
                        "-o", str(out), "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["constrained_edges"] >= 2
    # Bad input: exit code 2, one line.
    np.save(tmp_path / "bad.npy", np.array([[0.0, np.nan], [1, 1], [2, 0]]))
    r = subprocess.run([str(cli), "delaunay", str(tmp_path / "bad.npy"), "-o", str(out)], capture_output=True,
                       text=True)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


def test_save_load_round_trip_and_bad_files(cli, tmp_path):
    rng = np.random.default_rng(6)
    pts = rng.random((400, 2))
    pts[7] = pts[2]
    dt = geods.Delaunay2(pts, segments=np.array([[0, 1], [3, 4]]))
    path = tmp_path / "dt.geods"
    dt.save(path)
    loaded = geods.Delaunay2.load(str(path))
    loaded.validate()
    for name in ("triangles", "halfedges", "hull", "constrained", "inside", "points"):
        assert np.array_equal(getattr(loaded, name), getattr(dt, name)), name
    queries = rng.random((50, 2))
    assert [loaded.locate(q) for q in queries] == [dt.locate(q) for q in queries]
    assert [loaded.nearest(q) for q in queries] == [dt.nearest(q) for q in queries]
    assert all(np.array_equal(loaded.neighbors(v), dt.neighbors(v)) for v in range(0, 400, 9))
    # Degenerate sets (collinear with a duplicate; one point) load too.
    for few in (np.array([[0.0, 0.0], [2, 2], [1, 1], [1, 1]]), np.array([[0.5, 0.5]])):
        small = geods.Delaunay2(few)
        small.save(tmp_path / "few.geods")
        back = geods.Delaunay2.load(tmp_path / "few.geods")
        back.validate()
        assert np.array_equal(back.hull, small.hull) and len(back.triangles) == 0
        assert back.nearest([0.9, 1.2]) == small.nearest([0.9, 1.2])
    # Updates go on as on the original.
    plain = geods.Delaunay2(pts)
    plain.save(path)
    again = geods.Delaunay2.load(path)
    for p in rng.random((20, 2)):
        assert again.insert(p) == plain.insert(p)
    again.remove(5)
    plain.remove(5)
    again.validate()
    assert np.array_equal(again.triangles, plain.triangles)
    # Truncated, corrupt, wrong kind, missing: ValueError.
    data = path.read_bytes()
    (tmp_path / "short.geods").write_bytes(data[: len(data) // 2])
    corrupt = bytearray(data)
    corrupt[data.index(pts[:4].tobytes()) + 20] ^= 0xFF  # inside the points section
    (tmp_path / "corrupt.geods").write_bytes(bytes(corrupt))
    geods.Voronoi2(pts).save(tmp_path / "voronoi.geods")
    for bad in ("short.geods", "corrupt.geods", "voronoi.geods", "missing.geods"):
        with pytest.raises(ValueError):
            geods.Delaunay2.load(tmp_path / bad)
    # The CLI's --save writes the same triangulation.
    np.save(tmp_path / "p.npy", pts)
    r = subprocess.run([str(cli), "delaunay", str(tmp_path / "p.npy"), "--save", str(tmp_path / "cli.geods")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert np.array_equal(geods.Delaunay2.load(tmp_path / "cli.geods").triangles, geods.Delaunay2(pts).triangles)
