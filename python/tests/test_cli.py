"""The geods command line: help, version, info, demo, and its error contract
(exit code 2 and one line on stderr naming the file and the problem)."""
import json
import subprocess

import pytest


def run(cli, *args, cwd=None):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=300, cwd=cwd)


def assert_bad_input(result, *words):
    assert result.returncode == 2, result.stdout + result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    for w in words:
        assert w in lines[0], lines[0]


def test_help_and_version(cli):
    r = run(cli, "--help")
    assert r.returncode == 0
    assert "info" in r.stdout and "demo" in r.stdout
    r = run(cli, "--version")
    assert r.returncode == 0 and r.stdout.startswith("geods ")


def test_bad_arguments_exit_2_with_one_line(cli):
    assert_bad_input(run(cli, "no-such-command"))
    assert_bad_input(run(cli, "info"), "info")
    assert_bad_input(run(cli, "info", "x.ply", "--threads", "-3"), "info")
    assert run(cli).returncode == 2


@pytest.mark.parametrize("name,kind", [
    ("bunny.ply", "mesh"), ("teapot.obj", "mesh"), ("brick.png", "image"), ("t1_head.nii.gz", "volume"),
    ("jacksboro_dem.npy", "array"), ("land_points.npy", "points"), ("land_segments.npy", "segments"),
    ("furniture.sh3f", "collection"), ("adf_bunny_v2.geodsadf", "archive"),
])
def test_info_json_on_every_data_file(cli, data_dir, name, kind):
    r = run(cli, "info", data_dir / name, "--json")
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert report["kind"] == kind
    assert report["file"].endswith(name)
    assert report["compute_s"] >= 0
    if kind == "mesh":
        assert report["triangles"] > 0 and len(report["bounds"]["min"]) == 3
    if kind == "archive":
        assert report["structure"] == "field.Adf" and report["version"] == 2
    # The human form names the file too.
    r = run(cli, "info", data_dir / name)
    assert r.returncode == 0 and name in r.stdout


def test_info_mesh_facts(cli, data_dir):
    bunny = json.loads(run(cli, "info", data_dir / "bunny.ply", "--json").stdout)
    assert (bunny["vertices"], bunny["triangles"]) == (1839, 3674)
    assert bunny["closed_manifold"] and bunny["problems"] == []
    teapot = json.loads(run(cli, "info", data_dir / "teapot.obj", "--json").stdout)
    assert not teapot["closed_manifold"]
    assert teapot["checks"]["boundary_edges"] > 0


def test_info_volume_facts(cli, data_dir):
    head = json.loads(run(cli, "info", data_dir / "t1_head.nii.gz", "--json").stdout)
    assert head["dims"] == [128, 128, 62]
    assert head["spacing"] == pytest.approx([2, 2, 3])


def test_info_raw_volume(cli, tmp_path):
    raw = tmp_path / "v.raw"
    raw.write_bytes(bytes(range(24)))
    report = json.loads(run(cli, "info", raw, "--dims", "4,3,2", "--dtype", "u8", "--json").stdout)
    assert report["kind"] == "volume" and report["dims"] == [4, 3, 2] and report["max"] == 23
    assert_bad_input(run(cli, "info", raw, "--dims", "4,4,4", "--dtype", "u8"), "v.raw")
    assert_bad_input(run(cli, "info", raw, "--dims", "4,3,2", "--dtype", "q7"), "q7")
    assert_bad_input(run(cli, "info", raw), "v.raw", "--dims")


@pytest.mark.parametrize("name,content", [
    ("missing.ply", None),
    ("empty.ply", b""),
    ("truncated.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\n"
                      b"property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                      b"end_header\n\x00\x00"),
    ("garbage.stl", b"solid x\nfacet normal nan nan\n"),
    ("bad.npy", b"\x93NUMPY\x01\x00\x10\x00{'descr': 'XX'}"),
    ("huge.npy", b"\x93NUMPY\x01\x00\x46\x00{'descr': '<f4', 'fortran_order': False, 'shape': (100000000000, 3), }   \n"),
    ("bad.png", b"\x89PNG\r\n\x1a\nnot really"),
    ("bad.nii", b"\x5c\x01\x00\x00" + b"\x00" * 40),
    ("unknown.xyzw", b"1 2 3"),
])
def test_info_malformed_input_exits_2_naming_the_file(cli, tmp_path, name, content):
    path = tmp_path / name
    if content is not None:
        path.write_bytes(content)
    assert_bad_input(run(cli, "info", path), name)


def test_info_nan_points_rejected(cli, tmp_path):
    path = tmp_path / "nan.xyz"
    path.write_text("0 0 0\n1 nan 2\n")
    assert_bad_input(run(cli, "info", path), "nan.xyz")


def test_demo_writes_gallery_with_every_step(cli, tmp_path, data_dir):
    out = tmp_path / "demo"
    r = run(cli, "demo", "--out", out, "--data", data_dir, "--json")
    assert r.returncode == 0, r.stdout + r.stderr
    report = json.loads(r.stdout)
    assert report["failed_steps"] == 0
    names = {f"{s['module']}/{s['name']}" for s in report["steps"]}
    assert {"core/info", "core/morton"} <= names
    html = (out / "index.html").read_text()
    for s in report["steps"]:
        assert f'id="{s["module"]}-{s["name"]}"' in html
    assert (out / "morton_order.svg").read_text().lstrip().startswith("<")
    assert_bad_input(run(cli, "demo", "--out", out, "--only", "nothing"), "demo")


def png_bytes(width, height, color_type, bit_depth, rows, palette=None):
    """A PNG written by hand (zlib + struct), for the kinds geods does not write: 16-bit, palette."""
    import struct
    import zlib

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    raw = b"".join(b"\0" + row for row in rows)
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, 0))
    if palette:
        out += chunk(b"PLTE", bytes(c for rgb in palette for c in rgb))
    return out + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def test_texture_json_and_bad_input(cli, data_dir, tmp_path):
    import numpy as np
    r = run(cli, "texture", data_dir / "brick.png", "-o", tmp_path / "t.png", "--size", "40,32", "--levels", "2",
            "--search", "exact", "--seed", "5", "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert (j["width"], j["height"], j["levels"], j["search"]) == (40, 32, 2, "exact")
    assert j["mean_neighborhood_distance"] > 0 and j["compute_s"] > 0
    assert (tmp_path / "t.png").exists()

    # A palette PNG is expanded to RGB; stripes of period 4 in it.
    rows = [bytes((x // 2) % 2 for x in range(48)) for _ in range(48)]
    (tmp_path / "palette.png").write_bytes(png_bytes(48, 48, 3, 8, rows, palette=[(200, 30, 30), (20, 20, 220)]))
    r = run(cli, "texture", tmp_path / "palette.png", "-o", tmp_path / "p.png", "--size", "32,32", "--neighborhood",
            "5", "--json")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["channels"] == 3

    sixteen = [np.arange(32, dtype=">u2").tobytes() * 1 for _ in range(32)]
    (tmp_path / "16.png").write_bytes(png_bytes(32, 32, 0, 16, sixteen))
    assert_bad_input(run(cli, "texture", tmp_path / "16.png", "-o", tmp_path / "o.png", "--size", "8,8"), "16-bit")
    (tmp_path / "tiny.png").write_bytes(png_bytes(1, 1, 0, 8, [b"\x80"]))
    assert_bad_input(run(cli, "texture", tmp_path / "tiny.png", "-o", tmp_path / "o.png", "--size", "8,8"), "sample")
    (tmp_path / "junk.png").write_bytes(b"not a png")
    assert_bad_input(run(cli, "texture", tmp_path / "junk.png", "-o", tmp_path / "o.png", "--size", "8,8"), "junk.png")
    brick = data_dir / "brick.png"
    assert_bad_input(run(cli, "texture", brick, "-o", tmp_path / "o.png", "--size", "0,8"), "size")
    assert_bad_input(run(cli, "texture", brick, "-o", tmp_path / "o.png", "--size", "100000,100000"), "2^30")
    assert_bad_input(run(cli, "texture", brick, "-o", tmp_path / "o.jpg", "--size", "8,8"), ".png")
    assert_bad_input(run(cli, "texture", brick, "-o", tmp_path / "o.png", "--size", "8,8", "--search", "kd"), "approx")
    assert_bad_input(run(cli, "texture", brick, "-o", tmp_path / "o.png", "--image", brick), "mask")


# ---------------------------------------------------------------- output names and standard streams

def run_bytes(cli, *args, stdin=b"", cwd=None):
    return subprocess.run([str(cli), *map(str, args)], input=stdin, capture_output=True, timeout=300, cwd=cwd)


def npy_from_bytes(data):
    import io
    import numpy as np
    return np.load(io.BytesIO(data))


@pytest.fixture
def points_and_boxes(tmp_path):
    import numpy as np
    rng = np.random.default_rng(5)
    p = rng.random((300, 2))
    lo = rng.random((20, 2)) * 0.7
    boxes = np.hstack([lo, lo + rng.random((20, 2)) * 0.5])
    np.save(tmp_path / "p.npy", p)
    np.save(tmp_path / "b.npy", boxes)
    # The oracle: brute-force counts (closed boxes).
    counts = np.array([np.all((p >= b[:2]) & (p <= b[2:]), axis=1).sum() for b in boxes])
    return tmp_path, p, boxes, counts


def test_table_outputs_are_written_in_the_format_their_name_says(cli, points_and_boxes):
    import numpy as np
    d, p, boxes, counts = points_and_boxes
    for name, load in (("c.npy", np.load), ("c.csv", lambda f: np.loadtxt(f, delimiter=",")),
                       ("c.txt", np.loadtxt), ("C.CSV", lambda f: np.loadtxt(f, delimiter=","))):
        r = run(cli, "range", d / "p.npy", "--boxes", d / "b.npy", "-o", d / name)
        assert r.returncode == 0, r.stderr
        np.testing.assert_array_equal(load(d / name), counts)
    for name in ("t.npy", "t.csv", "t.txt"):
        assert run(cli, "delaunay", d / "p.npy", "-o", d / name).returncode == 0
    tri = np.load(d / "t.npy")
    assert tri.shape[1] == 3 and tri.dtype == np.int64
    np.testing.assert_array_equal(np.loadtxt(d / "t.csv", delimiter=",", dtype=np.int64), tri)
    np.testing.assert_array_equal(np.loadtxt(d / "t.txt", dtype=np.int64), tri)
    # geods reads back what it writes.
    assert run(cli, "info", d / "t.csv", "--json").returncode == 0


@pytest.mark.parametrize("args,accepted", [
    (["range", "p.npy", "--boxes", "b.npy", "-o", "c.jpg"], ".npy, .csv, .txt"),
    (["range", "p.npy", "--boxes", "b.npy", "-o", "c"], ".npy, .csv, .txt"),
    (["delaunay", "p.npy", "-o", "t.ply"], ".npy, .csv, .txt"),
    (["delaunay", "p.npy", "--svg", "d.png"], ".svg"),
    (["voronoi", "p.npy", "-o", "v.csv"], ".json"),
    (["voronoi", "p.npy", "--svg", "v.json"], ".svg"),
    (["edt", "m.npy", "-o", "d.csv"], ".npy"),
    (["edt", "m.npy", "-o", "d.npy", "--indices", "i.txt"], ".npy"),
    (["iso", "v.npy", "--iso", "0.5", "-o", "m.off"], ".ply, .obj, .stl"),
    (["iso", "v.npy", "--iso", "0.5", "-o", "-"], ".ply, .obj, .stl"),
    (["render", "m.ply", "-o", "r.jpg"], ".png"),
    (["render", "m.ply", "-o", "-"], ".png"),
    (["texture", "s.png", "--size", "8,8", "-o", "t.bmp"], ".png"),
    (["bvh", "m.ply", "--rays", "r.npy", "-o", "h.ply"], ".npy, .csv, .txt"),
])
def test_unwritable_output_names_are_refused_before_any_work(cli, tmp_path, args, accepted):
    # The inputs do not exist: the output name is refused first, before any input is read.
    r = run(cli, *args, cwd=tmp_path)
    assert_bad_input(r, "accepted: " + accepted)
    assert not any(tmp_path.iterdir())


def test_standard_output_and_input(cli, points_and_boxes, data_dir):
    import numpy as np
    d, p, boxes, counts = points_and_boxes
    # "-o -": .npy bytes on stdout, the report on stderr.
    r = run_bytes(cli, "range", d / "p.npy", "--boxes", d / "b.npy", "-o", "-")
    assert r.returncode == 0, r.stderr
    np.testing.assert_array_equal(npy_from_bytes(r.stdout), counts)
    assert b"range:" in r.stderr
    # "-" as input: .npy, CSV text (with a header) or PLY, told apart by their bytes.
    csv = "x,y\n" + "".join(f"{x!r},{y!r}\n" for x, y in p)
    for stdin in ((d / "p.npy").read_bytes(), csv.encode()):
        r = run_bytes(cli, "range", "-", "--boxes", d / "b.npy", "-o", "-", stdin=stdin)
        assert r.returncode == 0, r.stderr
        np.testing.assert_array_equal(npy_from_bytes(r.stdout), counts)
        r = run_bytes(cli, "info", "-", "--json", stdin=stdin)
        assert r.returncode == 0, r.stderr
        report = json.loads(r.stdout)
        assert (report["kind"], report["count"], report["dim"]) == ("points", 300, 2)
    r = run_bytes(cli, "info", "-", "--json", stdin=(data_dir / "bunny.ply").read_bytes())
    assert json.loads(r.stdout)["triangles"] == 3674
    # A pipeline: delaunay of stdin to stdout equals delaunay of the file.
    r = run_bytes(cli, "delaunay", "-", "-o", "-", stdin=(d / "p.npy").read_bytes())
    assert r.returncode == 0, r.stderr
    assert run(cli, "delaunay", d / "p.npy", "-o", d / "t.npy").returncode == 0
    np.testing.assert_array_equal(npy_from_bytes(r.stdout), np.load(d / "t.npy"))
    # knn and nearest read "-" too (queries from stdin), and write .npy to "-".
    q = p[:7] + 1e-3
    np.save(d / "q.npy", q)
    r = run_bytes(cli, "knn", d / "p.npy", "--queries", "-", "--k", "2", "--indices", "-", stdin=(d / "q.npy").read_bytes())
    assert r.returncode == 0, r.stderr
    brute = np.argsort(((q[:, None, :] - p[None, :, :]) ** 2).sum(-1), axis=1)[:, :2]
    np.testing.assert_array_equal(npy_from_bytes(r.stdout), brute)
    # Two outputs cannot share stdout; an empty stdin is an error, not an empty result.
    r = run_bytes(cli, "delaunay", d / "p.npy", "-o", "-", "--svg", "-")
    assert r.returncode == 2 and b"standard output already holds another output" in r.stderr
    r = run_bytes(cli, "range", "-", "--boxes", d / "b.npy", stdin=b"")
    assert r.returncode == 2 and b"standard input is empty" in r.stderr


def test_info_reads_every_mesh_render_reads(cli, tmp_path, data_dir):
    import gzip
    import numpy as np
    import geods
    v, f = geods.read_mesh(data_dir / "bunny.ply")
    for ext in (".stl", ".obj", ".ply", ".off"):
        plain = tmp_path / ("m" + ext)
        if ext == ".off":
            plain.write_text(f"OFF\n{len(v)} {len(f)} 0\n" + "".join(f"{a} {b} {c}\n" for a, b, c in v)
                             + "".join(f"3 {a} {b} {c}\n" for a, b, c in f))
        else:
            geods.write_mesh(plain, v, f)
        packed = tmp_path / ("m" + ext + ".gz")
        packed.write_bytes(gzip.compress(plain.read_bytes()))
        r = run(cli, "info", packed, "--json")
        assert r.returncode == 0, r.stderr
        assert json.loads(r.stdout)["triangles"] == len(f)
        r = run(cli, "render", packed, "-o", tmp_path / "r.png", "--width", "8", "--height", "8")
        assert r.returncode == 0, r.stderr


def test_messages_are_short_and_speak_the_users_language(cli, tmp_path, data_dir):
    import re
    import numpy as np
    np.save(tmp_path / "p.npy", np.random.default_rng(1).random((20, 2)))
    np.save(tmp_path / "b.npy", np.array([[0.0, 0.0, 1.0, 1.0]]))
    np.save(tmp_path / "m.npy", np.ones((4, 4)))
    cases = [
        (["range", "p.npy", "--boxes", "b.npy", "--leaf-size", "0"], "must be an integer >= 1, got '0'"),
        (["range", "p.npy", "--boxes", "b.npy", "--threads", "-2"], "must be an integer >= 0"),
        (["edt", "m.npy", "-o", "d.npy", "--spacing", "1e-300,1"], "spacing 1e-300 along x"),
        (["edt", "m.npy", "-o", "d.npy", "--spacing", "1e300,1"], "spacing 1e+300 along x"),
        (["edt", "m.npy", "-o", "d.npy", "--spacing", "0,1"], "got 0 along x"),
        (["bvh", data_dir / "bunny.ply", "--leaf-size", "0"], "leaf_size must be in 1..255"),
        (["info", "/dev/null"], "/dev/null: not a regular file"),
        (["texture", data_dir / "brick.png", "-o", "t.png", "--size", "8,8", "--eps", "-1"], "eps must be"),
    ]
    for args, words in cases:
        r = run(cli, *args, cwd=tmp_path)
        assert_bad_input(r, words)
        line = r.stderr.strip()
        assert not re.search(r"\d{13,}|\d\.\d{7,}", line), line          # no 300-digit numbers
        assert "internal error" not in line and "::" not in line and "<" not in line, line
        command = str(args[0])
        assert not line.startswith(f"geods {command}: {command}:"), line  # the command is named once


def test_library_messages_print_short_numbers():
    import numpy as np
    import geods
    mask = np.ones((3, 3), dtype=bool)
    with pytest.raises(ValueError, match=r"spacing 1e-300 along x"):   # was "0.000000"
        geods.edt(mask, spacing=(1e-300, 1))
    tree = geods.DynamicKdTree(dim=2)
    tree.insert([0.0, 0.0])
    with pytest.raises(ValueError, match=r"got -1e\+300$"):            # was 301 digits
        tree.query_radius([0.0, 0.0], -1e300)


def test_knn_and_nearest_never_write_npy_bytes_under_another_name(cli, points_and_boxes):
    d = points_and_boxes[0]
    for args in (["knn", "p.npy", "--queries", "p.npy", "--k", "2", "--indices", "i.jpg"],
                 ["knn", "p.npy", "--queries", "p.npy", "--k", "2", "--distances", "x.ply"],
                 ["nearest", "p.npy", "--queries", "p.npy", "-o", "n.png"]):
        r = run(cli, *args, cwd=d)
        assert_bad_input(r, "accepted: .npy")
        assert not (d / args[-1]).exists()
