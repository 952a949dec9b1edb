"""The working resolution of a learned prox (lipjax.resolution) and the full-size output (inference.complete_at)."""
import math

import cv2
import numpy as np
import pytest

from lipjax import inference
from lipjax.classical.interpolate import linear_fill
from lipjax.inputs import is_lidar_pattern
from lipjax.methods import get_completer
from lipjax.resolution import (
    DENSE,
    MAX_WORKING_PIXELS,
    MIN_SCALE_CHANGE,
    MIN_WORKING_SIDE_PX,
    TARGET_SPACING_PX,
    max_side_size,
    sample_spacing_px,
    working_size,
)
from lipjax.spread import spread_on_host


def _sparse(h, w, n, seed=0):
    rng = np.random.default_rng(seed)
    out = np.zeros((h, w), np.float32)
    idx = rng.choice(h * w, n, replace=False)
    out.reshape(-1)[idx] = rng.uniform(1.0, 5.0, n)
    return out


def test_sample_spacing_is_sqrt_of_pixels_per_sample():
    assert sample_spacing_px(_sparse(480, 640, 200)) == pytest.approx(math.sqrt(480 * 640 / 200))
    assert sample_spacing_px(np.zeros((4, 4))) == math.inf


def test_working_size_puts_the_samples_at_the_target_spacing():
    spacing = math.sqrt(240 * 320 / 50)  # 39.2 px
    h, w = working_size((240, 320), spacing)
    s = TARGET_SPACING_PX / spacing
    assert h * w < MAX_WORKING_PIXELS and (h, w) == (round(240 * s), round(320 * s))
    # at the working size the n samples lie TARGET_SPACING_PX apart (up to rounding)
    assert math.sqrt(h * w / 50) == pytest.approx(TARGET_SPACING_PX, rel=0.01)


def test_dense_samples_and_small_frames_run_at_full_size():
    assert working_size((200, 280), 4.7, capped=True) == (200, 280)  # a dense scan under the pixel cap
    # a KITTI-size scan: the pixel cap alone sets the scale
    h, w = working_size((352, 1216), 4.7, capped=True)
    assert h * w == pytest.approx(MAX_WORKING_PIXELS, rel=0.01) and w / h == pytest.approx(1216 / 352, rel=0.01)
    # as many scattered samples: no cap, full size
    assert working_size((352, 1216), 4.7) == (352, 1216)
    s = MIN_SCALE_CHANGE + 0.01
    assert working_size((200, 280), TARGET_SPACING_PX / s) == (200, 280)  # a resize would not pay
    # never below MIN_WORKING_SIDE_PX on the shorter side, however sparse
    assert min(working_size((480, 640), 1000.0)) == MIN_WORKING_SIDE_PX
    with pytest.raises(ValueError, match="spacing_px"):
        working_size((10, 10), 0.0)


def test_max_side_size_keeps_the_aspect():
    assert max_side_size((480, 640), 320) == (240, 320)
    assert max_side_size((100, 50), 320) == (100, 50)


class _LinearAtAnySize:
    """A stand-in learned model: the linear fill of whatever it is given."""

    name = "linear-stand-in"

    def __call__(self, rgb, sparse):
        return linear_fill(sparse)


def test_complete_at_keeps_every_measured_pixel():
    sparse = _sparse(48, 64, 60, seed=2)
    rgb = np.zeros((48, 64, 3), np.uint8)
    out = inference.complete_at(_LinearAtAnySize(), rgb, sparse, (20, 27))
    assert out.shape == (48, 64) and out.dtype == np.float32
    np.testing.assert_array_equal(out[sparse > 0], sparse[sparse > 0])
    # elsewhere: the small estimate (here the small linear fill) resized back (bilinear), the residuals spread
    small = linear_fill(inference.reproject_sparse(sparse, (20, 27)))
    back = cv2.resize(small, (64, 48), interpolation=cv2.INTER_LINEAR)
    np.testing.assert_allclose(out[sparse == 0], spread_on_host(back, sparse, (20, 27))[sparse == 0], rtol=1e-6)
    plain = inference.complete_at(_LinearAtAnySize(), rgb, sparse, (20, 27), spread=False)
    np.testing.assert_allclose(plain[sparse == 0], back[sparse == 0], rtol=1e-6)


def test_frame_size_follows_the_samples_for_learned_models_only():
    sparse = _sparse(240, 320, 50)
    model = inference.Completer.random()
    h, w = inference.frame_size(model, sparse)
    assert (h, w) == working_size((240, 320), sample_spacing_px(sparse))
    assert (h, w) != (240, 320)
    # LiDAR scan lines on a frame over the pixel cap: capped; as many scattered samples: full size
    lines = np.zeros((352, 1216), np.float32)
    lines[100::5, ::2] = 10.0
    assert is_lidar_pattern(lines)
    h, w = inference.frame_size(model, lines)
    assert h * w <= MAX_WORKING_PIXELS * 1.01 and (h, w) == working_size((352, 1216), sample_spacing_px(lines),
                                                                            capped=True)
    scattered = _sparse(352, 1216, int(np.count_nonzero(lines)))
    assert not is_lidar_pattern(scattered) and inference.frame_size(model, scattered) == (352, 1216)
    assert inference.frame_size(model, scattered, scan_lines=True) == (h, w)  # a caller's pattern is believed
    assert inference.frame_size(model, lines, scan_lines=False) == (352, 1216)
    # a dense map (a depth camera's, over DENSE samples a pixel) is capped as scan lines are; just below, full size
    n_dense = int(DENSE * 240 * 320)
    assert inference.frame_size(model, _sparse(240, 320, n_dense)) == (240, 320)
    h, w = inference.frame_size(model, _sparse(240, 320, n_dense + 1))
    s = (MAX_WORKING_PIXELS / (240 * 320)) ** 0.5  # 0.88: under MIN_SCALE_CHANGE, so the frame is resized
    assert (h, w) == (round(240 * s), round(320 * s)) == (212, 283)
    assert inference.frame_size(get_completer("linear"), sparse) == (240, 320)
    assert inference.frame_size(model, sparse, max_side=160) == (120, 160)
    with pytest.raises(inference.InputError, match="max_side 3"):
        inference.frame_size(model, sparse, max_side=3)


def test_complete_at_checks_its_inputs_before_resizing():
    # a resize would make a wrong-size image fit: the mismatch is an error first
    sparse = _sparse(48, 64, 60, seed=3)
    with pytest.raises(inference.InputError, match="shape mismatch"):
        inference.complete_at(_LinearAtAnySize(), np.zeros((20, 30, 3), np.uint8), sparse, (24, 32))
    with pytest.raises(inference.InputError, match="float metres"):
        inference.complete_at(_LinearAtAnySize(), np.zeros((48, 64, 3), np.uint8), (sparse * 1000).astype(np.uint16),
                              (24, 32))
