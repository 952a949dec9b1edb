"""The working resolution of a learned prox: the size at which the samples lie as far apart as in training.

A learned prox sees pixels, not metres: it was trained on frames whose samples lie a few to a few tens of pixels
apart, and it only knows how to fill gaps of those sizes. Run on a larger frame with the same number of samples
(200 points on 480x640 or 1088x1376 instead of 256x320), the gaps are 2-8x wider than anything it saw, and its gain
over a linear fill disappears. So the prox runs at the working size where the mean sample spacing is about what
training saw, and only there:

    spacing_px = sqrt(H W / n)                                n samples on an H x W frame
    s          = min(1, TARGET_SPACING_PX / spacing_px,       the working scale (never above the frame's size),
                     sqrt(MAX_WORKING_PIXELS / (H W)))        and at most MAX_WORKING_PIXELS pixels
    (h, w)     = round(s H), round(s W), the shorter side at least MIN_WORKING_SIDE_PX

Sparse inputs (200 points on 480x640: 39 px apart) run at 0.56x (270x360, capped to 60,000 pixels: 212x283). Dense
ones (a 64-beam scan, ~5 px apart on a KITTI frame) already lie closer than TARGET_SPACING_PX, but a KITTI-size
frame still runs below full size (0.38x, 132x455): the prox's receptive field and its training frames (128x160
crops) cover a fixed number of pixels, and a scan at its full 352x1216 leaves the prox's field of view a narrow
slice of the street. Measured with lip-any on synthetic test frames (geometric-mean RMSE ratio to linear, native
size -> rule): 64-beam 352x1216 streets 0.670 -> 0.449, 200 points on 480x640 rooms 0.962 -> 0.846, 50 points
1.441 -> 0.896; the frame is also 7x cheaper at KITTI size. The data-consistency step and
the output stay at full resolution (`lipjax.inference.complete_frame`): the prox's estimate is upsampled and every
measured pixel is set back to its measured value (the x-update with rho -> 0 at m = 1).

TARGET_SPACING_PX and MAX_WORKING_PIXELS were chosen on synthetic renders larger than the training frames, by a rule
fixed before any real frame was scored (benchmarks/working_resolution.py --model lip-any: the (T, P) with the lowest
geometric-mean RMSE ratio to the linear fill over rooms at 480x640 and streets at 352x1216; T=22 px, P=60,000: 0.732).
"""
from __future__ import annotations

import math

import numpy as np

TARGET_SPACING_PX = 22.0  # mean sample spacing, pixels, at which the learned prox runs (see the module doc)
MAX_WORKING_PIXELS = 60_000  # the largest working size, pixels (see the module doc)
MIN_WORKING_SIDE_PX = 64  # the prox downsamples 8x internally; below this its coarsest features are 8 px wide
MIN_MAX_SIDE_PX = 16  # the smallest longer side a user may ask for (--max-side): two of the prox's 8 px cells
MIN_SCALE_CHANGE = 0.9  # scales above this run at full size: a resize would cost more than it brings


def sample_spacing_px(sparse_m: np.ndarray) -> float:
    """Mean spacing of the samples of a (H, W) sparse depth map (0 = none), in pixels: sqrt(H W / n); inf for n = 0.

    Over the whole frame (TARGET_SPACING_PX was chosen by it); lipjax.uncertainty.sample_spacing is the spacing within
    the samples' bounding box (where a scan's samples are), for the support rules."""
    n = int(np.count_nonzero(np.asarray(sparse_m) > 0))
    h, w = np.shape(sparse_m)[-2:]
    return math.sqrt(h * w / n) if n else math.inf


def working_size(shape: tuple[int, int], spacing_px: float, target_spacing_px: float = TARGET_SPACING_PX,
                 max_pixels: float = MAX_WORKING_PIXELS, min_side_px: int = MIN_WORKING_SIDE_PX) -> tuple[int, int]:
    """(h, w) at which a learned prox runs on a frame of `shape` (H, W) whose samples lie `spacing_px` apart.

    The frame's own size when it is already at most that coarse (s >= MIN_SCALE_CHANGE) or has no samples.
    """
    big_h, big_w = shape
    if not spacing_px > 0:
        raise ValueError(f"spacing_px must be > 0, got {spacing_px}")
    s = min(1.0, target_spacing_px / spacing_px, math.sqrt(max_pixels / (big_h * big_w)))
    s = max(s, min(1.0, min_side_px / min(big_h, big_w)))
    if s >= MIN_SCALE_CHANGE:
        return big_h, big_w
    return max(1, round(big_h * s)), max(1, round(big_w * s))


def max_side_size(shape: tuple[int, int], max_side: int) -> tuple[int, int]:
    """(h, w) of a frame of `shape` resized so that its longer side is at most `max_side` (aspect kept)."""
    big_h, big_w = shape
    if max(big_h, big_w) <= max_side:
        return big_h, big_w
    s = max_side / max(big_h, big_w)
    return max(1, round(big_h * s)), max(1, round(big_w * s))
