"""Spreads the samples' residuals over the frame once the working-size estimate is resized back to full size.

Below full size the learned prox runs on a coarser grid (lipjax.resolution), and its estimate z, resized back
(bilinear), cannot follow the measured depths y between working pixels: near the samples the full-size linear
fill is closer than z (seen on renders scored where KITTI's ground truth lies: docs/design-notes.md, rule 46).
The samples give it back. With r = y - z at the measured pixels (m = 1, else 0) and G a Gaussian of
sigma = SIGMA_WORKING_PX working pixels (in full-size pixels (H / h, W / w) times that, one sigma per axis),

    x = max(z + (G * (m r)) / (G * m + delta), 0),     delta = DELTA G(0, 0)

a normalised convolution of the residuals that fades to z where G * m is small next to delta, about a working
pixel from every sample. A lone sample keeps r / (1 + DELTA) of its residual on its own pixel; the measured pixels
are set back exactly afterwards (lipjax.inference.complete_at). G is separable, its taps cut at 3 sigmas and
dropped outside the frame (zero padding; lipjax.resample.gaussian_taps), so that the same step runs on the host (jitted) and inside the ONNX graph (lipjax.onnx_export).
"""
from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np

from lipjax.resample import gaussian_kernel, gaussian_taps, resample_axis

SIGMA_WORKING_PX = 0.5  # the Gaussian's sigma, in working pixels (rule 46)
DELTA = 0.05  # the fade: delta = DELTA x the Gaussian's centre weight (rule 46)


def spread_sigmas_px(frame: tuple[int, int], working: tuple[int, int]) -> tuple[float, float]:
    """(sigma_y, sigma_x) in full-size pixels: SIGMA_WORKING_PX working pixels of `working` inside `frame`."""
    return tuple(SIGMA_WORKING_PX * big / small for big, small in zip(frame, working))


def spread_residuals(z: jnp.ndarray, sparse: jnp.ndarray, sigmas_px: tuple[float, float]) -> jnp.ndarray:
    """x (..., H, W) metres from the full-size estimate z and the samples `sparse` (..., H, W) metres, 0 = none:
    the module docstring's formula with G of (sigma_y, sigma_x) = `sigmas_px`."""
    (h, w), (sy, sx) = z.shape[-2:], sigmas_px
    taps_y, taps_x = gaussian_taps(h, sy), gaussian_taps(w, sx)

    def blur(a):
        return resample_axis(resample_axis(a, *taps_y, -2), *taps_x, -1)

    m = (sparse > 0).astype(jnp.float32)
    delta = DELTA * float(np.prod([gaussian_kernel(s)[1].max() for s in sigmas_px]))
    return jnp.maximum(z + blur(m * (sparse - z)) / (blur(m) + delta), 0.0)


@functools.partial(jax.jit, static_argnames="sigmas_px")
def _spread_jit(z, sparse, sigmas_px):
    return spread_residuals(z, sparse, sigmas_px)


def spread_on_host(z: np.ndarray, sparse: np.ndarray, working: tuple[int, int]) -> np.ndarray:
    """`spread_residuals` of a numpy (H, W) estimate resized up from `working`, compiled once per shape."""
    sigmas = spread_sigmas_px(z.shape[-2:], working)
    return np.array(_spread_jit(jnp.asarray(z, jnp.float32), jnp.asarray(sparse, jnp.float32), sigmas))
