import numpy as np
import pytest
from scipy import interpolate

from lipjax.interfaces import DepthCompleter
from lipjax.classical import (
    ColorizationFill,
    LinearFill,
    NearestFill,
    nearest_fill,
)
from lipjax.classical.interpolate import linear_fill, linear_fill_at
from lipjax.classical.colorization import _OFFSETS, luma, neighbour_weights, nested_dissection_order
from lipjax.methods import CLASSICAL, get_completer

FILLS = [CLASSICAL[name]() for name in CLASSICAL if name != "lip-wavelet"]


def _random_sparse(h, w, n, seed=0, lo=1.0, hi=5.0):
    rng = np.random.default_rng(seed)
    s = np.zeros((h, w), np.float32)
    s.flat[rng.choice(h * w, n, replace=False)] = rng.uniform(lo, hi, n)
    return s


def _gray(h, w, value=128):
    return np.full((h, w, 3), value, np.uint8)


# ---------------------------------------------------------------- interface and input checks


@pytest.mark.parametrize("completer", FILLS, ids=lambda c: c.name)
def test_output_contract(completer):
    s = _random_sparse(24, 30, 20)
    out = completer(_gray(24, 30), s)
    assert isinstance(completer, DepthCompleter)
    assert out.shape == (24, 30) and out.dtype == np.float32
    assert np.all(np.isfinite(out))
    # IP-Basic's original fills leave 0 (no depth) beyond their kernels' reach; every other method fills all
    filled = out > 0
    assert filled.all() or completer.name in ("ip_basic", "ip_basic_multiscale")
    assert filled[s > 0].all()
    # no method may leave the range of its samples by much (all are interpolators or local averages)
    assert s[s > 0].min() - 1e-4 <= out[filled].min() and out.max() <= s.max() + 1e-4


@pytest.mark.parametrize("completer", FILLS, ids=lambda c: c.name)
def test_invalid_inputs_raise_value_error(completer):
    rgb, s = _gray(8, 9), _random_sparse(8, 9, 5)
    with pytest.raises(ValueError, match="empty"):
        completer(rgb, np.zeros_like(s))
    with pytest.raises(ValueError, match="mismatch"):
        completer(_gray(8, 10), s)
    bad = s.copy()
    bad[0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        completer(rgb, bad)
    bad[0, 0] = -1.0
    with pytest.raises(ValueError, match="negative"):
        completer(rgb, bad)
    with pytest.raises(ValueError, match="uint8"):
        completer(rgb.astype(np.float32), s)
    with pytest.raises(ValueError):
        completer(rgb, s[None])


def test_registry():
    assert all(get_completer(name).name == name for name in CLASSICAL)  # each method answers to its registered name
    assert get_completer("ip_basic_adaptive", radius_px=3).radius_px == 3
    with pytest.raises(ValueError, match="unknown model 'bicubic'"):
        get_completer("bicubic")
    with pytest.raises(ValueError, match="learned model"):
        get_completer("lip-ad-indoor", radius_px=3)


# ---------------------------------------------------------------- nearest


def test_nearest_exact_at_samples_and_takes_nearest_sample():
    s = np.zeros((5, 5), np.float32)
    s[0, 0], s[4, 4] = 1.0, 3.0
    out = NearestFill()(_gray(5, 5), s)
    assert out[0, 0] == 1.0 and out[4, 4] == 3.0
    assert out[1, 1] == 1.0 and out[0, 3] == 1.0  # closer to (0, 0)
    assert out[3, 4] == 3.0 and out[2, 4] == 3.0  # (2, 4): distance 2 to (4, 4) vs sqrt(20) to (0, 0)
    s = _random_sparse(20, 25, 30)
    out = NearestFill()(_gray(20, 25), s)
    np.testing.assert_array_equal(out[s > 0], s[s > 0])
    assert set(np.unique(out)) <= set(np.unique(s[s > 0]))  # every value is a sample value


# ---------------------------------------------------------------- linear


def test_linear_exact_on_a_plane_inside_hull_and_nearest_outside():
    h, w = 30, 40
    yy, xx = np.mgrid[0:h, 0:w]
    plane = (2.0 + 0.05 * xx + 0.03 * yy).astype(np.float32)
    s = np.zeros((h, w), np.float32)
    pts = [(3, 4), (3, 35), (26, 5), (25, 36), (15, 20), (10, 28)]
    for p in pts:
        s[p] = plane[p]
    out = LinearFill()(_gray(h, w), s)
    # inside the quadrilateral hull of the four corner samples: exact plane
    inside = (yy >= 4) & (yy <= 24) & (xx >= 6) & (xx <= 34)
    np.testing.assert_allclose(out[inside], plane[inside], atol=1e-5)
    np.testing.assert_allclose(out[s > 0], s[s > 0], atol=1e-6)
    corner = nearest_fill(s)
    assert out[0, 0] == corner[0, 0] == s[3, 4]  # outside the hull: nearest sample


def _grid_sparse(h, w, n, step, seed=0):
    """Samples on a coarse grid: many pixels lie exactly on triangle edges, and many samples on one line."""
    rng = np.random.default_rng(seed)
    s = np.zeros((h, w), np.float32)
    s[rng.integers(0, h // step, n) * step, rng.integers(0, w // step, n) * step] = rng.uniform(1.0, 5.0, n)
    return s


@pytest.mark.parametrize("s", [_random_sparse(23, 31, 40, seed=3), _grid_sparse(29, 41, 30, 4),
                               _grid_sparse(40, 33, 60, 3, seed=1)], ids=["random", "grid4", "grid3"])
def test_linear_matches_scipy_linearndinterpolator(s):
    """Same values inside the hull, pixels on triangle edges included; the nearest fill outside it."""
    out = LinearFill()(_gray(*s.shape), s)
    ys, xs = np.nonzero(s)
    ref = interpolate.LinearNDInterpolator(np.stack([ys, xs], 1).astype(float), s[ys, xs].astype(float))(
        *np.mgrid[0:s.shape[0], 0:s.shape[1]]
    )
    inside = ~np.isnan(ref)
    np.testing.assert_allclose(out[inside], ref[inside], atol=1e-5)
    np.testing.assert_array_equal(out[~inside], nearest_fill(s)[~inside])


def test_linear_degenerate_samples_fall_back_to_nearest():
    s = np.zeros((9, 9), np.float32)
    s[4, 1], s[4, 5], s[4, 8] = 1.0, 2.0, 3.0  # one scan line: collinear
    np.testing.assert_array_equal(LinearFill()(_gray(9, 9), s), nearest_fill(s))
    s2 = np.zeros((9, 9), np.float32)
    s2[1, 1], s2[7, 7] = 1.0, 2.0  # two points
    np.testing.assert_array_equal(LinearFill()(_gray(9, 9), s2), nearest_fill(s2))


@pytest.mark.parametrize("s", [_random_sparse(23, 31, 40, seed=3), _grid_sparse(29, 41, 30, 4),
                               _grid_sparse(40, 33, 60, 3, seed=1), _random_sparse(9, 9, 2, seed=4)],
                         ids=["random", "grid4", "grid3", "two points"])
def test_linear_fill_at_pixels_equals_the_full_fill_there(s):
    """On triangle edges, outside the hull, at ties between equidistant samples and at the samples themselves."""
    rows, cols = np.mgrid[0:s.shape[0], 0:s.shape[1]].reshape(2, -1)
    np.testing.assert_allclose(linear_fill_at(s, rows, cols), linear_fill(s)[rows, cols], rtol=0, atol=1e-5)


def _holes_sparse(h=30, w=40, seed=0):
    """Dense depth with holes, as a depth camera gives it: 98 % of the pixels, less two rectangles."""
    s = _random_sparse(h, w, int(0.98 * h * w), seed=seed)
    s[5:12, 8:20] = 0
    s[18:26, 25:31] = 0
    return s


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_linear_fill_of_dense_input_is_delaunay_for_all_the_samples(seed):
    """Only the edge samples are triangulated; every triangle that holds an unsampled pixel has no sample at all
    strictly inside its circumcircle (exact integer in-circle test), so the fill is a Delaunay linear fill of every
    sample; each sample keeps its value, and linear_fill_at reads the same values at the unsampled pixels."""
    from lipjax.classical.interpolate import _delaunay, _edge_samples

    s = _holes_sparse(seed=seed)
    ys, xs = _edge_samples(s)
    assert ys.size < 0.6 * (s > 0).sum()  # the interior of the sampled region is left out
    simplices = _delaunay(ys, xs)
    ay, ax = np.nonzero(s > 0)
    holes = np.argwhere(s == 0)
    checked = 0
    for tri in simplices:
        (y0, y1, y2), (x0, x1, x2) = ys[tri], xs[tri]
        den = (y1 - y2) * (x0 - x2) + (x2 - x1) * (y0 - y2)
        if den == 0:
            continue
        a0 = (y1 - y2) * (holes[:, 1] - x2) + (x2 - x1) * (holes[:, 0] - y2)
        a1 = (y2 - y0) * (holes[:, 1] - x2) + (x0 - x2) * (holes[:, 0] - y2)
        if not np.any((np.sign(den) * a0 >= 0) & (np.sign(den) * a1 >= 0) & (np.sign(den) * (den - a0 - a1) >= 0)):
            continue  # holds no unsampled pixel
        dx = np.array([x0, x1, x2])[None, :] - ax[:, None]  # (N, 3): corners relative to every sample
        dy = np.array([y0, y1, y2])[None, :] - ay[:, None]
        sq = dx ** 2 + dy ** 2
        det = (dx[:, 0] * (dy[:, 1] * sq[:, 2] - dy[:, 2] * sq[:, 1])
               - dy[:, 0] * (dx[:, 1] * sq[:, 2] - dx[:, 2] * sq[:, 1])
               + sq[:, 0] * (dx[:, 1] * dy[:, 2] - dx[:, 2] * dy[:, 1]))
        orient = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0)
        assert not np.any(det * np.sign(orient) > 0), tri  # > 0: a sample strictly inside the circumcircle
        checked += 1
    assert checked > 10
    out = linear_fill(s)
    np.testing.assert_array_equal(out[s > 0], s[s > 0])
    rows, cols = holes[:40].T
    np.testing.assert_allclose(linear_fill_at(s, rows, cols), out[rows, cols], rtol=0, atol=1e-5)


def test_linear_fill_at_collinear_samples_is_the_nearest_fill_ties_included():
    line = np.zeros((9, 9), np.float32)
    line[4, 1], line[4, 5], line[4, 8] = 1.0, 2.0, 3.0  # no triangle: the full fill is the nearest fill
    rows, cols = np.mgrid[0:9, 0:9].reshape(2, -1)
    np.testing.assert_array_equal(linear_fill_at(line, rows, cols), nearest_fill(line).reshape(-1))


def test_linear_fill_at_many_pixels_of_dense_input_reads_the_full_fill(monkeypatch):
    import lipjax.classical.interpolate as interpolate_module

    s = _random_sparse(23, 31, 300, seed=5)
    rows, cols = np.mgrid[0:23, 0:31].reshape(2, -1)
    full = []
    monkeypatch.setattr(interpolate_module, "linear_fill", lambda sparse: full.append(1) or linear_fill(sparse))
    np.testing.assert_allclose(linear_fill_at(s, rows[:2], cols[:2]), linear_fill(s)[rows[:2], cols[:2]], atol=1e-5)
    assert not full  # 2 x 300 pairs on 713 pixels: pointwise
    np.testing.assert_allclose(linear_fill_at(s, rows, cols), linear_fill(s)[rows, cols], rtol=0, atol=1e-5)
    assert full == [1]  # 713 x 300 pairs: 300 a pixel, over POINTWISE_PAIRS_PER_PIXEL


# IP-Basic: tests/test_ipbasic.py


# ---------------------------------------------------------------- colourisation


def test_colorization_reproduces_constant_and_keeps_samples_exactly():
    rng = np.random.default_rng(2)
    rgb = rng.integers(0, 256, (20, 24, 3)).astype(np.uint8)
    s = np.zeros((20, 24), np.float32)
    s[rng.random((20, 24)) < 0.05] = 2.5
    np.testing.assert_allclose(ColorizationFill()(rgb, s), 2.5, rtol=1e-5)
    s = _random_sparse(20, 24, 15, seed=4)
    out = ColorizationFill()(rgb, s)
    np.testing.assert_array_equal(out[s > 0], s[s > 0])


def test_colorization_solves_the_levin_equations():
    rng = np.random.default_rng(5)
    rgb = rng.integers(0, 256, (12, 14, 3)).astype(np.uint8)
    s = _random_sparse(12, 14, 10, seed=6)
    x = ColorizationFill()(rgb, s).astype(np.float64)
    wts = neighbour_weights(luma(rgb))
    wts /= wts.sum(0)
    xp = np.pad(x, 1)
    avg = sum(wts[k] * xp[1 + dy : 13 + dy, 1 + dx : 15 + dx] for k, (dy, dx) in enumerate(_OFFSETS))
    unknown = s == 0
    np.testing.assert_allclose(x[unknown], avg[unknown], atol=1e-5)  # x_r = sum_s wbar_rs x_s


def test_colorization_follows_image_edges():
    # Left half dark, right half bright (edge between columns 15 and 16); one sample on each side.
    h, w = 16, 32
    rgb = np.zeros((h, w, 3), np.uint8)
    rgb[:, 16:] = 255
    s = np.zeros((h, w), np.float32)
    s[8, 2], s[8, 22] = 1.0, 5.0
    out = ColorizationFill()(rgb, s)
    assert np.all(np.abs(out[:, :16] - 1.0) < 0.05)
    assert np.all(np.abs(out[:, 16:] - 5.0) < 0.05)
    # an image-blind fill puts its boundary half-way between the samples (column 12), not at the image edge
    np.testing.assert_array_equal(nearest_fill(s)[:, 13:16], 5.0)


def test_nested_dissection_order_is_a_permutation():
    for h, w in [(1, 1), (3, 7), (17, 9), (64, 80)]:
        np.testing.assert_array_equal(np.sort(nested_dissection_order(h, w)), np.arange(h * w))


# ---------------------------------------------------------------- LIP+Wavelet (the unrolled solver, fixed prox)

def test_lip_wavelet_keeps_constants_scales_with_depth_and_is_the_box_fill_without_a_threshold():
    """Soft-thresholding Haar details leaves a constant map constant; the threshold follows the median sampled depth,
    so scaling every depth by c scales the output by c (box fill, thresholding and x-update are all homogeneous);
    with tau = 0 the prox is the identity (perfect reconstruction), so the solver returns its start, the box fill."""
    from lipjax.classical.lip_wavelet import LIPWavelet
    from lipjax.fill import box_fill

    sparse, rgb = _random_sparse(24, 32, 40), _gray(24, 32)
    constant = np.where(sparse > 0, 3.0, 0.0).astype(np.float32)
    np.testing.assert_allclose(LIPWavelet()(rgb, constant), 3.0, rtol=1e-6)
    out = LIPWavelet()(rgb, sparse)
    np.testing.assert_allclose(LIPWavelet()(rgb, 2.5 * sparse), 2.5 * out, rtol=1e-5, atol=1e-5)
    start = np.asarray(box_fill(sparse[None], (sparse > 0)[None].astype(np.float32)))[0]
    np.testing.assert_allclose(LIPWavelet(tau_per_m_depth=0.0)(rgb, sparse), start, rtol=1e-5, atol=1e-5)
    assert np.abs(out - start).max() > 0.1  # the default threshold does act
