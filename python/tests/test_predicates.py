"""geods.orient2d / orient3d / incircle / insphere: conventions, exact signs
against fractions.Fraction arithmetic, array forms and argument errors."""
import math
import random
from fractions import Fraction

import numpy as np
import pytest

import geods


def sign(x):
    return int(x > 0) - int(x < 0)


def det(rows):
    """Exact determinant of a small square matrix of Fractions (cofactors)."""
    if len(rows) == 1:
        return rows[0][0]
    return sum((-1) ** j * rows[0][j] * det([r[:j] + r[j + 1:] for r in rows[1:]]) for j in range(len(rows)))


def exact(points, lifted):
    """Sign of det[p_i - p_last (, |p_i - p_last|^2)] in exact rational arithmetic."""
    q = [[Fraction(x) for x in p] for p in points]
    rows = []
    for p in q[:-1]:
        d = [x - y for x, y in zip(p, q[-1])]
        rows.append(d + [sum(x * x for x in d)] if lifted else d)
    return sign(det(rows))


PREDICATES = {
    # name: (function, number of points, dimension, lifted)
    "orient2d": (geods.orient2d, 3, 2, False),
    "orient3d": (geods.orient3d, 4, 3, False),
    "incircle": (geods.incircle, 4, 2, True),
    "insphere": (geods.insphere, 5, 3, True),
}


def nudge(x, rng, ulps=2):
    for _ in range(rng.randint(0, ulps)):
        x = math.nextafter(x, math.inf if rng.random() < 0.5 else -math.inf)
    return x


def near_degenerate(name, rng, scale):
    """Points on a line / plane / circle / sphere, the last moved by ulps."""
    _, count, dim, lifted = PREDICATES[name]
    rand = lambda: [rng.uniform(-1, 1) * scale for _ in range(dim)]  # noqa: E731
    if not lifted:
        points = [rand() for _ in range(dim)]
        s, t = rng.uniform(-1, 2), rng.uniform(-1, 2)
        last = [points[0][k] + s * (points[1][k] - points[0][k]) for k in range(dim)]
        if dim == 3:
            last = [last[k] + t * (points[2][k] - points[0][k]) for k in range(dim)]
        points.append(last)
    else:
        center = rand()
        points = []
        for _ in range(count):
            v = [rng.gauss(0, 1) for _ in range(dim)]
            n = math.sqrt(sum(x * x for x in v))
            points.append([c + scale * x / n for c, x in zip(center, v)])
    points[-1] = [nudge(x, rng) for x in points[-1]]
    return points


def test_conventions():
    assert geods.orient2d((0, 0), (1, 0), (0, 1)) > 0
    assert geods.orient2d((0, 0), (0, 1), (1, 0)) < 0
    assert geods.orient2d((0, 0), (1, 1), (3, 3)) == 0
    assert geods.orient3d((0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, -1)) > 0
    assert geods.orient3d((0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)) < 0
    assert geods.incircle((0, 0), (1, 0), (0, 1), (0.25, 0.25)) > 0
    assert geods.incircle((0, 0), (1, 0), (0, 1), (2, 2)) < 0
    assert geods.incircle((0, 0), (1, 0), (0, 1), (1, 1)) == 0
    tetra = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, -1)]
    assert geods.orient3d(*tetra) > 0
    assert geods.insphere(*tetra, (0.2, 0.2, -0.2)) > 0
    assert geods.insphere(*tetra, (3, 3, 3)) < 0
    assert geods.insphere(*tetra, (1, 1, 0)) == 0
    assert isinstance(geods.orient2d([0, 0], np.array([1.0, 0.0]), (0, 1)), float)


@pytest.mark.parametrize("name", sorted(PREDICATES))
@pytest.mark.parametrize("scale", [1.0, 1e-3, 1e150, 1e-150, 1e-310])
def test_exact_signs_near_degenerate(name, scale):
    function, count, dim, lifted = PREDICATES[name]
    rng = random.Random(f"{name} {scale}")
    wrong = []
    cases = 150
    for _ in range(cases):
        points = near_degenerate(name, rng, scale)
        want = exact(points, lifted)
        got = function(*points)
        if sign(got) != want or (want == 0 and got != 0.0):
            wrong.append((points, got, want))
    assert not wrong, f"{len(wrong)} of {cases} wrong, first: {wrong[0]}"


@pytest.mark.parametrize("name", sorted(PREDICATES))
def test_exactly_degenerate_is_zero(name):
    function, count, dim, lifted = PREDICATES[name]
    if name == "orient2d":
        points = [(1e6 + 1, 3), (1e6 + 3, 7), (1e6 + 6, 13)]
    elif name == "orient3d":
        points = [(1, 2, 3), (4, 5, 6), (7, 8, 10), (10, 11, 13)]
    elif name == "incircle":
        points = [(3 / 8, 4 / 8), (-4 / 8, 3 / 8), (5 / 8, 0), (0, -5 / 8)]
    else:
        points = [(1, 2, 2), (2, -1, 2), (-2, -2, 1), (3, 0, 0), (0, 0, -3)]
    assert exact(points, lifted) == 0
    assert function(*points) == 0.0


@pytest.mark.parametrize("name", sorted(PREDICATES))
def test_array_form_matches_single_calls(name):
    function, count, dim, lifted = PREDICATES[name]
    rng = random.Random(7)
    n = 200
    stacked = [np.empty((n, dim)) for _ in range(count)]
    for r in range(n):
        points = near_degenerate(name, rng, 1.0) if r % 2 else [[rng.random() for _ in range(dim)] for _ in range(count)]
        for i, p in enumerate(points):
            stacked[i][r] = p
    result = function(*stacked)
    assert isinstance(result, np.ndarray) and result.dtype == np.float64 and result.shape == (n,)
    for r in range(n):
        rows = [s[r] for s in stacked]
        assert result[r] == function(*rows)
        assert sign(result[r]) == exact([list(map(float, p)) for p in rows], lifted)
    # Other float dtypes and nested lists are converted.
    as_float32 = function(*[s.astype(np.float32) for s in stacked])
    expected = function(*[s.astype(np.float32).astype(np.float64) for s in stacked])
    np.testing.assert_array_equal(as_float32, expected)
    np.testing.assert_array_equal(function(*[s.tolist() for s in stacked]), result)
    # Empty batches and non-contiguous views.
    assert function(*[np.empty((0, dim)) for _ in range(count)]).shape == (0,)
    wide = [np.repeat(s, 2, axis=0)[::2] for s in stacked]
    np.testing.assert_array_equal(function(*wide), result)


def test_many_rows_in_parallel():
    rng = np.random.default_rng(3)
    a, b = rng.random((2, 100_000, 2))
    t = rng.uniform(-1, 2, (100_000, 1))
    c = a + t * (b - a)  # nearly collinear
    result = geods.orient2d(a, b, c)
    for i in range(0, 100_000, 997):
        assert sign(result[i]) == exact([a[i].tolist(), b[i].tolist(), c[i].tolist()], False)


@pytest.mark.parametrize(
    "args, message",
    [
        (((0, 0, 0), (1, 0), (0, 1)), "argument 'a'"),
        (((0, 0), (1, 0), (0,)), "argument 'c'"),
        ((np.zeros((3, 2)), np.zeros((4, 2)), np.zeros((3, 2))), "4 rows"),
        ((np.zeros((3, 2)), (1, 0), np.zeros((3, 2))), "mix"),
        ((np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3))), "argument 'a'"),
        ((np.zeros((2, 2, 2)), np.zeros((2, 2)), np.zeros((2, 2))), "argument 'a'"),
        (("ab", (1, 0), (0, 1)), "argument 'a'"),
    ],
)
def test_bad_arguments_raise_value_error(args, message):
    with pytest.raises(ValueError, match=message):
        geods.orient2d(*args)


def test_wrong_arity_and_dimension():
    with pytest.raises(ValueError):
        geods.orient3d((0, 0), (1, 0), (0, 1), (1, 1))
    with pytest.raises(ValueError):
        geods.insphere(*[np.zeros((5, 3))] * 4, np.zeros((6, 3)))
    with pytest.raises(TypeError):
        geods.incircle((0, 0), (1, 0), (0, 1))


def test_non_finite_gives_nan():
    assert math.isnan(geods.orient2d((math.nan, 0), (1, 0), (0, 1)))
    assert math.isnan(geods.incircle((math.inf, 0), (1, 0), (0, 1), (1, 1)))
    out = geods.orient3d(np.array([[0, 0, 0], [math.inf, 0, 0]]), np.eye(3)[:2], np.eye(3)[1:], np.ones((2, 3)))
    assert not math.isnan(out[0]) and math.isnan(out[1])


def test_num_threads():
    before = geods.num_threads()
    assert before >= 1
    try:
        geods.set_num_threads(1)
        assert geods.num_threads() == 1
    finally:
        geods.set_num_threads(0)
    assert geods.num_threads() == before
