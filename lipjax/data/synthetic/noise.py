"""Deterministic procedural noise and texture primitives.

A fixed lattice table, per-cell hash, value noise, fbm, an anti-aliased square wave and a rectangle mask.
"""
from __future__ import annotations

import math

import numpy as np

from lipjax.data.synthetic.constants import _F32

# A fixed table of uniform values: the lattice of the value noise and a cheap per-cell hash. A constant,
# not random state: it never changes, so textures are reproducible.
_TABLE = np.random.default_rng(0x1D5EED).random(65536, dtype=_F32)
# The same lattice padded to 257 x 257 (row 256 = row 0, column 256 = column 0): the four corners of a cell
# are then at base, base + 1, base + 257, base + 258, one index computation instead of four.
_TABLE_PAD = np.pad(_TABLE.reshape(256, 256), ((0, 1), (0, 1)), mode="wrap").ravel()
# The four corners of every cell side by side, (255 * 257 + 256, 4) (one row per base index): one gather of
# 16 bytes per point fetches them.
_TABLE_CORNERS = np.stack([_TABLE_PAD[i:i + 255 * 257 + 256] for i in (0, 1, 257, 258)], axis=1)


def _lattice(i: np.ndarray, j: np.ndarray) -> np.ndarray:
    return ((j & 255) << 8) | (i & 255)


def _hash(x: np.ndarray, y: np.ndarray | float = 0.0) -> np.ndarray:
    """Uniform [0, 1) value per integer cell (x, y) (floats are floored)."""
    i = np.floor(x).astype(np.int32)
    j = np.floor(y).astype(np.int32) if not np.isscalar(y) else np.int32(int(math.floor(y)))
    return _TABLE.take(_lattice(i, j))


def _vnoise(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Smooth value noise in [0, 1) with unit lattice spacing."""
    xf = np.floor(x)
    yf = np.floor(y)
    fx = x - xf
    fy = y - yf
    base = (yf.astype(np.int32) & 255) * 257 + (xf.astype(np.int32) & 255)
    a, b, c, d = _TABLE_CORNERS.take(base, axis=0).T
    sx = fx * fx * (3.0 - 2.0 * fx)
    sy = fy * fy * (3.0 - 2.0 * fy)
    ab = a + (b - a) * sx
    return ab + (c + (d - c) * sx - ab) * sy


def _fbm(x: np.ndarray, y: np.ndarray, octaves: int, fp: np.ndarray | None = None) -> np.ndarray:
    """Fractal value noise in ~[0, 1]. fp: pixel footprint in lattice units; octaves finer than a pixel
    fade to their mean instead of aliasing."""
    total = np.zeros_like(x)
    amp, norm = 1.0, 0.0
    for _ in range(octaves):
        n = _vnoise(x, y) - 0.5
        if fp is not None:
            n *= np.minimum(np.maximum(1.5 - 2.0 * fp, 0.0), 1.0)
            fp = fp * 2.03
        total += amp * n
        norm += amp
        amp *= 0.5
        x = x * 2.03 + 17.13
        y = y * 2.03 + 31.71
    return total * (1.0 / norm) + 0.5


def _frac(x):
    return x - np.floor(x)


def _square(s: np.ndarray, period: float, duty: float, fp: np.ndarray) -> np.ndarray:
    """Anti-aliased square wave: ~1 where frac(s / period) < duty, else ~0; tends to `duty` when a pixel
    covers a whole period."""
    inv = 1.0 / period
    f = _frac(s * inv)
    w = fp * inv + 1e-4
    sd = np.where(f < duty, np.minimum(f, duty - f), -np.minimum(f - duty, 1.0 - f))
    val = np.minimum(np.maximum(0.5 + sd / w, 0.0), 1.0)
    k = np.minimum(np.maximum(2.0 * w - 0.5, 0.0), 1.0)
    return val + (duty - val) * k


def _box(u, v, u0, v0, u1, v1):
    return (u >= u0) & (u < u1) & (v >= v0) & (v < v1)
