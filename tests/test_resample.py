"""The in-graph resizes (lipjax.resample) against what the host path calls: cv2.resize and reproject_sparse."""
import cv2
import numpy as np
import pytest

from lipjax.inference import reproject_sparse
from lipjax.resample import area_taps, bilinear_taps, reproject_nearest, resize_area_uint8, resize_bilinear

SIZES = [((96, 128), (64, 85)), ((64, 80), (32, 40)), ((50, 70), (49, 33)), ((132, 190), (40, 61))]


@pytest.mark.parametrize("big, small", SIZES)
def test_area_resize_is_opencvs_to_a_rounding_in_a_thousand(big, small):
    rgb = np.random.default_rng(0).integers(0, 256, (*big, 3), dtype=np.uint8)
    expected = cv2.resize(rgb, small[::-1], interpolation=cv2.INTER_AREA)
    got = np.asarray(resize_area_uint8(rgb[None], small))[0]
    assert np.abs(got - expected).max() <= 1  # float sums in another order: a value at x.5 +- 1e-6 may round apart
    assert np.mean(got != expected) < 2e-3


@pytest.mark.parametrize("big, small", SIZES)
def test_bilinear_resize_is_opencvs(big, small):
    depth = np.random.default_rng(1).uniform(0.5, 80, small).astype(np.float32)
    expected = cv2.resize(depth, big[::-1], interpolation=cv2.INTER_LINEAR)
    got = np.asarray(resize_bilinear(depth[None], big))[0]
    np.testing.assert_allclose(got, expected, rtol=1e-4)  # OpenCV's rounding of its weights: ~3e-5 relative


@pytest.mark.parametrize("big, small", SIZES)
def test_reprojection_is_reproject_sparse_exactly(big, small):
    rng = np.random.default_rng(2)
    sparse = np.where(rng.random(big) < 0.2, rng.uniform(0.5, 80, big), 0).astype(np.float32)
    np.testing.assert_array_equal(np.asarray(reproject_nearest(sparse[None], small))[0],
                                  reproject_sparse(sparse, small))


def test_taps_are_partitions_of_unity():
    for n_in, n_out in ((455, 132), (1216, 455), (7, 7)):
        _, wt = area_taps(n_in, n_out)
        np.testing.assert_allclose(wt.sum(axis=1), 1.0, rtol=1e-6)
        idx, wt = bilinear_taps(n_out, n_in)
        np.testing.assert_allclose(wt.sum(axis=1), 1.0, rtol=1e-6)
        assert idx.min() >= 0 and idx.max() < n_out
    with pytest.raises(ValueError, match="shrinks"):
        area_taps(10, 20)
