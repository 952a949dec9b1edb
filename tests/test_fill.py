"""The box fill used as ADMM's z_0: exact at samples, exact on constants, nearest-ish elsewhere."""
import jax.numpy as jnp
import numpy as np
import pytest

from lipjax.fill import box_fill, box_fill_with_radius, sample_radius


def test_samples_are_kept_and_radius_measures_distance_to_a_sample():
    y = np.zeros((1, 9, 11), np.float32)
    y[0, 4, 5] = 3.0
    y[0, 0, 0] = 1.0
    filled, radius = box_fill_with_radius(y, (y > 0).astype(np.float32))
    filled, radius = np.asarray(filled), np.asarray(radius)
    assert filled[0, 4, 5] == 3.0 and filled[0, 0, 0] == 1.0
    assert radius[0, 4, 5] == 0 and radius[0, 0, 0] == 0
    # a pixel one step (Chebyshev distance 1) from the centre sample is filled from the radius-1 window
    assert radius[0, 5, 6] == 1 and filled[0, 5, 6] == 3.0
    # the Chebyshev distance d to the nearest sample lies in (radius / 2, radius]
    d = np.minimum(np.maximum(np.abs(np.arange(9)[:, None] - 4), np.abs(np.arange(11)[None] - 5)),
                   np.maximum(np.arange(9)[:, None], np.arange(11)[None]))
    unmeasured = radius[0] > 0
    assert np.all(d[unmeasured] <= radius[0][unmeasured]) and np.all(d[unmeasured] > radius[0][unmeasured] / 2)


def test_constant_depth_is_reproduced_everywhere():
    rng = np.random.default_rng(0)
    mask = (rng.random((2, 20, 30)) < 0.02).astype(np.float32)
    mask[:, 3, 3] = 1
    filled = np.asarray(box_fill(2.5 * mask, mask))
    np.testing.assert_allclose(filled, 2.5, rtol=1e-6)


def test_empty_image_stays_zero():
    y = np.zeros((1, 5, 5), np.float32)
    assert not np.asarray(box_fill(y, y)).any()


@pytest.mark.parametrize("shape,p", [((2, 13, 21), 0.01), ((1, 40, 64), 0.002), ((1, 7, 300), 0.2)])
def test_sample_radius_equals_the_box_fills_radius(shape, p):
    rng = np.random.default_rng(0)
    mask = (rng.random(shape) < p).astype(np.float32)
    mask.reshape(-1)[0] = 1.0  # at least one sample
    y = mask * rng.uniform(1, 5, shape).astype(np.float32)
    expected = box_fill_with_radius(jnp.asarray(y), jnp.asarray(mask))[1]
    np.testing.assert_array_equal(sample_radius(jnp.asarray(mask)), expected)


def test_sample_radius_without_samples_is_zero_like_the_box_fills():
    mask = jnp.zeros((2, 9, 13), jnp.float32)
    np.testing.assert_array_equal(sample_radius(mask), box_fill_with_radius(mask, mask)[1])
    assert not np.asarray(sample_radius(mask)).any()
