"""geods.Delaunay3 against scipy's Qhull (tetrahedron counts, containment), exact integer
empty-sphere checks, numpy brute force (nearest point, hull), and the delaunay3 command."""
import json
import subprocess
from fractions import Fraction

import numpy as np
import pytest
from scipy.spatial import ConvexHull, Delaunay

import geods


def insphere_exact(a, b, c, d, e):
    """Sign of the in-sphere determinant in exact rationals: > 0 when e lies inside the
    sphere of the positively oriented (a, b, c, d)."""
    rows = []
    for p in (a, b, c, d):
        q = [Fraction(float(p[k])) - Fraction(float(e[k])) for k in range(3)]
        rows.append(q + [q[0] * q[0] + q[1] * q[1] + q[2] * q[2]])

    def det(m):
        if len(m) == 1:
            return m[0][0]
        return sum((-1) ** j * m[0][j] * det([r[:j] + r[j + 1:] for r in m[1:]]) for j in range(len(m)))

    orient = det([[Fraction(float(p[k])) - Fraction(float(a[k])) for k in range(3)] for p in (b, c, d)])
    assert orient > 0
    return -det(rows)  # rows a - e ... with the lift last: the sign flips for a positive tetrahedron


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_tetrahedra_match_scipy_on_general_position(seed):
    pts = np.random.default_rng(seed).random((3000, 3))
    dt = geods.Delaunay3(pts)
    dt.validate()
    ref = Delaunay(pts)
    assert dt.tetrahedra.shape == ref.simplices.shape
    # non-degenerate: the Delaunay tetrahedralization is unique, so the sets are equal
    assert set(map(tuple, np.sort(dt.tetrahedra, 1))) == set(map(tuple, np.sort(ref.simplices, 1)))
    # positively oriented, volumes add up to the hull's
    t = pts[dt.tetrahedra]
    vol = np.einsum("ij,ij->i", t[:, 1] - t[:, 0], np.cross(t[:, 2] - t[:, 0], t[:, 3] - t[:, 0])) / 6
    assert (vol > 0).all()
    assert vol.sum() == pytest.approx(ConvexHull(pts).volume, rel=1e-12)
    assert len(dt.hull()) == len(ConvexHull(pts).simplices)


def test_neighbors_share_faces_and_hull_is_open():
    pts = np.random.default_rng(4).random((500, 3))
    dt = geods.Delaunay3(pts)
    tets, nb = dt.tetrahedra, dt.neighbors
    assert nb.shape == tets.shape
    for t in range(len(tets)):
        for f in range(4):
            u = nb[t, f]
            if u < 0:
                continue
            assert set(np.delete(tets[t], f)) <= set(tets[u])
            assert t in nb[u]
    assert (nb < 0).sum() == len(dt.hull())


def test_empty_spheres_exact_on_a_lattice_with_duplicates():
    g = np.stack(np.meshgrid(np.arange(4.0), np.arange(4.0), np.arange(3.0), indexing="ij"), -1).reshape(-1, 3)
    pts = np.concatenate([g, g[:7]])  # 7 duplicates
    rng = np.random.default_rng(8)
    pts = pts[rng.permutation(len(pts))]
    dt = geods.Delaunay3(pts)
    dt.validate()
    assert dt.stats()["duplicates"] == 7
    used = np.unique(dt.tetrahedra)
    assert len(used) == len(g)
    for tet in dt.tetrahedra[::3]:
        a, b, c, d = pts[tet]
        for v in used:
            assert insphere_exact(a, b, c, d, pts[v]) <= 0


def test_queries_insert_remove():
    rng = np.random.default_rng(5)
    pts = rng.random((400, 3))
    dt = geods.Delaunay3(pts)
    ref = Delaunay(pts)
    for q in rng.uniform(-0.1, 1.1, (100, 3)):
        t = dt.locate(q)
        assert (t >= 0) == (ref.find_simplex(q) >= 0)
        if t >= 0:  # q's barycentric coordinates in the tetrahedron are >= 0
            a, b, c, d = pts[dt.tetrahedra[t]]
            lam = np.linalg.solve(np.stack([b - a, c - a, d - a], 1), q - a)
            assert (lam >= -1e-12).all() and lam.sum() <= 1 + 1e-12
        n = dt.nearest_vertex(q)
        assert np.linalg.norm(pts[n] - q) == np.linalg.norm(pts - q, axis=1).min()
    i = dt.insert([0.5, 0.5, 0.5])
    assert i == 400 and dt.nearest_vertex([0.5, 0.5, 0.5]) == 400
    dt.validate()
    assert len(dt.tetrahedra) == len(Delaunay(np.vstack([pts, [[0.5, 0.5, 0.5]]])).simplices)
    dt.remove(400)
    assert dt.representative(400) == -1
    assert set(map(tuple, np.sort(dt.tetrahedra, 1))) == set(map(tuple, np.sort(ref.simplices, 1)))
    assert set(dt.vertex_neighbors(0)) == {int(v) for s in ref.simplices if 0 in s for v in s} - {0}


def test_lower_dimensional_and_bad_input():
    flat = np.random.default_rng(6).random((50, 3))
    flat[:, 2] = 1.0
    dt = geods.Delaunay3(flat)
    assert dt.dimension == 2 and dt.tetrahedra.shape == (0, 4) and len(dt.hull()) == 0
    assert geods.Delaunay3(np.zeros((0, 3))).dimension == -1
    assert geods.Delaunay3([[1, 2, 3], [1, 2, 3]]).dimension == 0
    bad = np.random.default_rng(7).random((10, 3))
    bad[4, 1] = np.nan
    with pytest.raises(ValueError):
        geods.Delaunay3(bad)
    with pytest.raises(ValueError):
        geods.Delaunay3(np.zeros((5, 2)))
    with pytest.raises(ValueError):
        geods.Delaunay3(flat).remove(50)


def test_cli_delaunay3(cli, tmp_path):
    pts = np.random.default_rng(9).random((800, 3))
    pts[17] = pts[2]
    np.save(tmp_path / "p.npy", pts)
    out = tmp_path / "tets.npy"
    r = subprocess.run([str(cli), "delaunay3", str(tmp_path / "p.npy"), "-o", str(out), "--hull",
                        str(tmp_path / "h.npy"), "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    tets = np.load(out)
    assert tets.dtype == np.int64 and tets.shape == (info["tetrahedra"], 4)
    assert np.array_equal(tets, geods.Delaunay3(pts).tetrahedra)
    assert info["duplicates"] == 1 and info["vertices"] == 799 and "compute_s" in info and "build_s" in info
    assert np.load(tmp_path / "h.npy").shape == (info["hull_triangles"], 3)
    r = subprocess.run([str(cli), "delaunay3", str(tmp_path / "p.npy"), "--save", str(tmp_path / "dt.geods")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    loaded = geods.Delaunay3.load(tmp_path / "dt.geods")
    loaded.validate()
    assert np.array_equal(loaded.tetrahedra, tets)
    (tmp_path / "bad.geods").write_bytes((tmp_path / "dt.geods").read_bytes()[:100])
    with pytest.raises(ValueError):
        geods.Delaunay3.load(tmp_path / "bad.geods")
    np.save(tmp_path / "bad.npy", np.array([[0.0, np.inf, 0], [1, 1, 1], [2, 0, 0], [0, 0, 1]]))
    r = subprocess.run([str(cli), "delaunay3", str(tmp_path / "bad.npy"), "-o", str(out)], capture_output=True,
                       text=True)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


def test_voronoi3_cells_partition_the_box(tmp_path):
    rng = np.random.default_rng(10)
    pts = rng.random((200, 3))
    box = [0, 0, 0, 1, 1, 1]
    vd = geods.voronoi3(pts, box)
    vd.validate()
    assert vd.stats()["sites"] == 200 and vd.volume_total() == pytest.approx(1.0, rel=1e-9)
    assert np.array_equal(vd.box, box)
    v, f = vd.mesh()
    assert f.shape[0] == sum(len(loop) - 2 for c in vd.cells for loop in c["faces"])
    saved = tmp_path / "cells.geods"
    vd.save(saved)
    loaded = geods.Voronoi3.load(saved)
    loaded.validate()
    assert [c["volume"] for c in loaded.cells] == [c["volume"] for c in vd.cells]
    cells = vd.cells
    assert len(cells) == 200 and sorted(c["site"] for c in cells) == list(range(200))
    assert sum(c["volume"] for c in cells) == pytest.approx(1.0, rel=1e-9)
    by_site = {c["site"]: c for c in cells}
    # each sampled point is inside the cell of its nearest site (scipy-free brute force)
    for q in rng.random((200, 3)):
        cell = by_site[int(np.argmin(np.linalg.norm(pts - q, axis=1)))]
        v = cell["vertices"]
        for loop in cell["faces"]:
            n = sum(np.cross(v[loop[k]], v[loop[(k + 1) % len(loop)]]) for k in range(len(loop)))
            assert np.dot(n / np.linalg.norm(n), q - v[loop[0]]) <= 1e-9
    # the faces across sites are the Delaunay edges; box sides are -2..-7
    dt = geods.Delaunay3(pts)
    for c in cells[:20]:
        across = {int(x) for x in c["neighbors"] if x >= 0}
        assert across <= set(dt.vertex_neighbors(c["site"]).tolist())
        assert all(-7 <= x <= -2 for x in c["neighbors"] if x < 0)
    with pytest.raises(ValueError):
        geods.voronoi3(pts, [0, 0, 0, 1, 1])


def test_cli_voronoi3(cli, tmp_path):
    pts = np.random.default_rng(11).random((150, 3))
    np.save(tmp_path / "p.npy", pts)
    r = subprocess.run([str(cli), "voronoi3", str(tmp_path / "p.npy"), "--box", "0,0,0,1,1,1", "-o",
                        str(tmp_path / "cells.ply"), "--volumes", str(tmp_path / "v.npy"), "--save",
                        str(tmp_path / "cells.geods"), "--json"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert info["cells"] == 150 and info["volume_total"] == pytest.approx(1.0, rel=1e-9)
    v = np.load(tmp_path / "v.npy")
    assert v.shape == (150, 5) and v[:, 1].sum() == pytest.approx(1.0, rel=1e-9)
    assert (tmp_path / "cells.ply").stat().st_size > 0
    saved = geods.Voronoi3.load(tmp_path / "cells.geods")
    saved.validate()
    assert np.allclose(sorted(c["volume"] for c in saved.cells), np.sort(v[:, 1]), rtol=0, atol=0)
    r = subprocess.run([str(cli), "voronoi3", str(tmp_path / "p.npy"), "--box", "0,0,0,1,1"], capture_output=True,
                       text=True)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


def test_proximity_in_3d_against_brute_force():
    pts = np.random.default_rng(12).random((250, 3))
    pts[40] = pts[3]
    d = np.linalg.norm(pts[:, None] - pts[None], axis=2)
    np.fill_diagonal(d, np.inf)
    i, j, dist = geods.closest_pair(pts)
    assert dist == d.min() and d[i, j] == d.min() and i < j
    nn = geods.all_nearest_neighbors(pts)
    assert np.array_equal(d[np.arange(len(pts)), nn], d.min(1))
    edges, length = geods.emst(pts)
    from scipy.sparse.csgraph import minimum_spanning_tree
    distinct = np.delete(pts, 40, axis=0)  # the duplicate joins by a zero-length edge, which scipy cannot hold
    dd = np.linalg.norm(distinct[:, None] - distinct[None], axis=2)
    assert edges.shape == (249, 2) and length == pytest.approx(minimum_spanning_tree(dd).sum(), rel=1e-12)


def test_voronoi3_cells_clipped_to_the_hull_and_the_largest_empty_sphere():
    rng = np.random.default_rng(13)
    pts = rng.normal(size=(150, 3))
    vd = geods.Voronoi3(pts)  # box=None: the convex hull
    vd.validate()
    cells = vd.cells
    hull = ConvexHull(pts)
    assert sum(c["volume"] for c in cells) == pytest.approx(hull.volume, rel=1e-9)
    inside = Delaunay(pts)
    for c in cells:
        assert np.all(inside.find_simplex(c["vertices"], tol=1e-9) >= 0)
    labels = np.concatenate([c["neighbors"] for c in cells])
    assert labels.min() <= -1000 and not np.any((labels < 0) & (labels > -1000))  # hull labels, no box sides
    centre, radius = geods.largest_empty_sphere(pts)
    assert np.linalg.norm(pts - centre, axis=1).min() == pytest.approx(radius, rel=1e-12)
    assert inside.find_simplex(centre, tol=1e-9) >= 0
    # no sample of the hull is farther from every point than the radius
    samples = rng.uniform(pts.min(0), pts.max(0), size=(20000, 3))
    samples = samples[inside.find_simplex(samples) >= 0]
    nearest = np.min(np.linalg.norm(samples[:, None] - pts[None], axis=2), axis=1)
    assert nearest.max() <= radius * (1 + 1e-12) and nearest.max() > 0.5 * radius
    flat_centre, flat_radius = geods.largest_empty_sphere([[0, 0, 1], [2, 0, 1], [2, 2, 1], [0, 2, 1]])
    assert flat_radius == pytest.approx(np.sqrt(2)) and np.allclose(flat_centre, [1, 1, 1])
    with pytest.raises(ValueError):
        geods.voronoi3([[0, 0, 0], [1, 0, 0], [0, 1, 0]])  # flat: no hull to clip to


def test_cli_voronoi3_hull(cli, tmp_path):
    pts = np.random.default_rng(14).random((120, 3))
    np.save(tmp_path / "p.npy", pts)
    r = subprocess.run([str(cli), "voronoi3", str(tmp_path / "p.npy"), "--hull", "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["volume_total"] == pytest.approx(ConvexHull(pts).volume, rel=1e-9)
    r = subprocess.run([str(cli), "voronoi3", str(tmp_path / "p.npy"), "--hull", "--box", "0,0,0,1,1,1"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


def test_flip_insertion_gives_the_cavity_tetrahedralization(cli, tmp_path):
    """insertion="flips" (1-4, 2-3, 3-2 flips) and the Bowyer-Watson cavity give the same arrays,
    on random points (also against scipy's Qhull), points on a sphere, and a lattice with duplicates."""
    rng = np.random.default_rng(11)
    random = rng.random((1500, 3))
    sphere = rng.normal(size=(600, 3))
    sphere = np.round(sphere / np.linalg.norm(sphere, axis=1)[:, None] * 8) / 2  # cospherical-ish, many duplicates
    g = np.stack(np.meshgrid(*[np.arange(4.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
    lattice = np.vstack([g, g[:9]])[rng.permutation(len(g) + 9)]
    for pts in (random, sphere, lattice):
        flips = geods.Delaunay3(pts, insertion="flips")
        cavity = geods.Delaunay3(pts)
        flips.validate()
        assert np.array_equal(flips.tetrahedra, cavity.tetrahedra)
        assert np.array_equal(flips.neighbors, cavity.neighbors)
        s = flips.stats()
        assert s["flips_14"] + s["splits"] + s["hull_inserts"] == s["vertices"] - 4
        assert s["duplicates"] == cavity.stats()["duplicates"] and s["flip_repairs"] == 0
    assert set(map(tuple, np.sort(geods.Delaunay3(random, insertion="flips").tetrahedra, 1))) == set(
        map(tuple, np.sort(Delaunay(random).simplices, 1)))
    dt = geods.Delaunay3(random[:1000], insertion="flips")
    for p in random[1000:1100]:
        dt.insert(p)
    dt.validate()
    assert set(map(tuple, np.sort(dt.tetrahedra, 1))) == set(map(tuple, np.sort(Delaunay(random[:1100]).simplices, 1)))
    with pytest.raises(ValueError):
        geods.Delaunay3(random, insertion="lawson")
    np.save(tmp_path / "p.npy", random)
    r = subprocess.run([str(cli), "delaunay3", str(tmp_path / "p.npy"), "--insertion", "flips", "-o",
                        str(tmp_path / "t.npy"), "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert info["insertion"] == "flips" and info["flips_23"] > 0 and info["flips_32"] > 0
    assert np.array_equal(np.load(tmp_path / "t.npy"), geods.Delaunay3(random).tetrahedra)
    r = subprocess.run([str(cli), "delaunay3", str(tmp_path / "p.npy"), "--insertion", "lawson"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
