"""Do colour edges mark depth edges as often in the renders as in photographs? The RGB guidance's shortcut, measured.

    python -m research.edge_statistics [--frames 30] [--realdata ../shared/realdata] [--texture 1,3,6]

A prox that learned "a colour edge is a depth edge" from the renders transfers to photographs only as far as that
holds there. Every frame (synthetic test renders of both kinds; the shared real frames, read from ../shared/realdata,
never copied) is brought to a longer side of SIDE_PX pixels (RGB area-resized, depth nearest), then per pixel:

    colour edge   |grad I| > COLOUR_EDGE      I the grey image in [0, 1] after a Gaussian blur of BLUR_PX,
                                               grad by central differences (per pixel)
    depth edge    |grad log D| > DEPTH_EDGE    D the ground truth in metres, where both neighbours are valid
    near          within NEAR_PX pixels (a 3x3 dilation)

(BLUR_PX, COLOUR_EDGE, DEPTH_EDGE and the gradients: research.common, shared with research/failure_look.py.)

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
do not share (research/README.md).
"""
from __future__ import annotations

import argparse
import os

import cv2
import numpy as np
from scipy.stats import spearmanr

from benchmarks.common import REALDATA, load_kitti, load_lingbot, load_middlebury, load_nyu
from lipjax.data.augment import paint_texture
from lipjax.data.synthetic import SyntheticDataset
from research.common import COLOUR_EDGE, DEPTH_EDGE, gradients

SIDE_PX = 320  # every frame's longer side, pixels, before the statistics
NEAR_PX = 1
DEPTH_MEDIAN_PX = 5  # median filter on D before the depth-edge density (cv2.medianBlur on float32 takes 3 or 5)
TEXTURE_STRENGTH = 0.7  # lip_any's texture_strength (experiments/configs/base.py)


def _resized(rgb: np.ndarray, depth: np.ndarray, valid: np.ndarray):
    h, w = depth.shape
    s = SIDE_PX / max(h, w)
    size = (max(1, round(w * s)), max(1, round(h * s)))
    return (cv2.resize(rgb, size, interpolation=cv2.INTER_AREA),
            cv2.resize(np.where(valid, depth, 0).astype(np.float32), size, interpolation=cv2.INTER_NEAREST))


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
    return {name: [(s.rgb, s.depth, s.valid) for s in frames] for name, frames in groups.items()}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=30, help="synthetic test frames per kind")
    ap.add_argument("--realdata", default=REALDATA)
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
