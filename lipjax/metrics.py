r"""Depth-completion metrics, with units in every name, and their data-set aggregation.

Evaluated pixels of one image (the evaluation mask E):

    E = valid & isfinite(gt) & (min_depth_m < gt <= max_depth_m)

(lower bound exclusive, upper inclusive). The named protocols of lipjax.data.protocols carry the ranges to pass
here (EvalProtocol.min_depth_m, max_depth_m), e.g. NYU (0, 10] m, outdoor (0, 80] m.

Per image, with d = prediction and g = ground truth (metres), over the pixels of E:

    mae_m          = mean |d - g|                                   metres
    rmse_m         = sqrt(mean (d - g)^2)                           metres
    mae_mm, rmse_mm = 1000 * the above                              millimetres
    rel            = mean |d - g| / g                               dimensionless
    delta{1,2,3}_pct = 100 * mean[max(d/g, g/d) < 1.25^j]           percent (not a fraction)
    imae_1_per_km  = mean |1000/d - 1000/g|                         1/km  (1000 / metres)
    irmse_1_per_km = sqrt(mean (1000/d - 1000/g)^2)                 1/km

and the two ablation quantities of the paper's Fig. 4 (plus two companions), all MAE in metres:

    mae_all_m        over all of E (Fig. 4b, "total MAE"); the same pixel set, hence the same value, as mae_m,
                     kept under the paper's name so ablation code reads like the figure.
    mae_sampled_m    over E & (sparse > 0): the measured pixels, scored against the ground truth (Fig. 4c).
    mae_unsampled_m  over E & (sparse == 0): the pixels the method had to invent.
    mae_vs_input_m   |d - sparse| over sparse > 0 (ground truth not needed): the data consistency the ADMM
                     x-update controls. It differs from mae_sampled_m wherever the sparse input is noisy or
                     disagrees with the ground truth (e.g. KITTI's raw LiDAR vs its accumulated ground truth).

Predictions <= 0: the linear metrics (mae, rmse, rel, and the four MAE above) use the raw prediction, so a
non-positive prediction is penalised by its full error. The ratio and inverse metrics (delta_j, imae, irmse) are
undefined for d <= 0; there the prediction is clamped to `pred_floor_m` (default 1 mm) first, so such a pixel fails
every delta threshold and contributes a large but finite inverse error (1000/0.001 = 1e6 1/km). Non-finite
predictions on evaluated pixels are an error (ValueError), never silently dropped.

Averaging: every metric is computed per image, then averaged over images with equal weight per image (as the
KITTI depth devkit does: RMSE is the mean of per-image RMSEs, not the RMSE of all pixels pooled).
`MetricAggregator` does the second step. An image with no evaluated pixel (or, for the sampled metrics, no
sampled pixel with ground truth) gets NaN for those metrics and is left out of their mean; `counts` says how
many images each mean is over.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

DEFAULT_MIN_DEPTH_M = 0.0
"""Default lower end (exclusive) of the evaluated ground-truth range, metres: only gt = 0 / invalid is cut."""
DEFAULT_MAX_DEPTH_M = math.inf
"""Default upper end of the evaluated ground-truth range, metres (no upper cut)."""
DEFAULT_PRED_FLOOR_M = 1e-3
"""Predictions below this (metres) are raised to it for the ratio and inverse metrics only."""

DELTA_BASE = 1.25

# Metric names, in the order tables print them. Counts are ints and not averaged like metrics.
ERROR_METRICS = (
    "mae_m",
    "rmse_m",
    "mae_mm",
    "rmse_mm",
    "rel",
    "delta1_pct",
    "delta2_pct",
    "delta3_pct",
    "imae_1_per_km",
    "irmse_1_per_km",
    "mae_all_m",
)
SAMPLED_METRICS = ("mae_sampled_m", "mae_unsampled_m", "mae_vs_input_m")
METRIC_NAMES = ERROR_METRICS + SAMPLED_METRICS


def _as_2d(name: str, a: Any, dtype) -> np.ndarray:
    a = np.asarray(a, dtype=dtype)
    if a.ndim != 2:
        raise ValueError(f"{name} must be (H, W), got shape {a.shape}")
    return a


def evaluation_mask(
    gt: np.ndarray, valid: np.ndarray, *, min_depth_m: float = DEFAULT_MIN_DEPTH_M,
    max_depth_m: float = DEFAULT_MAX_DEPTH_M
) -> np.ndarray:
    """(H, W) bool mask E of the pixels that are scored: valid, finite ground truth in (min, max] metres."""
    gt = np.asarray(gt)
    with np.errstate(invalid="ignore"):
        return np.asarray(valid, dtype=bool) & np.isfinite(gt) & (gt > min_depth_m) & (gt <= max_depth_m)


def compute_metrics(
    pred: Any,
    gt: Any,
    valid: Any,
    sparse: Any | None = None,
    *,
    min_depth_m: float = DEFAULT_MIN_DEPTH_M,
    max_depth_m: float = DEFAULT_MAX_DEPTH_M,
    pred_floor_m: float = DEFAULT_PRED_FLOOR_M,
) -> dict[str, float]:
    """All metrics of one image (see the module docstring for definitions, units and edge cases).

    Args:
      pred: (H, W) predicted depth, metres (numpy or jax array).
      gt: (H, W) ground-truth depth, metres.
      valid: (H, W) bool, True where gt is trusted.
      sparse: optional (H, W) sparse input depth, metres, 0 where not sampled; enables the sampled metrics.
      min_depth_m, max_depth_m: evaluated ground-truth range (min, max] in metres.
      pred_floor_m: floor applied to pred for delta and inverse metrics only, metres (> 0).

    Returns:
      dict of float metrics (METRIC_NAMES; the sampled ones only when sparse is given) plus integer pixel
      counts: n_eval_px = |E|, and with sparse: n_sampled_eval_px = |E & sampled|, n_input_px = |sampled|.
    """
    if not pred_floor_m > 0:
        raise ValueError(f"pred_floor_m must be > 0 metres, got {pred_floor_m}")
    if not min_depth_m < max_depth_m:
        raise ValueError(f"empty depth range ({min_depth_m}, {max_depth_m}] m")
    d = _as_2d("pred", pred, np.float64)
    g = _as_2d("gt", gt, np.float64)
    v = _as_2d("valid", valid, bool)
    if not d.shape == g.shape == v.shape:
        raise ValueError(f"shape mismatch: pred {d.shape}, gt {g.shape}, valid {v.shape}")
    e = evaluation_mask(g, v, min_depth_m=min_depth_m, max_depth_m=max_depth_m)
    if not np.all(np.isfinite(d[e])):
        raise ValueError("pred has NaN/inf on evaluated pixels")

    out: dict[str, float] = {}
    n = int(e.sum())
    if n == 0:
        out.update({k: math.nan for k in ERROR_METRICS})
    else:
        de, ge = d[e], g[e]
        err = de - ge
        abs_err = np.abs(err)
        mae = float(abs_err.mean())
        rmse = float(np.sqrt(np.mean(err**2)))
        dc = np.maximum(de, pred_floor_m)
        ratio = np.maximum(dc / ge, ge / dc)
        inv_err = 1000.0 / dc - 1000.0 / ge
        out.update(
            mae_m=mae,
            rmse_m=rmse,
            mae_mm=1000.0 * mae,
            rmse_mm=1000.0 * rmse,
            rel=float(np.mean(abs_err / ge)),
            delta1_pct=100.0 * float(np.mean(ratio < DELTA_BASE)),
            delta2_pct=100.0 * float(np.mean(ratio < DELTA_BASE**2)),
            delta3_pct=100.0 * float(np.mean(ratio < DELTA_BASE**3)),
            imae_1_per_km=float(np.mean(np.abs(inv_err))),
            irmse_1_per_km=float(np.sqrt(np.mean(inv_err**2))),
            mae_all_m=mae,
        )
    out["n_eval_px"] = n

    if sparse is not None:
        s = _as_2d("sparse", sparse, np.float64)
        if s.shape != d.shape:
            raise ValueError(f"shape mismatch: sparse {s.shape}, pred {d.shape}")
        sampled = np.isfinite(s) & (s > 0)
        if not np.all(np.isfinite(d[sampled])):
            raise ValueError("pred has NaN/inf on sampled pixels")

        def _mae(mask: np.ndarray, ref: np.ndarray) -> float:
            return float(np.mean(np.abs(d[mask] - ref[mask]))) if mask.any() else math.nan

        out["mae_sampled_m"] = _mae(e & sampled, g)
        out["mae_unsampled_m"] = _mae(e & ~sampled, g)
        out["mae_vs_input_m"] = _mae(sampled, s)
        out["n_sampled_eval_px"] = int((e & sampled).sum())
        out["n_input_px"] = int(sampled.sum())
    return out


class MetricAggregator:
    """Accumulates per-image metric dicts and returns the per-image-then-mean data-set metrics.

    Each image weighs the same regardless of its number of valid pixels (KITTI devkit convention). NaN entries
    (an image without pixels for that metric) are skipped for that metric only. Integer pixel counts
    (keys starting with "n_") are summed, not averaged.
    """

    def __init__(self) -> None:
        self._values: dict[str, list[float]] = {}
        self._pixel_counts: dict[str, int] = {}
        self.num_images = 0

    def add(self, metrics: Mapping[str, float]) -> None:
        """Adds one image's metrics (a dict from `compute_metrics`)."""
        self.num_images += 1
        for k, val in metrics.items():
            if k.startswith("n_"):
                self._pixel_counts[k] = self._pixel_counts.get(k, 0) + int(val)
            else:
                self._values.setdefault(k, []).append(float(val))

    def means(self) -> dict[str, float]:
        """Mean over images of each metric, ignoring NaNs; NaN if no image had that metric."""
        out = {}
        for k, vals in self._values.items():
            a = np.asarray(vals, dtype=np.float64)
            a = a[np.isfinite(a)]
            out[k] = float(a.mean()) if a.size else math.nan
        return out

    def counts(self) -> dict[str, int]:
        """For each metric, the number of images its mean is over; for each "n_" key, the summed pixel count."""
        out = {k: int(np.isfinite(np.asarray(v, dtype=np.float64)).sum()) for k, v in self._values.items()}
        out.update(self._pixel_counts)
        return out
