"""The one interface every depth completer implements, classical or learned, and its input checks.

A completer maps one frame to a dense depth map:

    completer(rgb: (H, W, 3) uint8, sparse: (H, W) float32 metres, 0 = no sample) -> (H, W) float32 metres

and has a `name` (used as the row label of result tables). A loaded learned model (`lipjax.Completer`, from
`lipjax.inference`) is one. One frame per call keeps classical methods simple;
learned models (jitted functions on batches) are wrapped by `BatchFnCompleter`, which adds and removes a
batch axis of size 1.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

import numpy as np

from lipjax.inputs import check_frame


@runtime_checkable
class DepthCompleter(Protocol):
    """Dense depth from an RGB image and sparse depth. See the module docstring for shapes and units."""

    name: str

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray: ...


@dataclasses.dataclass
class BatchFnCompleter:
    """Wraps a batched (typically jitted) function as a one-frame `DepthCompleter`.

    `fn(rgb (1, H, W, 3) float32 in [0, 1], sparse (1, H, W) float32 metres) -> (1, H, W) metres`. The output is
    converted to numpy, which also waits for asynchronous JAX dispatch, so timing this call times the
    computation. The first call for a new shape compiles: `lipjax.evaluate` makes one untimed warm-up call.
    """

    name: str
    fn: Callable[[Any, Any], Any]

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray:
        rgb, sparse = check_frame(rgb, sparse)
        out = self.fn((rgb.astype(np.float32) / 255.0)[None], sparse[None])
        out = np.asarray(out, dtype=np.float32)
        if out.shape != (1,) + sparse.shape:
            raise ValueError(f"{self.name}: fn returned shape {out.shape}, expected {(1,) + sparse.shape}")
        return out[0]
