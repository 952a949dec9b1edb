"""Per-pixel expected absolute error of a completed depth map, in metres, derived from where the samples are.

    u = expected_error(sparse, depth)                  # (H, W) or (B, H, W) float32 metres, 0 on measured pixels
    depth = drop_uncertain(depth, u, max_uncertainty=2.0)  # 0 (no depth) where u > 2 m
    depth = mask_unsupported(depth, sparse)            # 0 (no depth) where no sample supports it (support_mask)
    write_uncertainty("u.npy", u, max_m=1.0)           # .npy metres, or .png: a colour picture, 0 .. max_m metres

The estimate does not look at the method that made `depth`: the error of any completion grows with how far a
pixel is from its samples and with the depth jumps among those samples. With, per pixel,

    s      the typical sample spacing (pixels): sqrt(area of the samples' bounding box / number of samples);
    r      the distance to the nearest sample in units of s (Euclidean, pixels / s);
    d      the depth range (max - min, metres) of the nearest-sample depths within about 2 s: a depth edge nearby;
    z      the completed depth (metres);

    u = RANGE_GAIN * r * d                                       supported pixels
    u = max(ABOVE_GAIN * z, the frame's largest supported u)     pixels more than one spacing above the highest
                                                                 sample of their columns (sky and anything above
                                                                 the top LiDAR beam)

so pixels without support always come out as the most uncertain of the frame, and elsewhere u grows with the
distance to the samples and with the depth jumps among them (and so with depth: far scenes have larger jumps).
A fronto-parallel surface (no depth range) gets 0, as any fill reproduces it; a slanted one (a floor, a road) does not.
"The highest sample of a column" is the highest sample within about 2 s columns (LiDAR scan lines have gaps;
scattered samples are rarely in the same column).

The constants were fitted on the synthetic VALIDATION splits (first 20 frames: indoor 200 uniform points,
outdoor HDL-64 pattern; completions by `linear` and the shipped `lip-cnn-*` models): RANGE_GAIN by least
squares of |error| / z on the supported pixels (an extra term in r**2 * z was tried and fitted to 0), ABOVE_GAIN
by least squares of |error| = gain * z above the samples. `python -m benchmarks.uncertainty --calibrate` refits
them; the same script reports the rank correlation with the actual error on the test splits and real frames.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import cv2
import numpy as np
from scipy import ndimage

from lipjax.defaults import ABOVE_GAIN, ABOVE_SPACINGS, REACH_SPACINGS, RANGE_GAIN  # why, benchmark: there
from lipjax.utils import written_whole


def box_sample_spacing_px(sparse: np.ndarray) -> float:
    """Typical distance between the samples of an (H, W) sparse map (metres, 0 = none) in pixels (>= 1):
    sqrt(area of their bounding box / their number), within that box.

    Not lipjax.resolution.sample_spacing_px, which spreads the samples over the whole frame (sqrt(H W / n)) to
    choose the working size: this is their spacing where they are, the unit of the support rules and of the gains
    above (a synthetic 64-beam scan of a 352x1216 street, from about row 120 down: 4.1 px here, 5.0 px over the
    frame)."""
    area, n = _box_area_and_count(np.asarray(sparse) > 0)
    return math.sqrt(max(area, n) / n)


def _box_area_and_count(measured: np.ndarray) -> tuple[int, int]:
    """(area of the bounding box of the True pixels of an (H, W) mask, pixels; their number)."""
    rows, cols = np.flatnonzero(measured.any(axis=1)), np.flatnonzero(measured.any(axis=0))
    if rows.size == 0:
        raise ValueError("sparse depth has no samples: the uncertainty is undefined")
    return int(rows[-1] - rows[0] + 1) * int(cols[-1] - cols[0] + 1), int(np.count_nonzero(measured))


def _squared_limit(spacings: float, area: int, n: int) -> int:
    """The largest integer k <= (spacings * s) ** 2, square pixels, with s ** 2 = max(area, n) / n (the spacing of
    n samples in a bounding box of `area` pixels, at least a pixel). Exact: one rounding, of a fraction."""
    return math.floor(spacings ** 2 * max(area, n) / n)


def _column_tops(measured: np.ndarray, s: float) -> np.ndarray:
    """(W,) int: the row of the highest sample within 2 * ceil(2 s) + 1 columns centred on each column (H where
    there is none): "the highest sample of a column" of the support rules."""
    h = measured.shape[0]
    top = np.where(measured.any(axis=0), measured.argmax(axis=0), h)
    return ndimage.minimum_filter1d(top, 2 * math.ceil(2 * s) + 1, mode="nearest")


def support_features(sparse: np.ndarray) -> dict[str, np.ndarray | float]:
    """What the estimate is made of, for one (H, W) sparse map in metres (0 = no sample).

    Returns {"spacing": s (pixels), "distance": r (H, W) in spacings, "depth_range": (H, W) metres,
    "height_above": (H, W) spacings above the highest sample of the column (<= 0 at or below it)}.
    """
    sparse = np.asarray(sparse, np.float32)
    if sparse.ndim != 2:
        raise ValueError(f"sparse depth must be (H, W), got shape {sparse.shape}")
    s = box_sample_spacing_px(sparse)
    measured = sparse > 0
    distance, (ri, ci) = ndimage.distance_transform_edt(~measured, return_indices=True)
    nearest = sparse[ri, ci]
    window = 2 * math.ceil(2 * s) + 1
    depth_range = ndimage.maximum_filter(nearest, window) - ndimage.minimum_filter(nearest, window)
    height_above = (_column_tops(measured, s)[None, :] - np.arange(sparse.shape[0])[:, None]) / s
    return {"spacing": s, "distance": distance / s, "depth_range": depth_range, "height_above": height_above}


def expected_error(sparse: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """(H, W) float32 expected absolute error in metres of `depth`, a completion of `sparse` (both metres); or
    (B, H, W) for a batch.

    0 on measured pixels; highest (above every supported pixel) more than one sample spacing above the highest
    samples; see the module docstring for the formula and its calibration.
    """
    depth = np.maximum(np.asarray(depth, np.float32), 0.0)
    if depth.shape != np.shape(sparse):
        raise ValueError(f"depth {depth.shape} and sparse depth {np.shape(sparse)} must have the same shape")
    if depth.ndim == 3:
        return np.stack([expected_error(s, d) for s, d in zip(sparse, depth)])
    f = support_features(sparse)
    r = f["distance"]
    u = RANGE_GAIN * r * f["depth_range"]
    above = f["height_above"] > ABOVE_SPACINGS
    if above.any():
        floor = u[~above].max() if (~above).any() else 0.0
        u[above] = np.maximum(ABOVE_GAIN * depth[above], floor)
    return u.astype(np.float32)


def drop_uncertain(depth: np.ndarray, uncertainty: np.ndarray, max_uncertainty: float) -> np.ndarray:
    """A copy of `depth` (metres) with 0 (no depth) where `uncertainty` (metres) exceeds `max_uncertainty` (m)."""
    if not max_uncertainty >= 0:
        raise ValueError(f"max_uncertainty must be >= 0 metres, got {max_uncertainty}")
    depth = np.asarray(depth, np.float32)
    if np.shape(uncertainty) != depth.shape:
        raise ValueError(f"uncertainty {np.shape(uncertainty)} and depth {depth.shape} must have the same shape")
    return np.where(np.asarray(uncertainty) > max_uncertainty, 0.0, depth).astype(np.float32)


def support_mask(sparse: np.ndarray) -> np.ndarray:
    """(H, W) bool, True where the samples of an (H, W) sparse map (metres, 0 = no sample) support a completed
    depth; or (B, H, W) for a batch.

    With s the sample spacing in pixels (`box_sample_spacing_px`: sqrt(area of the samples' bounding box / number of
    samples)), a pixel has NO support when it is
      - more than ABOVE_SPACINGS * s pixels (1 s) above the highest sample of its column, the highest within
        about 2 s columns either side (the sky, anything above the top LiDAR beam); or
      - farther than REACH_SPACINGS * s pixels (3 s) from every sample (Euclidean; a hole in the scan, a corner).
    So 200 points on a 480x640 frame (s = 35 px) reach 105 px, and a 64-beam scan of a KITTI frame (s = 6.4 px)
    19 px. Measured pixels always have support. The rule reads the sample positions only, never the depth.

    Both limits are decided in integers, exactly (s ** 2 = area / n is a fraction): a height of t pixels is within
    when t ** 2 <= (ABOVE_SPACINGS s) ** 2, a distance of sqrt(k) pixels when k <= (REACH_SPACINGS s) ** 2.
    The distance is OpenCV's exact Euclidean transform (DIST_MASK_PRECISE), float32: it decides the reach exactly
    while the reach is under 1,000 px (the float32 distances of neighbouring k are then far enough apart).
    """
    measured = np.asarray(sparse) > 0
    if measured.ndim == 3:
        return np.stack([support_mask(s) for s in measured])
    area, n = _box_area_and_count(measured)
    tops = _column_tops(measured, math.sqrt(max(area, n) / n))
    first = tops - math.isqrt(_squared_limit(ABOVE_SPACINGS, area, n))  # per column, the highest supported row
    start = max(0, int(first.min()))  # every sample lies below: the rows above have no support, no distance to take
    mask = np.zeros(measured.shape, bool)
    below = np.arange(start, measured.shape[0])[:, None] >= first[None, :]
    distance = cv2.distanceTransform((~measured[start:]).view(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    reach = np.float32(math.sqrt(_squared_limit(REACH_SPACINGS, area, n) + 0.5))  # between sqrt(k_max) and the next
    mask[start:] = below & (distance <= reach)
    return mask


def mask_unsupported(depth: np.ndarray, sparse: np.ndarray) -> np.ndarray:
    """A float32 copy of `depth` (metres) with 0 (no depth) where the samples of `sparse` (metres, same shape)
    give no support (`support_mask`): what `lipjax complete --blank-unsupported` writes."""
    depth = np.asarray(depth, np.float32)
    if depth.shape != np.shape(sparse):
        raise ValueError(f"depth {depth.shape} and sparse depth {np.shape(sparse)} must have the same shape")
    return np.where(support_mask(sparse), depth, 0.0).astype(np.float32)


def write_uncertainty(path: str | os.PathLike, uncertainty: np.ndarray, max_m: float) -> None:
    """Writes (H, W) expected error (metres): X.npy as float32 metres; X.png as a colour picture (the error-map
    colours of lipjax.viz: dark blue 0 m to dark red >= max_m metres), whole or not at all."""
    from lipjax import viz

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".npy", ".png"):
        raise ValueError(f"{path}: unknown uncertainty format {suffix!r}; use .npy (metres) or .png (picture)")
    u = np.asarray(uncertainty, np.float32)
    with written_whole(path) as temporary:
        if suffix == ".npy":
            np.save(temporary, u)
        else:
            viz.write_png(temporary, viz.error_map(u, np.zeros_like(u), np.ones(u.shape, bool), max_error_m=max_m))
