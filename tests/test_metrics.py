import math

import numpy as np
import pytest

from lipjax.metrics import METRIC_NAMES, MetricAggregator, compute_metrics, evaluation_mask

# A 2x2 image with errors known by hand: +0.5 m, 0, -1 m, 0.
GT = np.array([[1.0, 2.0], [4.0, 5.0]], np.float32)
PRED = np.array([[1.5, 2.0], [3.0, 5.0]], np.float32)
ALL = np.ones((2, 2), bool)


def test_hand_computed_values_2x2():
    m = compute_metrics(PRED, GT, ALL)
    assert m["mae_m"] == pytest.approx(1.5 / 4)
    assert m["rmse_m"] == pytest.approx(math.sqrt((0.25 + 1.0) / 4))
    assert m["rel"] == pytest.approx((0.5 / 1 + 1.0 / 4) / 4)
    # ratios max(d/g, g/d): 1.5, 1, 4/3, 1 -> two of four below 1.25; all below 1.25^2 = 1.5625.
    assert m["delta1_pct"] == pytest.approx(50.0)
    assert m["delta2_pct"] == pytest.approx(100.0)
    assert m["delta3_pct"] == pytest.approx(100.0)
    # inverse depth in 1/km: 1000/1.5 - 1000/1 = -1000/3; 1000/3 - 1000/4 = 250/3.
    assert m["imae_1_per_km"] == pytest.approx((1000 / 3 + 250 / 3) / 4)
    assert m["irmse_1_per_km"] == pytest.approx(math.sqrt(((1000 / 3) ** 2 + (250 / 3) ** 2) / 4))
    assert m["mae_all_m"] == m["mae_m"]
    assert m["n_eval_px"] == 4
    assert "mae_sampled_m" not in m  # no sparse input given


def test_units_mm_is_1000_m_and_delta_in_percent():
    rng = np.random.default_rng(0)
    gt = rng.uniform(0.5, 10, (7, 9)).astype(np.float32)
    pred = gt + rng.normal(0, 0.7, gt.shape).astype(np.float32)
    m = compute_metrics(pred, gt, gt > 0)
    assert m["mae_mm"] == pytest.approx(1000 * m["mae_m"])
    assert m["rmse_mm"] == pytest.approx(1000 * m["rmse_m"])
    ratio = np.maximum(np.maximum(pred, 1e-3) / gt, gt / np.maximum(pred, 1e-3))
    assert m["delta1_pct"] == pytest.approx(100 * np.mean(ratio < 1.25))
    assert 0 < m["delta1_pct"] < m["delta3_pct"] <= 100  # percent, not a fraction


def test_valid_mask_and_depth_range_select_pixels():
    gt = np.array([[0.5, 2.0], [20.0, 5.0]], np.float32)
    pred = np.array([[9.0, 3.0], [0.0, 5.0]], np.float32)
    valid = np.array([[True, True], [True, True]])
    m = compute_metrics(pred, gt, valid, min_depth_m=1.0, max_depth_m=10.0)
    # only gt = 2 (error 1) and gt = 5 (error 0) are in [1, 10] m
    assert m["n_eval_px"] == 2
    assert m["mae_m"] == pytest.approx(0.5)
    valid[0, 1] = False
    m = compute_metrics(pred, gt, valid, min_depth_m=1.0, max_depth_m=10.0)
    assert m["n_eval_px"] == 1 and m["mae_m"] == 0.0
    # the range is (min, max]: lower bound exclusive, upper inclusive (as lipjax.data.protocols)
    e = evaluation_mask(gt, np.ones_like(valid), min_depth_m=2.0, max_depth_m=5.0)
    np.testing.assert_array_equal(e, [[False, False], [False, True]])
    e = evaluation_mask(gt, np.ones_like(valid), min_depth_m=1.9, max_depth_m=5.0)
    np.testing.assert_array_equal(e, [[False, True], [False, True]])


def test_sampled_unsampled_and_vs_input():
    gt = np.array([[1.0, 2.0], [3.0, 0.0]], np.float32)
    valid = gt > 0
    pred = np.array([[1.1, 2.5], [3.0, 7.0]], np.float32)
    # sampled: (0,0) with a noisy measurement 1.2 and (1,1) where the ground truth is invalid
    sparse = np.array([[1.2, 0.0], [0.0, 6.0]], np.float32)
    m = compute_metrics(pred, gt, valid, sparse)
    assert m["mae_sampled_m"] == pytest.approx(0.1)  # vs gt, only (0,0) has valid gt
    assert m["mae_unsampled_m"] == pytest.approx((0.5 + 0.0) / 2)
    assert m["mae_vs_input_m"] == pytest.approx((0.1 + 1.0) / 2)  # vs the input, at both samples
    assert (m["n_sampled_eval_px"], m["n_input_px"], m["n_eval_px"]) == (1, 2, 3)


def test_non_positive_predictions_clamped_only_for_ratio_and_inverse():
    gt = np.array([[2.0, 4.0]], np.float32)
    pred = np.array([[0.0, -1.0]], np.float32)
    m = compute_metrics(pred, gt, gt > 0)
    assert m["mae_m"] == pytest.approx((2 + 5) / 2)  # raw predictions: full error
    assert m["delta3_pct"] == 0.0
    expected_inv = np.array([1000 / 1e-3 - 1000 / 2, 1000 / 1e-3 - 1000 / 4])
    assert m["imae_1_per_km"] == pytest.approx(expected_inv.mean())
    assert m["irmse_1_per_km"] == pytest.approx(np.sqrt(np.mean(expected_inv**2)))


def test_nan_prediction_and_bad_shapes_raise():
    pred = PRED.copy()
    pred[0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        compute_metrics(pred, GT, ALL)
    # a NaN on a pixel that is not evaluated is harmless
    valid = ALL.copy()
    valid[0, 0] = False
    assert compute_metrics(pred, GT, valid)["n_eval_px"] == 3
    with pytest.raises(ValueError, match="shape"):
        compute_metrics(PRED, GT[:1], ALL[:1])
    with pytest.raises(ValueError):
        compute_metrics(PRED[None], GT, ALL)


def test_empty_image_gives_nan_and_is_skipped_by_aggregator():
    empty = compute_metrics(PRED, GT, np.zeros((2, 2), bool), GT * 0)
    assert math.isnan(empty["mae_m"]) and empty["n_eval_px"] == 0 and math.isnan(empty["mae_vs_input_m"])
    agg = MetricAggregator()
    agg.add(empty)
    agg.add(compute_metrics(PRED, GT, ALL, GT * 0))
    assert agg.means()["mae_m"] == pytest.approx(0.375)
    assert agg.counts()["mae_m"] == 1 and agg.num_images == 2
    assert math.isnan(agg.means()["mae_vs_input_m"]) and agg.counts()["mae_vs_input_m"] == 0


def test_per_image_then_mean_averaging():
    # image A: one valid pixel with error 1 m; image B: three valid pixels with error 0.
    gt = np.full((2, 2), 2.0, np.float32)
    va = np.array([[True, False], [False, False]])
    ma = compute_metrics(gt + 1, gt, va)
    mb = compute_metrics(gt, gt, ~va)
    agg = MetricAggregator()
    agg.add(ma)
    agg.add(mb)
    means = agg.means()
    assert means["mae_m"] == pytest.approx(0.5)  # pooled over pixels it would be 0.25
    assert agg.counts()["n_eval_px"] == 4  # pixel counts are summed
    assert set(METRIC_NAMES[:11]) <= set(means)


def test_rmse_is_mean_of_per_image_rmse():
    gt = np.ones((1, 2), np.float32)
    agg = MetricAggregator()
    agg.add(compute_metrics(np.array([[4.0, 1.0]]), gt, gt > 0))  # rmse sqrt(9/2)
    agg.add(compute_metrics(np.array([[1.0, 1.0]]), gt, gt > 0))  # rmse 0
    assert agg.means()["rmse_m"] == pytest.approx(math.sqrt(4.5) / 2)
