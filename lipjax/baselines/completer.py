"""The one interface every depth completer implements, classical or learned, and its input checks.

A completer maps one frame to a dense depth map:

    completer(rgb: (H, W, 3) uint8, sparse: (H, W) float32 metres, 0 = no sample) -> (H, W) float32 metres

and has a `name` (used as the row label of result tables). One frame per call keeps classical methods simple;
learned models (jitted functions on batches) are wrapped by `BatchFnCompleter`, which adds and removes a
batch axis of size 1.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Completer(Protocol):
    """Dense depth from an RGB image and sparse depth. See the module docstring for shapes and units."""

    name: str

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray: ...


def check_inputs(rgb: Any, sparse: Any) -> tuple[np.ndarray, np.ndarray]:
    """Validates one frame's inputs; returns (rgb uint8 (H, W, 3), sparse float32 (H, W)).

    Raises ValueError with a message naming the problem for: a wrong rank or channel count, rgb not uint8,
    mismatching (H, W), NaN / inf or negative sparse depth, and a sparse map without any sample (> 0).
    """
    rgb = np.asarray(rgb)
    sparse = np.asarray(sparse)
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"rgb must be (H, W, 3), got shape {rgb.shape}")
    if rgb.dtype != np.uint8:
        raise ValueError(f"rgb must be uint8, got {rgb.dtype}")
    if sparse.ndim != 2:
        raise ValueError(f"sparse depth must be (H, W), got shape {sparse.shape}")
    if sparse.shape != rgb.shape[:2]:
        raise ValueError(f"shape mismatch: rgb {rgb.shape[:2]} vs sparse {sparse.shape}")
    sparse = sparse.astype(np.float32, copy=False)
    if not np.all(np.isfinite(sparse)):
        raise ValueError("sparse depth contains NaN or inf; use 0 for 'no sample'")
    if np.any(sparse < 0):
        raise ValueError("sparse depth contains negative values; depth is in metres, 0 = no sample")
    if not np.any(sparse > 0):
        raise ValueError("sparse depth map is empty: no pixel > 0, nothing to complete from")
    return rgb, sparse


@dataclasses.dataclass
class BatchFnCompleter:
    """Wraps a batched (typically jitted) function as a one-frame `Completer`.

    `fn(rgb (1, H, W, 3) float32 in [0, 1], sparse (1, H, W) float32 metres) -> (1, H, W) metres`. The output is
    converted to numpy, which also waits for asynchronous JAX dispatch, so timing this call times the
    computation. The first call for a new shape compiles: `lipjax.evaluate` makes one untimed warm-up call.
    """

    name: str
    fn: Callable[[Any, Any], Any]

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray:
        rgb, sparse = check_inputs(rgb, sparse)
        out = self.fn((rgb.astype(np.float32) / 255.0)[None], sparse[None])
        out = np.asarray(out, dtype=np.float32)
        if out.shape != (1,) + sparse.shape:
            raise ValueError(f"{self.name}: fn returned shape {out.shape}, expected {(1,) + sparse.shape}")
        return out[0]
