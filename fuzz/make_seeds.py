#!/usr/bin/env python3
"""Writes small valid seed files for every fuzz target: make_seeds.py OUT_DIR.

OUT_DIR/<target>/<seed> for the targets of fuzz/run.sh. Only the standard
library is used, so the seeds do not depend on numpy.
"""
import gzip
import struct
import sys
import zlib
from pathlib import Path


def npy(descr, shape, data):
    header = "{'descr': '%s', 'fortran_order': False, 'shape': %s, }" % (descr, repr(tuple(shape)))
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + data


def png(w, h, channels, depth=8):
    color = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    row = bytes(w * channels * depth // 8)
    raw = b"".join(b"\x00" + bytes((x * 37 + y) % 256 for x in range(len(row))) for y in range(h))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    ihdr = struct.pack(">IIBBBBB", w, h, depth, color, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def bmp(w, h):
    stride = (w * 3 + 3) & ~3
    pixels = bytes(stride * h)
    header = struct.pack("<2sIHHI", b"BM", 54 + len(pixels), 0, 0, 54)
    info = struct.pack("<IiiHHIIiiII", 40, w, h, 1, 24, 0, len(pixels), 2835, 2835, 0, 0)
    return header + info + pixels


def nifti(dims, datatype, bitpix, data):
    hdr = bytearray(348)
    struct.pack_into("<i", hdr, 0, 348)
    struct.pack_into("<8h", hdr, 40, 3, *dims, 1, 1, 1, 1)
    struct.pack_into("<hh", hdr, 70, datatype, bitpix)
    struct.pack_into("<8f", hdr, 76, 1, 2, 2, 3, 1, 1, 1, 1)
    struct.pack_into("<f", hdr, 108, 352.0)
    struct.pack_into("<ff", hdr, 112, 1.0, 0.0)
    struct.pack_into("<h", hdr, 252, 1)  # qform_code
    struct.pack_into("<6f", hdr, 256, 0, 0, 0, 10, 20, 30)  # quatern b c d, qoffset x y z
    hdr[344:348] = b"n+1\x00"
    return bytes(hdr) + b"\x00" * 4 + data


PLY_ASCII = b"""ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
element face 2
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
1 1 0
0 1 0
3 0 1 2
4 0 1 2 3
"""


def ply_binary():
    head = (b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            b"property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n")
    return head + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + b"\x03" + struct.pack("<3i", 0, 1, 2)


def stl_binary():
    tri = struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0)
    return b"binary".ljust(80, b" ") + struct.pack("<I", 2) + tri + tri


GLTF = (b'{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],'
        b'"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],'
        b'"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,'
        b'AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],'
        b'"bufferViews":[{"buffer":0,"byteLength":36}],'
        b'"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]}')


def glb():
    body = GLTF.replace(b',"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"', b"")
    body += b" " * ((4 - len(body) % 4) % 4)
    binary = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    chunks = struct.pack("<I4s", len(body), b"JSON") + body + struct.pack("<I4s", len(binary), b"BIN\x00") + binary
    return b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks


def checksum(data):
    """The payload checksum of core/archive.cpp."""
    mask = (1 << 64) - 1
    h = 0x9e3779b97f4a7c15 ^ len(data)
    whole = len(data) // 8 * 8
    for i in range(0, whole, 8):
        h = ((h ^ int.from_bytes(data[i:i + 8], "little")) * 0xff51afd7ed558ccd) & mask
        h ^= h >> 32
    tail = int.from_bytes(data[whole:], "little")
    h = ((h ^ tail) * 0xc4ceb9fe1a85ec53) & mask
    return h ^ (h >> 29)


def archive(kind, sections, version=1):
    """A geods archive (core/archive.hpp): sections are (name, type code, element bytes, payload)."""
    def up(x):
        return (x + 63) // 64 * 64
    table, payloads = b"", []
    offset = up(64 + 64 * len(sections))
    for name, code, size, data in sections:
        table += name.encode().ljust(32, b"\0") + struct.pack("<IIQQQ", code, size, offset, len(data) // size,
                                                                checksum(data))
        payloads.append((offset, data))
        offset = up(offset + len(data))
    out = bytearray(b"GEODSARC" + struct.pack("<II", 1, 0x01020304) + kind.encode().ljust(32, b"\0") +
                    struct.pack("<IIQ", version, len(sections), checksum(table)) + table)
    for at, data in payloads:
        out += bytes(at - len(out)) + data
    return bytes(out)


U8, U32, U64, F32, F64, RECORD = 0, 4, 6, 8, 9, 255


def value(name, code, fmt, x):
    return (name, code, struct.calcsize(fmt), struct.pack(fmt, x))


def kd_tree(points, nodes, perm, leaf_size):
    """A k-d tree of float64 2-D points: nodes are (begin, end, right, axis, low, high)."""
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    return archive("spatial.KdTree", [
        value("scalar", U32, "<I", F64), value("dim", U64, "<Q", 2), value("leaf_size", U64, "<Q", leaf_size),
        ("bounds_lo", F64, 8, struct.pack("<2d", min(xs), min(ys))),
        ("bounds_hi", F64, 8, struct.pack("<2d", max(xs), max(ys))),
        ("nodes", RECORD, 32, b"".join(struct.pack("<4I2d", *n) for n in nodes)),
        ("permutation", U32, 4, struct.pack("<%dI" % len(perm), *perm)),
        ("points", F64, 8, b"".join(struct.pack("<2d", *p) for p in points))])


def quadtree(points, nodes, bucket, side):
    """A quadtree of float64 points rooted at (0, 0): nodes are (first_child, parent, begin, end, depth, cx, cy)."""
    return archive("spatial.Orthtree", [
        value("scalar", U32, "<I", F64), value("dim", U64, "<Q", 2), value("bucket", U64, "<Q", bucket),
        value("max_depth", U32, "<I", 32), value("balanced", U32, "<I", 0), value("root_side", F64, "<d", side),
        ("root_lo", F64, 8, struct.pack("<2d", 0, 0)),
        ("nodes", RECORD, 28, b"".join(struct.pack("<7I", *n) for n in nodes)),
        ("permutation", U32, 4, struct.pack("<%dI" % len(points), *range(len(points)))),
        ("points", F64, 8, b"".join(struct.pack("<2d", *p) for p in points))])


def min_max_octree(n, code, fmt, samples, leaf_cells):
    """A min/max octree over an n x n x n volume (samples x fastest)."""
    cells = n - 1
    levels, dims = [], (cells + leaf_cells - 1) // leaf_cells
    while True:
        levels.append(dims)
        if dims == 1:
            break
        dims = (dims + 1) // 2
    lo, hi, below = [], [], None
    for level, d in enumerate(levels):
        mins, maxs = [], []
        for z in range(d):
            for y in range(d):
                for x in range(d):
                    if level == 0:
                        r = range(x * leaf_cells, min(x * leaf_cells + leaf_cells, cells) + 1)
                        s = [samples[i + n * (j + n * k)] for k in range(z * leaf_cells, min(z * leaf_cells + leaf_cells, cells) + 1)
                             for j in range(y * leaf_cells, min(y * leaf_cells + leaf_cells, cells) + 1) for i in r]
                        mins.append(min(s))
                        maxs.append(max(s))
                    else:
                        cd, (cmin, cmax) = levels[level - 1], below
                        kids = [cx + cd * (cy + cd * cz) for cz in range(2 * z, min(2 * z + 2, cd))
                                for cy in range(2 * y, min(2 * y + 2, cd)) for cx in range(2 * x, min(2 * x + 2, cd))]
                        mins.append(min(cmin[c] for c in kids))
                        maxs.append(max(cmax[c] for c in kids))
        below = (mins, maxs)
        lo += mins
        hi += maxs
    size = struct.calcsize(fmt)
    pack = lambda xs: struct.pack("<%d%s" % (len(xs), fmt), *xs)
    return archive("iso.MinMaxOctree", [
        value("scalar", U32, "<I", code), value("leaf_cells", U64, "<Q", leaf_cells),
        ("dims", U64, 8, struct.pack("<3Q", n, n, n)), ("origin", F32, 4, struct.pack("<3f", 0, 0, 0)),
        ("spacing", F32, 4, struct.pack("<3f", 1, 1, 1)), ("samples", code, size, pack(samples)),
        ("min", code, size, pack(lo)), ("max", code, size, pack(hi))])


def archive_seeds():
    no = 0xFFFFFFFF
    square = [(0, 0), (1, 1), (2, 0), (3, 1)]
    return {
        "leaf.kdt": kd_tree([(0, 0), (1, 0.5), (0.25, 1)], [(0, 3, 0, 0, 0, 0)], [0, 1, 2], 10),
        "split.kdt": kd_tree(square, [(0, 4, 2, 0, 1, 2), (0, 2, 0, 0, 0, 0), (2, 4, 0, 0, 0, 0)], [0, 1, 2, 3], 2),
        "leaf.qt": quadtree([(0, 0), (1, 0.5), (0.25, 1)], [(0, no, 0, 3, 0, 0, 0)], 4, 1.0),
        "split.qt": quadtree([(0, 0), (1, 1)], [(1, no, 0, 2, 0, 0, 0), (0, 0, 0, 1, 1, 0, 0), (0, 0, 1, 1, 1, 1, 0),
                                                (0, 0, 1, 1, 1, 0, 1), (0, 0, 1, 2, 1, 1, 1)], 1, 1.0),
        "u8.mmo": min_max_octree(3, U8, "B", list(range(27)), 4),
        "f32.mmo": min_max_octree(4, F32, "f", [float((i * 7) % 27) for i in range(64)], 1),
    }


I32 = 5
INF = float("inf")


def bvh_sections():
    """The sections of a one-triangle TriangleBvh (AABB, 4 wide)."""
    tri = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    values = [("builder", U32, 4, struct.pack("<I", 0)), ("bv", U32, 4, struct.pack("<I", 0)),
              ("leaf_size", I32, 4, struct.pack("<i", 8)), ("arity", I32, 4, struct.pack("<i", 4)),
              ("sah_bins", I32, 4, struct.pack("<i", 32))]
    bounds = [[0.0, INF, INF, INF], [1.0, -INF, -INF, -INF]] * 2 + [[0.0, INF, INF, INF], [0.0, -INF, -INF, -INF]]
    wide = b"".join(struct.pack("<4f", *row) for row in bounds) + struct.pack("<4I", 0, *[0xFFFFFFFF] * 3)
    wide += struct.pack("<4I", 1, 0, 0, 0)
    corners = b"".join(struct.pack("<4f", *[tri[3 * k + a]] * 4) for k in range(3) for a in range(3))
    return values + [("nodes", RECORD, 16, struct.pack("<4I", 0, 0, 0, 1)), ("triangle_ids", U32, 4, struct.pack("<I", 0)),
                     ("volumes", RECORD, 24, struct.pack("<6f", 0, 0, 0, 1, 1, 0)),
                     ("triangles", RECORD, 36, struct.pack("<9f", *tri)), ("wide4", RECORD, 128, wide),
                     ("groups", RECORD, 160, corners + bytes(16))]


def accelerator_seeds():
    corners = ("corners", RECORD, 12, struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0))
    build_s = ("build_s", F64, 8, struct.pack("<d", 0))
    grid = archive("ray.UniformGrid", [corners, build_s, ("resolution", RECORD, 12, struct.pack("<3i", 1, 1, 1)),
                                         ("cell_begin", U32, 4, struct.pack("<2I", 0, 1)),
                                         ("cell_triangles", U32, 4, struct.pack("<I", 0))])
    octree = archive("ray.RayOctree", [corners, build_s, ("depth", 6, 8, struct.pack("<Q", 0)),
                                         ("nodes", RECORD, 8, struct.pack("<2I", 0, 1)),
                                         ("leaf_triangles", U32, 4, struct.pack("<I", 0))])
    rays5d = archive("ray.RayClassifier", [corners, build_s, ("leaf_size", U32, 4, struct.pack("<I", 8)),
                                             ("max_depth", U32, 4, struct.pack("<I", 8)),
                                             ("max_references", 6, 8, struct.pack("<Q", 1 << 20)),
                                             ("cutoff", 8, 4, struct.pack("<f", 0.25))])
    bvh = archive("ray.BvhAccelerator", [corners, build_s] + bvh_sections())
    return {"grid.geods": grid, "octree.geods": octree, "rays5d.geods": rays5d, "bvh_accel.geods": bvh}


def delaunay2_seed():
    """A Delaunay2 of the triangle (0, 0), (1, 0), (0, 1) closed by its three ghost triangles."""
    ghost = 0xFFFFFFFE
    none = 0xFFFFFFFF
    xy = struct.pack("<6d", 0, 0, 1, 0, 0, 1)
    iota = struct.pack("<3I", 0, 1, 2)
    vert = struct.pack("<12I", 0, 1, 2, 1, 0, ghost, 2, 1, ghost, 0, 2, ghost)
    twin = struct.pack("<12I", 3, 6, 9, 0, 11, 7, 1, 5, 10, 2, 8, 4)
    return archive("voronoi.Delaunay2", [
        value("seed", U64, "<Q", 1), value("location", U32, "<I", 0), value("has_constraints", U8, "<B", 0),
        value("last_triangle", U32, "<I", 0), ("counters", U64, 8, struct.pack("<3Q", 0, 0, 0)),
        ("points", F64, 8, xy), ("segments", U32, 4, b""), ("intersections", U32, 4, b""),
        ("representative", U32, 4, iota), ("coords", F64, 8, xy), ("original_of", U32, 4, iota),
        ("internal_of", U32, 4, iota), ("vert", U32, 4, vert), ("twin", U32, 4, twin),
        ("free_triangles", U32, 4, b""), ("vertex_edge", U32, 4, struct.pack("<3I", 9, 7, 10)),
        ("fixed", U8, 1, b""), ("triangles", U32, 4, iota),
        ("halfedges", U32, 4, struct.pack("<3I", none, none, none)), ("hull", U32, 4, struct.pack("<3I", 0, 1, 2)),
        ("constrained", U8, 1, b""), ("public_triangle", U32, 4, struct.pack("<4I", 0, none, none, none)),
        ("internal_triangle", U32, 4, struct.pack("<I", 0))], version=2)


def sh3f():
    """A Sweet Home 3D furniture library of one OBJ model (a zip), and a plain zip of one mesh."""
    import io as _io
    import zipfile
    obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
    out = []
    for catalog in (True, False):
        buffer = _io.BytesIO()
        with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as z:
            if catalog:
                z.writestr("PluginFurnitureCatalog.properties",
                           "id#1=t\nname#1=Tetra\\u00e9dre\ncategory#1=Misc\nmodel#1=/t/t.obj\n")
            z.writestr("t/t.obj", obj)
        out.append(buffer.getvalue())
    return out


def main():
    out = Path(sys.argv[1])
    raw = bytes(range(24))
    seeds = {
        "ply": {"quad.ply": PLY_ASCII, "tri_bin.ply": ply_binary()},
        "obj": {"quad.obj": b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n"},
        "stl": {"tri.stl": b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                           b"endloop\nendfacet\nendsolid t\n", "bin.stl": stl_binary()},
        "off": {"quad.off": b"OFF\n# quad\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"},
        "gltf": {"tri.gltf": GLTF, "tri.glb": glb()},
        "image": {"g.png": png(4, 3, 1), "ga.png": png(3, 3, 2), "rgb.png": png(5, 2, 3), "rgba.png": png(2, 2, 4),
                  "g16.png": png(3, 2, 1, 16), "rgb.bmp": bmp(3, 2)},
        "npy": {"f8.npy": npy("<f8", (3, 2), struct.pack("<6d", *range(6))),
                "be.npy": npy(">i2", (2, 2), struct.pack(">4h", 1, -2, 3, -4)),
                "b1.npy": npy("|b1", (3,), b"\x01\x00\x01")},
        "nrrd": {"raw.nrrd": b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 3 4\nspacings: 1 1 2\nencoding: raw\n\n" + raw,
                 "gz.nrrd": b"NRRD0004\ntype: short\ndimension: 3\nsizes: 2 3 2\nendian: big\n"
                            b"space directions: (1,0,0) (0,2,0) (0,0,3)\nspace origin: (1,2,3)\nencoding: gzip\n\n"
                            + gzip.compress(raw)},
        "nifti": {"u8.nii": nifti((2, 3, 4), 2, 8, raw), "f4.nii.gz": gzip.compress(nifti((2, 2, 2), 16, 32, bytes(32)))},
        "points": {"p.npy": b"\x00" + npy("<f8", (2, 3), struct.pack("<6d", *range(6))),
                   "p.xyz": b"\x01" + b"0 0 0 0 0 1\n1 2 3 0 1 0\n", "p.csv": b"\x02x,y\n1,2\n3,4\n",
                   "p.ply": b"\x03" + PLY_ASCII, "p.txt": b"\x04x y z w\n1,2,3,4\n5 6 7 8\n"},
        "archive": {**archive_seeds(), "bvh.geods": archive("bvh.TriangleBvh", bvh_sections()),
                    "delaunay2.geods": delaunay2_seed(), **accelerator_seeds()},
        "shape": dict(zip(("furniture.sh3f", "meshes.zip"), sh3f()),
                      **{"labels.csv": b"path,label\nt/t.obj,Misc\n\"a,b.ply\",\"x \"\"y\"\"\"\n"}),
        "segments": {"s.npy": b"\x00" + npy("<f8", (1, 4), struct.pack("<4d", 0, 0, 1, 1)),
                     "s.edg": b"\x01" + b"2\n0 0 1 1\n1 1 2 0\n", "s.cin": b"\x02" + b"p 0 0\ns 0 0 1 1\ns 1 1 2 0\n",
                     "s.csv": b"\x03" + b"x0,y0,x1,y1\n0,0,1,1\n"},
    }
    for target, files in seeds.items():
        (out / target).mkdir(parents=True, exist_ok=True)
        for name, data in files.items():
            (out / target / name).write_bytes(data)


if __name__ == "__main__":
    main()
