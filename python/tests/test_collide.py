"""geods.collide / geods.distance / `geods collide` against independent oracles:
the separating axis theorem in exact integer arithmetic on integer soups
(poses that keep integer coordinates: 180-degree turns and integer
shifts), distances of boxes known in closed form, and the CLI against the
module."""
import itertools
import json
import subprocess

import numpy as np
import pytest

import geods


def sat_disjoint(s, t):
    """Exact: a candidate axis with a strict gap separates the closed triangles."""
    s, t = [tuple(map(int, p)) for p in s], [tuple(map(int, p)) for p in t]
    sub = lambda a, b: (a[0] - b[0], a[1] - b[1], a[2] - b[2])
    cross = lambda a, b: (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    dot = lambda a, b: a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    es = [sub(s[(i + 1) % 3], s[i]) for i in range(3)]
    et = [sub(t[(i + 1) % 3], t[i]) for i in range(3)]
    axes = [cross(es[0], es[1]), cross(et[0], et[1])] + [cross(e, f) for e in es for f in et]
    for p, q in itertools.product(s, t):
        w = sub(p, q)
        axes.append(w)
        axes += [cross(cross(e, w), e) for e in es + et]
    for ax in axes:
        if ax == (0, 0, 0):
            continue
        ps, pt = [dot(p, ax) for p in s], [dot(p, ax) for p in t]
        if max(ps) < min(pt) or max(pt) < min(ps):
            return True
    return False


def integer_soup(rng, n, spread):
    V = rng.integers(-spread, spread + 1, size=(3 * n, 3)).astype(np.float32)
    F = np.arange(3 * n).reshape(n, 3)
    F[::7, 2] = F[::7, 0]  # some degenerate triangles
    return V, F


TURNS = [(1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1)]  # identity and 180 degrees about x, y, z


def world(V, pose):
    q = np.array(pose[:4], dtype=float)
    w, x, y, z = q / np.linalg.norm(q)
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    return np.rint(V.astype(float) @ R.T + np.array(pose[4:], dtype=float)).astype(np.int64)


@pytest.mark.parametrize("bv", ["aabb", "sphere", "kdop18", "obb", "boxtree", "rss"])
def test_collide_equals_exact_brute_force(bv):
    rng = np.random.default_rng(5)
    Va, Fa = integer_soup(rng, 25, 4)
    Vb, Fb = integer_soup(rng, 20, 4)
    a, b = geods.CollisionMesh(Va, Fa, bv=bv), geods.CollisionMesh(Vb, Fb, bv=bv, leaf_size=1)
    outcomes = set()
    for k in range(6):
        pose = TURNS[k % 4] + tuple(int(v) for v in rng.integers(-6, 7, 3))
        Wa, Wb = world(Va, (1, 0, 0, 0, 0, 0, 0)), world(Vb, pose)
        expect = sorted((i, j) for i in range(len(Fa)) for j in range(len(Fb))
                        if not sat_disjoint(Wa[Fa[i]], Wb[Fb[j]]))
        r = geods.collide(a, None, b, pose, mode="all")
        assert r.pairs.dtype == np.int64 and r.pairs.shape == (len(expect), 2)
        assert [tuple(p) for p in r.pairs] == expect
        assert r.colliding == bool(expect) == bool(geods.collide(a, None, b, pose))
        first = geods.collide(a, None, b, pose, mode="first")
        if expect:
            assert tuple(first.pairs[0]) in expect
        # Swapped arguments: the same pairs, swapped.
        swapped = geods.collide(b, pose, a, None, mode="all").pairs
        assert sorted(map(tuple, swapped[:, ::-1])) == expect
        outcomes.add(bool(expect))
    assert outcomes == {True, False}


def box(lo, hi):
    V = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])], np.float32)
    F = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
         [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    return V, np.array(F)


@pytest.mark.parametrize("bv", ["aabb", "kdop14", "obb", "sphere", "rss"])
def test_distance_of_boxes(bv):
    a = geods.CollisionMesh(*box((0, 0, 0), (1, 1, 1)), bv=bv)
    for gap in [0.5, 2.0]:
        d, pa, pb = geods.distance(a, None, a, (1, 0, 0, 0, 1 + gap, 0.25, 0))
        assert d == pytest.approx(gap, abs=1e-6)
        assert pa.shape == (3,) and pb.shape == (3,)
        assert pa[0] == pytest.approx(1) and pb[0] == pytest.approx(1 + gap)
        assert np.linalg.norm(pa - pb) == pytest.approx(d)
    # Rotated 45 degrees about z (about the origin) and shifted by 3: B's vertical edge at x = 3 - sqrt(2)/2.
    c, s = np.cos(np.pi / 8), np.sin(np.pi / 8)
    d, _, _ = geods.distance(a, None, a, (c, 0, 0, s, 3, 0, 0))
    assert d == pytest.approx(2 - np.sqrt(2) / 2, abs=1e-6)
    # Overlapping: distance 0, and within-d queries.
    assert geods.distance(a, None, a, (1, 0, 0, 0, 0.5, 0, 0))[0] == 0
    assert geods.distance(a, None, a, (1, 0, 0, 0, 1.5, 0, 0), within=0.6)[0] <= 0.6


def test_bad_input():
    V, F = box((0, 0, 0), (1, 1, 1))
    a = geods.CollisionMesh(V, F)
    with pytest.raises(ValueError, match="not finite"):
        geods.collide(a, None, a, (1, 0, 0, 0, np.nan, 0, 0))
    with pytest.raises(ValueError, match="zero quaternion"):
        geods.distance(a, (0, 0, 0, 0, 0, 0, 0), a, None)
    with pytest.raises(ValueError):
        geods.CollisionMesh(V, F, bv="cube")
    Vn = V.copy()
    Vn[2, 1] = np.nan
    with pytest.raises(ValueError):
        geods.CollisionMesh(Vn, F)
    with pytest.raises(ValueError, match="mode"):
        geods.collide(a, None, a, None, mode="some")


def test_cli_equals_module(cli, tmp_path, data_dir):
    V, F = geods.read_mesh(str(data_dir / "bunny.ply"))[:2]
    rng = np.random.default_rng(3)
    size = np.ptp(V, axis=0).max()
    poses = np.hstack([rng.normal(size=(12, 4)), rng.uniform(-0.6, 0.6, (12, 3)) * size])
    np.save(tmp_path / "poses.npy", poses)
    mesh = geods.CollisionMesh(V, F, bv="kdop18")
    expect = [geods.collide(mesh, None, mesh, p, mode="all").pairs for p in poses]
    out = subprocess.run([str(cli), "collide", str(data_dir / "bunny.ply"), str(data_dir / "bunny.ply"), "--poses",
                          str(tmp_path / "poses.npy"), "--mode", "all", "--bv", "kdop18", "-o",
                          str(tmp_path / "c.npy"), "--json"], capture_output=True, text=True, check=True)
    j = json.loads(out.stdout)
    assert j["poses"] == 12 and j["colliding"] == sum(len(e) > 0 for e in expect)
    assert j["pairs"] == sum(len(e) for e in expect)
    assert 0 < j["colliding"] < 12
    for key in ["build_s", "query_s", "compute_s"]:
        assert j[key] >= 0
    rows = np.load(tmp_path / "c.npy")
    for i, e in enumerate(expect):
        np.testing.assert_array_equal(rows[rows[:, 0] == i, 1:], e)
    out = subprocess.run([str(cli), "collide", str(data_dir / "bunny.ply"), str(data_dir / "bunny.ply"), "--poses",
                          str(tmp_path / "poses.npy"), "--mode", "distance", "-o", str(tmp_path / "d.npy"),
                          "--json"], capture_output=True, text=True, check=True)
    d = np.load(tmp_path / "d.npy")
    assert d.shape == (12, 8)
    for i in range(12):
        assert d[i, 1] == pytest.approx(geods.distance(mesh, None, mesh, poses[i])[0], abs=1e-9)
    assert json.loads(out.stdout)["min_distance"] == d[:, 1].min()
    # Bad poses: one line on stderr, exit code 2.
    poses[3, 5] = np.nan
    np.save(tmp_path / "bad.npy", poses)
    bad = subprocess.run([str(cli), "collide", str(data_dir / "bunny.ply"), str(data_dir / "bunny.ply"), "--poses",
                          str(tmp_path / "bad.npy")], capture_output=True, text=True)
    assert bad.returncode == 2 and "pose 3" in bad.stderr and bad.stderr.count("\n") == 1
