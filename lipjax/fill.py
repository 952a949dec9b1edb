"""A cheap, jit-able dense initial guess from sparse depth: multi-scale normalised box convolution.

For growing box radii r = 1, 2, 4, ... the estimate at a pixel is sum(w * y) / sum(w) over its (2r+1)^2 window;
each pixel takes the estimate of the smallest window that holds at least one sample. The result is a
piecewise-smooth fill (close to a nearest-neighbour fill, but averaged), computed with cumulative sums in
O(H W log max(H, W)). It is used as ADMM's z_0 so that the first learned prox refines a dense map instead of
inventing depth from isolated points; measured pixels are restored exactly by the x-update anyway.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp


def _window_sum(a: jax.Array, radius: int, axis: int) -> jax.Array:
    """Sum over [i - radius, i + radius] along `axis`, treating outside the image as zero."""
    n = a.shape[axis]
    c = jnp.cumsum(a, axis=axis)
    pad = [(0, 0)] * a.ndim
    pad[axis] = (1, 0)
    c = jnp.pad(c, pad)
    idx = jnp.arange(n)
    hi = jnp.minimum(idx + radius + 1, n)
    lo = jnp.maximum(idx - radius, 0)
    return jnp.take(c, hi, axis=axis) - jnp.take(c, lo, axis=axis)


def box_fill_with_radius(y: jax.Array, weights: jax.Array) -> tuple[jax.Array, jax.Array]:
    """Dense fill of sparse depth, and the window radius each pixel was filled from.

    Args:
      y: (..., H, W) sparse depth in metres, 0 where unmeasured.
      weights: (..., H, W) mask or confidence weights >= 0.

    Returns:
      filled: (..., H, W) dense depth in metres; 0 only where the whole image has no sample.
      radius: (..., H, W) float32, the half-width in pixels of the smallest window holding a sample (0 at a
        sample itself): a cheap distance-to-the-nearest-measurement, i.e. how far the fill was extrapolated.
    """
    h, w = y.shape[-2:]
    wy = weights * y
    measured = weights > 1e-6
    filled = jnp.where(measured, y, 0.0)
    found = measured
    radius_map = jnp.zeros(y.shape, jnp.float32)
    radius = 1
    while True:
        num = _window_sum(_window_sum(wy, radius, -2), radius, -1)
        den = _window_sum(_window_sum(weights, radius, -2), radius, -1)
        has = den > 1e-6
        new = ~found & has
        filled = jnp.where(new, num / jnp.where(has, den, 1.0), filled)
        radius_map = jnp.where(new, float(radius), radius_map)
        found = found | has
        if radius >= max(h, w):
            break
        radius *= 2
    return filled, radius_map


def box_fill(y: jax.Array, weights: jax.Array) -> jax.Array:
    """Dense fill of sparse depth (see box_fill_with_radius): (..., H, W) metres in, (..., H, W) metres out."""
    return box_fill_with_radius(y, weights)[0]


def sample_radius(weights: jax.Array) -> jax.Array:
    """(..., H, W) weights >= 0 -> (..., H, W) float32: `box_fill_with_radius`'s radius map, without the fill.

    The same windows and the same rule (the smallest r in 1, 2, 4, ... whose (2r+1)^2 window holds a sample,
    weight > 1e-6; 0 at a sample), from one summed-area table of the sample count read by slicing for every r,
    instead of two cumulative sums and gathers per r. Counts are exact in float32 up to 2^24 pixels.
    """
    h, w = weights.shape[-2:]
    measured = (weights > 1e-6).astype(jnp.float32)
    lead = [(0, 0)] * (weights.ndim - 2)
    table = jnp.pad(jnp.cumsum(jnp.cumsum(measured, axis=-2), axis=-1), lead + [(1, 0), (1, 0)])
    radius_map = jnp.zeros(weights.shape, jnp.float32)
    found = measured > 0
    radius = 1
    while True:
        # table[i, j] = count in rows < i, cols < j; edge padding clamps the window to the image
        t = jnp.pad(table, lead + [(radius, radius), (radius, radius)], mode="edge")
        hi_r, lo_r = slice(2 * radius + 1, 2 * radius + 1 + h), slice(0, h)
        hi_c, lo_c = slice(2 * radius + 1, 2 * radius + 1 + w), slice(0, w)
        count = t[..., hi_r, hi_c] - t[..., lo_r, hi_c] - t[..., hi_r, lo_c] + t[..., lo_r, lo_c]
        new = ~found & (count > 0.5)
        radius_map = jnp.where(new, float(radius), radius_map)
        found = found | new
        if radius >= max(h, w):
            break
        radius *= 2
    return radius_map
