"""Spreads the samples' residuals over the frame once the working-size estimate is resized back to full size.

Below full size the learned prox runs on a coarser grid (lipjax.resolution), and its estimate z, resized back
(bilinear), cannot follow the measured depths y between working pixels: near the samples the full-size linear fill is
closer than z (seen on renders scored where KITTI's ground truth lies: docs/decisions/0018-residual-spreading.md). The
samples give it back. With r = y - z at the measured pixels (m = 1, else 0) and G a Gaussian of sigma =
SIGMA_WORKING_PX working pixels along both axes for scattered samples and SCAN_LINE_SIGMAS_WORKING_PX (across the
lines, along them) for LiDAR scan lines (in full-size pixels (H / h, W / w) times those),

    x = max(z + (G * (m r)) / (G * m + delta), 0),     delta = DELTA G(0, 0)

a normalised convolution of the residuals that fades to z where G * m is small next to delta, about a working
pixel from every sample. A lone sample keeps r / (1 + DELTA) of its residual on its own pixel; the measured pixels
are set back exactly afterwards (lipjax.inference.complete_at). G is separable, cut at RADIUS_SIGMAS sigmas,
with zero padding outside the frame: on the host as cv2.sepFilter2D (`spread_on_host`), in a jax or ONNX graph as
two convolutions (`spread_residuals`, lipjax.onnx_export).
"""
from __future__ import annotations

import math

import cv2
import jax
import jax.numpy as jnp
import numpy as np

# why each, and its benchmark: lipjax.defaults (SCAN_LINE_SIGMAS_WORKING_PX: across the lines = along the rows' axis,
# then along them)
from lipjax.defaults import DELTA, RADIUS_SIGMAS, SCAN_LINE_SIGMAS_WORKING_PX, SIGMA_WORKING_PX


def spread_sigmas_px(frame: tuple[int, int], working: tuple[int, int], scan_lines: bool = False
                     ) -> tuple[float, float]:
    """(sigma_y, sigma_x) in full-size pixels: SIGMA_WORKING_PX working pixels of `working` inside `frame` both ways,
    or with `scan_lines` (samples in LiDAR scan lines, lipjax.inputs.is_lidar_pattern) SCAN_LINE_SIGMAS_WORKING_PX."""
    sigmas = SCAN_LINE_SIGMAS_WORKING_PX if scan_lines else (SIGMA_WORKING_PX, SIGMA_WORKING_PX)
    return tuple(sigma * big / small for sigma, big, small in zip(sigmas, frame, working))


def gaussian_kernel(sigma_px: float) -> np.ndarray:
    """The 1-D Gaussian of sigma_px at integer offsets -R..R, R = ceil(RADIUS_SIGMAS sigma_px), summing to 1."""
    if not sigma_px > 0:
        raise ValueError(f"sigma_px={sigma_px}: a Gaussian's sigma must be positive")
    radius = math.ceil(RADIUS_SIGMAS * sigma_px)
    kernel = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma_px) ** 2)
    return (kernel / kernel.sum()).astype(np.float32)


def _delta(kernels) -> float:
    """delta = DELTA G(0, 0) for the separable G of these 1-D kernels."""
    return DELTA * float(np.prod([k.max() for k in kernels]))


def spread_residuals(z: jnp.ndarray, sparse: jnp.ndarray, sigmas_px: tuple[float, float]) -> jnp.ndarray:
    """x (..., H, W) metres from the full-size estimate z and the samples `sparse` (..., H, W) metres, 0 = none:
    the module docstring's formula with G of (sigma_y, sigma_x) = `sigmas_px`, as two 1-D convolutions with zero
    padding (jax.lax; what the ONNX graph runs)."""
    ky, kx = (gaussian_kernel(s) for s in sigmas_px)
    shape = z.shape

    def blur(a):  # (..., H, W) -> (N, H, W, 1), a column then a row convolution, back
        a = a.reshape((-1,) + shape[-2:] + (1,))
        for k, pad in ((ky.reshape(-1, 1, 1, 1), ((len(ky) // 2,) * 2, (0, 0))),
                       (kx.reshape(1, -1, 1, 1), ((0, 0), (len(kx) // 2,) * 2))):
            a = jax.lax.conv_general_dilated(a, jnp.asarray(k), (1, 1), pad,
                                             dimension_numbers=("NHWC", "HWIO", "NHWC"))
        return a.reshape(shape)

    m = (sparse > 0).astype(jnp.float32)
    return jnp.maximum(z + blur(m * (sparse - z)) / (blur(m) + _delta((ky, kx))), 0.0)


def spread_on_host(z: np.ndarray, sparse: np.ndarray, working: tuple[int, int], scan_lines: bool = False
                   ) -> np.ndarray:
    """`spread_residuals` of a numpy (H, W) estimate resized up from `working`, with the sigmas of
    `spread_sigmas_px(..., scan_lines)` (cv2.sepFilter2D, zero padding)."""
    ky, kx = (gaussian_kernel(s) for s in spread_sigmas_px(z.shape, working, scan_lines))
    m = (sparse > 0).astype(np.float32)

    def blur(a):
        return cv2.sepFilter2D(a, cv2.CV_32F, kx, ky, borderType=cv2.BORDER_CONSTANT)

    return np.maximum(z + blur(m * (sparse - z)) / (blur(m) + _delta((ky, kx))), 0.0).astype(np.float32)
