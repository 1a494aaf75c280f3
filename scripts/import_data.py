#!/usr/bin/python3
"""Rebuilds data/ from the third-party originals (see data/PROVENANCE.md).

Usage: /usr/bin/python3 scripts/import_data.py SHARED_DATA_DIR
SHARED_DATA_DIR is the folder of original data sets (shared/data in the
workplace). Conversions are lossless: JS arrays -> PLY/OBJ, npz -> npy,
TopoJSON arcs -> points and segments (dequantized to degrees). The hole-filling
example (brick_hole*.png) is cut out of brick.png with the geods Python module
of a build (PYTHONPATH=build/release/python).
"""
import gzip
import io
import json
import os
import re
import shutil
import sys
import tarfile

import numpy as np

SRC = sys.argv[1]
DST = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data")


def npm_arrays(tgz, member):
    with tarfile.open(os.path.join(SRC, tgz)) as t:
        text = t.extractfile(member).read().decode()
    def grab(name):
        m = re.search(r"exports\.%s\s*=\s*(\[.*?\]\])" % name, text, re.S)
        return json.loads(m.group(1))
    return np.array(grab("positions"), np.float32), np.array(grab("cells"), np.int32)


def write_ply(path, V, F):
    header = ("ply\nformat binary_little_endian 1.0\ncomment Stanford bunny (npm bunny 1.0.1)\n"
              f"element vertex {len(V)}\nproperty float x\nproperty float y\nproperty float z\n"
              f"element face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n")
    rec = np.zeros(len(F), dtype=[("n", "u1"), ("i", "<i4", 3)])
    rec["n"], rec["i"] = 3, F
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(V.astype("<f4").tobytes())
        f.write(rec.tobytes())


def write_obj(path, V, F, comment):
    with open(path, "w") as f:
        f.write(f"# {comment}\n")
        for v in V:
            f.write("v %.6g %.6g %.6g\n" % tuple(v))
        for t in F:
            f.write("f %d %d %d\n" % tuple(t + 1))


def land_arcs():
    with tarfile.open(os.path.join(SRC, "points_polygons/world-atlas-2.0.2.tgz")) as t:
        topo = json.load(t.extractfile("package/land-110m.json"))
    scale, translate = np.array(topo["transform"]["scale"]), np.array(topo["transform"]["translate"])
    arcs = []
    for arc in topo["arcs"]:
        q = np.cumsum(np.array(arc, np.int64), axis=0)  # delta-encoded integer positions
        keep = np.ones(len(q), bool)
        keep[1:] = np.any(q[1:] != q[:-1], axis=1)      # drop zero-length steps
        arcs.append(q[keep] * scale + translate)
    return arcs


def write_hole_example():
    """brick.png[128:256, 128:256] with a 40 x 48 hole blacked out, and the hole's mask."""
    import geods
    brick = geods.read_image(os.path.join(DST, "brick.png"))[128:256, 128:256].copy()
    mask = np.zeros((128, 128), np.uint8)
    mask[44:84, 40:88] = 255
    brick[mask > 0] = 0
    geods.write_png(os.path.join(DST, "brick_hole.png"), brick)
    geods.write_png(os.path.join(DST, "brick_hole_mask.png"), mask)


# The models of data/furniture.sh3f: small ones of four categories of the Blend Swap CC-0 library.
FURNITURE = ["rock1", "rock2", "rock3", "lantern", "stoneLantern", "upperCabinet", "lowerCabinet",
             "lowerCornerCabinet", "upperCornerCabinet", "ammoBox", "crate", "box", "pallet", "JapaneseLantern"]


def write_furniture_subset():
    """data/furniture.sh3f: the OBJ models of FURNITURE and their catalog entries, unchanged (no materials)."""
    import zipfile
    src = zipfile.ZipFile(os.path.join(SRC, "shape_db/BlendSwap-CC-0.sh3f"))
    catalog = src.read("PluginFurnitureCatalog.properties").decode("latin-1").splitlines()
    keep = set()
    for line in catalog:
        m = re.match(r"model#(\d+)=/blendswap-cc-0/([^/]+)/", line)
        if m and m.group(2) in FURNITURE:
            keep.add(m.group(1))
    lines = [l for l in catalog if not re.match(r"\w+#(\d+)=", l) or re.match(r"\w+#(\d+)=", l).group(1) in keep]
    with zipfile.ZipFile(os.path.join(DST, "furniture.sh3f"), "w", zipfile.ZIP_DEFLATED) as out:
        out.writestr("PluginFurnitureCatalog.properties", "\n".join(lines) + "\n")
        out.writestr("LICENSE.TXT", src.read("LICENSE.TXT"))
        for name in FURNITURE:
            member = f"blendswap-cc-0/{name}/{name}.obj"
            out.writestr(member, src.read(member))


def write_dem_bmp(elevation):
    """jacksboro_dem_crop.bmp: the DEM's top-left 128 x 96 samples as (z - 236) // 4, a
    24-bit BMP grey in all channels (the terrain module's BMP input test)."""
    from PIL import Image
    g = ((elevation[:96, :128].astype(np.int32) - 236) // 4).astype(np.uint8)
    Image.fromarray(np.stack([g, g, g], axis=-1), "RGB").save(os.path.join(DST, "jacksboro_dem_crop.bmp"))


def main():
    os.makedirs(DST, exist_ok=True)
    V, F = npm_arrays("meshes/bunny-1.0.1.tgz", "package/index.js")
    write_ply(os.path.join(DST, "bunny.ply"), V, F)
    V, F = npm_arrays("meshes/teapot-1.0.0.tgz", "package/teapot.js")
    write_obj(os.path.join(DST, "teapot.obj"), V, F, "Utah teapot (npm teapot 1.0.0), not watertight")
    for texture in ("brick", "grass", "gravel"):
        shutil.copy(os.path.join(SRC, f"textures/{texture}.png"), os.path.join(DST, f"{texture}.png"))
    write_hole_example()
    shutil.copy(os.path.join(SRC, "volumes/KmeansTest_T1UCharRaw.nii.gz"), os.path.join(DST, "t1_head.nii.gz"))
    dem = np.load(os.path.join(SRC, "heightfields/jacksboro_fault_dem.npz"))
    np.save(os.path.join(DST, "jacksboro_dem.npy"), np.ascontiguousarray(dem["elevation"]))
    write_dem_bmp(dem["elevation"])
    arcs = land_arcs()
    points = np.unique(np.concatenate(arcs), axis=0)
    segments = np.concatenate([np.hstack([a[:-1], a[1:]]) for a in arcs if len(a) > 1])
    np.save(os.path.join(DST, "land_points.npy"), points.astype(np.float64))
    np.save(os.path.join(DST, "land_segments.npy"), segments.astype(np.float64))
    write_furniture_subset()


if __name__ == "__main__":
    main()
