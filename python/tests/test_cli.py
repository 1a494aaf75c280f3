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
    ("furniture.sh3f", "collection"),
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
