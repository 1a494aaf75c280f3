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
