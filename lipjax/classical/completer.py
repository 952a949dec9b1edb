"""The interface every depth completer implements, classical or learned: `DepthCompleter`.

A completer maps one frame to a dense depth map:

    completer(rgb: (H, W, 3) uint8, sparse: (H, W) float32 metres, 0 = no sample) -> (H, W) float32 metres

and has a `name` (used as the row label of result tables). The classical fills (this package), LIP+Wavelet
(`lip_wavelet.LIPWavelet`) and a loaded learned model (`lipjax.inference.Completer`, which also takes batches) are
completers; `lipjax.methods.get_completer` builds any of them by name. Their inputs are checked by lipjax.inputs.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class DepthCompleter(Protocol):
    """Dense depth from an RGB image and sparse depth. See the module docstring for shapes and units."""

    name: str

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray: ...
