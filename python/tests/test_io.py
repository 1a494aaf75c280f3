"""geods io bindings: round trips, the real files of data/, malformed files."""
import gzip
import re

import numpy as np
import pytest

import geods


def cube():
    v = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=np.float32)
    f = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return v, f


@pytest.mark.parametrize("name,binary", [("c.ply", True), ("c.ply", False), ("c.obj", True),
                                         ("c.stl", True), ("c.stl", False)])
def test_mesh_round_trip(tmp_path, name, binary):
    v, f = cube()
    geods.write_mesh(tmp_path / name, v, f, binary=binary)
    rv, rf = geods.read_mesh(str(tmp_path / name))
    assert rv.dtype == np.float32 and rv.shape == (8, 3)
    assert rf.dtype == np.int32 and rf.shape == (12, 3)
    # Same triangles as sets of corner positions (STL may renumber vertices).
    def tris(vv, ff):
        return sorted(tuple(sorted(map(tuple, vv[t].tolist()))) for t in ff)
    assert tris(rv, rf) == tris(v, f)


def test_real_meshes(data_dir):
    v, f = geods.read_mesh(data_dir / "bunny.ply")
    assert v.shape == (1839, 3) and f.shape == (3674, 3)
    assert f.min() >= 0 and f.max() < len(v)
    v, f = geods.read_mesh(data_dir / "teapot.obj")
    assert f.shape == (992, 3)


def test_volume_round_trip_and_meta(tmp_path):
    for dtype in (np.uint8, np.uint16, np.int16, np.float32, np.float64):
        a = (np.arange(60).reshape(3, 4, 5) % 50).astype(dtype)
        for ext in (".npy", ".nrrd", ".nii", ".nii.gz"):
            p = tmp_path / ("v" + ext)
            geods.write_volume(p, a, origin=(1, 2, 3), spacing=(0.5, 1, 2))
            r, origin, spacing = geods.read_volume(p, with_meta=True)
            assert r.dtype == dtype and r.shape == (3, 4, 5)
            np.testing.assert_array_equal(r, a)
            if ext != ".npy":
                assert origin == (1, 2, 3) and spacing == (0.5, 1, 2)
    np.save(tmp_path / "n.npy", np.ones((2, 3, 4), dtype=np.float32))
    assert geods.read_volume(tmp_path / "n.npy").shape == (2, 3, 4)


def test_real_volumes(data_dir):
    head, origin, spacing = geods.read_volume(data_dir / "t1_head.nii.gz", with_meta=True)
    assert head.shape == (62, 128, 128)
    assert spacing == (2.0, 2.0, 3.0)


def test_points_and_segments(tmp_path, data_dir):
    rng = np.random.default_rng(1)
    for d in (2, 3):
        p = rng.normal(size=(10, d))
        for ext in (".npy", ".xyz", ".csv", ".ply"):
            geods.write_points(tmp_path / ("p" + ext), p)
            np.testing.assert_array_equal(geods.read_points(tmp_path / ("p" + ext)), p)
    land = geods.read_points(data_dir / "land_points.npy")
    assert land.shape == (4996, 2)
    np.testing.assert_array_equal(land, np.load(data_dir / "land_points.npy"))
    seg = geods.read_segments(data_dir / "land_segments.npy")
    np.testing.assert_array_equal(seg, np.load(data_dir / "land_segments.npy"))
    (tmp_path / "s.edg").write_text("1\n0 0 1 2\n")
    np.testing.assert_array_equal(geods.read_segments(tmp_path / "s.edg"), [[0, 0, 1, 2]])


def test_images(tmp_path, data_dir):
    brick = geods.read_image(data_dir / "brick.png")
    assert brick.dtype == np.uint8 and brick.shape == (512, 512)
    for shape in ((5, 7), (5, 7, 2), (5, 7, 3), (5, 7, 4)):
        a = (np.arange(np.prod(shape)) % 251).astype(np.uint8).reshape(shape)
        geods.write_png(tmp_path / "a.png", a)
        np.testing.assert_array_equal(geods.read_image(tmp_path / "a.png"), a)


def test_write_png_by_dtype(tmp_path):
    rng = np.random.default_rng(3)
    # Floats in [0, 1] are scaled to 0..255 (white stays white, not black).
    f = rng.random((6, 5, 3))
    f[0, 0] = [0.0, 1.0, 0.5]
    geods.write_png(tmp_path / "f.png", f)
    np.testing.assert_array_equal(geods.read_image(tmp_path / "f.png"), np.rint(f * 255).astype(np.uint8))
    geods.write_png(tmp_path / "f32.png", f.astype(np.float32))
    assert geods.read_image(tmp_path / "f32.png")[0, 0, 1] == 255
    # uint16 is a 16-bit PNG (read back through numpy from the raw PNG rows).
    u = rng.integers(0, 65536, size=(4, 7), dtype=np.uint16)
    u[0, :2] = [0, 65535]
    geods.write_png(tmp_path / "u16.png", u)
    assert png_16_bit_rows(tmp_path / "u16.png", 4, 7, 1).tolist() == u.tolist()
    # Other integers and bools are written as 8-bit when every value is in 0..255.
    i = rng.integers(0, 256, size=(3, 4), dtype=np.int64)
    geods.write_png(tmp_path / "i.png", i)
    np.testing.assert_array_equal(geods.read_image(tmp_path / "i.png"), i)
    geods.write_png(tmp_path / "b.png", np.eye(3, dtype=bool))
    np.testing.assert_array_equal(geods.read_image(tmp_path / "b.png"), np.eye(3))


def png_16_bit_rows(path, h, w, c):
    """The samples of a 16-bit PNG written with filter 0 rows, decoded here with zlib (an independent reader)."""
    import struct
    import zlib
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        assert zlib.crc32(kind + body) == struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])[0]
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBB", body[:10])
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    assert ihdr[:3] == (w, h, 16)
    raw = np.frombuffer(zlib.decompress(idat), dtype=np.uint8).reshape(h, 1 + 2 * w * c)
    assert (raw[:, 0] == 0).all()
    return raw[:, 1:].copy().view(">u2").reshape(h, w * c)


@pytest.mark.parametrize("image,message", [
    (np.array([[0.5, 1.5]]), "outside [0, 1]"),
    (np.array([[0.5, -0.01]], dtype=np.float32), "outside [0, 1]"),
    (np.array([[0.5, np.nan]]), "outside [0, 1]"),
    (np.array([[0.5, np.inf]]), "outside [0, 1]"),
    (np.array([[255.0, 0.0]]), "outside [0, 1]"),   # 0..255 floats are refused, not clamped to white
    (np.array([[1, 256]], dtype=np.int64), "outside 0..255"),
    (np.array([[1, -1]], dtype=np.int16), "outside 0..255"),
    (np.array([[1, 2**64 - 1]], dtype=np.uint64), "outside 0..255"),
    (np.array([[1, 70000]], dtype=np.uint32), "outside 0..255"),
    (np.array([[1 + 1j]]), "cannot write PNG"),
])
def test_write_png_refuses_values_it_would_change(tmp_path, image, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        geods.write_png(tmp_path / "x.png", image)
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("ext", [".ply", ".obj", ".stl"])
def test_write_mesh_refuses_what_read_mesh_refuses(tmp_path, ext):
    v, f = cube()
    out = tmp_path / ("x" + ext)
    for bad in (np.nan, np.inf, -np.inf, 1e300):
        w = v.astype(np.float64)
        w[5, 1] = bad
        with pytest.raises(ValueError, match="vertex 5 has a non-finite coordinate"):
            geods.write_mesh(out, w, f)
        assert not out.exists()
    for bad_index in (8, -1, 2**40):
        g = f.copy()
        g[3, 1] = bad_index
        with pytest.raises(ValueError, match="out of range"):
            geods.write_mesh(out, v, g)
        assert not out.exists()
    with pytest.raises(ValueError, match="integer array"):
        geods.write_mesh(out, v, f + 0.5)   # would be truncated to other indices
    assert not out.exists()
    geods.write_mesh(out, v, f)
    rv, rf = geods.read_mesh(out)
    assert len(rf) == 12


@pytest.mark.parametrize("ext", [".npy", ".xyz", ".csv", ".ply", ".txt"])
def test_write_points_refuses_non_finite(tmp_path, ext):
    p = np.random.default_rng(2).normal(size=(6, 3))
    for bad in (np.nan, np.inf, -np.inf):
        q = p.copy()
        q[4, 2] = bad
        with pytest.raises(ValueError, match="point 4 has a non-finite coordinate"):
            geods.write_points(tmp_path / ("p" + ext), q)
        assert not (tmp_path / ("p" + ext)).exists()


@pytest.mark.parametrize("name,reader,content", [
    ("missing.ply", geods.read_mesh, None),
    ("empty.obj", geods.read_mesh, b""),
    ("bad.ply", geods.read_mesh, b"ply\nformat ascii 1.0\nelement vertex 99999999\nproperty float x\nend_header\n1\n"),
    ("nan.off", geods.read_mesh, b"OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
    ("idx.off", geods.read_mesh, b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
    ("gz.ply.gz", geods.read_mesh, b"not gzip"),
    ("bad.nrrd", geods.read_volume, b"NRRD0004\ntype: float\ndimension: 3\nsizes: 1000 1000 1000\nendian: little\nencoding: raw\n\n"),
    ("bad.nii", geods.read_volume, b"\x00" * 400),
    ("bad.npy", geods.read_volume, b"\x93NUMPY\x01\x00\x10\x00{'descr': '<f8'}"),
    ("nan.xyz", geods.read_points, b"1 2 3\nnan 1 2\n"),
    ("none.csv", geods.read_points, b"x,y\n"),
    ("bad.edg", geods.read_segments, b"3\n0 0 1 1\n"),
    ("bad.png", geods.read_image, b"\x89PNG\r\n\x1a\n\x00\x00"),
])
def test_malformed_files_raise_value_error_naming_the_file(tmp_path, name, reader, content):
    p = tmp_path / name
    if content is not None:
        p.write_bytes(content)
    with pytest.raises(ValueError, match=name.replace(".", r"\.")):
        reader(p)


def test_gzip_mesh_and_bad_arguments(tmp_path):
    v, f = cube()
    geods.write_mesh(tmp_path / "c.ply", v, f)
    (tmp_path / "c.ply.gz").write_bytes(gzip.compress((tmp_path / "c.ply").read_bytes()))
    assert geods.read_mesh(tmp_path / "c.ply.gz")[1].shape == (12, 3)
    with pytest.raises(ValueError, match="out of range"):
        geods.write_mesh(tmp_path / "x.ply", v, f + 10)
    with pytest.raises(ValueError):
        geods.write_points(tmp_path / "x.xyz", np.zeros((3, 5)))
    with pytest.raises(ValueError):
        geods.write_volume(tmp_path / "x.nrrd", np.zeros((2, 2)))
    assert issubclass(geods.Error, ValueError)


def test_fortran_order_npy_reads_as_its_values(tmp_path):
    rng = np.random.default_rng(4)
    t = rng.normal(size=(7, 3))
    np.save(tmp_path / "t.npy", np.asfortranarray(t))
    np.testing.assert_array_equal(geods.read_table(tmp_path / "t.npy"), t)
    np.testing.assert_array_equal(geods.read_points(tmp_path / "t.npy"), t)
    v = rng.integers(0, 1000, size=(4, 5, 6)).astype(np.uint16)
    np.save(tmp_path / "v.npy", np.asfortranarray(v))
    np.testing.assert_array_equal(geods.read_volume(tmp_path / "v.npy"), v)


def test_csv_header_only_when_no_field_is_a_number(tmp_path):
    (tmp_path / "h.csv").write_text("x,y\n1,2\n3,4\n")
    np.testing.assert_array_equal(geods.read_table(tmp_path / "h.csv"), [[1, 2], [3, 4]])
    for first in ("0x10,2", "x,2", "1_000,2", "0b1,2"):
        (tmp_path / "b.csv").write_text(first + "\n3,4\n")
        with pytest.raises(ValueError, match="line 1: .* is not a number"):
            geods.read_table(tmp_path / "b.csv")


def test_off_variants(tmp_path):
    v, f = cube()
    body = f"{len(v)} {len(f)} 0\n"
    for keyword, extra in (("COFF", " 255 0 0 255"), ("NOFF", " 0 0 1"), ("CNOFF", " 0 0 1 0.5 0.5 0.5 1")):
        text = keyword + "\n" + body + "".join(f"{a} {b} {c}{extra}\n" for a, b, c in v) \
            + "".join(f"3 {a} {b} {c} 10 20 30\n" for a, b, c in f)
        (tmp_path / "c.off").write_text(text)
        rv, rf = geods.read_mesh(tmp_path / "c.off")
        np.testing.assert_array_equal(rv, v)
        np.testing.assert_array_equal(rf, f)
