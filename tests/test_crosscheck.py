"""The per-frame check of a learned model against the linear fill on held-out samples (lipjax.crosscheck)."""
import math
import threading
import warnings

import numpy as np
import pytest

from lipjax import crosscheck, inputs
from lipjax.classical.interpolate import linear_fill
from lipjax.inference import Completer, complete_at
from lipjax.model import LIPConfig


def _plane(h=48, w=64):
    """Depth of a tilted plane, metres: the linear fill of any samples of it is exact inside their hull."""
    rows, cols = np.mgrid[0:h, 0:w]
    return (2.0 + 0.02 * rows + 0.03 * cols).astype(np.float32)


def _scattered(depth, n, seed=0):
    rng = np.random.default_rng(seed)
    out = np.zeros_like(depth)
    idx = rng.choice(depth.size, n, replace=False)
    out.reshape(-1)[idx] = depth.reshape(-1)[idx]
    return out


def _binomial_tail(k, n):
    """P(Binomial(n, 1/2) >= k), summed term by term."""
    return sum(math.comb(n, i) for i in range(k, n + 1)) / 2**n


def test_the_model_gives_way_exactly_when_the_sign_test_says_so():
    """n = 40 held-out samples: the model keeps w = 1 while it misses by more at k samples with
    P(Bin(40, 1/2) >= k) >= 0.05, and gets the least-squares weight from the first k below that level."""
    n = 40
    first = next(k for k in range(n + 1) if _binomial_tail(k, n) < crosscheck.P_VALUE)
    assert first == 26 and _binomial_tail(25, n) > 0.05  # 0.040 and 0.077
    y = np.zeros(n)
    x_l = np.full(n, -1.0)  # linear misses every sample by 1
    for k in (first - 1, first):
        x_m = np.where(np.arange(n) < k, 3.0, 0.5)  # the model misses k samples by 3, the others by 0.5
        d = x_m - x_l
        expected = 1.0 if k < first else float(np.clip(np.sum((y - x_l) * d) / np.sum(d * d), 0, 1))
        assert crosscheck.blend_weight(y, x_m, x_l) == pytest.approx(expected, rel=1e-12)
    assert expected < 1.0


def test_a_model_worse_everywhere_gets_the_closed_form_weight():
    """x_m = y + 3 e, x_l = y - e: w = sum (y - x_l)(x_m - x_l) / sum (x_m - x_l)^2 = 4 / 16 = 1/4, and the blend
    w x_m + (1 - w) x_l is then y exactly."""
    rng = np.random.default_rng(1)
    y = rng.uniform(1, 9, 50)
    e = rng.uniform(0.1, 1.0, 50) * rng.choice([-1, 1], 50)
    w = crosscheck.blend_weight(y, y + 3 * e, y - e)
    assert w == pytest.approx(0.25, rel=1e-12)
    np.testing.assert_allclose(w * (y + 3 * e) + (1 - w) * (y - e), y, atol=1e-12)
    assert crosscheck.blend_weight(y, y - e, y + 3 * e) == 1.0  # the better model is left alone
    assert crosscheck.blend_weight(y, y + e, y + e) == 1.0  # equal estimates: the model is never worse


def test_the_folds_hold_out_every_sample_once():
    """203 samples in 5 folds of 41 or 40: each kept map is the input without its fold, the folds are disjoint and
    cover every sample, and the same input gives the same folds."""
    sparse = _scattered(_plane(), 203)
    folds = list(crosscheck.fold_out(sparse))
    assert [rows.size for _, rows, _ in folds] == [41, 41, 41, 40, 40]
    held = np.zeros(sparse.shape, int)
    for kept, rows, cols in folds:
        assert np.all(sparse[rows, cols] > 0) and np.all(kept[rows, cols] == 0)
        restored = kept.copy()
        restored[rows, cols] = sparse[rows, cols]
        np.testing.assert_array_equal(restored, sparse)  # nothing else changed
        held[rows, cols] += 1
    np.testing.assert_array_equal(held, (sparse > 0).astype(int))  # every sample held out exactly once
    for (_, rows, cols), (_, again_rows, again_cols) in zip(folds, crosscheck.fold_out(sparse)):
        np.testing.assert_array_equal(again_rows, rows)
        np.testing.assert_array_equal(again_cols, cols)


def test_it_applies_to_100_scattered_samples_or_more_and_never_to_scan_lines():
    depth = _plane()
    assert not crosscheck.applies(_scattered(depth, crosscheck.MIN_SAMPLES - 1))
    assert crosscheck.applies(_scattered(depth, crosscheck.MIN_SAMPLES))
    lines = np.zeros_like(depth)
    lines[2::4] = depth[2::4]  # 12 full rows: 768 samples
    assert not crosscheck.applies(lines)
    assert crosscheck.applies(lines, scan_lines=False)  # a caller that knew the pattern (complete_at) is believed
    assert not crosscheck.applies(_scattered(depth, crosscheck.MIN_SAMPLES), scan_lines=True)


def test_a_wrong_estimate_gives_way_to_the_linear_fill_and_a_right_one_is_kept():
    """On a plane the linear fill is exact inside the samples' hull: an estimate 1 m off everywhere loses at every
    held-out sample, and its weight is the least-squares one (near 0); the true depth itself is kept as it is."""
    depth = _plane()
    sparse = _scattered(depth, 300)
    off = depth + 1.0
    x, w = crosscheck.cross_checked(lambda s, at: off, sparse, depth.shape)
    folds = list(crosscheck.fold_out(sparse))
    y = np.concatenate([sparse[rows, cols] for _, rows, cols in folds])
    x_l = np.concatenate([linear_fill(kept)[rows, cols] for kept, rows, cols in folds])
    d = np.concatenate([off[rows, cols] for _, rows, cols in folds]) - x_l
    assert w == pytest.approx(np.clip(np.sum((y - x_l) * d) / np.sum(d * d), 0, 1), rel=1e-6) and 0.0 <= w < 0.02
    np.testing.assert_allclose(x, w * off + (1 - w) * linear_fill(sparse), rtol=1e-6)
    inside = np.abs(linear_fill(sparse) - depth) < 1e-4
    assert inside.mean() > 0.8 and np.abs(x - depth)[inside].max() < 0.021  # w * 1 m at most
    x, w = crosscheck.cross_checked(lambda s, at: depth, sparse, depth.shape)
    assert w == 1.0 and x is depth
    few = _scattered(depth, crosscheck.MIN_SAMPLES - 1)  # not checked: returned as it is
    x, w = crosscheck.cross_checked(lambda s, at: off, few, depth.shape)
    assert w == 1.0 and x is off


def test_a_model_that_fits_the_first_fold_costs_one_held_out_run():
    """The first fold runs before the others: a model closer than the linear fill at more than half of its held-out
    depths keeps w = 1 without the other folds (one held-out call of `estimate`, besides the frame's own); one that
    misses most of them by more gets all FOLDS runs, and the weight is then fitted on every sample."""
    depth = _plane()
    sparse = _scattered(depth, 300)
    bowl = depth + 0.05 * ((np.arange(depth.shape[1]) - 32) / 32.0) ** 2  # the plane bent: linear is exact, this not
    calls = []
    for estimate_of, runs in ((lambda s: depth, 1), (lambda s: bowl, crosscheck.FOLDS)):
        calls.clear()
        crosscheck.cross_checked(lambda s, at: calls.append(1) or estimate_of(s), sparse, depth.shape)
        assert len(calls) == 1 + runs  # the frame's own estimate and the held-out ones


def test_the_first_fold_runs_beside_the_frames_own_estimate():
    """XLA runs a model on about one core of two, so the first held-out estimate runs in another thread while the
    frame's own runs: here the frame's estimate waits for it to start (run one after the other, it would wait in
    vain), and every fold's call sees the quiet input checks, the frame's call not."""
    depth = _plane()
    sparse = _scattered(depth, 300)
    started, waited, quiet = threading.Event(), [], []
    bowl = depth + 0.05 * ((np.arange(depth.shape[1]) - 32) / 32.0) ** 2  # every fold runs

    def estimate(s, at):
        quiet.append(inputs._QUIET.get())
        if np.count_nonzero(s) == 300:
            waited.append(started.wait(timeout=60))
        else:
            started.set()
        return bowl

    crosscheck.cross_checked(estimate, sparse, depth.shape)
    assert waited == [True] and sorted(quiet) == [False] + [True] * crosscheck.FOLDS


def test_the_default_path_checks_a_learned_model_on_scattered_samples_only():
    """An untrained model (identity prox) returns its nearest fill, worse than the linear fill on a plane: the
    default path leans on the linear fill and comes closer to the depth, keeps every sample, and
    cross_check=False returns the model's own estimate; on scan lines the check does not run."""
    depth = _plane()
    rgb = np.full(depth.shape + (3,), 128, np.uint8)
    model = Completer.random(LIPConfig(initial_estimate="nearest"))
    sparse = _scattered(depth, 300)
    checked, plain = (complete_at(model, rgb, sparse, depth.shape, cross_check=c) for c in (True, False))
    unsampled = sparse == 0
    np.testing.assert_array_equal(plain[unsampled], model(rgb, sparse)[unsampled])  # the model's own estimate
    rmse = [float(np.sqrt(np.mean((x - depth)[unsampled] ** 2))) for x in (checked, plain)]
    assert rmse[0] < 0.5 * rmse[1], rmse
    np.testing.assert_array_equal(checked[~unsampled], sparse[~unsampled])
    lines = np.zeros_like(depth)
    lines[2::4] = depth[2::4]
    with pytest.warns(UserWarning, match="trained on scattered points") as warned:  # the untrained model's training
        np.testing.assert_array_equal(complete_at(model, rgb, lines, depth.shape),
                                      complete_at(model, rgb, lines, depth.shape, cross_check=False))
    assert {w.filename for w in warned} == {__file__}  # each warning points at the caller's line, not lipjax's


def test_the_held_out_estimate_runs_where_the_kept_samples_lie_as_far_apart_as_in_training():
    """200 points on 480x640 run at 196x261; the 160 kept beside a fold of 40 lie sqrt(200 / 160) x further apart, so
    their working size is that much smaller, and never larger than the frame's own run (a max_side cap)."""
    from lipjax.resolution import TARGET_SPACING_PX

    sparse = _scattered(np.full((480, 640), 3.0, np.float32), 200)
    s = TARGET_SPACING_PX / math.sqrt(480 * 640 / 160)
    assert crosscheck.held_out_size((196, 261), sparse) == (round(480 * s), round(640 * s)) == (175, 234)
    assert crosscheck.held_out_size((120, 160), sparse) == (120, 160)
    dense = _scattered(np.full((48, 64), 3.0, np.float32), 2000)  # 1.2 px apart: full size, as the frame
    assert crosscheck.held_out_size((48, 64), dense) == (48, 64)
    uneven = _scattered(np.full((480, 640), 3.0, np.float32), 203)  # folds of 41 and 40: all at the first's size
    t = TARGET_SPACING_PX / math.sqrt(480 * 640 / (203 - 41))
    assert crosscheck.held_out_size((196, 261), uneven) == (round(480 * t), round(640 * t))


def test_the_held_out_run_resizes_to_its_own_working_size(monkeypatch):
    """100 points on 160x200 run at full size; the 80 kept beside each fold of 20 lie 20 px apart, so the held-out
    runs are at 0.8x (128x160): the model sees the resized image there, and every sample is still kept in the
    output."""
    depth = _plane(160, 200)
    sparse = _scattered(depth, 100)
    sizes = []
    call = Completer.__call__
    monkeypatch.setattr(Completer, "__call__",
                        lambda self, rgb, s, **kw: sizes.append(rgb.shape[:2]) or call(self, rgb, s, **kw))
    model = Completer.random(LIPConfig(initial_estimate="nearest"))
    x = complete_at(model, np.full(depth.shape + (3,), 128, np.uint8), sparse, depth.shape)
    assert sorted(sizes, reverse=True) == [(160, 200)] + [(128, 160)] * crosscheck.FOLDS  # in threads: any order
    np.testing.assert_array_equal(x[sparse > 0], sparse[sparse > 0])


@pytest.mark.parametrize("flip", [False, True])
def test_a_frame_that_warns_warns_once_from_the_same_line(flip):
    """The held-out runs' checks (and the flipped frame's, each in a thread of its own) are quiet without touching the
    warning filters (whose every change makes Python forget what it has shown): three frames from one line warn
    once, as a folder of frames should."""
    depth = np.full((48, 64), 12.0, np.float32)  # beyond the untrained indoor model's 10 m range
    sparse = _scattered(depth, 300)
    model = Completer.random(LIPConfig(initial_estimate="nearest"))
    rgb = np.full(depth.shape + (3,), 128, np.uint8)
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("default")
        for _ in range(3):
            complete_at(model, rgb, sparse, depth.shape, flip=flip)
    assert len(shown) == 1 and "10 m range" in str(shown[0].message), [str(w.message) for w in shown]


def test_dense_input_is_not_checked():
    """Over DENSE samples per pixel (a depth camera's map with holes) the held-out samples lie a pixel from kept
    ones, where every fill is right: the default path runs the model once, as with cross_check=False."""
    from lipjax.resolution import DENSE

    depth = _plane()
    sparse = _scattered(depth, int(0.9 * depth.size))
    sparse[10:20, 20:40] = 0
    assert (sparse > 0).mean() > DENSE and not crosscheck.applies(sparse)
    assert crosscheck.applies(_scattered(depth, 300))
    model = Completer.random(LIPConfig(initial_estimate="nearest"))
    rgb = np.full(depth.shape + (3,), 128, np.uint8)
    np.testing.assert_array_equal(complete_at(model, rgb, sparse, depth.shape),
                                  complete_at(model, rgb, sparse, depth.shape, cross_check=False))


@pytest.mark.parametrize("shape", [(72, 1040), (48, 64)])
def test_the_check_and_the_working_size_agree_on_what_is_dense(shape):
    """At the DENSE boundary (one definition: lipjax.resolution.dense_from) a map is either checked at its own
    working size or capped as a dense map, never both ((0.3 * H) * W and 0.3 * (H * W) round differently on 72x1040,
    which split the two before)."""
    from lipjax.resolution import dense_from, is_capped

    n = dense_from(shape[0] * shape[1])
    for count, dense in ((n - 1, False), (n, True)):
        sparse = _scattered(np.full(shape, 3.0, np.float32), count)
        assert crosscheck.applies(sparse) is not dense and is_capped(count, shape, False) is dense
