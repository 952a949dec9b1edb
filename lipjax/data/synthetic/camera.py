"""The camera model: per-frame parameters and image formation.

`_camera_model` draws the parameters (exposure, white balance, blur, noise, vignetting, gamma);
`_camera_image` turns linear radiance into 8-bit RGB: optical blur, exposure and white balance, vignetting,
signal-dependent sensor noise, a tone curve with a highlight shoulder, quantisation.
"""
from __future__ import annotations

import functools

import cv2
import numpy as np

from lipjax.data.synthetic.constants import _F32
from lipjax.data.synthetic.scene import Scene


def _camera_model(rng) -> dict:
    return dict(
        exposure=rng.uniform(0.1, 0.28),
        wb=np.array([rng.uniform(0.85, 1.15), 1.0, rng.uniform(0.85, 1.15)], _F32),
        blur=rng.uniform(0.05, 0.22),
        # in linear units, before the ~1/2.2 gamma that amplifies it in the shadows
        noise_read=rng.uniform(0.0002, 0.002),
        noise_shot=rng.uniform(0.002, 0.015),
        vignette=rng.uniform(0.0, 0.35),
        gamma=float(rng.choice([2.0, 2.2, 2.4])),
    )


@functools.lru_cache(maxsize=16)
def _tone_lut(gamma: float) -> np.ndarray:
    """Linear [0, _LUT_MAX] -> uint8 with a soft highlight shoulder and 1/gamma encoding."""
    x = np.linspace(0.0, _LUT_MAX, _LUT_SIZE)
    y = np.where(x < 0.7, x, 0.7 + 0.3 * (1.0 - np.exp(-(x - 0.7) / 0.3)))
    return np.round(255.0 * np.clip(y, 0, 1) ** (1.0 / gamma)).astype(np.uint8)


_LUT_MAX = 4.0
_LUT_SIZE = 1 << 16


@functools.lru_cache(maxsize=1)
def _noise_bank() -> np.ndarray:
    # Gaussian noise is the slowest part of the camera model; a fixed bank read at a random offset is as
    # good for sensor noise and ~10x cheaper than drawing it per frame.
    return np.random.default_rng(0xB0A7).standard_normal(1 << 21, dtype=_F32)


@functools.lru_cache(maxsize=16)
def _vignette(H: int, W: int) -> np.ndarray:
    yy = (np.arange(H, dtype=_F32) - (H - 1) / 2) / (H / 2)
    xx = (np.arange(W, dtype=_F32) - (W - 1) / 2) / (W / 2)
    return (xx[None, :] ** 2 + yy[:, None] ** 2) * 0.5


def _camera_image(lin: np.ndarray, scene: Scene, H: int, W: int, noise_rng) -> np.ndarray:
    """Linear radiance lin (3, H * W) float32 (overwritten) -> (H, W, 3) uint8: blur, exposure + white
    balance, vignetting, noise, tone curve, 8 bits. noise_rng: the frame's sensor-noise stream."""
    a = scene.blur
    kernel = np.array([a, 1.0 - 2.0 * a, a], _F32)
    img = lin.reshape(3, H, W)
    for c in range(3):
        img[c] = cv2.sepFilter2D(img[c], -1, kernel, kernel, borderType=cv2.BORDER_REPLICATE)
    lum = 0.2126 * float(img[0, ::3, ::3].mean()) + 0.7152 * float(img[1, ::3, ::3].mean()) + \
        0.0722 * float(img[2, ::3, ::3].mean())
    gain = scene.exposure / max(lum, 1e-6)
    img *= 1.0 - scene.vignette * _vignette(H, W)
    img *= (gain * scene.wb)[:, None, None]
    # Signal-dependent noise sqrt(max(img, 0) * shot^2 + read^2) * g, computed in place.
    noise = np.maximum(img, 0.0)
    noise *= scene.noise_shot ** 2
    noise += scene.noise_read ** 2
    np.sqrt(noise, out=noise)
    n = img.size
    bank = _noise_bank()
    negate = False
    if n <= bank.size // 2:
        off = int(noise_rng.integers(0, bank.size - n))
        g = bank[off:off + n].reshape(img.shape)
        negate = noise_rng.random() < 0.5  # img - noise * g is exactly img + noise * (-g)
    else:
        g = noise_rng.standard_normal(img.shape, dtype=_F32)
    noise *= g
    if negate:
        img -= noise
    else:
        img += noise
    img *= _LUT_SIZE / _LUT_MAX
    q = np.clip(img, 0, _LUT_SIZE - 1, out=img).astype(np.int32)
    # planar (3, H, W) -> interleaved (H, W, 3): cv2.merge is ~4x faster than numpy's transposing copy
    return cv2.merge(list(_tone_lut(scene.gamma).take(q)))
