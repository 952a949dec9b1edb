"""The working resolution of a learned prox: the size at which the samples lie as far apart as in training.

A learned prox sees pixels, not metres: it was trained on frames whose samples lie a few to a few tens of pixels
apart, and it only knows how to fill gaps of those sizes. Run on a larger frame with the same number of samples
(200 points on 480x640 or 1088x1376 instead of 256x320), the gaps are 2-8x wider than anything it saw, and its gain
over a linear fill disappears. So the prox runs at the working size where the mean sample spacing is about what
training saw, and only there:

    spacing_px = sqrt(H W / n)                                n samples on an H x W frame
    s          = min(1, TARGET_SPACING_PX / spacing_px,       the working scale (never above the frame's size),
                     sqrt(MAX_WORKING_PIXELS / (H W)))        and, for LiDAR scan lines and dense maps
                                                              only (`capped`), at most MAX_WORKING_PIXELS pixels
    (h, w)     = round(s H), round(s W), the shorter side at least MIN_WORKING_SIDE_PX

Sparse inputs (200 points on 480x640: 39 px apart) run at 0.41x (196x261). Dense scattered ones (1,000 points or
more on 480x640, 30 % of a KITTI frame's valid pixels) already lie closer than TARGET_SPACING_PX and run at full
size. A LiDAR scan (64 beams, ~5 px apart on a KITTI frame) also lies closer, but a KITTI-size frame still runs
below full size (0.38x, 132x455): the prox's receptive field and its training frames (128x160 crops) cover a fixed
number of pixels, and a scan at its full 352x1216 leaves the prox's field of view a narrow slice of the street
(the rows between beams, the sky above the top beam). Scattered samples carry no such structure, and capping them
only throws their detail away. Dense maps (over DENSE samples a pixel: a depth camera's, stereo's,
with holes) are capped as scan lines are (docs/decisions/0017-dense-input-capped.md: 8 synthetic 480x640 rooms with
holes, 0.9663 x linear at full size, 0.7508 at 212x283; the prox learned to fill gaps of a few working pixels, and a
camera's holes are tens of pixels wide; every sample is set back at full size). The data-consistency step and the
output stay at full resolution (`lipjax.inference.complete_frame`): the prox's estimate is upsampled and every measured
pixel is set back to its measured value (the x-update with rho -> 0 at m = 1).

The constants were chosen on synthetic renders larger than the training frames (`python -m
benchmarks.working_resolution --model lip-any --frames 6`, geometric-mean RMSE ratio to the full-size linear fill
over 50 to 5,000 points on 480x640 rooms and 200 or 25,000 points on 352x1216 streets for T and the scattered cap;
over 64- and 32-beam scans on those streets for the scan-line cap), as the most accurate rule whose frames meet the
speed target of 10 frames/s (normalised to 195 GFLOP/s, benchmarks/speed.py) at 480x640 with 200 points and at
352x1216 with 64 beams. Unconstrained, the best were T=22 px without a cap for scattered samples (0.813) and a
100,000-pixel cap for scan lines (0.697), but those frames took 49 and 45 ms (8.8 and 9.7 frames/s normalised);
the rule's T=16 px (0.816) and 60,000 pixels (0.701) are within 0.6 % of them. The earlier rule, one cap of 60,000
pixels for every input, scored 0.860 on the scattered settings: it ran 25,000 points on a street at 0.37x (1.051x
linear against 0.892x at full size). Per setting, native size -> rule: 64-beam streets 0.690 -> 0.534, 200 points
on rooms 0.954 -> 0.821, 50 points 1.321 -> 0.805.
"""
from __future__ import annotations

import math

import numpy as np

# the rule's numbers (why each, and its benchmark: lipjax.defaults); DENSE and MIN_MAX_SIDE_PX also read from here
from lipjax.defaults import (DENSE, MAX_WORKING_PIXELS, MIN_MAX_SIDE_PX, MIN_SCALE_CHANGE,  # noqa: F401
                             MIN_WORKING_SIDE_PX, TARGET_SPACING_PX)


def sample_spacing_px(sparse_m: np.ndarray) -> float:
    """Mean spacing of the samples of a (H, W) sparse depth map (0 = none), in pixels: sqrt(H W / n); inf for n = 0.

    Over the whole frame (TARGET_SPACING_PX was chosen by it); lipjax.uncertainty.box_sample_spacing_px is the
    spacing within the samples' bounding box (where a scan's samples are), for the support rules."""
    n = int(np.count_nonzero(np.asarray(sparse_m) > 0))
    h, w = np.shape(sparse_m)[-2:]
    return math.sqrt(h * w / n) if n else math.inf


def working_size(shape: tuple[int, int], spacing_px: float, target_spacing_px: float = TARGET_SPACING_PX,
                 max_pixels: float | None = None, min_side_px: int = MIN_WORKING_SIDE_PX, *,
                 capped: bool = False) -> tuple[int, int]:
    """(h, w) at which a learned prox runs on a frame of `shape` (H, W) whose samples lie `spacing_px` apart.

    `max_pixels` None: MAX_WORKING_PIXELS for LiDAR scan lines and dense maps (`capped`: `is_capped`), no cap for
    other scattered samples. The frame's own size when it is already at most that coarse
    (s >= MIN_SCALE_CHANGE) or has no samples.
    """
    big_h, big_w = shape
    if not spacing_px > 0:
        raise ValueError(f"spacing_px must be > 0, got {spacing_px}")
    if max_pixels is None:
        max_pixels = MAX_WORKING_PIXELS if capped else math.inf
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


def dense_from(pixels: int) -> int:
    """The fewest samples that make a map of `pixels` pixels dense (over DENSE samples a pixel); every test of
    density in the library goes through here, so that all of them agree at the boundary."""
    return math.floor(DENSE * pixels) + 1


def is_capped(samples: int, shape: tuple[int, int], scan_lines: bool) -> bool:
    """Whether `working_size` caps a frame of `shape` with `samples` samples at MAX_WORKING_PIXELS: LiDAR scan lines
    (lipjax.inputs.is_lidar_pattern), or a dense map (`dense_from`; docs/decisions/0017-dense-input-capped.md, module
    doc)."""
    return scan_lines or samples >= dense_from(shape[0] * shape[1])
