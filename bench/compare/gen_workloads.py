#!/usr/bin/python3
"""Deterministic workload generator for the anchor benchmarks (geods' copy).

Usage: /usr/bin/python3 bench/compare/gen_workloads.py [OUT_DIR] [--force] [--check]

  OUT_DIR   default: $ANCHORS_DATA, else <repo>/build/anchors-data
  --force   regenerate even if OUT_DIR/DONE exists and the hashes match
  --check   only verify the files against the reference hashes (no generation)

This is a copy of the reference generator ../shared/anchors/gen_workloads.py
(WORKLOADS.md); the numerical code is unchanged, so on Debian 12's numpy 1.24.2
it writes byte-identical files.  After generation every file listed in the
reference hash list is checked: ../shared/anchors/workloads.sha256 (relative
to the repo root) when it exists, else the copy bench/compare/workloads.sha256.
The result is printed and written to OUT_DIR/VERIFY.json; a mismatch is a
warning (exit 0) unless --strict is given (exit 3).
If OUT_DIR/DONE exists and the hashes match, generation is skipped.

Every file is header-less little-endian binary (except the PLY meshes, which
are standard binary_little_endian PLY with a fixed header) and is documented
in WORKLOADS.md.  All randomness comes from numpy.random.default_rng(SEED)
with the fixed seeds listed below, so re-running reproduces identical bytes.

The mesh is the Stanford bunny from the npm package `bunny` (1.0.1, 1839
vertices / 3674 triangles, closed genus-0), Loop-subdivided.  It is fetched
with `npm pack bunny@1.0.1`; if npm fails, the tarball is taken from
data/bunny-1.0.1.tgz or ../shared/data/meshes/bunny-1.0.1.tgz.  If none is
available, a noisy icosphere is used instead and this is recorded in
meta.json ("mesh_source") -- the mesh hashes then do not match.
"""
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
_ARGS = [a for a in sys.argv[1:] if not a.startswith("--")]
_FLAGS = {a for a in sys.argv[1:] if a.startswith("--")}
OUT = os.path.abspath(_ARGS[0] if _ARGS else
                      os.environ.get("ANCHORS_DATA", os.path.join(REPO, "build", "anchors-data")))
# reference hashes: the shared anchors folder beside the repo, else the project's copy
HASH_FILES = [os.path.join(REPO, "..", "shared", "anchors", "workloads.sha256"),
              os.path.join(REPO, "bench", "compare", "workloads.sha256")]
# fallback copies of the npm tarball, in order
BUNNY_TGZ = [os.path.join(REPO, "data", "bunny-1.0.1.tgz"),
             os.path.join(REPO, "..", "shared", "data", "meshes", "bunny-1.0.1.tgz")]

SEED_KNN = 1001
SEED_KNN_CLUSTER = 1002
SEED_DEL2 = 2001
SEED_DEL3 = 3001
SEED_RAYS = 4001
SEED_COLLIDE = 5001
SEED_VOLUME = 6001
SEED_CSG = 7001
SEED_ICOSPHERE = 8001


def log(*a):
    print("[gen]", *a, flush=True)


def write_raw(name, arr, dtype):
    arr = np.ascontiguousarray(arr, dtype=np.dtype(dtype).newbyteorder("<"))
    path = os.path.join(OUT, name)
    arr.tofile(path)
    log(f"wrote {name} shape={arr.shape} dtype={arr.dtype} bytes={arr.nbytes}")


# --------------------------------------------------------------------------
# mesh utilities
# --------------------------------------------------------------------------
def load_bunny():
    d = os.path.join(OUT, "npm")
    js = os.path.join(d, "package", "index.js")
    if not os.path.exists(js):
        os.makedirs(d, exist_ok=True)
        try:
            subprocess.run(["npm", "pack", "bunny@1.0.1"], cwd=d, check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=120)
        except Exception as e:  # noqa: BLE001
            log("npm pack bunny failed:", e)
            local = [p for p in BUNNY_TGZ if os.path.exists(p)]
            if not local:
                log("no local copy of bunny-1.0.1.tgz either (looked in: " + ", ".join(BUNNY_TGZ) + ")")
                return load_bunny_ply()
            log("using local copy", os.path.normpath(local[0]))
            shutil.copyfile(local[0], os.path.join(d, "bunny-1.0.1.tgz"))
        try:
            subprocess.run(["tar", "xzf", "bunny-1.0.1.tgz"], cwd=d, check=True)
        except Exception as e:  # noqa: BLE001
            log("unpacking bunny-1.0.1.tgz failed:", e)
            return None
    s = open(js).read()
    m = re.search(r"exports\.positions\s*=\s*(\[.*?\]\])", s, re.S)
    c = re.search(r"exports\.cells\s*=\s*(\[.*?\]\])", s, re.S)
    P = np.array(json.loads(m.group(1)), dtype=np.float64)
    F = np.array(json.loads(c.group(1)), dtype=np.int64)
    return P, F


BUNNY_FROM_PLY = False


def load_bunny_ply():
    """Last resort before the icosphere: the project's float32 copy data/bunny.ply (same mesh, but
    its coordinates are rounded to float32, so the mesh files will not match the reference hashes)."""
    path = os.path.join(REPO, "data", "bunny.ply")
    if not os.path.exists(path):
        return None
    d = open(path, "rb").read()
    i = d.index(b"end_header\n") + len(b"end_header\n")
    nv = int(re.search(rb"element vertex (\d+)", d[:i]).group(1))
    nf = int(re.search(rb"element face (\d+)", d[:i]).group(1))
    P = np.frombuffer(d[i:i + nv * 12], dtype="<f4").reshape(-1, 3).astype(np.float64)
    fr = np.frombuffer(d[i + nv * 12:i + nv * 12 + nf * 13], dtype=[("n", "u1"), ("v", "<i4", (3,))])
    log("using data/bunny.ply (float32 coordinates: the mesh hashes will differ from the reference)")
    global BUNNY_FROM_PLY
    BUNNY_FROM_PLY = True
    return P, fr["v"].astype(np.int64)


def icosphere_noisy():
    t = (1 + 5 ** 0.5) / 2
    P = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
                  [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                  [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                  [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    for _ in range(4):
        P, F = midpoint_subdivide(P, F)
        P /= np.linalg.norm(P, axis=1, keepdims=True)
    rng = np.random.default_rng(SEED_ICOSPHERE)
    k = rng.normal(size=(8, 3)) * 2.0
    ph = rng.uniform(0, 2 * np.pi, 8)
    r = 1 + 0.08 * np.sin(P @ k.T + ph).sum(1) / 8 ** 0.5
    return P * r[:, None], F


def unique_edges(F):
    he = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])  # half-edges, face-major blocks
    key = np.sort(he, axis=1)
    E, inv = np.unique(key, axis=0, return_inverse=True)
    return E, inv.reshape(-1)


def midpoint_subdivide(P, F):
    E, inv = unique_edges(F)
    m = len(F)
    mid = 0.5 * (P[E[:, 0]] + P[E[:, 1]])
    nv = len(P)
    e01, e12, e20 = (inv[0:m] + nv, inv[m:2 * m] + nv, inv[2 * m:3 * m] + nv)
    a, b, c = F[:, 0], F[:, 1], F[:, 2]
    NF = np.concatenate([np.stack([a, e01, e20], 1), np.stack([b, e12, e01], 1),
                         np.stack([c, e20, e12], 1), np.stack([e01, e12, e20], 1)])
    return np.vstack([P, mid]), NF


def loop_subdivide(P, F):
    """One step of Loop subdivision for a closed 2-manifold triangle mesh."""
    E, inv = unique_edges(F)
    m = len(F)
    nv = len(P)
    # opposite vertex of each half-edge: half-edge (F[:,i],F[:,i+1]) has opposite F[:,i+2]
    opp = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    oppsum = np.zeros((len(E), 3))
    np.add.at(oppsum, inv, P[opp])
    cnt = np.bincount(inv, minlength=len(E))
    assert np.all(cnt == 2), "mesh is not closed/manifold"
    odd = 0.375 * (P[E[:, 0]] + P[E[:, 1]]) + 0.125 * oppsum
    # even vertices
    nsum = np.zeros_like(P)
    np.add.at(nsum, E[:, 0], P[E[:, 1]])
    np.add.at(nsum, E[:, 1], P[E[:, 0]])
    val = np.bincount(E.reshape(-1), minlength=nv).astype(float)
    beta = (0.625 - (0.375 + 0.25 * np.cos(2 * np.pi / val)) ** 2) / val
    even = (1 - val * beta)[:, None] * P + beta[:, None] * nsum
    e01, e12, e20 = (inv[0:m] + nv, inv[m:2 * m] + nv, inv[2 * m:3 * m] + nv)
    a, b, c = F[:, 0], F[:, 1], F[:, 2]
    NF = np.concatenate([np.stack([a, e01, e20], 1), np.stack([b, e12, e01], 1),
                         np.stack([c, e20, e12], 1), np.stack([e01, e12, e20], 1)])
    return np.vstack([even, odd]), NF


def signed_volume(P, F):
    a, b, c = P[F[:, 0]], P[F[:, 1]], P[F[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0


def write_ply(name, P, F):
    path = os.path.join(OUT, name)
    P = np.ascontiguousarray(P, dtype="<f4")
    F = np.ascontiguousarray(F, dtype="<i4")
    hdr = ("ply\nformat binary_little_endian 1.0\n"
           f"element vertex {len(P)}\nproperty float x\nproperty float y\nproperty float z\n"
           f"element face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n")
    fr = np.zeros(len(F), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    fr["n"] = 3
    fr["v"] = F
    with open(path, "wb") as f:
        f.write(hdr.encode("ascii"))
        f.write(P.tobytes())
        f.write(fr.tobytes())
    log(f"wrote {name}: {len(P)} vertices, {len(F)} triangles")


def quat_to_mat(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def random_quats(rng, n):
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[q[:, 0] < 0] *= -1  # canonical: w >= 0
    return q


# --------------------------------------------------------------------------
def main():
    os.makedirs(OUT, exist_ok=True)
    t0 = time.time()
    meta = {"generator": "geods bench/compare/gen_workloads.py (copy of anchors/gen_workloads.py)", "numpy": np.__version__}

    # ---------------- knn ----------------
    rng = np.random.default_rng(SEED_KNN)
    write_raw("knn_uniform_points.f32", rng.random((1_000_000, 3), dtype=np.float32), "<f4")
    write_raw("knn_uniform_queries.f32", rng.random((100_000, 3), dtype=np.float32), "<f4")
    rng = np.random.default_rng(SEED_KNN_CLUSTER)
    centers = rng.random((100, 3))
    lab = rng.integers(0, 100, 1_000_000)
    pts = centers[lab] + rng.normal(scale=0.01, size=(1_000_000, 3))
    write_raw("knn_clustered_points.f32", pts, "<f4")
    labq = rng.integers(0, 100, 100_000)
    q = centers[labq] + rng.normal(scale=0.01, size=(100_000, 3))
    write_raw("knn_clustered_queries.f32", q, "<f4")

    # ---------------- del2 / del3 ----------------
    rng = np.random.default_rng(SEED_DEL2)
    write_raw("del2_uniform.f64", rng.random((1_000_000, 2)), "<f8")
    g = np.arange(1000, dtype=np.float64)
    gy, gx = np.meshgrid(g, g, indexing="ij")
    write_raw("del2_grid.f64", np.stack([gx.ravel(), gy.ravel()], 1), "<f8")  # row-major, x fastest
    rng = np.random.default_rng(SEED_DEL3)
    write_raw("del3_uniform.f64", rng.random((1_000_000, 3)), "<f8")

    # ---------------- mesh ----------------
    b = load_bunny()
    if b is not None:
        P0, F0 = b
        meta["mesh_source"] = "npm bunny@1.0.1 (Stanford bunny, 1839 v / 3674 f), Loop-subdivided"
        if BUNNY_FROM_PLY:
            meta["mesh_source"] = "data/bunny.ply (float32 copy of npm bunny@1.0.1), Loop-subdivided"
    else:
        P0, F0 = icosphere_noisy()
        meta["mesh_source"] = "fallback noisy icosphere (npm bunny unavailable)"
    lo, hi = P0.min(0), P0.max(0)
    P0 = (P0 - 0.5 * (lo + hi)) * (2.0 / (hi - lo).max())  # centre bbox at 0, max extent 2
    if signed_volume(P0, F0) < 0:
        F0 = F0[:, ::-1].copy()
    levels = {0: (P0, F0)}
    P, F = P0, F0
    for lvl in range(1, 5):
        P, F = loop_subdivide(P, F)
        levels[lvl] = (P, F)
    # L2 = 58,784 triangles ("~100k"/"~50k" class), L4 = 940,544 triangles ("~1M")
    PM, FM = levels[2]
    PL, FL = levels[4]
    # Loop subdivision shrinks slightly; renormalise both with the SAME transform (from L4)
    lo, hi = PL.min(0), PL.max(0)
    c, s = 0.5 * (lo + hi), 2.0 / (hi - lo).max()
    PM = (PM - c) * s
    PL = (PL - c) * s
    PM32 = PM.astype(np.float32).astype(np.float64)
    write_ply("mesh_1m.ply", PL, FL)
    write_ply("mesh_100k.ply", PM, FM)
    meta["mesh_1m"] = {"vertices": len(PL), "triangles": len(FL),
                       "bbox_min": PL.astype(np.float32).min(0).tolist(),
                       "bbox_max": PL.astype(np.float32).max(0).tolist(),
                       "volume": float(signed_volume(PL.astype(np.float32).astype(float), FL))}
    meta["mesh_100k"] = {"vertices": len(PM), "triangles": len(FM),
                         "bbox_min": PM32.min(0).tolist(), "bbox_max": PM32.max(0).tolist(),
                         "volume": float(signed_volume(PM32, FM))}
    bmin = PL.min(0)
    bmax = PL.max(0)

    # ---------------- rays ----------------
    rng = np.random.default_rng(SEED_RAYS)
    W = H = 1024
    eye = np.array([0.6, 0.5, 3.2])
    target = np.zeros(3)
    up = np.array([0.0, 1.0, 0.0])
    fov_y = 40.0
    fwd = target - eye
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    upv = np.cross(right, fwd)
    th = np.tan(np.radians(fov_y) / 2)
    jj, ii = np.meshgrid(np.arange(H), np.arange(W), indexing="ij")  # row j (top=0), column i
    u = ((ii + 0.5) / W * 2 - 1) * th * (W / H)
    v = (1 - (jj + 0.5) / H * 2) * th
    d = fwd[None, None, :] + u[..., None] * right + v[..., None] * upv
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    o = np.broadcast_to(eye, d.shape)
    write_raw("rays_coherent.f32", np.concatenate([o, d], -1).reshape(-1, 6), "<f4")
    meta["rays_coherent"] = {"width": W, "height": H, "eye": eye.tolist(), "target": target.tolist(),
                             "up": up.tolist(), "fov_y_deg": fov_y}
    n = 1_000_000
    R = 3.0
    og = rng.normal(size=(n, 3))
    og = og / np.linalg.norm(og, axis=1, keepdims=True) * R
    tg = bmin + rng.random((n, 3)) * (bmax - bmin)
    dd = tg - og
    dd /= np.linalg.norm(dd, axis=1, keepdims=True)
    write_raw("rays_incoherent.f32", np.concatenate([og, dd], 1), "<f4")
    meta["rays_incoherent"] = {"count": n, "origin_sphere_radius": R,
                               "targets": "uniform in mesh_1m bbox"}

    # ---------------- collide ----------------
    log("calibrating collision poses (KD-tree proxy) ...")
    from scipy.spatial import cKDTree
    rng = np.random.default_rng(SEED_COLLIDE)
    E, _ = unique_edges(FM)
    elen = np.linalg.norm(PM32[E[:, 0]] - PM32[E[:, 1]], axis=1).mean()
    eps = 1.5 * elen
    tree = cKDTree(PM32)
    sub = PM32[::4]
    npose = 1000
    quats = random_quats(rng, npose)
    dirs = rng.normal(size=(npose, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    fac = rng.uniform(0.75, 1.25, npose)

    def touching(Rm, t):
        x = sub @ Rm.T + t
        dist, _ = tree.query(x, k=1, distance_upper_bound=eps, workers=2)
        return np.isfinite(dist).any()

    dstar = np.zeros(npose)
    for i in range(npose):
        Rm = quat_to_mat(quats[i])
        a, bnd = 0.0, 3.5  # contact at 0, no contact at 3.5 (> 2 * bounding radius)
        for _ in range(9):
            mid = 0.5 * (a + bnd)
            if touching(Rm, mid * dirs[i]):
                a = mid
            else:
                bnd = mid
        dstar[i] = 0.5 * (a + bnd)
    # separating poses (fac > 1) whose world AABBs would not overlap are pulled back
    # (bisection on the distance) to the farthest distance where the AABBs still overlap
    amin, amax = PM32.min(0), PM32.max(0)
    scale = dstar * fac
    pulled = 0
    for i in range(npose):
        X = PM32 @ quat_to_mat(quats[i]).T
        xmin, xmax = X.min(0), X.max(0)

        def ovl(sv):
            t = sv * dirs[i]
            return bool(np.all((xmin + t <= amax) & (xmax + t >= amin)))
        if not ovl(scale[i]):
            pulled += 1
            a, bnd = 0.0, scale[i]  # AABBs overlap at 0 (both contain the origin)
            for _ in range(30):
                mid = 0.5 * (a + bnd)
                a, bnd = (mid, bnd) if ovl(mid) else (a, mid)
            scale[i] = a
    trans = dirs * scale[:, None]
    poses = np.concatenate([quats, trans], 1)
    write_raw("collide_poses.f64", poses, "<f8")
    ov = 0
    for i in range(npose):
        X = PM32 @ quat_to_mat(quats[i]).T + trans[i]
        ov += np.all((X.min(0) <= amax) & (X.max(0) >= amin))
    meta["collide"] = {"poses": npose, "mesh": "mesh_100k.ply (both objects)",
                       "proxy_eps": float(eps), "factor_range": [0.75, 1.25],
                       "proxy_expected_contact_fraction": float((fac < 1).mean()),
                       "world_aabb_overlap_fraction": float(ov / npose),
                       "poses_pulled_back_to_aabb_overlap": pulled}
    log("collide:", meta["collide"])

    # ---------------- csg ----------------
    rng = np.random.default_rng(SEED_CSG)
    qc = random_quats(rng, 1)[0]
    tc = np.array([0.35, 0.2, 0.15])
    PB = PM32 @ quat_to_mat(qc).T + tc
    write_ply("csg_a.ply", PM32, FM)
    write_ply("csg_b.ply", PB, FM)
    meta["csg"] = {"a": "csg_a.ply (= mesh_100k)", "b": "csg_b.ply (mesh_100k rotated by q then translated)",
                   "q_wxyz": qc.tolist(), "t": tc.tolist(), "triangles_each": len(FM)}

    # ---------------- volume / edt ----------------
    log("volume ...")
    from scipy.ndimage import gaussian_filter
    rng = np.random.default_rng(SEED_VOLUME)
    N = 256
    ax = np.arange(N, dtype=np.float64)
    vol = np.zeros((N, N, N), dtype=np.float64)  # [z][y][x]
    cen = rng.uniform(72, 184, (20, 3))  # (x, y, z) voxel coordinates
    sig = rng.uniform(10, 22, 20)
    amp = rng.uniform(0.6, 1.0, 20)
    for k in range(20):
        gx = np.exp(-0.5 * ((ax - cen[k, 0]) / sig[k]) ** 2)
        gy = np.exp(-0.5 * ((ax - cen[k, 1]) / sig[k]) ** 2)
        gz = np.exp(-0.5 * ((ax - cen[k, 2]) / sig[k]) ** 2)
        vol += amp[k] * gz[:, None, None] * gy[None, :, None] * gx[None, None, :]
    noise = gaussian_filter(rng.standard_normal((N, N, N)).astype(np.float32), sigma=6.0, mode="wrap")
    noise /= noise.std()
    vol += 0.02 * noise
    iso = 0.3
    vol32 = vol.astype(np.float32)
    border = np.concatenate([vol32[0].ravel(), vol32[-1].ravel(), vol32[:, 0].ravel(), vol32[:, -1].ravel(),
                             vol32[:, :, 0].ravel(), vol32[:, :, -1].ravel()])
    assert border.max() < iso, "surface would not be closed"
    write_raw("volume_256.f32", vol32, "<f4")
    binv = (vol32 > np.float32(iso)).astype(np.uint8)
    write_raw("edt_256.u8", binv, "u1")
    meta["volume"] = {"dims_zyx": [N, N, N], "layout": "C order [z][y][x], x fastest",
                      "sample_position": "voxel (x,y,z) at integer coordinates (spacing 1, origin 0)",
                      "isovalue": iso, "max": float(vol32.max()), "border_max": float(border.max()),
                      "fraction_above_iso": float(binv.mean()),
                      "blobs": {"centers_xyz": cen.tolist(), "sigma": sig.tolist(), "amp": amp.tolist()}}
    meta["edt"] = {"file": "edt_256.u8", "definition": "volume_256 > isovalue (1 = foreground)",
                   "foreground_voxels": int(binv.sum())}

    # ---------------- sdf grid ----------------
    mlo, mhi = np.array(meta["mesh_100k"]["bbox_min"]), np.array(meta["mesh_100k"]["bbox_max"])
    cen3 = 0.5 * (mlo + mhi)
    L = 1.1 * (mhi - mlo).max()
    h = L / 128
    origin = cen3 - L / 2 + 0.5 * h  # position of sample (0,0,0)
    meta["sdf"] = {"mesh": "mesh_100k.ply", "n": 128, "voxel": h, "origin_first_sample": origin.tolist(),
                   "sample_ijk": "p = origin + (i, j, k) * voxel; output layout [k][j][i], i fastest",
                   "sign": "negative inside"}

    # params.txt: flat "key value..." lines for the C++ programs
    with open(os.path.join(OUT, "params.txt"), "w") as f:
        f.write(f"iso {iso!r}\n")
        f.write(f"sdf_n 128\nsdf_voxel {h!r}\nsdf_origin {origin[0]!r} {origin[1]!r} {origin[2]!r}\n")
        f.write(f"mesh100k_volume {meta['mesh_100k']['volume']!r}\n")
    meta["generation_s"] = round(time.time() - t0, 1)
    with open(os.path.join(OUT, "meta.json"), "w") as f:
        json.dump(meta, f, indent=1)
    with open(os.path.join(OUT, "DONE"), "w") as f:
        f.write("ok\n")
    log(f"done in {time.time() - t0:.1f}s")


# --------------------------------------------------------------------------
# verification against the reference hashes
# --------------------------------------------------------------------------
def sha256_file(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 22), b""):
            h.update(chunk)
    return h.hexdigest()


def verify():
    """Check OUT against the first reference hash list found; write OUT/VERIFY.json.

    Returns {"reference", "checked", "matched", "mismatched", "missing", "ok"}.
    """
    ref = next((p for p in HASH_FILES if os.path.exists(p)), None)
    res = {"reference": os.path.normpath(ref) if ref else None, "checked": 0, "matched": [],
           "mismatched": [], "missing": [], "ok": False}
    if ref is None:
        log("verify: no reference hash list found (looked in: " + ", ".join(HASH_FILES) + ")")
    else:
        for line in open(ref):
            parts = line.split()
            if len(parts) != 2:
                continue
            want, name = parts[0], parts[1].lstrip("*")
            res["checked"] += 1
            path = os.path.join(OUT, name)
            if not os.path.exists(path):
                res["missing"].append(name)
            elif sha256_file(path) != want:
                res["mismatched"].append(name)
            else:
                res["matched"].append(name)
        res["ok"] = res["checked"] > 0 and not res["mismatched"] and not res["missing"]
        if res["ok"]:
            log(f"verify: all {res['checked']} files match the reference hashes ({res['reference']})")
        else:
            log(f"verify: MISMATCH against {res['reference']}: "
                f"{len(res['matched'])}/{res['checked']} files match")
            for name in res["mismatched"]:
                log(f"  MISMATCH {name}")
            for name in res["missing"]:
                log(f"  MISSING  {name}")
            log("  (another numpy/scipy than Debian 12's, or the icosphere fallback, changes the bytes; "
                "side-by-side comparisons stay fair, the reference figures of WORKLOADS.md do not apply)")
    if os.path.isdir(OUT):
        with open(os.path.join(OUT, "VERIFY.json"), "w") as f:
            json.dump(res, f, indent=1)
    return res


def run():
    if "--check" in _FLAGS:
        sys.exit(0 if verify()["ok"] else 3)
    accepted = os.path.join(OUT, "MISMATCH_ACCEPTED")
    if os.path.exists(os.path.join(OUT, "DONE")) and "--force" not in _FLAGS:
        log(f"{OUT}/DONE exists; verifying instead of regenerating")
        res = verify()
        if res["ok"] or res["reference"] is None:
            log("skipping generation")
            return
        if os.path.exists(accepted) and open(accepted).read().strip() == np.__version__:
            log(f"these files were generated with this numpy ({np.__version__}) and did not match "
                "then either; not regenerating (--force to retry)")
            if "--strict" in _FLAGS:
                sys.exit(3)
            return
        log("hashes do not match; regenerating")
        os.remove(os.path.join(OUT, "DONE"))
    main()
    res = verify()
    if res["ok"] or res["reference"] is None:
        if os.path.exists(accepted):
            os.remove(accepted)
    else:
        with open(accepted, "w") as f:  # do not regenerate on every run with this numpy
            f.write(np.__version__ + "\n")
        if "--strict" in _FLAGS:
            sys.exit(3)


if __name__ == "__main__":
    run()
