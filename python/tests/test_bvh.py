"""geods.Bvh against numpy brute force, and the bvh command."""
import json
import subprocess

import numpy as np
import pytest

import geods

BUILDERS = ["sah", "median", "pca", "bottomup", "tiling", "insertion", "boxtree"]
VOLUMES = ["aabb", "sphere", "kdop6", "kdop14", "kdop18", "kdop26", "obb", "obb_hull", "rss"]


@pytest.fixture(scope="module")
def bunny(data_dir):
    return geods.read_mesh(str(data_dir / "bunny.ply"))


def brute_intersect(V, F, origins, directions):
    """Closest t per ray (Moller-Trumbore in float64), inf on a miss."""
    a, b, c = (V[F[:, k]].astype(np.float64) for k in range(3))
    e1, e2 = b - a, c - a
    out = np.full(len(origins), np.inf)
    for i, (o, d) in enumerate(zip(origins.astype(np.float64), directions.astype(np.float64))):
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = o - a
            u = np.einsum("ij,ij->i", s, p) / det
            q = np.cross(s, e1)
            v = (q @ d) / det
            t = np.einsum("ij,ij->i", e2, q) / det
        ok = (det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0)
        if ok.any():
            out[i] = t[ok].min()
    return out


def winding_number(V, F, p):
    a, b, c = (V[F[:, k]].astype(np.float64) - p for k in range(3))
    la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
    num = np.einsum("ij,ij->i", a, np.cross(b, c))
    den = la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la + np.einsum("ij,ij->i", c, a) * lb
    return 2 * np.arctan2(num, den).sum() / (4 * np.pi)


def rays_at(V, n, seed):
    rng = np.random.default_rng(seed)
    d = rng.standard_normal((n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    origins = (3 * d).astype(np.float32)
    targets = rng.uniform(V.min(0), V.max(0), (n, 3))
    return origins, (targets - origins).astype(np.float32)


def test_intersect_matches_brute_force(bunny):
    V, F = bunny
    origins, directions = rays_at(V, 200, 1)
    expected = brute_intersect(V, F, origins, directions)
    bvh = geods.Bvh(V, F)
    t, prim, u, v = bvh.intersect(origins, directions)
    assert t.dtype == np.float32 and t.shape == (200,)
    hit = np.isfinite(expected)
    assert 20 < hit.sum() < 200
    assert np.array_equal(np.isfinite(t), hit)
    assert np.all(prim[~hit] == -1) and np.all(prim[hit] >= 0)
    assert np.allclose(t[hit], expected[hit], rtol=1e-5, atol=1e-6)
    # The hit point from (prim, u, v) lies on the ray at t.
    a, b, c = (V[F[prim[hit], k]] for k in range(3))
    p = (1 - u[hit] - v[hit])[:, None] * a + u[hit][:, None] * b + v[hit][:, None] * c
    assert np.allclose(p, origins[hit] + t[hit][:, None] * directions[hit], atol=1e-4)
    # tmax: per ray or one number.
    half = np.where(hit, expected * 0.5, 1.0).astype(np.float32)
    assert not bvh.occluded(origins, directions, half)[hit].any()
    assert np.array_equal(bvh.occluded(origins, directions), hit)
    t2, prim2, _, _ = bvh.intersect(origins, directions, tmax=0.0)
    assert np.all(prim2 == -1) and np.all(np.isinf(t2))


@pytest.mark.parametrize("builder", BUILDERS)
def test_every_builder_and_volume_gives_the_same_hits(bunny, builder):
    V, F = bunny
    origins, directions = rays_at(V, 100, 2)
    reference, _, _, _ = geods.Bvh(V, F).intersect(origins, directions)
    for bv in VOLUMES:
        bvh = geods.Bvh(V, F, builder=builder, bv=bv)
        bvh.validate()
        t, _, _, _ = bvh.intersect(origins, directions)
        assert np.array_equal(np.isfinite(t), np.isfinite(reference)), (builder, bv)
        assert np.allclose(t[np.isfinite(t)], reference[np.isfinite(reference)], rtol=1e-6), (builder, bv)
        s = bvh.stats()
        assert s["builder"] == builder and s["bv"] == bv
        assert s["triangles"] == len(F) and s["nodes"] > s["leaves"] > 0
        assert s["sah_cost"] >= 1 and s["tightness_volume"] > 0 and s["tightness_hausdorff"] > 0


def closest_on_triangles(p, a, b, c):
    """Ericson's closest point of p on each triangle (vectorized), float64."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = ab @ np.zeros(3) + np.einsum("ij,ij->i", ab, ap), np.einsum("ij,ij->i", ac, ap)
    bp = p - b
    d3, d4 = np.einsum("ij,ij->i", ab, bp), np.einsum("ij,ij->i", ac, bp)
    cp = p - c
    d5, d6 = np.einsum("ij,ij->i", ab, cp), np.einsum("ij,ij->i", ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = 1 / (va + vb + vc)
        res = a + ab * (vb * denom)[:, None] + ac * (vc * denom)[:, None]
        w_ab = d1 / (d1 - d3)
        r_ab = a + w_ab[:, None] * ab
        w_ac = d2 / (d2 - d6)
        r_ac = a + w_ac[:, None] * ac
        w_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        r_bc = b + w_bc[:, None] * (c - b)
    res = np.where(((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0))[:, None], r_bc, res)
    res = np.where(((vb <= 0) & (d2 >= 0) & (d6 <= 0))[:, None], r_ac, res)
    res = np.where(((d6 >= 0) & (d5 <= d6))[:, None], c, res)
    res = np.where(((vc <= 0) & (d1 >= 0) & (d3 <= 0))[:, None], r_ab, res)
    res = np.where(((d3 >= 0) & (d4 <= d3))[:, None], b, res)
    res = np.where(((d1 <= 0) & (d2 <= 0))[:, None], a, res)
    return res


def test_closest_point_and_contains(bunny):
    V, F = bunny
    bvh = geods.Bvh(V, F, bv="obb")
    rng = np.random.default_rng(3)
    pts = rng.uniform(-1.2, 1.2, (60, 3)).astype(np.float32)
    q, prim, dist = bvh.closest_point(pts)
    assert q.shape == (60, 3) and prim.shape == (60,)
    a, b, c = (V[F[:, k]].astype(np.float64) for k in range(3))
    for i, p in enumerate(pts.astype(np.float64)):
        best = np.linalg.norm(closest_on_triangles(p, a, b, c) - p, axis=1).min()
        assert dist[i] == pytest.approx(best, rel=1e-4, abs=1e-6)
        assert np.linalg.norm(q[i] - p) == pytest.approx(dist[i], rel=1e-4, abs=1e-6)
    inside = bvh.contains(pts)
    for i, p in enumerate(pts):
        if dist[i] > 1e-3:
            assert inside[i] == (winding_number(V, F, p.astype(np.float64)) > 0.5)
    assert 0 < inside.sum() < len(pts)


def test_cull_box(bunny):
    V, F = bunny
    bvh = geods.Bvh(V, F)
    ids = bvh.cull_box([-0.2, -0.2, -0.2], [0.2, 0.2, 0.2])
    lo, hi = V[F].min(1), V[F].max(1)
    boxes_overlap = np.all(lo <= 0.2, axis=1) & np.all(hi >= -0.2, axis=1)
    assert set(ids) <= set(np.nonzero(boxes_overlap)[0])
    # Triangles with a vertex inside the box are certainly in.
    vertex_in = np.any(np.all(np.abs(V[F]) <= 0.2, axis=2), axis=1)
    assert set(np.nonzero(vertex_in)[0]) <= set(ids)


def test_cull_frustum(bunny):
    V, F = bunny
    bvh = geods.Bvh(V, F)
    # A box-shaped frustum with unnormalized normals (the binding normalizes them).
    planes = np.array([[2, 0, 0, -2], [-1, 0, 0, -3], [0, 3, 0, 6],
                       [0, -1, 0, -6], [0, 0, 1, -2.5], [0, 0, -1, -2.5]], np.float32)
    ids = bvh.cull_frustum(planes)
    n = planes[:, :3] / np.linalg.norm(planes[:, :3], axis=1)[:, None]
    off = planes[:, 3] / np.linalg.norm(planes[:, :3], axis=1)
    d = np.einsum('tvk,pk->tvp', V[F], n) - off  # (triangles, 3 corners, planes)
    behind = np.any(np.all(d < 0, axis=1), axis=1)
    assert list(ids) == list(np.nonzero(~behind)[0])
    assert 0 < len(ids) < len(F)
    with pytest.raises(geods.Error):
        bvh.cull_frustum(np.zeros((1, 4), np.float32))
    with pytest.raises(geods.Error):
        bvh.cull_frustum(np.zeros((2, 3), np.float32))


def test_bad_input_raises():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    F = np.array([[0, 1, 2]])
    with pytest.raises(geods.Error):
        geods.Bvh(V, F, builder="octree")
    with pytest.raises(geods.Error):
        geods.Bvh(V, F, bv="cone")
    with pytest.raises(geods.Error):
        geods.Bvh(V, np.array([[0, 1, 3]]))
    with pytest.raises(geods.Error):
        geods.Bvh(V, F, arity=3)
    bvh = geods.Bvh(V, F)
    with pytest.raises(geods.Error):
        bvh.intersect(np.zeros((2, 3)), np.zeros((3, 3)))
    with pytest.raises(geods.Error):
        bvh.intersect(np.zeros((2, 2)), np.zeros((2, 2)))


def test_cli_bvh(cli, data_dir, workdir):
    out = subprocess.run([cli, "bvh", data_dir / "bunny.ply", "--builder", "boxtree", "--bv", "kdop14", "--json"],
                         capture_output=True, text=True, check=True)
    report = json.loads(out.stdout)
    assert report["builder"] == "boxtree" and report["bv"] == "kdop14"
    assert report["triangles"] == 3674 and report["nodes"] > 0 and report["compute_s"] >= report["build_s"] >= 0
    for key in ("depth", "bytes", "sah_cost", "tightness_volume", "tightness_hausdorff"):
        assert key in report
    V, F = geods.read_mesh(str(data_dir / "bunny.ply"))
    origins, directions = rays_at(V, 50, 4)
    np.save(workdir / "rays.npy", np.hstack([origins, directions]).astype(np.float64))
    subprocess.run([cli, "bvh", data_dir / "bunny.ply", "--rays", "rays.npy", "-o", "hits.npy"], cwd=workdir,
                   check=True, capture_output=True)
    hits = np.load(workdir / "hits.npy")
    t, prim, _, _ = geods.Bvh(V, F).intersect(origins, directions)
    assert hits.shape == (50, 2)
    assert np.array_equal(hits[:, 1], prim)
    assert np.allclose(hits[:, 0][prim >= 0], t[prim >= 0])
    bad = subprocess.run([cli, "bvh", data_dir / "bunny.ply", "--arity", "3"], capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1


@pytest.mark.parametrize("bv", ["aabb", "kdop14", "obb"])
def test_save_load_gives_identical_answers(bunny, tmp_path, bv):
    V, F = bunny
    bvh = geods.Bvh(V, F, bv=bv, arity=8 if bv == "aabb" else 4)
    bvh.save(tmp_path / "bunny.bvh")
    loaded = geods.Bvh.load(str(tmp_path / "bunny.bvh"))  # str or path
    assert loaded.stats()["bv"] == bv and loaded.stats()["triangles"] == len(F)
    loaded.validate()
    origins, directions = rays_at(V, 300, 9)
    for a, b in zip(bvh.intersect(origins, directions), loaded.intersect(origins, directions)):
        assert np.array_equal(a, b)
    assert np.array_equal(bvh.occluded(origins, directions), loaded.occluded(origins, directions))
    points = origins * 0.3 + V.mean(0) * 0.7
    for a, b in zip(bvh.closest_point(points), loaded.closest_point(points)):
        assert np.array_equal(a, b)
    assert np.array_equal(bvh.contains(points), loaded.contains(points))
    lo, hi = V.min(0), V.mean(0)
    assert np.array_equal(bvh.cull_box(lo, hi), loaded.cull_box(lo, hi))


def test_load_refuses_bad_files(bunny, tmp_path):
    V, F = bunny
    path = tmp_path / "bunny.bvh"
    geods.Bvh(V, F).save(path)
    data = path.read_bytes()
    (tmp_path / "cut.bvh").write_bytes(data[: len(data) // 2])
    with pytest.raises(geods.Error, match="cut.bvh"):
        geods.Bvh.load(tmp_path / "cut.bvh")
    flipped = bytearray(data)
    flipped[len(data) - 100] ^= 0x40
    (tmp_path / "flipped.bvh").write_bytes(bytes(flipped))
    with pytest.raises(ValueError, match="corrupt"):
        geods.Bvh.load(tmp_path / "flipped.bvh")
    geods.RayAccelerator(V, F, "grid").save(tmp_path / "grid.geods")
    with pytest.raises(geods.Error, match="ray.UniformGrid"):
        geods.Bvh.load(tmp_path / "grid.geods")
    with pytest.raises(geods.Error):
        geods.Bvh.load(tmp_path / "missing.bvh")


def camera_rays(V, width, height, tile_h=2):
    """Pinhole camera rays in 4 x tile_h pixel tiles (coherent packets), float32."""
    lo, hi = V.min(0), V.max(0)
    eye = (lo + hi) / 2 + 1.5 * (hi - lo)
    forward = (lo + hi) / 2 - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0, 1, 0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    dirs = []
    for ty in range(0, height, tile_h):
        for tx in range(0, width, 4):
            for y in range(ty, ty + tile_h):
                for x in range(tx, tx + 4):
                    dirs.append(forward + (x / width - 0.5) * 0.8 * right - (y / height - 0.5) * 0.8 * up)
    d = np.array(dirs)
    d /= np.linalg.norm(d, axis=1)[:, None]
    return np.tile(eye, (len(d), 1)).astype(np.float32), d.astype(np.float32)


@pytest.mark.parametrize("arity", [4, 8])
@pytest.mark.parametrize("packet_size", [8, 16])
def test_packets_give_the_single_ray_hits_bit_for_bit(bunny, arity, packet_size):
    V, F = bunny
    bvh = geods.TriangleBvh(V, F, arity=arity)
    o1, d1 = camera_rays(V, 32, 16, tile_h=packet_size // 4)
    o2, d2 = rays_at(V, 101, 9)  # incoherent, and not a multiple of 8
    d2[::7] = [1, 0, 0]          # axis-parallel rays among them
    o3 = np.tile((V.min(0) + V.max(0)) / 2, (40, 1)).astype(np.float32)  # from inside the boxes
    d3 = np.random.default_rng(3).standard_normal((40, 3)).astype(np.float32)
    origins, directions = np.vstack([o1, o2, o3]), np.vstack([d1, d2, d3])
    for tmax in (np.inf, np.float32(0.3)):
        single = bvh.intersect(origins, directions, tmax)
        packets = bvh.intersect_packets(origins, directions, tmax, packet_size=packet_size)
        for a, b in zip(single, packets):  # t, prim, u, v: the same bits
            assert a.dtype == b.dtype and a.tobytes() == b.tobytes()
        blocked = bvh.occluded_packets(origins, directions, tmax, packet_size=packet_size)
        assert blocked.dtype == np.bool_ and np.array_equal(blocked, bvh.occluded(origins, directions, tmax))
    t = bvh.intersect_packets(o1, d1, packet_size=packet_size)[0]
    expected = brute_intersect(V, F, o1[::3], d1[::3])
    hit = np.isfinite(expected)
    assert hit.sum() > 10
    assert np.array_equal(np.isfinite(t[::3]), hit)
    assert np.allclose(t[::3][hit], expected[hit], rtol=1e-5, atol=1e-6)
    with pytest.raises(geods.Error):
        bvh.intersect_packets(np.zeros((2, 3)), np.zeros((3, 3)))
    with pytest.raises(geods.Error):
        bvh.occluded_packets(o1, d1, packet_size=4)


def test_simd_level_names_and_cap(bunny):
    V, F = bunny
    names = ["portable", "avx", "avx2", "avx512"]
    best, before = geods.best_simd_level(), geods.simd_level()
    assert best in names and before in names and names.index(before) <= names.index(best)
    bvh = geods.TriangleBvh(V, F, arity=8)
    origins, directions = camera_rays(V, 16, 8)
    reference = bvh.intersect_packets(origins, directions)
    try:
        for level in names[: names.index(best) + 1]:
            geods.set_simd_level(level)
            assert geods.simd_level() == level
            for a, b in zip(bvh.intersect_packets(origins, directions), reference):
                assert a.tobytes() == b.tobytes()
        if best != "avx512":
            with pytest.raises(ValueError):
                geods.set_simd_level("avx512")
        with pytest.raises(ValueError):
            geods.set_simd_level("sse9")
    finally:
        geods.set_simd_level(before)
    assert geods.simd_level() == before


def test_cli_packets_and_simd(cli, data_dir, workdir):
    V, F = geods.read_mesh(str(data_dir / "bunny.ply"))
    origins, directions = camera_rays(V, 16, 8)
    np.save(workdir / "prays.npy", np.hstack([origins, directions]).astype(np.float64))
    out = subprocess.run([cli, "bvh", data_dir / "bunny.ply", "--arity", "8", "--rays", "prays.npy", "-o", "phits.npy",
                          "--packets", "--simd", "portable", "--json"], cwd=workdir, check=True, capture_output=True, text=True)
    report = json.loads(out.stdout)
    assert report["packets"] is True and report["packet_size"] == 8 and report["simd_level"] == "portable"
    hits = np.load(workdir / "phits.npy")
    t, prim, _, _ = geods.TriangleBvh(V, F, arity=8).intersect(origins, directions)
    assert np.array_equal(hits[:, 1], prim) and np.array_equal(hits[:, 0][prim >= 0], t[prim >= 0].astype(np.float64))
    # Packets of 16 (4 x 2 tiles two by two here): the same hits.
    out = subprocess.run([cli, "bvh", data_dir / "bunny.ply", "--arity", "8", "--rays", "prays.npy", "-o", "phits16.npy",
                          "--packets", "16", "--json"], cwd=workdir, check=True, capture_output=True, text=True)
    assert json.loads(out.stdout)["packet_size"] == 16
    assert np.array_equal(np.load(workdir / "phits16.npy"), hits)
    bad = subprocess.run([cli, "bvh", data_dir / "bunny.ply", "--rays", "prays.npy", "--packets", "4"], cwd=workdir,
                         capture_output=True, text=True)
    assert bad.returncode != 0
    # --simd caps like GEODS_SIMD: a level above the CPU's runs the CPU's best.
    out = subprocess.run([cli, "bvh", data_dir / "bunny.ply", "--simd", "avx512", "--json"], capture_output=True, text=True, check=True)
    assert json.loads(out.stdout)["build_s"] >= 0
    bad = subprocess.run([cli, "bvh", data_dir / "bunny.ply", "--simd", "sse9"], capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1
