"""Nearest-neighbour fill: every pixel takes the depth of its closest sample (Euclidean distance in pixels).

Exact at sampled pixels; piecewise constant over the Voronoi cells of the samples. Ties between equidistant
samples are broken by scipy's distance transform (deterministic).
"""
from __future__ import annotations

import dataclasses

import numpy as np
from scipy import ndimage

from lipjax.inputs import check_frame


def nearest_fill(sparse: np.ndarray) -> np.ndarray:
    """(H, W) float32 metres, 0 = no sample -> (H, W) float32 dense, nearest sample's depth everywhere.

    Assumes at least one sample (> 0); callers validate with `lipjax.inputs.check_frame`.
    """
    # The EDT of the "no sample" mask returns, for each pixel, the index of the nearest zero of that mask,
    # i.e. of the nearest sample.
    iy, ix = ndimage.distance_transform_edt(sparse <= 0, return_distances=False, return_indices=True)
    return sparse[iy, ix].astype(np.float32)


def fill_holes(depth: np.ndarray) -> np.ndarray:
    """(H, W) or (B, H, W) metres with 0 where a completion gave no depth -> float32 with depth at every pixel: each
    0 takes the depth of the nearest pixel that has some (`nearest_fill` of the map itself); the rest is kept as it
    is. What `--fill-all` / `lipjax.complete(..., fill_all=True)` does to a method that leaves holes (IP-Basic far
    from its samples). A map without any depth is returned as it is."""
    depth = np.asarray(depth, np.float32)
    if depth.ndim == 3:
        return np.stack([fill_holes(d) for d in depth])
    if (depth > 0).all() or not (depth > 0).any():
        return depth
    return nearest_fill(depth)


@dataclasses.dataclass(frozen=True)
class NearestFill:
    """DepthCompleter: nearest-neighbour fill (ignores the RGB image)."""

    name: str = "nearest"

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray:
        _, sparse = check_frame(rgb, sparse)
        return nearest_fill(sparse)
