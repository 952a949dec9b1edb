"""Do colour edges mark depth edges as often in the renders as in photographs? The RGB guidance's shortcut, measured.

    python benchmarks/edge_statistics.py [--frames 30] [--realdata ../shared/realdata] [--texture 1,3,6]

A prox that learned "a colour edge is a depth edge" from the renders transfers to photographs only as far as that
holds there. Every frame (synthetic test renders of both kinds; the shared real frames, read from ../shared/realdata,
never copied) is brought to a longer side of SIDE_PX pixels (RGB area-resized, depth nearest), then per pixel:

    colour edge   |grad I| > COLOUR_EDGE      I the grey image in [0, 1] after a Gaussian blur of BLUR_PX,
                                               grad by central differences (per pixel)
    depth edge    |grad log D| > DEPTH_EDGE    D the ground truth in metres, where both neighbours are valid
    near          within NEAR_PX pixels (a 3x3 dilation)

and per frame kind it prints, over pixels where the depth gradient is defined:
    colour edge density      P(colour edge)
    precision                P(depth edge near | colour edge): how often a colour edge is a depth edge
    recall                   P(colour edge near | depth edge): how often a depth edge shows in the image
    rank correlation         Spearman's rho of |grad I| and |grad log D|
    depth-edge density       P(depth edge) after a DEPTH_MEDIAN_PX median filter of D: real sensors' noise out,
                             so that it counts geometry (is a real room more broken up than a rendered one?)
`--texture N,...` adds rows for the renders with 1-N textured rectangles painted as training paints them
(lipjax.data.augment.paint_texture at strength TEXTURE_STRENGTH, exactly N per frame, seeded by the frame's index).
The renders' numbers against the photographs' tell which shortcut the prox can learn from renders that photographs
do not share (docs/design-notes.md, "RGB guidance from renders to photographs").
"""
from __future__ import annotations

import argparse
import os
import sys

import cv2
import numpy as np
from scipy.stats import spearmanr

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from benchmarks.real_frames import load_lingbot  # noqa: E402
from benchmarks.baselines import load_kitti, load_middlebury, load_nyu  # noqa: E402
from lipjax.data.augment import paint_texture  # noqa: E402
from lipjax.data.synthetic import SyntheticDataset  # noqa: E402

SIDE_PX = 320  # every frame's longer side, pixels, before the statistics
BLUR_PX = 1.0  # Gaussian blur of the grey image, pixels
COLOUR_EDGE = 0.04  # grey-level change per pixel (of full scale 1) that counts as a colour edge
DEPTH_EDGE = 0.05  # log-depth change per pixel (5 %) that counts as a depth edge
NEAR_PX = 1
DEPTH_MEDIAN_PX = 5  # median filter on D before the depth-edge density (cv2.medianBlur on float32 takes 3 or 5)
TEXTURE_STRENGTH = 0.7  # lip_any's texture_strength (experiments/configs/base.py)


def _resized(rgb: np.ndarray, depth: np.ndarray, valid: np.ndarray):
    h, w = depth.shape
    s = SIDE_PX / max(h, w)
    size = (max(1, round(w * s)), max(1, round(h * s)))
    return (cv2.resize(rgb, size, interpolation=cv2.INTER_AREA),
            cv2.resize(np.where(valid, depth, 0).astype(np.float32), size, interpolation=cv2.INTER_NEAREST))


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


def frame_statistics(rgb: np.ndarray, depth: np.ndarray, valid: np.ndarray) -> dict | None:
    rgb, depth = _resized(rgb, depth, valid)
    g_i, g_d, defined = gradients(rgb, depth)
    if defined.sum() < 100:
        return None
    kernel = np.ones((2 * NEAR_PX + 1,) * 2, np.uint8)
    colour = (g_i > COLOUR_EDGE) & defined
    depth_edge = (g_d > DEPTH_EDGE) & defined
    colour_near = cv2.dilate(colour.astype(np.uint8), kernel).astype(bool)
    depth_near = cv2.dilate(depth_edge.astype(np.uint8), kernel).astype(bool)
    _, g_smooth, defined_smooth = gradients(rgb, cv2.medianBlur(depth, DEPTH_MEDIAN_PX) * (depth > 0))
    nan = float("nan")
    return {
        "density": float(colour.sum() / defined.sum()),
        "precision": float((depth_near & colour).sum() / colour.sum()) if colour.any() else nan,
        "recall": float((colour_near & depth_edge).sum() / depth_edge.sum()) if depth_edge.any() else nan,
        "rho": float(spearmanr(g_i[defined], g_d[defined])[0]),
        "depth_density": float(((g_smooth > DEPTH_EDGE) & defined_smooth).sum() / max(defined_smooth.sum(), 1)),
    }


def _renders(kind: str, frames: int):
    for s in SyntheticDataset(kind, "test", size=frames, height=256, width=320):
        yield s.rgb, s.depth, s.valid


def _textured(frames: list, patches: int) -> list:
    """The frames with `patches` textured rectangles painted on their RGB, depth untouched."""
    out = []
    for i, (rgb, depth, valid) in enumerate(frames):
        rng = np.random.default_rng(i)
        for _ in range(patches):
            rgb = paint_texture(rgb, TEXTURE_STRENGTH, rng)
        out.append((rgb, depth, valid))
    return out


def _real(root: str):
    groups = {"NYU v2": load_nyu(os.path.join(root, "nyu_v2")),
              "Middlebury": load_middlebury(os.path.join(root, "middlebury2014_motorcycle")),
              "lingbot": load_lingbot(os.path.join(root, "lingbot_rgbd")),
              "KITTI": load_kitti(os.path.join(root, "kitti"))}
    return {name: [(s.rgb, s.depth, s.valid) for s in samples] for name, samples in groups.items()}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=30, help="synthetic test frames per kind")
    ap.add_argument("--realdata", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "realdata"))
    ap.add_argument("--texture", default="", help="comma-separated patch counts: also the textured renders")
    args = ap.parse_args(argv)
    rooms, streets = list(_renders("indoor", args.frames)), list(_renders("outdoor", args.frames))
    sources = {"renders, rooms": rooms, "renders, streets": streets}
    for n in (int(t) for t in args.texture.split(",") if t):
        sources[f"renders, rooms, {n} textured"] = _textured(rooms, n)
        sources[f"renders, streets, {n} textured"] = _textured(streets, n)
    sources.update(_real(os.path.abspath(args.realdata)))
    keys = ("density", "precision", "recall", "rho", "depth_density")
    print("| frames | n | colour edge density | P(depth edge | colour edge) | P(colour edge | depth edge) | "
          "Spearman rho | depth-edge density (median-filtered D) |\n|---|---|---|---|---|---|---|")
    for name, frames in sources.items():
        stats = [s for s in (frame_statistics(*f) for f in frames) if s is not None]
        means = {k: np.nanmean([s[k] for s in stats]) for k in keys}
        print(f"| {name} | {len(stats)} | " + " | ".join(f"{means[k]:.3f}" for k in keys) + " |", flush=True)


if __name__ == "__main__":
    main()
