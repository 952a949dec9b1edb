"""Resizes between a frame and its working size as fixed programs of gathers, sums and mins: the tables are numpy,
the application jax.numpy, so that the same resize runs in a jitted or an exported (ONNX) graph.

Each resize is separable: along an axis of n_in pixels, output pixel o reads the taps idx[o, t] (t < T) of the
input with weights wt[o, t], a (n_out, T) table:

    out[o] = sum_t wt[o, t] in[idx[o, t]]          (`resample_axis`)
    out[o] = min_t in[idx[o, t]]                  (`min_over_taps`; idx = n_in, one past the end, pads)

The tables reproduce what the host path (lipjax.inference.complete_at) calls:
  - `area_taps`: cv2.resize(..., INTER_AREA) downscaling, the weights of OpenCV's computeResizeAreaTab: input pixel
    j covers [j, j + 1), output pixel o covers [o s, (o + 1) s) with s = n_in / n_out, wt = overlap / s (overlaps
    under 1e-3 px dropped, as OpenCV does).
  - `bilinear_taps`: cv2.resize(..., INTER_LINEAR) on float32: x = (o + 0.5) / s' - 0.5 with s' = n_out / n_in,
    taps floor(x) and floor(x) + 1 with weights 1 - f, f (f = x - floor(x), in float32 as OpenCV), clamped to the
    first and last pixel at the borders.
  - `reproject_taps`: lipjax.inference.reproject_sparse's mapping, input pixel j -> output pixel
    min(floor((j + 0.5) n_out / n_in), n_out - 1); output o takes the min over its preimage (nearest depth wins).
"""
from __future__ import annotations

import math

import jax.numpy as jnp
import numpy as np

AREA_EPS_PX = 1e-3  # OpenCV's threshold for a partial input pixel in an area resize


def _table(rows: list[list[tuple[int, float]]], pad_index: int) -> tuple[np.ndarray, np.ndarray]:
    """Ragged (index, weight) lists -> (n_out, T) int32 indices and float32 weights, padded with (pad_index, 0)."""
    taps = max(len(r) for r in rows)
    idx = np.full((len(rows), taps), pad_index, np.int32)
    wt = np.zeros((len(rows), taps), np.float32)
    for o, row in enumerate(rows):
        for t, (j, weight) in enumerate(row):
            idx[o, t], wt[o, t] = j, weight
    return idx, wt


def area_taps(n_in: int, n_out: int) -> tuple[np.ndarray, np.ndarray]:
    """(n_out, T) indices and weights of an INTER_AREA downscaling from n_in to n_out <= n_in pixels."""
    if not 1 <= n_out <= n_in:
        raise ValueError(f"an area resize shrinks: n_out must be in [1, {n_in}], got {n_out}")
    s = n_in / n_out
    rows = []
    for o in range(n_out):
        lo, hi = o * s, o * s + s
        cell = min(s, n_in - lo)
        first, last = math.ceil(lo), min(math.floor(hi), n_in - 1)
        first = min(first, last)
        row = [(first - 1, (first - lo) / cell)] if first - lo > AREA_EPS_PX else []
        row += [(j, 1.0 / cell) for j in range(first, last)]
        if hi - last > AREA_EPS_PX:
            row.append((last, min(hi - last, 1.0, cell) / cell))
        rows.append(row)
    return _table(rows, 0)


def bilinear_taps(n_in: int, n_out: int) -> tuple[np.ndarray, np.ndarray]:
    """(n_out, 2) indices and weights of an INTER_LINEAR resize (half-pixel centres) from n_in to n_out pixels."""
    scale = 1.0 / (n_out / n_in)
    rows = []
    for o in range(n_out):
        x = np.float32((o + 0.5) * scale - 0.5)
        j = math.floor(x)
        f = float(x - np.float32(j))
        if j < 0:
            j, f = 0, 0.0
        if j >= n_in - 1:
            j, f = n_in - 1, 0.0
        rows.append([(j, 1.0 - f), (min(j + 1, n_in - 1), f)])
    return _table(rows, 0)


def reproject_taps(n_in: int, n_out: int) -> np.ndarray:
    """(n_out, T) indices: the input pixels that land in each output pixel (lipjax.inference.reproject_sparse),
    padded with n_in."""
    target = np.minimum(((np.arange(n_in) + 0.5) * n_out / n_in).astype(np.int64), n_out - 1)
    return _table([[(int(j), 1.0) for j in np.flatnonzero(target == o)] for o in range(n_out)], n_in)[0]


def resample_axis(a: jnp.ndarray, idx: np.ndarray, wt: np.ndarray, axis: int) -> jnp.ndarray:
    """sum_t wt[o, t] a[..., idx[o, t], ...] along `axis`: float32, that axis becomes n_out long."""
    axis = axis % a.ndim
    shape = (1,) * axis + (idx.shape[0],) + (1,) * (a.ndim - axis - 1)
    out = None
    for t in range(idx.shape[1]):
        term = jnp.take(a, idx[:, t], axis=axis).astype(jnp.float32) * wt[:, t].reshape(shape)
        out = term if out is None else out + term
    return out


def min_over_taps(a: jnp.ndarray, idx: np.ndarray, axis: int) -> jnp.ndarray:
    """min_t a[..., idx[o, t], ...] along `axis`, the pad index reading +inf."""
    axis = axis % a.ndim
    pad = [(0, 0)] * a.ndim
    pad[axis] = (0, 1)
    a = jnp.pad(a, pad, constant_values=jnp.inf)
    out = None
    for t in range(idx.shape[1]):
        term = jnp.take(a, idx[:, t], axis=axis)
        out = term if out is None else jnp.minimum(out, term)
    return out


def reproject_nearest(sparse: jnp.ndarray, size: tuple[int, int]) -> jnp.ndarray:
    """(..., H, W) sparse depth metres (0 = none) -> (..., h, w): each sample moved to the pixel of the (h, w) grid
    its centre falls in, the smallest depth where several land in one (lipjax.inference.reproject_sparse)."""
    big_h, big_w = sparse.shape[-2:]
    far = jnp.where(sparse > 0, sparse, jnp.inf)
    small = min_over_taps(min_over_taps(far, reproject_taps(big_h, size[0]), -2), reproject_taps(big_w, size[1]), -1)
    return jnp.where(jnp.isfinite(small), small, 0.0)


def resize_area_uint8(rgb: jnp.ndarray, size: tuple[int, int]) -> jnp.ndarray:
    """(..., H, W, C) uint8 -> (..., h, w, C) float32 holding cv2.resize(rgb, (w, h), INTER_AREA)'s uint8 values:
    rounded half to even (OpenCV's saturate_cast), or half up for an exact 2x2 shrink (OpenCV's fast path computes
    (sum + 2) >> 2 there)."""
    big_h, big_w = rgb.shape[-3:-1]
    small = resample_axis(resample_axis(rgb, *area_taps(big_h, size[0]), -3), *area_taps(big_w, size[1]), -2)
    rounded = jnp.floor(small + 0.5) if (big_h, big_w) == (2 * size[0], 2 * size[1]) else jnp.round(small)
    return jnp.clip(rounded, 0.0, 255.0)


def resize_bilinear(a: jnp.ndarray, size: tuple[int, int]) -> jnp.ndarray:
    """(..., h, w) float32 -> (..., H, W): cv2.resize(a, (W, H), INTER_LINEAR)."""
    h, w = a.shape[-2:]
    return resample_axis(resample_axis(a, *bilinear_taps(h, size[0]), -2), *bilinear_taps(w, size[1]), -1)
