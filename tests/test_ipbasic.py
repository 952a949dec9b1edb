"""IP-Basic: lipjax's `ip_basic` / `ip_basic_multiscale` against a slow step-by-step transcription of the published
algorithm (kujason/ip_basic `fill_in_fast` / `fill_in_multiscale`, written here from its description), and
properties of the fills that can fail."""
import cv2
import numpy as np
import pytest

from lipjax.classical.ipbasic import (
    IPBasicAdaptiveFill,
    IPBasicFill,
    IPBasicMultiscaleFill,
    auto_radii_px,
    diamond_kernel,
    ip_basic,
    ip_basic_multiscale,
)
from lipjax.classical.nearest import nearest_fill
from lipjax.data.sampling import LidarSampler
from lipjax.data.synthetic.dataset import render
from lipjax.methods import get_completer

# ---------------------------------------------------------------- reference transcription (slow, obvious)

DIAMOND_5 = np.array([[0, 0, 1, 0, 0], [0, 1, 1, 1, 0], [1, 1, 1, 1, 1], [0, 1, 1, 1, 0], [0, 0, 1, 0, 0]], np.uint8)
CROSS_3 = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], np.uint8)
CROSS_5 = np.zeros((5, 5), np.uint8)
CROSS_5[2, :] = 1
CROSS_5[:, 2] = 1
CROSS_7 = np.zeros((7, 7), np.uint8)
CROSS_7[3, :] = 1
CROSS_7[:, 3] = 1


def ones(n):
    return np.ones((n, n), np.uint8)


def reference_fill_in_fast(depth, max_depth=100.0, extrapolate=False, blur_type="bilateral"):
    """fill_in_fast, step by step. depth: (H, W) float32 metres; returns what the original returns."""
    d = depth.astype(np.float32).copy()
    h, w = d.shape
    # 1. invert the pixels deeper than 0.1 m: d <- max_depth - d
    for y in range(h):
        for x in range(w):
            if d[y, x] > 0.1:
                d[y, x] = max_depth - d[y, x]
    # 2. dilate with the 5x5 diamond
    d = cv2.dilate(d, DIAMOND_5)
    # 3. hole closing with a 5x5 full kernel
    d = cv2.morphologyEx(d, cv2.MORPH_CLOSE, ones(5))
    # 4. pixels below 0.1 take the value of a 7x7 full dilation
    big = cv2.dilate(d, ones(7))
    holes = d < 0.1
    d[holes] = big[holes]
    if extrapolate:
        # 5a. per column: every row above the first pixel over 0.1 gets that pixel's value
        for x in range(w):
            rows = [y for y in range(h) if d[y, x] > 0.1]
            top = rows[0] if rows else 0
            for y in range(top):
                d[y, x] = d[top, x]
        # 5b. pixels still below 0.1 take the value of a 31x31 full dilation
        big = cv2.dilate(d, ones(31))
        holes = d < 0.1
        d[holes] = big[holes]
    # 6. median 5x5
    d = cv2.medianBlur(d, 5)
    # 7. bilateral (diameter 5, sigma colour 1.5, sigma space 2) or a 5x5 Gaussian on pixels over 0.1
    if blur_type == "bilateral":
        d = cv2.bilateralFilter(d, 5, 1.5, 2.0)
    elif blur_type == "gaussian":
        g = cv2.GaussianBlur(d, (5, 5), 0)
        keep = d > 0.1
        d[keep] = g[keep]
    # 8. invert back the pixels over 0.1
    keep = d > 0.1
    d[keep] = max_depth - d[keep]
    return d


def column_top_mask(d):
    """True from each column's first pixel over 0.1 downwards (a column without one is all True)."""
    mask = np.ones(d.shape, bool)
    for x in range(d.shape[1]):
        over = np.nonzero(d[:, x] > 0.1)[0]
        if len(over):
            mask[: over[0], x] = False
    return mask


def reference_fill_in_multiscale(depth, max_depth=100.0, extrapolate=False, blur_type="bilateral"):
    """fill_in_multiscale, step by step. depth: (H, W) float32 metres; returns the original's depths_out."""
    depth = depth.astype(np.float32)
    # 1. depth bins on the input: near (0.1, 15], medium (15, 30], far above 30 m
    near = (depth > 0.1) & (depth <= 15.0)
    med = (depth > 15.0) & (depth <= 30.0)
    far = depth > 30.0
    # 2. invert the pixels over 0.1 m
    s1 = depth.copy()
    s1[depth > 0.1] = max_depth - depth[depth > 0.1]
    # 3. dilate each bin on its own: far with a 3x3 cross, medium 5x5 cross, near 7x7 cross
    dil_far = cv2.dilate(s1 * far, CROSS_3)
    dil_med = cv2.dilate(s1 * med, CROSS_5)
    dil_near = cv2.dilate(s1 * near, CROSS_7)
    # 4. paste the dilations over the inverted map, far, then medium, then near (nearest wins)
    s2 = s1.copy()
    for dil in (dil_far, dil_med, dil_near):
        s2[dil > 0.1] = dil[dil > 0.1]
    # 5. close with a 5x5 full kernel
    s3 = cv2.morphologyEx(s2, cv2.MORPH_CLOSE, ones(5))
    # 6. median 5x5 on pixels over 0.1
    s4 = s3.copy()
    med5 = cv2.medianBlur(s3, 5)
    s4[s3 > 0.1] = med5[s3 > 0.1]
    # 7. pixels not over 0.1 and below their column's top take a 9x9 full dilation
    top = column_top_mask(s4)
    holes = ~(s4 > 0.1) & top
    s5 = s4.copy()
    s5[holes] = cv2.dilate(s4, ones(9))[holes]
    # 8. extend each column's top value upwards (then nothing is masked), or mask everything above the top
    s6 = s5.copy()
    if extrapolate:
        top = np.ones(s5.shape, bool)
        for x in range(s5.shape[1]):
            over = np.nonzero(s5[:, x] > 0.1)[0]
            first = over[0] if len(over) else 0
            s6[:first, x] = s5[first, x]
    else:
        top = column_top_mask(s5)
    # 9. six times: pixels below 0.1 under the top take a 5x5 full dilation
    s7 = s6.copy()
    for _ in range(6):
        holes = (s7 < 0.1) & top
        s7[holes] = cv2.dilate(s7, ones(5))[holes]
    # 10. median 5x5 on pixels over 0.1 under the top (this mask is reused by the bilateral step)
    keep = (s7 > 0.1) & top
    s7[keep] = cv2.medianBlur(s7, 5)[keep]
    # 11. Gaussian 5x5 on the pixels now over 0.1 under the top, or bilateral (5, 0.5, 2) on the step-10 mask
    if blur_type == "gaussian":
        gkeep = (s7 > 0.1) & top
        s7[gkeep] = cv2.GaussianBlur(s7, (5, 5), 0)[gkeep]
    elif blur_type == "bilateral":
        s7[keep] = cv2.bilateralFilter(s7, 5, 0.5, 2.0)[keep]
    # 12. invert back the pixels over 0.1
    out = s7.copy()
    out[s7 > 0.1] = max_depth - s7[s7 > 0.1]
    return out


# ---------------------------------------------------------------- generated LiDAR-like frames


def lidar_frames():
    """Synthetic outdoor renders with spinning-LiDAR samples: a KITTI-like 64-beam pattern (beams ~2 px apart,
    returns ~2 px apart) and a sparser 16-beam one (beams ~6 px apart)."""
    a = render("outdoor", "test", 0, height=128, width=416)
    b = render("outdoor", "test", 1, height=96, width=312)
    return [LidarSampler.hdl64(azimuth_step_deg=0.5)(a), LidarSampler.vlp16()(b)]


FRAMES = lidar_frames()
OPTIONS = [(False, "bilateral"), (False, "gaussian"), (True, "bilateral"), (True, "gaussian"), (False, "none")]


def within_1cm(a, b):
    return float(np.mean(np.abs(a - b) <= 0.01))


@pytest.mark.parametrize("extrapolate,blur_type", OPTIONS)
def test_ip_basic_matches_the_published_fill_in_fast(extrapolate, blur_type):
    for sparse in FRAMES:
        assert 0.03 < np.mean(sparse > 0) < 0.3 and sparse.max() < 100.0
        ours = ip_basic(sparse, extrapolate=extrapolate, blur_type=blur_type)
        ref = reference_fill_in_fast(sparse, extrapolate=extrapolate, blur_type=blur_type)
        np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-5)  # the same OpenCV operations: equal


@pytest.mark.parametrize("extrapolate,blur_type", OPTIONS)
def test_ip_basic_multiscale_matches_the_published_fill_in_multiscale(extrapolate, blur_type):
    for sparse in FRAMES:
        ours = ip_basic_multiscale(sparse, extrapolate=extrapolate, blur_type=blur_type)
        ref = reference_fill_in_multiscale(sparse, extrapolate=extrapolate, blur_type=blur_type)
        np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-5)


def test_the_two_fills_and_the_options_differ():
    # guards the comparisons above against options that are silently ignored
    sparse = FRAMES[1]
    fast = ip_basic(sparse)
    assert within_1cm(fast, ip_basic_multiscale(sparse)) < 0.9
    assert within_1cm(fast, ip_basic(sparse, blur_type="gaussian")) < 0.98
    assert np.mean(ip_basic(sparse, extrapolate=True) > 0) > np.mean(fast > 0) + 0.05
    multi = ip_basic_multiscale(sparse)
    assert within_1cm(multi, ip_basic_multiscale(sparse, blur_type="gaussian")) < 0.98
    assert np.mean(ip_basic_multiscale(sparse, extrapolate=True) > 0) > np.mean(multi > 0) + 0.05


# ---------------------------------------------------------------- properties


def test_nothing_is_made_up_above_the_top_beam_without_extrapolation():
    reach = 7  # px: diamond 2 + 7x7 fill 3 + median 2 (the 5x5 closing adds nothing), upwards and sideways
    for sparse in FRAMES:
        h, w = sparse.shape
        top = np.where((sparse > 0).any(axis=0), np.argmax(sparse > 0, axis=0), h)
        top_near = np.array([top[max(0, x - reach) : x + reach + 1].min() for x in range(w)])
        far_above = np.arange(h)[:, None] < top_near[None, :] - reach
        assert far_above.mean() > 0.05
        assert np.all(ip_basic(sparse)[far_above] == 0)
        assert np.all(ip_basic_multiscale(sparse)[far_above] == 0)
        assert np.all(ip_basic(sparse, extrapolate=True)[far_above] > 0)


def test_samples_of_a_flat_surface_are_kept_and_a_lone_sample_spreads_to_its_neighbourhood():
    plane = np.zeros((40, 60), np.float32)
    plane[10:36:3, ::2] = 12.5  # scan lines 3 rows apart, a return every 2 px
    for fill in (ip_basic, ip_basic_multiscale):
        out = fill(plane)
        np.testing.assert_allclose(out[plane > 0], 12.5, atol=1e-4)
        assert np.all(out[10:34, 4:-4] > 0)
    lone = np.zeros((31, 31), np.float32)
    lone[15, 15] = 7.0
    out = ip_basic(lone)
    assert out[15, 15] == pytest.approx(7.0, abs=1e-4)
    assert out[0, 0] == 0 and out[15, 15 - 8] == 0  # 2 (diamond) + 3 (7x7) + 2 (median) px reach at most
    np.testing.assert_allclose(ip_basic(lone, extrapolate=True), 7.0, atol=1e-4)  # 31x31 fill reaches all


def test_the_nearer_surface_wins_where_dilations_meet():
    s = np.zeros((21, 21), np.float32)
    s[4:17:2, 0:7:2] = 2.0  # a near surface up to column 6
    s[4:17:2, 9::2] = 30.0  # a far one from column 9
    # column 8 is 2 px from the near samples and 1 px from the far ones: the near surface still takes it
    for blur_type in ("none", "bilateral"):
        out = ip_basic(s, blur_type=blur_type)
        np.testing.assert_allclose(out[6:15, :9], 2.0, atol=1e-4)
        np.testing.assert_allclose(out[6:15, 9:], 30.0, atol=1e-4)
    assert np.all(nearest_fill(s)[6:15, 8] == 30.0)


def test_output_never_exceeds_max_depth_and_far_samples_are_ignored():
    rng = np.random.default_rng(0)
    s = FRAMES[1].copy()
    far = (s > 0) & (rng.random(s.shape) < 0.3)
    s[far] = rng.uniform(100.5, 150.0, far.sum())
    for fill in (ip_basic, ip_basic_multiscale):
        for blur_type in ("bilateral", "gaussian"):
            out = fill(s, blur_type=blur_type, extrapolate=True)
            assert out.min() >= 0 and out.max() <= 100.0
            np.testing.assert_array_equal(out, fill(np.where(far, 0, s), blur_type=blur_type, extrapolate=True))
    out = ip_basic(FRAMES[1], max_depth_m=20.0)
    assert out.max() <= 20.0 and np.any(out > 0)


def test_bad_inputs_raise_one_line_value_errors():
    rgb = np.zeros((8, 9, 3), np.uint8)
    for completer in (IPBasicFill(), IPBasicMultiscaleFill(), IPBasicAdaptiveFill()):
        with pytest.raises(ValueError, match="empty"):
            completer(rgb, np.zeros((8, 9), np.float32))
    far = np.zeros((8, 9), np.float32)
    far[4, 4] = 150.0
    for fill in (ip_basic, ip_basic_multiscale):
        with pytest.raises(ValueError, match=r"no sample in \(0.1, 100\] m \(farthest 150.0 m: raise max_depth_m\)"):
            fill(far)
        with pytest.raises(ValueError, match="blur_type") as err:
            fill(far * 0.1, blur_type="box")
        assert "\n" not in str(err.value)
        with pytest.raises(ValueError, match="max_depth_m"):
            fill(far * 0.1, max_depth_m=0.0)


def test_registered_by_name():
    assert isinstance(get_completer("ip_basic"), IPBasicFill)
    assert isinstance(get_completer("ip_basic_multiscale"), IPBasicMultiscaleFill)
    assert isinstance(get_completer("ip_basic_adaptive"), IPBasicAdaptiveFill)
    assert get_completer("ip_basic", extrapolate=True).extrapolate
    rgb = np.zeros(FRAMES[1].shape + (3,), np.uint8)
    np.testing.assert_array_equal(get_completer("ip_basic")(rgb, FRAMES[1]), ip_basic(FRAMES[1]))


# ---------------------------------------------------------------- the density-adaptive variant


def test_adaptive_keeps_a_dense_smooth_map():
    h, w = 32, 40
    yy, xx = np.mgrid[0:h, 0:w]
    dense = (3.0 + 0.02 * xx + 0.05 * yy).astype(np.float32)
    out = IPBasicAdaptiveFill()(np.zeros((h, w, 3), np.uint8), dense)
    # Dense input -> radii (1, 1); dilating inverted depth moves each pixel to its nearest neighbour's depth,
    # i.e. by about one pixel step of the ramp (0.05 m per row); median and bilateral (nearly) keep a ramp.
    interior = (slice(3, -3), slice(3, -3))
    assert np.abs(out - dense)[interior].max() < 0.06


def test_adaptive_fills_everything_from_few_samples():
    rng = np.random.default_rng(1)
    s = np.zeros((40, 50), np.float32)
    s.flat[rng.choice(2000, 6, replace=False)] = rng.uniform(1.0, 5.0, 6)
    out = IPBasicAdaptiveFill()(np.zeros((40, 50, 3), np.uint8), s)
    assert np.all(out > 0) and np.all(np.isfinite(out))
    assert np.mean(ip_basic(s) > 0) < 0.5  # the original's 5x5 / 7x7 kernels cannot


def test_adaptive_radii_follow_density_and_layout():
    dense = np.zeros((64, 64), np.float32)
    dense[::4, ::4] = 5.0  # a sample every 4 px: |dy| (and |dx|) to the nearest sample is 2 for < 25 % of pixels
    sparse = np.zeros((64, 64), np.float32)
    sparse[::16, ::16] = 5.0
    lines = np.zeros((64, 64), np.float32)
    lines[::12, :] = 5.0  # scan lines 12 rows apart, dense along each line
    assert auto_radii_px(dense) == (1, 1)
    # Closed forms (the RADIUS_PERCENTILE = 75th percentile of |dy| and |dx| to the nearest sample over the samples'
    # box, numpy's linear rule): on a grid the nearest sample lies on the nearest row and column. Rows 0-48 of the
    # ::16 grid lie 0 (4 rows), 1-7 (6 rows each) and 8 (3 rows) from a sample row: sorted, entry 36 of 49 is 6.
    assert auto_radii_px(sparse) == (6, 6)
    # Rows 0-60 of ::12 lines lie 0 (6), 1-5 (10 each), 6 (5) from a line: entry 45 of 61 is 4; every column holds
    # samples, so |dx| = 0, raised to MIN_RADIUS_PX = 1. Anisotropic: tall, thin kernels for LiDAR lines.
    assert auto_radii_px(lines) == (4, 1)
    np.testing.assert_array_equal(diamond_kernel(2), DIAMOND_5)
    np.testing.assert_array_equal(diamond_kernel(2, 1), [[0, 1, 0], [0, 1, 0], [1, 1, 1], [0, 1, 0], [0, 1, 0]])


@pytest.mark.parametrize("name", ["ip_basic", "ip_basic_multiscale", "ip_basic_adaptive", "linear", "nearest"])
def test_the_default_path_returns_a_hand_crafted_method_exactly_as_the_method_itself(name):
    """lipjax.complete (and so `lipjax complete`) runs a hand-crafted method as published: what the completer itself
    returns, value for value, measured pixels included (IP-Basic replaces background returns seen through gaps in
    the foreground, and smooths every pixel: setting them back made it agree on 96.6 % of a KITTI frame's pixels).
    Below full size (max_side) the resize back moves the samples, and they are set back."""
    import lipjax
    from lipjax.inference import complete_frame

    for sparse in FRAMES:
        rgb = np.zeros(sparse.shape + (3,), np.uint8)
        own = get_completer(name)(rgb, sparse)
        np.testing.assert_array_equal(lipjax.complete(rgb, sparse, model=name), own)
    measured = sparse > 0
    if name.startswith("ip_basic"):
        assert (own[measured] != sparse[measured]).mean() > 0.5  # what the set-back used to undo
    small = complete_frame(get_completer(name), rgb, sparse, max_side=156)
    np.testing.assert_array_equal(small[measured], sparse[measured])
