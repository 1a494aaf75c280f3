"""geods.convex_hull against scipy's Qhull and exact side tests."""
import numpy as np
import pytest
from scipy.spatial import ConvexHull

import geods


def test_matches_qhull_on_random_points():
    rng = np.random.default_rng(3)
    for n in (4, 10, 100, 2000):
        p = rng.standard_normal((n, 3))
        vertices, faces, dim = geods.convex_hull(p)
        assert dim == 3
        assert list(vertices) == sorted(ConvexHull(p).vertices)
        # Every point on the inner side of every face (exact orient3d >= 0).
        for f in faces[:50]:
            a, b, c = (np.broadcast_to(p[f[k]], p.shape) for k in range(3))
            assert (geods.orient3d(a, b, c, p) >= 0).all()
        # Closed and consistently oriented: each directed edge once, reversed once.
        edges = {(int(f[i]), int(f[(i + 1) % 3])) for f in faces for i in range(3)}
        assert len(edges) == 3 * len(faces)
        assert all((b, a) in edges for a, b in edges)


def test_degenerate_sets():
    cube = np.array([[x, y, z] for x in range(4) for y in range(4) for z in range(4)], float)
    vertices, faces, dim = geods.convex_hull(cube)
    assert dim == 3 and len(vertices) == 8 and len(faces) == 12
    square = np.array([[x, y, 1.0] for x in range(5) for y in range(5)])
    vertices, faces, dim = geods.convex_hull(square)
    assert dim == 2 and faces.shape == (0, 3)
    assert sorted(map(tuple, square[vertices][:, :2])) == [(0, 0), (0, 4), (4, 0), (4, 4)]
    assert geods.convex_hull(np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2.0]]))[2] == 1
    assert geods.convex_hull(np.zeros((0, 3)))[2] == -1
    with pytest.raises(geods.Error):
        geods.convex_hull(np.array([[0, 0, np.nan]]))
    with pytest.raises(geods.Error):
        geods.convex_hull(np.zeros((4, 2)))
