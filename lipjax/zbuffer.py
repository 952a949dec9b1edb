"""The z-buffer: of several values that land in one cell (pixel), keep the nearest.

One helper for every place that scatters points onto a grid: LiDAR points projected into a camera
(lipjax.pointcloud), simulated LiDAR returns picked per (beam, azimuth) cell (lipjax.data.sampling), and sparse
depth moved onto a smaller grid (lipjax.inference).
"""
from __future__ import annotations

import numpy as np


def nearest_per_cell(cell: np.ndarray, cost: np.ndarray, tiebreak: np.ndarray | None = None) -> np.ndarray:
    """Positions (into the input arrays) of the element with the smallest cost in each cell, one per cell.

    Args:
      cell: (N,) integer cell index of each element (e.g. row * width + column).
      cost: (N,) what "nearest" means: depth in metres, or an angular distance.
      tiebreak: (N,) optional second key among equal costs (smallest wins); otherwise the first in input order.

    Returns:
      (M,) int64 positions, sorted by cell, M = number of distinct cells.
    """
    cell, cost = np.asarray(cell), np.asarray(cost)
    keys = (cost, cell) if tiebreak is None else (np.asarray(tiebreak), cost, cell)
    order = np.lexsort(keys)  # stable: by cell, then cost, then tiebreak / input order
    first = np.ones(order.size, bool)
    first[1:] = cell[order][1:] != cell[order][:-1]
    return order[first]


def splat_nearest(pixel: np.ndarray, depth_m: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """An (H, W) float32 depth image (metres, 0 = empty) from positive depths at flat pixel indices (row * W +
    column); where several land in one pixel the smallest depth is kept (np.minimum.at: one pass, no sort)."""
    h, w = size
    out = np.full(h * w, np.inf, np.float32)
    np.minimum.at(out, np.asarray(pixel), np.asarray(depth_m, np.float32))
    out[out == np.inf] = 0.0
    return out.reshape(h, w)
