"""geods.synthesize_texture and geods.fill_hole against brute force and the invariants of the C++ tests."""
import numpy as np
import pytest

import geods

from conftest import REPO


def noise_sample(shape, seed=0):
    """A sample with structure at several scales (smoothed noise), so matches are not ties."""
    rng = np.random.default_rng(seed)
    a = rng.integers(0, 256, shape).astype(np.float64)
    for axis in (0, 1):
        a = (a + np.roll(a, 1, axis) + np.roll(a, 2, axis)) / 3
    return a.astype(np.uint8)


def test_shape_channels_and_stats():
    for shape in ((32, 40), (32, 40, 3), (32, 40, 4)):
        sample = noise_sample(shape)
        out, stats = geods.synthesize_texture(sample, (24, 20), neighborhood=5, levels=2, stats=True)
        assert out.dtype == np.uint8 and out.shape == (20, 24) + shape[2:]
        assert stats["width"] == 24 and stats["height"] == 20 and stats["levels"] == 2
        assert stats["channels"] == (shape[2] if len(shape) == 3 else 1)
        assert stats["mean_neighborhood_distance"] >= 0 and stats["compute_s"] >= 0
        # Every output pixel is some sample pixel (a match copies its value).
        colours = {tuple(np.atleast_1d(p)) for p in sample.reshape(-1, stats["channels"])}
        assert all(tuple(np.atleast_1d(p)) in colours for p in out.reshape(-1, stats["channels"]))


def test_exact_search_gives_the_brute_force_image():
    sample = noise_sample((28, 28, 3), seed=4)
    for tile in (False, True):
        args = dict(neighborhood=5, levels=2, seed=7, tile=tile)
        brute = geods.synthesize_texture(sample, (30, 26), search="brute", **args)
        exact = geods.synthesize_texture(sample, (30, 26), search="exact", **args)
        assert np.array_equal(brute, exact)


def test_approximate_search_stays_within_one_plus_eps_of_exact_on_average():
    sample = noise_sample((40, 40), seed=5)
    _, exact = geods.synthesize_texture(sample, (48, 48), neighborhood=7, search="exact", stats=True)
    _, approx = geods.synthesize_texture(sample, (48, 48), neighborhood=7, search="approx", eps=0.5, stats=True)
    # Each match is within (1 + eps) of the nearest, so the mean is too (the
    # images differ, so this compares two syntheses, not pixel for pixel).
    assert approx["mean_neighborhood_distance"] <= 1.5 * exact["mean_neighborhood_distance"] + 1e-9
    assert approx["full_distances"] < exact["full_distances"]


def test_same_seed_same_bytes_other_seed_other_bytes():
    sample = noise_sample((32, 32, 3), seed=6)
    a = geods.synthesize_texture(sample, (40, 40), neighborhood=5, seed=3)
    b = geods.synthesize_texture(sample, (40, 40), neighborhood=5, seed=3)
    c = geods.synthesize_texture(sample, (40, 40), neighborhood=5, seed=4)
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_stripes_keep_their_period():
    x = np.arange(48)
    sample = np.tile(np.where(x % 6 < 3, 30, 220).astype(np.uint8), (48, 1))  # vertical stripes, period 6
    out = geods.synthesize_texture(sample, (60, 60), neighborhood=7, levels=1, seed=1)
    body = out[16:]  # past the first rows, which start from the random border
    assert np.array_equal(body[:, 6:], body[:, :-6])
    assert (body == body[0]).all()  # every row the same: the stripes stay vertical


def test_fill_hole_keeps_the_known_pixels_and_matches_the_surroundings():
    brick = geods.read_image(REPO / "data" / "brick.png")
    image = brick[:96, :96].copy()
    mask = np.zeros(image.shape[:2], np.uint8)
    mask[36:60, 30:66] = 255
    damaged = image.copy()
    damaged[mask > 0] = 0
    filled, stats = geods.fill_hole(damaged, mask, neighborhood=7, stats=True)
    assert np.array_equal(filled[mask == 0], image[mask == 0])
    assert stats["mean_neighborhood_distance"] < 40
    # The hole is filled with texture, not left black or smeared flat.
    assert filled[mask > 0].mean() > 0.5 * image.mean() and filled[mask > 0].std() > 0.3 * image.std()
    # A separate sample works too, and must have the image's channels.
    again = geods.fill_hole(damaged, mask, sample=brick[96:, 96:], neighborhood=7)
    assert np.array_equal(again[mask == 0], image[mask == 0])
    with pytest.raises(geods.Error, match="channel"):
        geods.fill_hole(damaged, mask, sample=np.stack([brick[96:, 96:]] * 3, axis=2), neighborhood=7)


def test_bad_input_raises_geods_error():
    sample = noise_sample((32, 32))
    with pytest.raises(geods.Error):
        geods.synthesize_texture(np.zeros((1, 1), np.uint8), (8, 8))
    with pytest.raises(geods.Error):
        geods.synthesize_texture(sample, (0, 8))
    with pytest.raises(geods.Error):
        geods.synthesize_texture(sample, (1 << 20, 1 << 20))
    with pytest.raises(geods.Error, match="approx"):
        geods.synthesize_texture(sample, (8, 8), search="kdtree")
    with pytest.raises(geods.Error):
        geods.synthesize_texture(sample, (8, 8), neighborhood=4)
    with pytest.raises(geods.Error, match="uint8"):
        geods.synthesize_texture(np.zeros((4, 4, 4, 4), np.uint8), (8, 8))
    with pytest.raises(geods.Error):
        geods.fill_hole(sample, np.zeros((31, 32), np.uint8))
