#!/usr/bin/python3
"""Writes fuzz_corpus.txt: the seeded corpus of degenerate boolean pairs of the csg bench.

    /usr/bin/python3 bench/compare/csg/gen_fuzz.py [--seed 1] [--out bench/compare/csg/fuzz_corpus.txt]

Cases: identical solids, copies moved or rotated by 1e-9, face-to-face, shared face parts,
edge and corner contact, coplanar faces inside, slivers a few grid steps thick, coplanar
rotated faces, a sphere against its copy moved by 1e-9 and touching at a vertex, and seeded
random boxes on a coarse lattice (many coplanar and touching faces) and random tetrahedra.
Every mesh is closed and outward oriented. Format (text):

    case NAME
    A nv nt
    x y z      (nv lines, repr of doubles)
    i j k      (nt lines)
    B nv nt
    ...
"""
import argparse
import math
import os
import random


def box(lo, hi):
    v = [(hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]) for i in range(8)]
    q = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    t = []
    for a, b, c, d in q:
        t += [(a, b, c), (a, c, d)]
    return v, t


def transformed(m, angle=0.0, shift=(0, 0, 0), axis=2):
    v, t = m
    c, s = math.cos(angle), math.sin(angle)
    out = []
    for p in v:
        x, y, z = p
        if axis == 2:
            x, y = c * x - s * y, s * x + c * y
        elif axis == 0:
            y, z = c * y - s * z, s * y + c * z
        else:
            z, x = c * z - s * x, s * z + c * x
        out.append((x + shift[0], y + shift[1], z + shift[2]))
    return out, list(t)


def icosphere(r=1.0, levels=2, center=(0, 0, 0)):
    p = (1 + 5 ** 0.5) / 2
    v = [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p), (0, -1, -p), (0, 1, -p),
         (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]
    t = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
         (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    v = [tuple(x / math.sqrt(sum(y * y for y in q)) for x in q) for q in v]
    for _ in range(levels):
        mid = {}

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                q = [(v[a][i] + v[b][i]) / 2 for i in range(3)]
                n = math.sqrt(sum(x * x for x in q))
                mid[k] = len(v)
                v.append(tuple(x / n for x in q))
            return mid[k]

        nt = []
        for a, b, c in t:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nt += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        t = nt
    return [tuple(center[i] + r * q[i] for i in range(3)) for q in v], t


def tetra(pts):
    a, b, c, d = pts
    t = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (0, 2, 3)]
    # Orient outward: the signed volume of (a, b, c, d) decides.
    u = [b[i] - a[i] for i in range(3)]
    w = [c[i] - a[i] for i in range(3)]
    z = [d[i] - a[i] for i in range(3)]
    det = u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0]) + u[2] * (w[0] * z[1] - w[1] * z[0])
    if det > 0:
        t = [(x, z_, y) for x, y, z_ in t]
    return list(pts), t


def cases(seed):
    rng = random.Random(seed)
    cube = box((0, 0, 0), (1, 1, 1))
    out = [
        ("identical", cube, cube),
        ("moved 1e-9", cube, transformed(cube, 0, (1e-9, 1e-9, 0))),
        ("rotated 1e-9", cube, transformed(cube, 1e-9)),
        ("face to face", cube, box((1, 0, 0), (2, 1, 1))),
        ("shared face part", cube, box((1, 0.25, 0.25), (2, 0.75, 0.75))),
        ("edge touching", cube, box((1, 1, 0), (2, 2, 1))),
        ("corner touching", cube, box((1, 1, 1), (2, 2, 2))),
        ("coplanar inside", cube, box((0.25, 0.25, 0), (0.75, 0.75, 1))),
        ("sliver 2e-5", cube, box((0.5, -1, -1), (0.5 + 2e-5, 2, 2))),
        ("coplanar rotated", cube, transformed(box((-0.5, -0.5, 0), (0.5, 0.5, 1)), 0.3, (0.5, 0.5, 0))),
        ("sphere moved 1e-9", icosphere(), transformed(icosphere(), 0, (1e-9, 0, 0))),
        ("sphere rotated 1e-9", icosphere(), transformed(icosphere(), 1e-9, axis=0)),
        ("spheres touching at a vertex", icosphere(), icosphere(center=(0, 2, 0))),
        ("sphere in cube, touching faces", box((-1, -1, -1), (1, 1, 1)), icosphere()),
    ]
    for i in range(8):  # boxes on a coarse lattice: coplanar and touching faces
        def rbox():
            lo = [rng.randint(0, 3) * 0.25 for _ in range(3)]
            return box(lo, [x + rng.randint(1, 3) * 0.25 for x in lo])
        out.append((f"lattice boxes {i}", rbox(), rbox()))
    for i in range(6):  # tetrahedra sharing vertices or faces of a small lattice
        pts = [tuple(rng.randint(0, 2) * 0.5 for _ in range(3)) for _ in range(12)]

        def rtet():
            while True:
                q = rng.sample(pts, 4)
                m = tetra(q)
                a, b, c, d = q
                u = [b[k] - a[k] for k in range(3)]
                w = [c[k] - a[k] for k in range(3)]
                z = [d[k] - a[k] for k in range(3)]
                det = u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0]) + u[2] * (w[0] * z[1] - w[1] * z[0])
                if abs(det) > 1e-12:
                    return m
        out.append((f"lattice tetrahedra {i}", rtet(), rtet()))
    for i in range(4):  # slivers: a needle box a random tiny thickness across a sphere
        th = 10 ** rng.uniform(-7, -4)
        x = rng.uniform(-0.5, 0.5)
        out.append((f"sliver {th:.1e}", icosphere(), transformed(box((x, -2, -0.3), (x + th, 2, 0.3)), rng.uniform(0, 1))))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "fuzz_corpus.txt"))
    a = ap.parse_args()
    with open(a.out, "w") as f:
        for name, ma, mb in cases(a.seed):
            f.write(f"case {name}\n")
            for tag, (v, t) in (("A", ma), ("B", mb)):
                f.write(f"{tag} {len(v)} {len(t)}\n")
                for p in v:
                    f.write(" ".join(repr(float(x)) for x in p) + "\n")
                for tr in t:
                    f.write(" ".join(str(i) for i in tr) + "\n")


if __name__ == "__main__":
    main()
