"""geods.RayAccelerator against a numpy brute force, geods.render, and the render command."""
import json
import subprocess

import numpy as np
import pytest

import geods

KINDS = ["bvh", "grid", "octree", "rays5d"]


def brute_force(V, F, origins, directions):
    """Moller-Trumbore in float64 over all triangles: closest t, triangle, and the
    smallest distance of the hit to its triangle's edges (in barycentric units)."""
    a, b, c = V[F[:, 0]].astype(float), V[F[:, 1]].astype(float), V[F[:, 2]].astype(float)
    e1, e2 = b - a, c - a
    n = len(origins)
    t_best = np.full(n, np.inf)
    prim = np.full(n, -1)
    margin = np.full(n, np.inf)
    for i in range(n):
        o, d = origins[i].astype(float), directions[i].astype(float)
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            s = o - a
            u = np.einsum("ij,ij->i", s, p) * inv
            q = np.cross(s, e1)
            v = (q @ d) * inv
            t = np.einsum("ij,ij->i", e2, q) * inv
        ok = (det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0)
        if ok.any():
            j = np.flatnonzero(ok)[np.argmin(t[ok])]
            t_best[i], prim[i] = t[j], j
            margin[i] = min(u[j], v[j], 1 - u[j] - v[j])
        # A ray grazing any triangle's edge may be decided either way.
        near = (det != 0) & (t >= 0) & (np.minimum(np.minimum(u, v), 1 - u - v) > -1e-5) & ~ok
        if near.any():
            margin[i] = 0
    return t_best, prim, margin


@pytest.fixture(scope="module")
def bunny(data_dir):
    return geods.read_mesh(str(data_dir / "bunny.ply"))


def random_rays(V, n, seed):
    rng = np.random.default_rng(seed)
    lo, hi = V.min(0), V.max(0)
    c, e = (lo + hi) / 2, hi - lo
    origins = (c + e * rng.uniform(-1.5, 1.5, (n, 3))).astype(np.float32)
    targets = (lo + e * rng.random((n, 3))).astype(np.float32)
    return origins, (targets - origins).astype(np.float32)


def test_every_kind_matches_brute_force(bunny):
    V, F = bunny
    origins, directions = random_rays(V, 300, 1)
    t_ref, prim_ref, margin = brute_force(V, F, origins, directions)
    clear = margin > 1e-4
    assert clear.sum() > 250
    assert (prim_ref[clear] >= 0).sum() > 50
    results = {}
    for kind in KINDS:
        acc = geods.RayAccelerator(V, F, kind=kind)
        assert acc.kind == kind
        t, prim, u, v = acc.intersect(origins, directions)
        assert t.dtype == np.float32 and prim.dtype == np.int64 and t.shape == (300,)
        np.testing.assert_array_equal(prim[clear], prim_ref[clear])
        hit = clear & (prim_ref >= 0)
        np.testing.assert_allclose(t[hit], t_ref[hit], rtol=1e-4)
        assert np.all(np.isinf(t[prim < 0]))
        h = prim >= 0
        assert np.all(u[h] >= 0) and np.all(v[h] >= 0) and np.all(u[h] + v[h] <= 1 + 1e-6)
        np.testing.assert_array_equal(acc.occluded(origins, directions), prim >= 0)
        results[kind] = (t, prim)
        acc.validate()
    # grid, octree and 5D classification give bit-identical answers.
    for kind in ["octree", "rays5d"]:
        np.testing.assert_array_equal(results[kind][0], results["grid"][0])
        np.testing.assert_array_equal(results[kind][1], results["grid"][1])


def test_tmax_limits_hits(bunny):
    V, F = bunny
    origins, directions = random_rays(V, 200, 2)
    acc = geods.RayAccelerator(V, F, kind="grid")
    t, prim, _, _ = acc.intersect(origins, directions)
    hit = prim >= 0
    half = np.where(hit, t * 0.5, np.inf).astype(np.float32)
    t2, prim2, _, _ = acc.intersect(origins, directions, tmax=half)
    assert np.all(prim2[hit] == -1)
    np.testing.assert_array_equal(acc.occluded(origins, directions, tmax=half)[hit], False)
    t3, prim3, _, _ = acc.intersect(origins, directions, tmax=1e30)
    np.testing.assert_array_equal(prim3, prim)


def test_stats(bunny):
    V, F = bunny
    for kind in KINDS:
        s = geods.RayAccelerator(V, F, kind=kind).stats()
        assert s["kind"] == kind
        assert s["triangles"] == len(F)
        assert s["nodes"] >= 1 and s["bytes"] > 0 and s["build_s"] >= 0
    g = geods.RayAccelerator(V, F, kind="grid").stats()
    assert np.prod(g["resolution"]) == g["nodes"]


def test_bad_input(bunny):
    V, F = bunny
    with pytest.raises(geods.Error):
        geods.RayAccelerator(V, F, kind="kdtree")
    with pytest.raises(geods.Error):
        geods.RayAccelerator(V, F + len(V), kind="grid")
    bad = V.copy()
    bad[0, 0] = np.nan
    with pytest.raises(geods.Error):
        geods.RayAccelerator(bad, F, kind="octree")
    acc = geods.RayAccelerator(V, F, kind="grid")
    with pytest.raises(geods.Error):
        acc.intersect(np.zeros((3, 2)), np.zeros((3, 2)))
    with pytest.raises(geods.Error):
        acc.intersect(np.zeros((3, 3)), np.zeros((4, 3)))
    with pytest.raises(geods.Error):
        acc.intersect(np.zeros((3, 3)), np.ones((3, 3)), tmax=np.ones(2))


def test_render_same_image_with_every_accelerator(bunny):
    V, F = bunny
    images = {kind: geods.render(V, F, width=64, height=48, accel=kind, shadows=True) for kind in KINDS}
    ref = images["grid"]
    assert ref.shape == (48, 64, 3) and ref.dtype == np.uint8
    for kind in ["octree", "rays5d"]:
        np.testing.assert_array_equal(images[kind], ref)
    # The BVH may pick another triangle at a shared vertex: a handful of pixels at most.
    assert (images["bvh"] != ref).any(axis=2).sum() <= 5
    # The bunny covers part of the picture: warm surface (red > blue) and bluish background.
    surface = ref[:, :, 0] > ref[:, :, 2]
    assert 0.1 < surface.mean() < 0.9
    assert not surface[0].any() and not surface[-1].any()


def test_render_packets_give_the_same_image(bunny, cli, data_dir, tmp_path):
    V, F = bunny
    for kind in ["bvh", "grid"]:
        packets = geods.render(V, F, width=45, height=27, accel=kind, shadows=True)
        single = geods.render(V, F, width=45, height=27, accel=kind, shadows=True, packets=False)
        np.testing.assert_array_equal(packets, single)
    reports = []
    for flag in ["--packets", "--no-packets"]:
        proc = subprocess.run([str(cli), "render", str(data_dir / "bunny.ply"), "-o", str(tmp_path / f"b{flag}.png"),
                               "--width", "40", "--height", "24", "--shadows", flag, "--json"],
                              capture_output=True, text=True, check=True)
        reports.append(json.loads(proc.stdout))
    assert reports[0]["packets"] is True and reports[1]["packets"] is False
    assert reports[0]["rays"] == reports[1]["rays"] and reports[0]["simd_level"] == geods.simd_level()
    assert np.array_equal(geods.read_image(str(tmp_path / "b--packets.png")),
                          geods.read_image(str(tmp_path / "b--no-packets.png")))


def test_render_camera(bunny):
    V, F = bunny
    c = (V.min(0) + V.max(0)) / 2
    # Looking away from the mesh: background only.
    away = geods.render(V, F, width=16, height=16, camera=[*c, *(c + [0, 0, 1]), 0, 1, 0, 40])
    eye = c + [0, 0, 5 * np.ptp(V, axis=0).max()]
    towards = geods.render(V, F, width=16, height=16, camera=[*eye, *c, 0, 1, 0])
    assert (towards[:, :, 0] > towards[:, :, 2]).any()
    assert away.shape == (16, 16, 3)
    with pytest.raises(geods.Error):
        geods.render(V, F, width=16, height=16, camera=[0, 0, 0, 0, 0, 0, 0, 1, 0])
    with pytest.raises(geods.Error):
        geods.render(V, F, width=0, height=16)


def test_render_command(cli, data_dir, tmp_path):
    out = tmp_path / "bunny.png"
    proc = subprocess.run([str(cli), "render", str(data_dir / "bunny.ply"), "-o", str(out), "--width", "64",
                           "--height", "64", "--accel", "octree", "--shadows", "--json"],
                          capture_output=True, text=True, check=True)
    report = json.loads(proc.stdout)
    assert report["accel"] == "octree" and report["width"] == 64
    assert report["rays"] >= 64 * 64 and report["mrays_per_s"] > 0
    assert report["compute_s"] == pytest.approx(report["build_s"] + report["render_s"])
    image = geods.read_image(str(out))
    assert image.shape == (64, 64, 3)
    bad = subprocess.run([str(cli), "render", str(data_dir / "bunny.ply"), "-o", str(out), "--accel", "kd"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "unknown accelerator" in bad.stderr
    bad = subprocess.run([str(cli), "render", str(data_dir / "bunny.ply"), "-o", str(out), "--camera", "1,2,3"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "10 numbers" in bad.stderr


@pytest.mark.parametrize("kind", KINDS)
def test_save_load_gives_identical_hits(bunny, tmp_path, kind):
    V, F = bunny
    accel = geods.RayAccelerator(V, F, kind)
    accel.save(tmp_path / "bunny.accel")
    loaded = geods.RayAccelerator.load(tmp_path / "bunny.accel")
    assert loaded.kind == kind
    loaded.validate()
    origins, directions = random_rays(V, 500, 12)
    for a, b in zip(accel.intersect(origins, directions), loaded.intersect(origins, directions)):
        assert np.array_equal(a, b)
    assert np.array_equal(accel.occluded(origins, directions), loaded.occluded(origins, directions))
    if kind != "rays5d":  # its 5D trees grow with the rays it is shot
        for key in ("nodes", "references", "depth", "build_s"):
            assert accel.stats()[key] == loaded.stats()[key]
    data = (tmp_path / "bunny.accel").read_bytes()
    (tmp_path / "cut.accel").write_bytes(data[:-1000])
    with pytest.raises(geods.Error, match="truncated"):
        geods.RayAccelerator.load(tmp_path / "cut.accel")


def test_render_save_and_load(cli, data_dir, tmp_path):
    mesh, saved = str(data_dir / "bunny.ply"), str(tmp_path / "bunny.grid")
    common = ["--width", "48", "--height", "32", "--json"]
    built = json.loads(subprocess.run([str(cli), "render", mesh, "-o", str(tmp_path / "a.png"), "--accel", "grid",
                                       "--save", saved] + common, capture_output=True, text=True, check=True).stdout)
    loaded = json.loads(subprocess.run([str(cli), "render", mesh, "-o", str(tmp_path / "b.png"), "--load", saved]
                                       + common, capture_output=True, text=True, check=True).stdout)
    assert built["saved"] == saved and loaded["loaded"] == saved and loaded["accel"] == "grid"
    assert loaded["build_s"] == 0 and loaded["accel_nodes"] == built["accel_nodes"]
    assert np.array_equal(geods.read_image(str(tmp_path / "a.png")), geods.read_image(str(tmp_path / "b.png")))
    assert geods.RayAccelerator.load(saved).kind == "grid"
    bad = subprocess.run([str(cli), "render", mesh, "-o", str(tmp_path / "c.png"), "--load", saved, "--accel", "octree"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "grid" in bad.stderr and bad.stderr.count("\n") == 1
    bvh_file = tmp_path / "bunny.bvh"
    subprocess.run([str(cli), "bvh", mesh, "--save", str(bvh_file)], check=True, capture_output=True)
    assert geods.Bvh.load(bvh_file).stats()["triangles"] == 3674
