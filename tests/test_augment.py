"""Training augmentation (lipjax.data.augment): geometry of the zoomed crop, determinism, noise statistics."""
import dataclasses

import numpy as np
import pytest

from lipjax.data.augment import (
    DEFAULT_TRAINING,
    Augment,
    augment_batch,
    camera_noise,
    move_samples,
    paint_texture,
    perturb_samples,
    photometric,
    relight,
)
from lipjax.data.frame import Batch


def _batch(n=4, h=40, w=48, seed=0):
    rng = np.random.default_rng(seed)
    gt = rng.uniform(1.0, 9.0, (n, h, w)).astype(np.float32)
    sparse = np.where(rng.random((n, h, w)) < 0.1, gt, 0.0).astype(np.float32)
    rgb = rng.integers(0, 256, (n, h, w, 3), dtype=np.uint8)
    return Batch(rgb=rgb, sparse=sparse, gt=gt, gt_valid=np.ones((n, h, w), bool))


def test_no_augmentation_is_a_plain_crop():
    b = _batch()
    out = augment_batch(b, Augment(), (16, 24), seed=0, step=3)
    assert out.rgb.shape == (4, 16, 24, 3) and out.sparse.shape == (4, 16, 24)
    for i in range(4):  # each example is a window of its frame, the same window for every array
        hits = [(t, l) for t in range(25) for l in range(25) if np.array_equal(out.gt[i], b.gt[i, t:t + 16, l:l + 24])]
        assert len(hits) == 1
        t, l = hits[0]
        np.testing.assert_array_equal(out.rgb[i], b.rgb[i, t:t + 16, l:l + 24])
        np.testing.assert_array_equal(out.sparse[i], b.sparse[i, t:t + 16, l:l + 24])


@pytest.mark.parametrize("zoom", [1.3, 0.8])
def test_zoomed_samples_land_on_their_own_ground_truth(zoom):
    """Every moved sample sits on a pixel whose (nearest-neighbour) ground truth is within the sample's pixel."""
    b = _batch(n=3, h=60, w=64)
    aug = Augment(zoom=(zoom, zoom))
    out = augment_batch(b, aug, (32, 40), seed=1, step=0)
    measured = out.sparse > 0
    assert measured.sum() > 20
    if zoom > 1:  # one old pixel covers several new ones: the sample lands inside its own pixel's footprint
        np.testing.assert_array_equal(out.sparse[measured], out.gt[measured])
    else:
        for i in range(3):
            _check_shrunk_samples(b.sparse[i], b.gt[i], out.sparse[i], out.gt[i], zoom)
    # each example's samples are its frame's moved into one window of the frame (move_samples: where several land
    # in one new pixel, the nearest wins); the window's corner is drawn, so look for it among all the corners
    for i in range(3):
        corners = [(t, l) for t in range(60) for l in range(64) if np.array_equal(
            out.sparse[i], move_samples(b.sparse[i], t, l, zoom, (32, 40)))]
        assert len(corners) >= 1 and all(t + 32 / zoom <= 60 and l + 40 / zoom <= 64 for t, l in corners)


def _check_shrunk_samples(sparse, gt, new_sparse, new_gt, s):
    """Zoom s < 1: new pixel x covers the old pixels r with floor((r + 0.5 - top) * s) = x (its footprint), and its
    ground truth is the old one nearest its centre, at old coordinate (x + 0.5) / s + top - 0.5. The window's corner
    is found from the ground truth alone; then each new pixel holds the nearest of the samples in its footprint,
    and its ground truth comes from that footprint too (for s = 0.8 no centre falls half-way between two pixels)."""
    h, w = new_gt.shape
    near_r, near_c = (np.round((np.arange(n) + 0.5) / s - 0.5).astype(int) for n in (h, w))
    corners = [(t, l) for t in range(gt.shape[0] - near_r[-1]) for l in range(gt.shape[1] - near_c[-1])
               if np.array_equal(new_gt, gt[np.ix_(near_r + t, near_c + l)])]
    assert len(corners) == 1
    top, left = corners[0]
    for x in range(h):
        rows = [r for r in range(gt.shape[0]) if np.floor((r + 0.5 - top) * s) == x]
        assert near_r[x] + top in rows
        for y in range(w):
            cols = [c for c in range(gt.shape[1]) if np.floor((c + 0.5 - left) * s) == y]
            assert near_c[y] + left in cols
            footprint = sparse[np.ix_(rows, cols)]
            samples = footprint[footprint > 0]
            assert new_sparse[x, y] == (samples.min() if samples.size else 0.0)


def test_move_samples_keeps_the_nearest_where_samples_collide():
    sparse = np.zeros((4, 4), np.float32)
    sparse[0, 0], sparse[0, 1], sparse[3, 3] = 5.0, 2.0, 7.0
    out = move_samples(sparse, top=0, left=0, scale=0.5, shape=(2, 2))
    np.testing.assert_array_equal(out, [[2.0, 0.0], [0.0, 7.0]])


def test_augmentation_is_a_pure_function_of_seed_step_and_example_index():
    b = _batch()
    a1 = augment_batch(b, DEFAULT_TRAINING, (16, 24), seed=5, step=7)
    a2 = augment_batch(b, DEFAULT_TRAINING, (16, 24), seed=5, step=7)
    for f in ("rgb", "sparse", "gt", "gt_valid"):
        np.testing.assert_array_equal(getattr(a1, f), getattr(a2, f))
    # a process that holds examples 2..3 of the global batch augments them exactly as the single process did
    half = Batch(*(getattr(b, f)[2:] for f in ("rgb", "sparse", "gt", "gt_valid")))
    a3 = augment_batch(half, DEFAULT_TRAINING, (16, 24), seed=5, step=7, first_example=2)
    np.testing.assert_array_equal(a3.sparse, a1.sparse[2:])
    a4 = augment_batch(b, DEFAULT_TRAINING, (16, 24), seed=5, step=8)
    assert not np.array_equal(a4.rgb, a1.rgb)


def test_photometric_identity_and_range():
    rgb = np.random.default_rng(0).integers(0, 256, (8, 8, 3), dtype=np.uint8)
    rng = np.random.default_rng(0)
    np.testing.assert_array_equal(photometric(rgb, Augment(), rng), rgb)
    out = photometric(rgb, Augment(brightness=0.5, contrast=0.5, saturation=0.5, gamma=1.0), rng)
    assert out.dtype == np.uint8 and not np.array_equal(out, rgb)
    # Brightness alone is one gain b ~ U(0.5, 1.5) on every channel, clipped to the uint8 range.
    b = np.random.default_rng(7).uniform(0.5, 1.5)
    expected = np.round(np.clip(rgb.astype(np.float32) / 255 * np.float32(b), 0, 1) * 255).astype(np.uint8)
    np.testing.assert_array_equal(photometric(rgb, Augment(brightness=0.5), np.random.default_rng(7)), expected)


def test_sensor_noise_is_relative_and_outliers_only_push_samples_back():
    rng = np.random.default_rng(0)
    sparse = np.where(rng.random((200, 200)) < 0.5, rng.uniform(1, 50, (200, 200)), 0).astype(np.float32)
    noisy = perturb_samples(sparse, Augment(depth_noise=0.02), np.random.default_rng(1))
    m = sparse > 0
    np.testing.assert_array_equal(noisy[~m], 0.0)
    rel = noisy[m] / sparse[m] - 1
    assert abs(rel.std() - 0.02) < 0.002 and abs(rel.mean()) < 0.001
    out = perturb_samples(sparse, Augment(outlier_fraction=0.1), np.random.default_rng(2))
    ratio = out[m] / sparse[m]
    moved = ratio != 1
    assert abs(moved.mean() - 0.1) < 0.01
    assert ratio[moved].min() >= 1.1 and ratio[moved].max() <= 3.0


def test_texture_paints_the_rgb_of_a_rectangle_and_nothing_else():
    """texture_prob=1: the RGB changes inside one rectangle only, by at most the strength (relative), while depth,
    samples and validity are exactly those of the same augmentation without texture; texture_prob=0 draws nothing."""
    b = _batch(n=6)
    rgb = np.full((40, 48, 3), 128, np.uint8)
    for seed in range(20):
        out = paint_texture(rgb, 0.4, np.random.default_rng(seed)).astype(float)
        assert np.abs(out - 128).max() <= 0.4 * 128 + 0.5
        rng = np.random.default_rng(seed)  # the rectangle is the first four draws: sides, then corner
        rh, rw = int(rng.integers(10, 41)), int(rng.integers(12, 49))
        top, left = int(rng.integers(0, 40 - rh + 1)), int(rng.integers(0, 48 - rw + 1))
        outside = np.ones((40, 48), bool)
        outside[top:top + rh, left:left + rw] = False
        assert np.all(out[outside] == 128)
    painted = sum(int(np.any(paint_texture(rgb, 0.4, np.random.default_rng(s)) != rgb)) for s in range(20))
    assert painted >= 15  # a zero amplitude or a flat pattern is rare
    plain = augment_batch(b, DEFAULT_TRAINING, (24, 32), seed=1, step=5)
    textured = augment_batch(b, dataclasses.replace(DEFAULT_TRAINING, texture_prob=1.0), (24, 32), seed=1, step=5)
    for name in ("gt", "sparse", "gt_valid"):
        np.testing.assert_array_equal(getattr(plain, name), getattr(textured, name))
    assert not np.array_equal(plain.rgb, textured.rgb)
    off = augment_batch(b, dataclasses.replace(DEFAULT_TRAINING, texture_prob=0.0, texture_strength=0.1), (24, 32),
                        seed=1, step=5)
    np.testing.assert_array_equal(plain.rgb, off.rgb)


def test_texture_patches_paint_one_to_that_many_rectangles_and_never_the_depth(monkeypatch):
    """texture_patches=N paints 1..N rectangles per textured example (N=1: exactly one, with no extra random draw,
    so the random stream of before): on a grey frame more of the RGB changes, and depth never does."""
    from lipjax.data import augment

    calls, real = [], augment.paint_texture

    def counted(rgb, strength, rng):
        calls.append(1)
        return real(rgb, strength, rng)

    monkeypatch.setattr(augment, "paint_texture", counted)
    b = _batch(n=8)
    grey = dataclasses.replace(b, rgb=np.full_like(b.rgb, 128))
    aug = dataclasses.replace(DEFAULT_TRAINING, texture_prob=1.0, texture_strength=0.3, brightness=0.0, contrast=0.0,
                              saturation=0.0, gamma=0.0, blur_prob=0.0)
    one = augment_batch(grey, aug, (24, 32), seed=2, step=3)
    assert len(calls) == 8
    calls.clear()
    many = augment_batch(grey, dataclasses.replace(aug, texture_patches=6), (24, 32), seed=2, step=3)
    assert 8 < len(calls) <= 48
    for name in ("gt", "sparse", "gt_valid"):
        np.testing.assert_array_equal(getattr(one, name), getattr(many, name))
    changed = lambda x: np.mean(np.any(x.rgb != 128, axis=-1))  # noqa: E731
    assert changed(many) > changed(one) + 0.1
    with pytest.raises(ValueError, match="texture_patches"):
        dataclasses.replace(aug, texture_patches=0)


def test_camera_noise_statistics_and_jpeg():
    """Noise of std U(0, a) * 255 per pixel: on a mid-grey frame the residual's std is below a * 255 and its mean is
    0; a JPEG round trip alone changes a textured frame by a few grey levels and leaves a flat one as it was; off:
    the frame as it was. Depth and samples never change (the RGB is the only input)."""
    flat = np.full((64, 64, 3), 128, np.uint8)
    stds = [float((camera_noise(flat, Augment(sensor_noise=0.05), np.random.default_rng(s)).astype(float) - 128)
                  .std()) for s in range(30)]
    assert max(stds) <= 0.05 * 255 * 1.05 and min(stds) < 0.3 * max(stds)  # sigma drawn in (0, 0.05 * 255)
    assert abs(np.mean(stds) - 0.025 * 255) < 0.01 * 255  # E[U(0, a)] = a / 2
    noisy = camera_noise(flat, Augment(sensor_noise=0.05), np.random.default_rng(0)).astype(float) - 128
    assert abs(noisy.mean()) < 0.5
    np.testing.assert_array_equal(camera_noise(flat, Augment(jpeg_prob=1.0), np.random.default_rng(0)), flat)
    textured = np.random.default_rng(1).integers(0, 256, (64, 64, 3), dtype=np.uint8)
    jpeg = camera_noise(textured, Augment(jpeg_prob=1.0), np.random.default_rng(0))
    assert jpeg.shape == textured.shape and jpeg.dtype == np.uint8 and not np.array_equal(jpeg, textured)
    np.testing.assert_array_equal(camera_noise(textured, Augment(), np.random.default_rng(0)), textured)
    b = _batch(n=3)
    plain = augment_batch(b, DEFAULT_TRAINING, (24, 32), seed=1, step=5)
    noisy_batch = augment_batch(b, dataclasses.replace(DEFAULT_TRAINING, sensor_noise=0.02, jpeg_prob=1.0), (24, 32),
                                seed=1, step=5)
    for name in ("gt", "sparse", "gt_valid"):
        np.testing.assert_array_equal(getattr(plain, name), getattr(noisy_batch, name))
    assert not np.array_equal(plain.rgb, noisy_batch.rgb)


def test_relight_is_one_smooth_grey_gain_within_the_strength_and_leaves_depth_alone():
    """relight multiplies every channel by the same gain exp(a f), |a f| <= strength, with f smooth: on a mid-grey
    frame out / in (before rounding) has |log| <= strength, and its log changes by at most strength * 2 * (ramp
    slope 2 / side + the bicubic grid's slope) per pixel, i.e. no colour edge; in the batch only the RGB changes."""
    h, w = 60, 80
    grey = np.full((h, w, 3), 100, np.uint8)
    changed = 0
    for seed in range(20):
        out = relight(grey, 0.7, np.random.default_rng(seed)).astype(float)
        assert (out[..., 0] == out[..., 1]).all() and (out[..., 1] == out[..., 2]).all()
        log_gain = np.log(out[..., 0] / 100.0)
        assert np.abs(log_gain).max() <= 0.7 + 0.01  # rounding to integers: <= 0.5 / 50 in log
        steps = max(np.abs(np.diff(log_gain, axis=0)).max(), np.abs(np.diff(log_gain, axis=1)).max())
        assert steps <= 0.2, steps  # a step edge would be up to 1.4 here: |a f| jumps over 2 * 0.7
        changed += int(np.abs(log_gain).max() > 0.05)
    assert changed >= 15  # a zero amplitude is rare
    np.testing.assert_array_equal(relight(grey, 0.0, np.random.default_rng(0)), grey)
    b = _batch(n=3)
    plain = augment_batch(b, DEFAULT_TRAINING, (24, 32), seed=1, step=5)
    lit = augment_batch(b, dataclasses.replace(DEFAULT_TRAINING, illumination_prob=1.0), (24, 32), seed=1, step=5)
    for name in ("gt", "sparse", "gt_valid"):
        np.testing.assert_array_equal(getattr(plain, name), getattr(lit, name))
    assert not np.array_equal(plain.rgb, lit.rgb)


def test_quarter_turns_turn_whole_frames_either_way_when_the_turned_frame_holds_the_crop():
    b = _batch(n=8, h=40, w=48)
    turned = augment_batch(b, Augment(quarter_turn_prob=1.0), None, seed=0, step=0)
    assert turned.gt.shape == (8, 48, 40)
    ways = []
    for i in range(8):
        k = [k for k in (1, 3) if np.array_equal(turned.gt[i], np.rot90(b.gt[i], k))]
        assert len(k) == 1
        for f in ("rgb", "sparse", "gt_valid"):
            np.testing.assert_array_equal(getattr(turned, f)[i], np.rot90(getattr(b, f)[i], k[0]))
        ways.append(k[0])
    assert set(ways) == {1, 3}
    # a 40x48 frame turned is 48x40: it holds a 30x36 crop, not a 20x44 one (left upright)
    upright = augment_batch(b, Augment(quarter_turn_prob=1.0), (20, 44), seed=0, step=0)
    assert all(any(np.array_equal(upright.gt[i], b.gt[i, t:t + 20, l:l + 44]) for t in range(21) for l in range(5))
               for i in range(8))
    small = augment_batch(b, Augment(quarter_turn_prob=1.0), (30, 36), seed=0, step=0)
    assert all(any(np.array_equal(small.gt[i], np.rot90(b.gt[i], k)[t:t + 30, l:l + 36])
                   for k in (1, 3) for t in range(19) for l in range(5)) for i in range(8))


def test_bad_settings_are_clear_errors():
    with pytest.raises(ValueError, match="zoom"):
        Augment(zoom=(1.5, 1.0))
    with pytest.raises(ValueError, match="brightness"):
        dataclasses.replace(DEFAULT_TRAINING, brightness=1.5)
    with pytest.raises(ValueError, match="sensor_noise"):
        Augment(sensor_noise=1.5)
    with pytest.raises(ValueError, match="illumination"):
        Augment(illumination_prob=2.0)
    with pytest.raises(ValueError, match="quarter_turn_prob"):
        Augment(quarter_turn_prob=1.5)
