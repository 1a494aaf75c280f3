"""geods.edt and `geods edt` against brute force and scipy's distance_transform_edt."""
import json
import subprocess

import numpy as np
import pytest

import geods


def brute_force(mask, spacing):
    """Squared distance and flat index of the nearest zero, numpy axis order; spacing x first."""
    s = np.array(spacing[::-1], dtype=np.float64)
    grid = np.indices(mask.shape).reshape(mask.ndim, -1).T.astype(np.float64)
    zeros = np.flatnonzero(mask.ravel() == 0)
    diff = (grid[:, None, :] - grid[zeros][None, :, :]) * s
    # The library's sum order: x first, then y, then z (the last numpy axis first).
    d = np.zeros(diff.shape[:2])
    for axis in range(mask.ndim - 1, -1, -1):
        d = d + diff[:, :, axis] ** 2
    best = np.argmin(d, axis=1)  # first of equals: the smallest flat index
    return d[np.arange(len(d)), best].reshape(mask.shape), zeros[best].reshape(mask.shape)


@pytest.mark.parametrize("shape", [(40,), (17, 23), (9, 8, 11)])
@pytest.mark.parametrize("foreground", [0.1, 0.6, 0.95])
def test_edt_equals_brute_force(shape, foreground):
    rng = np.random.default_rng(len(shape) * 10 + int(foreground * 10))
    mask = (rng.random(shape) < foreground).astype(np.float32) * rng.integers(1, 5, shape)
    mask.flat[0] = 0  # at least one zero
    for spacing in [None, (1, 2, 3)[: len(shape)]]:
        sq, idx = brute_force(mask, spacing or (1,) * len(shape))
        d, i = geods.edt(mask, spacing=spacing, return_indices=True)
        assert d.dtype == np.float64 and d.shape == shape and i.shape == shape
        np.testing.assert_array_equal(d, np.sqrt(sq))
        np.testing.assert_array_equal(i, idx)
        np.testing.assert_array_equal(geods.edt(mask, spacing=spacing, squared=True), sq)


def test_edt_matches_scipy_on_real_data(data_dir):
    ndimage = pytest.importorskip("scipy.ndimage")
    head = geods.read_volume(str(data_dir / "t1_head.nii.gz"))
    mask = head[::2, ::2, ::2] > np.percentile(head, 60)
    spacing = (0.9, 1.1, 1.3)  # x, y, z: scipy's sampling is in numpy axis order, the reverse
    expected = ndimage.distance_transform_edt(mask, sampling=spacing[::-1])
    np.testing.assert_allclose(geods.edt(mask, spacing=spacing), expected, rtol=1e-12)
    brick = geods.read_image(str(data_dir / "brick.png"))
    stones = brick if brick.ndim == 2 else brick[..., 0]
    stones = stones > 100
    np.testing.assert_array_equal(geods.edt(stones), ndimage.distance_transform_edt(stones))


def test_edt_degenerate_and_bad_input():
    assert np.isinf(geods.edt(np.ones((3, 4)))).all()
    d, i = geods.edt(np.ones(5), return_indices=True)
    assert (i == -1).all()
    d, i = geods.edt(np.zeros((2, 3)), return_indices=True)
    assert (d == 0).all() and (i.ravel() == np.arange(6)).all()
    assert geods.edt(np.array([True, False, True]), spacing=2.5).tolist() == [2.5, 0, 2.5]
    with pytest.raises(geods.Error, match="NaN"):
        geods.edt(np.array([0.0, np.nan]))
    with pytest.raises(geods.Error, match="1-, 2- or 3-D"):
        geods.edt(np.zeros((2, 2, 2, 2)))
    with pytest.raises(geods.Error, match="spacing"):
        geods.edt(np.zeros((2, 2)), spacing=(1, 1, 1))
    with pytest.raises(geods.Error, match="spacing"):
        geods.edt(np.zeros((2, 2)), spacing=(1, 0))
    with pytest.raises(geods.Error, match="numbers"):
        geods.edt(np.array(["a", "b"]))


def run(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=300)


def test_cli_edt_npy_volume_and_image(cli, data_dir, tmp_path):
    rng = np.random.default_rng(3)
    mask = (rng.random((6, 7, 8)) < 0.8).astype(np.uint8)
    mask[0, 0, 0] = 0
    np.save(tmp_path / "m.npy", mask)
    r = run(cli, "edt", tmp_path / "m.npy", "-o", tmp_path / "d.npy", "--spacing", "1,2,3", "--indices",
            tmp_path / "i.npy", "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["dims"] == [8, 7, 6] and j["spacing"] == [1, 2, 3] and j["foreground"] == int(mask.sum())
    d, i = geods.edt(mask, spacing=(1, 2, 3), return_indices=True)
    np.testing.assert_array_equal(np.load(tmp_path / "d.npy"), d)
    np.testing.assert_array_equal(np.load(tmp_path / "i.npy"), i)
    assert j["max_distance"] == d.max()

    # A NIfTI volume keeps its header spacing; an image is 2-D (its first channel).
    r = run(cli, "edt", data_dir / "brick_hole_mask.png", "-o", tmp_path / "h.npy", "--json")
    assert r.returncode == 0, r.stderr
    hole = geods.read_image(str(data_dir / "brick_hole_mask.png"))
    hole = hole if hole.ndim == 2 else hole[..., 0]
    np.testing.assert_array_equal(np.load(tmp_path / "h.npy"), geods.edt(hole))

    bad = [(["--spacing", "1,2"], "3 values"), (["--spacing", "1,-2,3"], "spacing")]
    for args, words in bad:
        r = run(cli, "edt", tmp_path / "m.npy", "-o", tmp_path / "x.npy", *args)
        assert r.returncode == 2 and words in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    np.save(tmp_path / "nan.npy", np.array([[0.0, np.nan]]))
    r = run(cli, "edt", tmp_path / "nan.npy", "-o", tmp_path / "x.npy")
    assert r.returncode == 2 and "NaN" in r.stderr
    r = run(cli, "edt", tmp_path / "m.npy", "-o", tmp_path / "x.png")
    assert r.returncode == 2 and ".npy" in r.stderr
    r = run(cli, "edt", tmp_path / "missing.npy", "-o", tmp_path / "x.npy")
    assert r.returncode == 2 and "missing.npy" in r.stderr
