"""The conventions of docs/README.md: one name in C++, Python and the CLI (old
spellings kept as deprecated aliases), one table reader, -1/inf for missing
results, stats from one field list, one rule for command inputs."""
import json
import subprocess

import numpy as np
import pytest

import geods


def run(cli, *args, cwd=None):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=300, cwd=cwd)


def tetrahedron():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return V, F


def test_python_classes_have_the_cpp_names_and_keep_the_old_ones():
    assert geods.Bvh is geods.TriangleBvh and geods.TriangleBvh.__name__ == "TriangleBvh"
    assert geods.RayAccelerator is geods.Accelerator and geods.Accelerator.__name__ == "Accelerator"
    V, F = tetrahedron()
    o = np.array([[0.2, 0.2, -1]], dtype=np.float32)
    d = np.array([[0, 0, 1]], dtype=np.float32)
    assert geods.TriangleBvh(V, F).intersect(o, d)[1][0] == geods.Accelerator(V, F).intersect(o, d)[1][0] == 0


def test_enum_strings_are_the_enum_names_and_old_spellings_still_work():
    V, F = tetrahedron()
    for name in ("bottom_up", "bottomup"):  # Builder::bottom_up; the second is deprecated
        b = geods.TriangleBvh(V, F, builder=name)
        b.validate()
        assert b.stats()["builder"] == name
    with pytest.raises(ValueError, match="bottom_up"):
        geods.TriangleBvh(V, F, builder="bottom-up")
    pts = np.random.default_rng(1).random((200, 2))
    a, b = geods.Quadtree(pts, build="top_down"), geods.Quadtree(pts, build="topdown")
    assert a.stats() == b.stats() == geods.Quadtree(pts, build="morton").stats()
    vol = np.random.default_rng(2).random((9, 8, 7)).astype(np.float32)
    tree = geods.MinMaxOctree(vol)
    surfaces = [tree.isosurface(0.5, sharing=s) for s in ("block_masks", "hash_table", "blocks", "hash")]
    assert len({len(V) for V, _, _ in surfaces}) == 1
    with pytest.raises(ValueError, match="block_masks"):
        tree.isosurface(0.5, sharing="octree")


def test_locators_mirror_cpp_and_agree_with_brute_force():
    rng = np.random.default_rng(3)
    sites = rng.random((300, 2))
    queries = rng.random((500, 2))
    v = geods.Voronoi2(sites)
    brute = np.argmin(((queries[:, None, :] - sites[None, :, :]) ** 2).sum(axis=2), axis=1)
    slab, walk = geods.SlabLocator(v), geods.WalkLocator(v)
    del v  # the locators keep the diagram alive
    assert (slab.nearest(queries) == brute).all() and (walk.nearest(queries) == brute).all()
    assert slab.nearest(queries[0]) == brute[0]
    s = slab.stats()
    assert set(s) == {"slabs", "crossings", "max_crossings", "bytes"} and s["slabs"] > 0


def test_missing_results_are_minus_one_and_inf_everywhere():
    pts = np.array([[0.0, 0.0], [1.0, 0.0]])
    for tree in (geods.KdTree(pts), geods.Quadtree(pts)):
        d, i = tree.query([0.1, 0.0], k=4)
        assert list(i) == [0, 1, -1, -1] and np.isinf(d[2:]).all() and np.isfinite(d[:2]).all()
    dyn = geods.DynamicKdTree(dim=2)
    dyn.insert(pts)
    d, i = dyn.query(np.array([[0.9, 0.0]]), k=3)
    assert i.shape == (1, 3) and list(i[0]) == [1, 0, -1] and np.isinf(d[0, 2])
    V, F = tetrahedron()
    t, prim, _, _ = geods.TriangleBvh(V, F).intersect(np.array([[5, 5, 5]], np.float32), np.array([[1, 0, 0]], np.float32))
    assert prim[0] == -1 and np.isinf(t[0])


def test_stats_dicts_hold_every_field_of_the_cpp_struct():
    rng = np.random.default_rng(4)
    pts = rng.random((500, 3))
    assert set(geods.KdTree(pts).stats()) == {"points", "nodes", "leaves", "depth", "bytes"}
    dt = geods.Delaunay2(pts[:, :2])
    s = dt.stats()
    assert {"points", "vertices", "duplicates", "removed", "triangles", "hull", "flips", "walk_steps", "dag_nodes",
            "bytes"} == set(s)
    assert s["triangles"] == len(dt.triangles) and s["hull"] == len(dt.hull)
    m = geods.MetricVoronoi(pts[:50, :2], metric="l1", box=(0, 0, 1, 1)).stats()
    assert m["sites"] == 50 and m["edges"] == len(geods.MetricVoronoi(pts[:50, :2], metric="l1", box=(0, 0, 1, 1)).edges[0])


def test_read_table_reads_any_width_and_is_what_read_points_reads(tmp_path):
    rng = np.random.default_rng(5)
    a = np.round(rng.random((30, 5)) * 1000) / 8
    np.save(tmp_path / "a.npy", a)
    np.savetxt(tmp_path / "a.csv", a, delimiter=",", header="a,b,c,d,e", comments="")
    np.savetxt(tmp_path / "a.xyz", a)
    for name in ("a.npy", "a.csv", "a.xyz"):
        assert (geods.read_table(tmp_path / name) == a).all()
    assert (geods.read_points(tmp_path / "a.xyz") == a[:, :3]).all()  # columns after x, y, z are ignored
    np.save(tmp_path / "i.npy", np.arange(12, dtype=np.int16).reshape(4, 3))
    assert (geods.read_table(tmp_path / "i.npy") == np.arange(12).reshape(4, 3)).all()
    (tmp_path / "bad.csv").write_text("1,2\n3\n")
    with pytest.raises(ValueError, match="line 2"):
        geods.read_table(tmp_path / "bad.csv")


def test_commands_take_their_main_input_first_and_keep_the_old_options(cli, tmp_path):
    rng = np.random.default_rng(6)
    pts, q = rng.random((400, 4)), rng.random((20, 4))
    np.save(tmp_path / "p.npy", pts)
    np.savetxt(tmp_path / "q.txt", q)  # blank-separated text: any width
    new = json.loads(run(cli, "knn", "p.npy", "--queries", "q.txt", "--k", 3, "--indices", "i1.npy", "--json",
                         cwd=tmp_path).stdout)
    old = run(cli, "knn", "--points", "p.npy", "--queries", "q.txt", "--k", 3, "--indices", "i2.npy", cwd=tmp_path)
    assert old.returncode == 0, old.stderr
    assert (np.load(tmp_path / "i1.npy") == np.load(tmp_path / "i2.npy")).all()
    brute = np.argsort(((q[:, None] - pts[None]) ** 2).sum(axis=2), axis=1)[:, :3]
    assert (np.load(tmp_path / "i1.npy") == brute).all()
    assert new["dim"] == 4 and new["tree_points"] == 400 and new["tree_nodes"] > 0 and "tree_bytes" in new
    missing = run(cli, "knn", "--queries", "q.txt", "--k", 3, cwd=tmp_path)
    assert missing.returncode == 2 and "points" in missing.stderr and len(missing.stderr.strip().splitlines()) == 1
    both = run(cli, "knn", "p.npy", "--points", "p.npy", "--queries", "q.txt", "--k", 3, cwd=tmp_path)
    assert both.returncode == 2

    sites = rng.random((100, 2))
    np.save(tmp_path / "s.npy", sites)
    np.save(tmp_path / "sq.npy", q[:, :2])
    outs = []
    for args in (["s.npy", "--method", "kd_tree"], ["--sites", "s.npy", "--method", "kdtree"], ["s.npy"],
                 ["s.npy", "--method", "slab"]):
        r = run(cli, "nearest", *args, "--queries", "sq.npy", "-o", "n.npy", "--json", cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        outs.append(np.load(tmp_path / "n.npy"))
    assert all((outs[0] == o).all() for o in outs[1:])
    report = json.loads(r.stdout)  # the slab locator's stats, prefixed
    assert report["locator_slabs"] > 0 and report["locator_bytes"] > 0
    bad = run(cli, "nearest", "q.txt", "--queries", "sq.npy", cwd=tmp_path)  # 4 columns, not 2
    assert bad.returncode == 2 and "q.txt" in bad.stderr and "n x 2" in bad.stderr
