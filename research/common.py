"""What the probes of research/ share beyond benchmarks.common: colour and depth edges per pixel, and the pixel
classes of research/failure_look.py (depth edge, colour only, flat).

    colour edge   |grad I| > COLOUR_EDGE     I the grey image in [0, 1] after a Gaussian blur of BLUR_PX,
                                              grad by central differences (per pixel)
    depth edge    |grad log D| > DEPTH_EDGE   D the ground truth in metres, where both neighbours are valid
"""
from __future__ import annotations

import cv2
import numpy as np

BLUR_PX = 1.0  # Gaussian blur of the grey image, pixels
COLOUR_EDGE = 0.04  # grey-level change per pixel (of full scale 1) that counts as a colour edge
DEPTH_EDGE = 0.05  # log-depth change per pixel (5 %) that counts as a depth edge
CLASS_NEAR_PX = 3  # pixel classes: "near" an edge is within this many pixels (at native size)
CLASSES = ("depth edge", "colour only", "flat")


def gradients(rgb: np.ndarray, depth: np.ndarray):
    """(|grad I|, |grad log D|, defined) per pixel, central differences, interior pixels only."""
    grey = cv2.GaussianBlur(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY).astype(np.float32) / 255.0, (0, 0), BLUR_PX)
    gy, gx = np.gradient(grey)
    log_d = np.log(np.where(depth > 0, depth, 1.0))
    dy, dx = np.gradient(log_d)
    ok = depth > 0
    defined = ok.copy()
    defined[1:-1, 1:-1] &= ok[:-2, 1:-1] & ok[2:, 1:-1] & ok[1:-1, :-2] & ok[1:-1, 2:]
    defined[[0, -1], :] = False
    defined[:, [0, -1]] = False
    return np.hypot(gx, gy), np.hypot(dx, dy), defined


def log_depth_step(depth: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """(H, W) float32: |central difference of log D| per pixel, the larger of x and y, where both ends are valid
    (0 elsewhere). A sharp step of s in log depth marks the pixel either side of it with s / 2."""
    ok = valid & (depth > 0)
    log_d = np.log(np.where(ok, depth, 1.0))
    step = np.zeros(depth.shape, np.float32)
    step[:, 1:-1] = np.where(ok[:, :-2] & ok[:, 2:], np.abs(log_d[:, 2:] - log_d[:, :-2]) / 2, 0)
    step[1:-1, :] = np.maximum(step[1:-1, :], np.where(ok[:-2] & ok[2:], np.abs(log_d[2:] - log_d[:-2]) / 2, 0))
    return step


def near(mask: np.ndarray, px: int = CLASS_NEAR_PX) -> np.ndarray:
    """The pixels within `px` pixels (a square dilation) of `mask`."""
    return cv2.dilate(mask.astype(np.uint8), np.ones((2 * px + 1,) * 2, np.uint8)).astype(bool)


def pixel_classes(rgb: np.ndarray, depth: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """Per pixel 0 (depth edge), 1 (colour only) or 2 (flat), as research/failure_look.py defines them: within
    CLASS_NEAR_PX of a log-depth step over DEPTH_EDGE; else within it of a colour edge; else flat."""
    ok = valid & (depth > 0)
    colour_gradient = gradients(rgb, np.where(ok, depth, 0))[0]
    depth_near, colour_near = near(log_depth_step(depth, valid) > DEPTH_EDGE), near(colour_gradient > COLOUR_EDGE)
    return np.where(depth_near, 0, np.where(colour_near, 1, 2))
