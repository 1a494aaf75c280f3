"""geods.SegmentVoronoi, geods.plan_path and the segvoronoi / plan commands,
checked with numpy brute force: edge samples equidistant to their two sites
with no site nearer; the medial axis of a square is its diagonals; a planned
path keeps its clearance; bad input raises ValueError."""
import json
import subprocess

import numpy as np
import pytest

import geods


def point_segment_distance(x, segs):
    """Distances from points x (n, 2) to closed segments segs (m, 4): (n, m)."""
    a, b = segs[:, :2], segs[:, 2:]
    d = b - a
    t = np.clip(((x[:, None, :] - a[None]) * d[None]).sum(-1) / (d * d).sum(-1)[None], 0, 1)
    foot = a[None] + t[..., None] * d[None]
    return np.linalg.norm(x[:, None, :] - foot, axis=-1)


def random_segments(seed, n):
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        p = np.floor(rng.uniform(0, 200, 2))
        q = p + np.floor(rng.uniform(-30, 30, 2))
        if (p == q).all():
            continue
        s = np.concatenate([p, q])
        if out and point_segment_distance(np.array([p, q, (p + q) / 2]), np.array(out)).min() < 2:
            continue
        if out and point_segment_distance(np.array(out)[:, :2], s[None]).min() < 2:
            continue
        if out and point_segment_distance(np.array(out)[:, 2:], s[None]).min() < 2:
            continue
        out.append(s)
    return np.array(out)


def site_distances(v, x):
    pts = v.points()
    segs = pts[v.segments()].reshape(-1, 4)
    dp = np.linalg.norm(x[:, None, :] - pts[None], axis=-1)
    ds = point_segment_distance(x, segs)
    return np.concatenate([dp, ds], axis=1)  # columns are site ids


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_edges_equidistant_and_nothing_nearer(seed):
    segs = random_segments(seed, 30)
    v = geods.SegmentVoronoi(segs)
    v.validate()
    e = v.edges()
    assert e["sites"].shape == (len(e["primary"]), 2)
    assert e["parabolic"].any()
    for i in range(len(e["primary"])):
        x = v.sample_edge(i, 5.0, (-50, -50, 250, 250))
        if len(x) == 0:
            continue
        d = site_distances(v, x)
        a, b = e["sites"][i]
        np.testing.assert_allclose(d[:, a], d[:, b], rtol=0, atol=1e-9 * 200)
        assert (d.min(axis=1) >= d[:, a] - 1e-9 * 200).all()
    cells = v.cells()
    assert len(cells) == v.num_points + v.num_segments
    assert sum(len(c) for c in cells) == 2 * len(e["primary"])


def test_medial_axis_of_a_square_is_its_diagonals():
    square = np.array([[0, 0, 1, 0], [1, 0, 1, 1], [1, 1, 0, 1], [0, 1, 0, 0]], float)
    v = geods.SegmentVoronoi(square)
    axis = v.medial_axis()
    assert len(axis) >= 4
    for i in axis:
        x = v.sample_edge(int(i), 0.05)
        on_diagonal = np.minimum(np.abs(x[:, 0] - x[:, 1]), np.abs(x[:, 0] + x[:, 1] - 1))
        assert on_diagonal.max() < 1e-12


def test_points_and_crossings():
    v = geods.SegmentVoronoi(np.array([[0, 0, 10, 10], [0, 10, 10, 0]], float), points=np.array([[5, 8.0]]))
    assert v.split_count() == 2
    assert v.stats()["segments"] == 4
    assert v.vertices().shape[1] == 3


def test_plan_path_keeps_clearance():
    obstacles = [np.array([[40, 40], [60, 40], [60, 60], [40, 60]], float),
                 np.array([[70, 20], [80, 25], [72, 35]], float)]
    path, length, clearance = geods.plan_path(obstacles, (10, 50), (90, 50), 3.0)
    assert path is not None and clearance >= 3.0 - 1e-9
    segs = np.concatenate([np.hstack([o, np.roll(o, -1, axis=0)]) for o in obstacles])
    assert point_segment_distance(path, segs).min() >= 3.0 - 1e-9
    assert length >= np.linalg.norm(path[-1] - path[0])
    none, length, _ = geods.plan_path(obstacles, (10, 50), (90, 50), 50.0)
    assert none is None and length == np.inf
    planner = geods.MotionPlanner(obstacles, bounds=(-10, 0, 110, 100))
    r = planner.max_radius((10, 50), (90, 50))
    assert planner.plan((10, 50), (90, 50), r * (1 - 1e-9))["found"]
    result = planner.plan((10, 50), (90, 50), r * 1.01)
    assert not result["found"] and result["reason"] in ("disconnected", "start_too_close", "goal_too_close")


def test_bad_input():
    with pytest.raises(ValueError):
        geods.SegmentVoronoi(np.array([[0, 0, np.nan, 1]]))
    with pytest.raises(ValueError):
        geods.SegmentVoronoi(np.array([[0, 0, 10, 0], [5, 0, 15, 0]], float))  # collinear overlap
    with pytest.raises(ValueError):
        geods.plan_path([np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)], (5, 5), (20, 5), 1.0)


def test_cli(cli, tmp_path):
    segs = random_segments(5, 20)
    np.savetxt(tmp_path / "segs.csv", segs, delimiter=",")
    out = subprocess.run([cli, "segvoronoi", tmp_path / "segs.csv", "-o", tmp_path / "d.json", "--svg", tmp_path / "d.svg",
                          "--json"], capture_output=True, text=True, check=True)
    report = json.loads(out.stdout)
    diagram = json.loads((tmp_path / "d.json").read_text())
    assert report["input_segments"] == 20 and len(diagram["edges"]) == report["edges"]
    (tmp_path / "obst.wkt").write_text("POLYGON((40 40, 60 40, 60 60, 40 60, 40 40))\n")
    out = subprocess.run([cli, "plan", tmp_path / "obst.wkt", "--start", "10,50", "--goal", "90,50", "--radius", "3",
                          "-o", tmp_path / "path.csv", "--json"], capture_output=True, text=True, check=True)
    report = json.loads(out.stdout)
    assert report["found"] and report["min_clearance"] >= 3 and abs(report["max_radius"] - 10) < 1e-9
    path = np.loadtxt(tmp_path / "path.csv", delimiter=",")
    assert path.shape[1] == 2
    out = subprocess.run([cli, "plan", tmp_path / "obst.wkt", "--start", "10,50", "--goal", "90,50", "--radius", "11",
                          "--json"], capture_output=True, text=True)
    assert out.returncode == 0
    report = json.loads(out.stdout)
    assert not report["found"] and report["reason"] == "disconnected"
    out = subprocess.run([cli, "plan", tmp_path / "obst.wkt", "--start", "50,50", "--goal", "90,50", "--radius", "1"],
                         capture_output=True, text=True)
    assert out.returncode == 2 and "inside an obstacle" in out.stderr
