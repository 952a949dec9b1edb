"""numpy helpers for planar (c, n) arrays and concatenated index ranges (faster than fancy indexing)."""
from __future__ import annotations

import numpy as np


def _cols(a: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """a[:, idx] for a (c, n) array and indices idx (k,): `take` is ~4x faster than 2-D fancy indexing."""
    return a.take(idx, axis=1)


def _set_cols(a: np.ndarray, idx, val) -> None:
    """a[:, idx] = val for a (c, n) array, idx indices (k,), a boolean mask (n,) or a slice, val (c, k) or
    (c, 1). Row by row: ~3x faster than 2-D fancy assignment."""
    if isinstance(idx, np.ndarray) and idx.dtype == bool:
        idx = np.flatnonzero(idx)
    for row, x in zip(a, val):
        row[idx] = x


def _ranges(starts, counts) -> np.ndarray:
    """The concatenation of arange(s, s + c) for (s, c) in zip(starts, counts), int64."""
    counts = np.asarray(counts, np.int64)
    before = np.cumsum(counts) - counts
    return np.arange(int(counts.sum())) + np.repeat(np.asarray(starts, np.int64) - before, counts)
