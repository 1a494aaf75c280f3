"""geods.shape_distribution, histogram_distance, ShapeDatabase and `geods shapes` against
closed forms, scipy (Wasserstein distance, rotations) and brute force with numpy."""
import json
import subprocess

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import wasserstein_distance

import geods

from conftest import REPO


def uv_sphere(n=96, r=1.0):
    """A closed UV sphere of radius r (poles shared)."""
    th = np.linspace(0, np.pi, n + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, 2 * n, endpoint=False)
    t, p = np.meshgrid(th, ph, indexing="ij")
    V = np.vstack([[0, 0, r], np.c_[(r * np.sin(t) * np.cos(p)).ravel(), (r * np.sin(t) * np.sin(p)).ravel(),
                                   (r * np.cos(t)).ravel()], [0, 0, -r]]).astype(np.float32)
    m = 2 * n
    F = []
    ring = lambda i, j: 1 + i * m + j % m  # noqa: E731
    for j in range(m):
        F.append([0, ring(0, j), ring(0, j + 1)])
        F.append([len(V) - 1, ring(n - 2, j + 1), ring(n - 2, j)])
    for i in range(n - 2):
        for j in range(m):
            F.append([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)])
            F.append([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)])
    return V, np.array(F, dtype=np.int64)


def box(sx=1.0, sy=1.0, sz=1.0):
    V = np.array([[x * sx, y * sy, z * sz] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=np.float32)
    F = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7],
                  [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]], dtype=np.int64)
    return V, F


@pytest.fixture(scope="module")
def bunny():
    return geods.read_mesh(str(REPO / "data" / "bunny.ply"))[:2]


def test_sphere_d2_is_the_closed_form_density():
    V, F = uv_sphere(r=2.0)
    h = geods.shape_distribution(V, F, "d2", samples=1 << 17, bins=20, normalization="none", max_value=4.0)
    assert h.dtype == np.float32 and h.shape == (20,)
    edges = np.linspace(0, 4, 21)
    expected = (edges[1:] ** 2 - edges[:-1] ** 2) / 16  # f(d) = d / (2 R^2) on [0, 2R]
    assert abs(h.sum() - 1) < 1e-5
    assert np.max(np.abs(h - expected)) < 0.004


def test_invariant_to_rotation_translation_and_scale(bunny):
    V, F = bunny
    R = Rotation.from_euler("xyz", [0.3, -1.2, 2.0]).as_matrix()
    moved = (5.0 * V @ R.T + np.array([1, -2, 30])).astype(np.float32)
    teapot = geods.read_mesh(str(REPO / "data" / "teapot.obj"))
    for kind in ("d1", "d2", "a3", "d3", "d4"):
        a = geods.shape_distribution(V, F, kind, samples=1 << 16, bins=32, seed=3)
        b = geods.shape_distribution(moved, F, kind, samples=1 << 16, bins=32, seed=3)
        c = geods.shape_distribution(teapot[0], teapot[1], kind, samples=1 << 16, bins=32, seed=3)
        assert geods.histogram_distance(a, b) < 0.01, kind
        assert geods.histogram_distance(a, c) > 4 * geods.histogram_distance(a, b), kind
    assert np.array_equal(geods.shape_distribution(V, F, seed=1), geods.shape_distribution(V, F, seed=1))


def test_distances_against_numpy_and_scipy():
    rng = np.random.default_rng(1)
    for _ in range(20):
        a, b = rng.random(24).astype(np.float32), rng.random(24).astype(np.float32)
        a /= a.sum()
        b /= b.sum()
        d = a.astype(np.float64) - b
        assert geods.histogram_distance(a, b, "l1") == pytest.approx(np.abs(d).sum(), rel=1e-6)
        assert geods.histogram_distance(a, b, "l2") == pytest.approx(np.sqrt((d * d).sum()), rel=1e-6)
        assert geods.histogram_distance(a, b, "chi2") == pytest.approx((d * d / (a + b)).sum(), rel=1e-5)
        centers = np.arange(24.0)
        assert geods.histogram_distance(a, b, "emd") == pytest.approx(
            wasserstein_distance(centers, centers, a, b), rel=1e-4, abs=1e-6)
    with pytest.raises(ValueError):
        geods.histogram_distance(a, b[:5])
    with pytest.raises(ValueError):
        geods.histogram_distance(a, b, "cosine")


def test_bad_meshes_raise_value_error():
    V, F = box()
    with pytest.raises(ValueError, match="no triangles"):
        geods.shape_distribution(V, F[:0])
    with pytest.raises(ValueError, match="zero area"):
        geods.shape_distribution(np.zeros((3, 3), np.float32), np.array([[0, 1, 2]]))
    bad = V.copy()
    bad[1, 2] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        geods.shape_distribution(bad, F)
    with pytest.raises(ValueError):
        geods.shape_distribution(V, F, "d9")
    with pytest.raises(ValueError):
        geods.shape_distribution(V, F, samples=0)


def test_database_knn_is_brute_force_and_survives_save_load(tmp_path, bunny):
    db = geods.ShapeDatabase(descriptor="d2+a3:0.5", samples=1 << 14, bins=16)
    assert db.dimension == 32 and db.descriptor_name == "d2:1+a3:0.5"
    shapes = {"cube": box(), "slab": box(4, 4, 0.3), "rod": box(0.2, 0.2, 5), "sphere": uv_sphere(24),
              "bunny": bunny}
    for i, (name, (V, F)) in enumerate(shapes.items()):
        assert db.add(name, V, F, label=name) == i
    rng = np.random.default_rng(2)
    rows = rng.random((300, 32)).astype(np.float32)
    ids = db.add_descriptors([f"r{i}" for i in range(300)], rows)
    assert list(ids) == list(range(5, 305)) and len(db) == 305
    stored = np.array([db.descriptor(i) for i in range(len(db))])
    for q in rng.random((15, 32)).astype(np.float32):
        d = np.sqrt(((stored.astype(np.float64) - q) ** 2).sum(1))
        order = np.argsort(d, kind="stable")
        got = db.query_descriptor(q, k=6)
        assert [m["id"] for m in got] == list(order[:6])
        assert np.allclose([m["distance"] for m in got], d[order[:6]], rtol=1e-5)
    # A scaled, moved cube finds the cube.
    V, F = box()
    hit = db.query((3 * V + 7).astype(np.float32), F, k=1)[0]
    assert hit["name"] == "cube" and hit["label"] == "cube"
    db.save(str(tmp_path / "db.geodsshapes"))
    loaded = geods.ShapeDatabase.load(str(tmp_path / "db.geodsshapes"))
    assert loaded.names == db.names and loaded.labels == db.labels and loaded.samples == 1 << 14
    assert loaded.query(V, F, k=3) == db.query(V, F, k=3)
    assert loaded.add("cube again", V, F) == 305
    assert set(loaded.stats()) == {"shapes", "dimension", "labels", "structures", "bytes"}
    (tmp_path / "junk.geodsshapes").write_bytes(b"GEODSARC" + bytes(100))
    with pytest.raises(ValueError):
        geods.ShapeDatabase.load(str(tmp_path / "junk.geodsshapes"))


def test_index_and_evaluate_the_furniture_library():
    db, skipped = geods.index_collection(str(REPO / "data" / "furniture.sh3f"), samples=1 << 14, bins=32)
    assert skipped == [] and len(db) == 14
    assert sorted(set(db.labels)) == ["Exterior", "Kitchen", "Lights", "Miscellaneous"]
    s = geods.evaluate_retrieval(db, k=3)
    assert s["queries"] == 13 and s["classes"] == 3
    for key in ("nn_rate", "precision_at_k", "first_tier", "second_tier", "mean_average_precision"):
        assert 0 <= s[key] <= 1
    assert len(s["recall"]) == len(s["precision"]) == 20
    assert all(np.diff(s["precision"]) <= 1e-12)


def run(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=300)


def test_cli_index_query_evaluate(cli, tmp_path):
    furniture = REPO / "data" / "furniture.sh3f"
    out = tmp_path / "f.geodsshapes"
    r = run(cli, "shapes", "index", furniture, "-o", out, "--samples", 16384, "--bins", 32, "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["shapes"] == 14 and j["skipped"] == 0 and j["dimension"] == 32 and j["compute_s"] > 0
    r = run(cli, "shapes", "query", out, REPO / "data" / "bunny.ply", "--k", 4, "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert len(j["results"]) == 4 and set(j["results"][0]) == {"name", "label", "distance"}
    assert [x["distance"] for x in j["results"]] == sorted(x["distance"] for x in j["results"])
    db = geods.ShapeDatabase.load(str(out))
    V, F = geods.read_mesh(str(REPO / "data" / "bunny.ply"))[:2]
    assert [x["name"] for x in j["results"]] == [m["name"] for m in db.query(V, F, k=4)]
    r = run(cli, "shapes", "evaluate", furniture, "--k", 3, "--samples", 16384, "--bins", 32, "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    for key in ("shapes", "nn_rate", "precision_at_k", "first_tier", "second_tier", "compute_s"):
        assert key in j
    assert j["shapes"] == 14
    assert j["nn_rate"] == pytest.approx(geods.evaluate_retrieval(db, k=3)["nn_rate"])
    # --append adds a directory through the dynamization, with the database's own descriptor options.
    (tmp_path / "more").mkdir()
    geods.write_mesh(str(tmp_path / "more" / "bunny.ply"), V, F)
    r = run(cli, "shapes", "index", tmp_path / "more", "-o", out, "--append", "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["shapes"] == 15 and j["append"] and j["dimension"] == 32
    grown = geods.ShapeDatabase.load(str(out))
    assert grown.names[:14] == db.names and grown.names[14] == "bunny.ply"
    assert grown.query(V, F, k=1)[0]["name"] == "bunny.ply"


def test_cli_skips_unreadable_members_by_name_and_refuses_bad_input(cli, tmp_path):
    (tmp_path / "c").mkdir()
    V, F = box()
    geods.write_mesh(str(tmp_path / "c" / "a.ply"), V, F)
    geods.write_mesh(str(tmp_path / "c" / "b.obj"), 2 * V, F)
    (tmp_path / "c" / "broken.stl").write_text("solid nothing\n")
    r = run(cli, "shapes", "index", tmp_path / "c", "-o", tmp_path / "c.geodsshapes", "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["shapes"] == 2 and j["skipped"] == 1 and j["skipped_shapes"][0]["name"] == "broken.stl"
    assert "broken.stl" in r.stderr
    for args, word in [(("query", tmp_path / "none.geodsshapes", tmp_path / "c" / "a.ply"), "none.geodsshapes"),
                       (("query", tmp_path / "c.geodsshapes", tmp_path / "c" / "broken.stl"), "broken.stl"),
                       (("index", tmp_path / "c", "-o", tmp_path / "x", "--descriptor", "d7"), "d7"),
                       (("index", tmp_path / "c" / "a.ply", "-o", tmp_path / "x"), "collection"),
                       (("evaluate", tmp_path / "c"), "label")]:
        r = run(cli, "shapes", *args)
        assert r.returncode == 2, r.stdout + r.stderr
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and word in lines[0], r.stderr
