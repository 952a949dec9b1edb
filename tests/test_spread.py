"""lipjax.spread: the samples' residuals spread over the full-size estimate, against closed forms and scipy."""
import numpy as np
import pytest
import scipy.ndimage

from lipjax.spread import DELTA, gaussian_kernel, spread_on_host, spread_residuals, spread_sigmas_px


def test_the_gaussian_is_normalised_and_cut_at_three_sigmas():
    kernel = gaussian_kernel(1.5)
    offsets = np.arange(-5, 6)
    assert len(kernel) == 11 and kernel.sum() == pytest.approx(1.0)
    np.testing.assert_allclose(kernel / kernel.max(), np.exp(-0.5 * (offsets / 1.5) ** 2), rtol=1e-6)
    with pytest.raises(ValueError, match="sigma"):
        gaussian_kernel(0.0)


def test_a_lone_sample_keeps_its_residual_over_one_plus_delta_and_fades_as_the_gaussian():
    """z = 3 m everywhere, one sample y = 5 m: x = 3 + 2 g(dy) g(dx) / (g(dy) g(dx) + DELTA g(0)^2), and exactly z
    beyond the kernel's reach."""
    h, w, sigmas = 31, 41, (1.2, 2.0)
    z, sparse = np.full((h, w), 3.0, np.float32), np.zeros((h, w), np.float32)
    sparse[15, 20] = 5.0
    x = np.asarray(spread_residuals(z, sparse, sigmas))
    g = np.outer(gaussian_kernel(sigmas[0]), gaussian_kernel(sigmas[1]))
    ry, rx = g.shape[0] // 2, g.shape[1] // 2
    expected = z.copy()
    expected[15 - ry:15 + ry + 1, 20 - rx:20 + rx + 1] += 2.0 * g / (g + DELTA * g.max())
    np.testing.assert_allclose(x, expected, rtol=1e-5, atol=1e-6)
    assert x[15, 20] == pytest.approx(3.0 + 2.0 / (1.0 + DELTA), rel=1e-6)
    assert x[0, 0] == 3.0 and x[15, 20 + rx + 1] == 3.0


def test_spread_equals_a_normalised_convolution_with_zero_padding_on_the_host_and_in_jax():
    rng = np.random.default_rng(0)
    h, w = 24, 33
    sigmas = spread_sigmas_px((h, w), (10, 11))  # (1.2, 1.5) full-size pixels
    z = rng.uniform(1, 10, (h, w)).astype(np.float32)
    sparse = np.where(rng.random((h, w)) < 0.1, rng.uniform(1, 10, (h, w)), 0).astype(np.float32)
    g = np.outer(gaussian_kernel(sigmas[0]), gaussian_kernel(sigmas[1]))
    m = (sparse > 0).astype(np.float64)
    num = scipy.ndimage.correlate(m * (sparse - z), g, mode="constant")
    den = scipy.ndimage.correlate(m, g, mode="constant")
    expected = np.maximum(z + num / (den + DELTA * g.max()), 0)
    np.testing.assert_allclose(np.asarray(spread_residuals(z, sparse, sigmas)), expected, rtol=1e-5, atol=1e-5)
    np.testing.assert_allclose(spread_on_host(z, sparse, (10, 11)), expected, rtol=1e-5, atol=1e-5)  # cv2


def test_nothing_to_spread_leaves_z_and_depth_stays_non_negative():
    rng = np.random.default_rng(1)
    z = rng.uniform(1, 10, (16, 20)).astype(np.float32)
    np.testing.assert_array_equal(np.asarray(spread_residuals(z, np.zeros_like(z), (1.0, 1.0))), z)
    exact = np.where(rng.random(z.shape) < 0.2, z, 0).astype(np.float32)  # samples where z is already right
    np.testing.assert_allclose(np.asarray(spread_residuals(z, exact, (1.0, 1.0))), z, rtol=1e-6)
    z = np.full((16, 20), 50.0, np.float32)
    z[:, :10] = 0.5  # z jumps from 0.5 m to 50 m between columns 9 and 10
    sample = np.zeros_like(z)
    sample[8, 10] = 0.1  # a sample at 0.1 m where z is 50 m: r = -49.9 m, spread onto column 9 where z is 0.5 m
    x = np.asarray(spread_residuals(z, sample, (1.0, 1.0)))
    assert x.min() == 0.0 and x[8, 9] == 0.0  # 0.5 + ~0.6 x (-49.9) would be negative: clipped at 0


def test_the_sigmas_in_working_pixels_and_a_batch_is_frame_by_frame():
    assert spread_sigmas_px((352, 1216), (132, 456)) == pytest.approx((0.5 * 352 / 132, 0.5 * 1216 / 456))
    # scan lines: a working pixel across the lines (rows), a quarter along them (docs/decisions/0019)
    assert spread_sigmas_px((352, 1216), (132, 456), scan_lines=True) == pytest.approx((352 / 132, 0.25 * 1216 / 456))
    rng = np.random.default_rng(2)
    z = rng.uniform(1, 10, (2, 12, 18)).astype(np.float32)
    sparse = np.where(rng.random(z.shape) < 0.2, rng.uniform(1, 10, z.shape), 0).astype(np.float32)
    batched = np.asarray(spread_residuals(z, sparse, (1.5, 1.5)))
    for b in range(2):  # in jax a batch is frame by frame; the host path (cv2) agrees to float32 rounding
        np.testing.assert_allclose(batched[b], np.asarray(spread_residuals(z[b], sparse[b], (1.5, 1.5))), rtol=1e-6)
        np.testing.assert_allclose(spread_on_host(z[b], sparse[b], (4, 6)), batched[b], rtol=1e-5, atol=1e-5)
