"""geods.Adf and `geods adf` against the closed-form signed distance of a box and geods.signed_distance."""
import json
import subprocess

import numpy as np
import pytest

import geods

LO, HI = np.array([0.0, 0.0, 0.0]), np.array([1.0, 0.6, 0.3])


def box_mesh():
    """The box [LO, HI] as 8 vertices and 12 outward triangles."""
    v = np.array([[HI[0] if i & 1 else LO[0], HI[1] if i & 2 else LO[1], HI[2] if i & 4 else LO[2]] for i in range(8)],
                 dtype=np.float32)
    f = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]], dtype=np.int64)
    return v, f


def box_sdf(p):
    """Closed-form signed distance of the box (negative inside)."""
    c, h = (LO + HI) / 2, (HI - LO) / 2
    q = np.abs(p - c) - h
    return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)


def random_points(adf, n, seed):
    rng = np.random.default_rng(seed)
    return (np.array(adf.origin) + rng.random((n, 3)) * adf.size).astype(np.float32)


@pytest.mark.parametrize("checks,bound", [(3, 2.0), (5, 1.25)])
def test_distance_within_the_bound(checks, bound):
    v, f = box_mesh()
    error = 0.01
    adf = geods.Adf(v, f, error, checks=checks)
    p = random_points(adf, 20000, checks)
    d = adf.distance(p)
    assert d.dtype == np.float64 and d.shape == (len(p),)
    assert np.abs(d - box_sdf(p.astype(np.float64))).max() <= bound * error
    s = adf.stats()
    assert set(s) >= {"cells", "leaves", "depth", "bytes", "dense_bytes", "unresolved", "exact_queries"}
    # Every byte: tree bits and ranks (12 bytes per 64 cells); the keys of the keyed corners (all but the
    # leaves' low corners), Elias-Fano: key_bits = floor(log2(lattice / keyed)) low bits each, the high parts
    # in unary (keyed + lattice / 2^key_bits bits), a 32-bit select sample per 128 zeros; the values of all.
    # Packed fields in 64-bit words, one of padding each; corners shared: fewer than 8 a leaf.
    def words(n, bits):
        return (n * bits + 63) // 64 + 1
    keyed = s["corners"] - s["leaves"]
    lattice = (2 ** s["depth"] + 1) ** 3
    assert keyed << s["key_bits"] <= lattice <= keyed << (s["key_bits"] + 1)
    zeros = ((lattice - 1) >> s["key_bits"]) + 1
    fixed = (12 * ((s["cells"] + 63) // 64) + 8 * words(keyed, s["key_bits"]) + 8 * words(s["corners"], s["value_bits"])
             + 8 * ((keyed + zeros + 63) // 64) + 4 * ((zeros + 127) // 128))
    assert s["unresolved"] == 0 and s["value_bits"] <= 16 and error / 64 < s["quantum"] <= error / 32
    assert 0 < keyed and s["bytes"] == fixed
    assert s["corners"] < 8 * s["leaves"]
    assert s["dense_bytes"] == 4 * (2 ** s["depth"] + 1) ** 3


def test_gradient_and_closest_point():
    v, f = box_mesh()
    adf = geods.Adf(v, f, 0.002, band=0.3)
    rng = np.random.default_rng(1)
    # Points off the middle of the faces, where the field is linear: gradient = the face normal.
    p = np.array([[0.5, 0.3, 0.45], [0.5, 0.3, -0.2], [1.2, 0.3, 0.15], [0.5, 0.8, 0.15]], dtype=np.float32)
    g = adf.gradient(p)
    np.testing.assert_allclose(g, [[0, 0, 1], [0, 0, -1], [1, 0, 0], [0, 1, 0]], atol=0.05)
    q = (LO + rng.random((500, 3)) * (HI - LO) + rng.normal(0, 0.1, (500, 3))).astype(np.float32)
    d = adf.distance(q)
    c = adf.closest_point(q)
    np.testing.assert_allclose(np.linalg.norm(c - q, axis=1), np.abs(d), atol=1e-5)
    assert np.abs(box_sdf(c.astype(np.float64))).max() < 0.05


def test_save_load_and_isosurface(tmp_path):
    v, f = box_mesh()
    adf = geods.Adf(v, f, 0.005, band=0.2, max_depth=8)
    adf.save(tmp_path / "box.geodsadf")
    loaded = geods.Adf.load(tmp_path / "box.geodsadf")
    p = random_points(adf, 3000, 2)
    np.testing.assert_array_equal(loaded.distance(p), adf.distance(p))
    np.testing.assert_array_equal(loaded.gradient(p), adf.gradient(p))
    assert loaded.stats() == adf.stats()
    h = adf.size / 64
    V, F = adf.isosurface(0.0, res=65)
    assert len(F) > 0 and F.max() < len(V)
    assert np.abs(box_sdf(V.astype(np.float64))).max() <= 0.005 + h
    V, F = adf.isosurface(0.1, res=65)
    assert np.abs(box_sdf(V.astype(np.float64)) - 0.1).max() <= 0.005 + h
    (tmp_path / "bad.geodsadf").write_bytes((tmp_path / "box.geodsadf").read_bytes()[:200])
    with pytest.raises(geods.Error):
        geods.Adf.load(tmp_path / "bad.geodsadf")


def test_bad_input():
    v, f = box_mesh()
    for kwargs in [dict(error=0), dict(error=float("nan")), dict(error=0.1, checks=4), dict(error=0.1, band=-1),
                   dict(error=0.1, max_depth=40), dict(error=0.1, sign="parity")]:
        with pytest.raises(geods.Error):
            geods.Adf(v, f, **kwargs)
    with pytest.raises(geods.Error):
        geods.Adf(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int64), 0.1)
    bad = v.copy()
    bad[0, 0] = np.nan
    with pytest.raises(geods.Error):
        geods.Adf(bad, f, 0.1)
    adf = geods.Adf(v, f, 0.1)
    with pytest.raises(geods.Error):
        adf.distance(np.array([[np.nan, 0, 0]], np.float32))
    with pytest.raises(geods.Error):
        adf.distance(np.zeros((4, 2)))


def run(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=300)


def test_cli_adf(cli, data_dir, tmp_path):
    out = tmp_path / "bunny.geodsadf"
    r = run(cli, "adf", data_dir / "bunny.ply", "--error", 0.1, "--band", 1, "-o", out, "--error-samples", 2000,
            "--surface", tmp_path / "s.ply", "--offset", 0.3, "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    for key in ["cells", "bytes", "dense_bytes", "max_error", "build_s", "compute_s", "leaves", "depth"]:
        assert key in j
    assert 0 < j["max_error"] <= 2 * 0.1 and j["bytes"] < j["dense_bytes"]
    adf = geods.Adf.load(out)
    assert adf.stats()["cells"] == j["cells"]
    V, F = geods.read_mesh(str(data_dir / "bunny.ply"))[:2]
    # The loaded ADF agrees with the exact field near the surface.
    rng = np.random.default_rng(0)
    p = (V[rng.integers(0, len(V), 500)] + rng.normal(0, 0.3, (500, 3))).astype(np.float32)
    exact = np.clip(geods.signed_distance(V, F, p)[0], -1, 1)
    assert np.abs(adf.distance(p) - exact).max() <= 2 * 0.1
    sV, sF = geods.read_mesh(str(tmp_path / "s.ply"))[:2]
    assert len(sF) > 0
    # Within the error at random points (at most 2E with the 19 test points) and a sample spacing.
    np.testing.assert_allclose(geods.signed_distance(V, F, sV)[0], 0.3, atol=2 * 0.1 + adf.size / 2 ** min(adf.stats()["depth"], 8))
    for args, words in [(["--error", "-1"], "error"), (["--error", "0.1", "--checks", "4"], "checks"),
                        (["--error", "0.1", "--band", "nan"], "band")]:
        r = run(cli, "adf", data_dir / "bunny.ply", "-o", tmp_path / "x.geodsadf", *args)
        assert r.returncode == 2 and words in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    r = run(cli, "adf", tmp_path / "missing.ply", "--error", 0.1, "-o", tmp_path / "x.geodsadf")
    assert r.returncode == 2 and "missing.ply" in r.stderr
