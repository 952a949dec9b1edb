"""How much could any image be worth to the prox on real rooms? An image drawn from the ground truth, as a ceiling.

The model's own estimate is scored (`cross_check=False`): the default path's check against the linear fill
(lipjax.crosscheck) would mix that fill into what is measured here.

Run by hand (never a test; the shared frames are read from ../shared/realdata, never copied):

    python -m research.image_ceiling [--model NAME] [--synthetic 8] [--variants grey,shading,...]
                                     [--realdata ../shared/realdata] [--json OUT]

On the renders the photograph is worth about 16 % to the default model (RMSE with a grey image / with the
photograph), on the shared real frames about 1 % (research/README.md). Either the prox cannot read photographs,
or a real room gives the image less to add. This feeds the same 200 samples with six images and gives each RMSE
ratio to the Delaunay linear fill, default path at native size (`complete_frame`):

    photograph   the frame's own image
    grey         uniform grey (GREY): the depth-only part of the prior
    edges        an image made from the ground truth, the renders' cleanest cue: light grey, with the depth edges
                 drawn dark (the pixels either side of a log-depth step: central difference over DEPTH_EDGE per
                 pixel along x or y, both ends valid, as research/failure_look.py classes them): where the
                 surfaces break, nothing else
    shading      an image from the ground truth: a grey, uniformly white world lit by one light from the
                 camera's upper left (LIGHT_DIR, camera frame), Lambertian: AMBIENT + (1 - AMBIENT) max(0, n . l),
                 n the normals of the back-projected ground truth (holes filled by the nearest valid pixel,
                 smoothed over NORMAL_BLUR_PX): shape shown by shading alone, the renders' other cue
    both         the shading with the depth edges drawn dark on it
    flattened    the photograph after mean-shift filtering (MEAN_SHIFT_SP / _SR): texture gone, strong edges kept

Frames: the 12 shared indoor frames (NYU v2 3, Middlebury 1, lingbot 8; 200 uniform points as
benchmarks/real_frames.py draws them) and `--synthetic N` test renders of rooms at 480x640; `--variants` runs
some (grey always among them). A variant's worth: RMSE with the grey image / with the variant's. The images
drawn from the ground truth hand the prox one cue each, on real rooms as on renders: a cue worth as much on both is
one the prox can use in real geometry, and what a photograph lacks is that cue's visibility; a cue worth less on
real rooms points to the depth side of the prior, or to the cue's own quality there (real ground truth is noisy
and has holes, so its normals, and so its shading, are bumpier than a render's).
"""
from __future__ import annotations

import argparse
import json
import os

import cv2
import numpy as np
from scipy import ndimage

from benchmarks.common import GREY, INDOOR_POINTS, REALDATA, frames_and_inputs, geometric_mean, ratios_to_linear
from lipjax.classical import nearest_fill
from lipjax.data.sampling import UniformSampler
from lipjax.data.synthetic import SyntheticDataset
from lipjax.methods import get_completer
from research.common import DEPTH_EDGE, log_depth_step

MEAN_SHIFT_SP, MEAN_SHIFT_SR = 12, 24  # cv2.pyrMeanShiftFiltering's spatial (px) and colour (0-255) windows
EDGE_GREY, BACKGROUND_GREY = 40, 200
LIGHT_DIR = (-0.4, -0.6, -0.7)  # towards the light, camera frame (x right, y down, z forward); normalised
AMBIENT = 0.25
NORMAL_BLUR_PX = 2.0  # Gaussian sigma on the back-projected points before the normals
VARIANTS = ("photograph", "grey", "edges", "shading", "both", "flattened")


def depth_edges(depth: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """(H, W) bool: the pixels either side of a log-depth step over DEPTH_EDGE per pixel along x or y."""
    return log_depth_step(depth, valid) > DEPTH_EDGE


def _grey_rgb(grey: np.ndarray) -> np.ndarray:
    return np.repeat(np.round(grey).astype(np.uint8)[..., None], 3, axis=-1)


def shading_image(depth: np.ndarray, valid: np.ndarray, intrinsics) -> np.ndarray:
    """(H, W, 3) uint8: the ground truth's surfaces, white and Lambertian under one light (module docstring)."""
    ok = valid & (depth > 0)
    z = ndimage.gaussian_filter(nearest_fill(np.where(ok, depth, 0.0)).astype(np.float64), NORMAL_BLUR_PX)
    v, u = np.mgrid[:depth.shape[0], :depth.shape[1]]
    points = np.stack([(u - intrinsics.cx) / intrinsics.fx * z, (v - intrinsics.cy) / intrinsics.fy * z, z], -1)
    normal = np.cross(np.gradient(points, axis=1), np.gradient(points, axis=0))
    normal /= np.maximum(np.linalg.norm(normal, axis=-1, keepdims=True), 1e-12)
    normal *= -np.sign(normal[..., 2:3] + 1e-12)  # towards the camera (n_z < 0)
    light = np.asarray(LIGHT_DIR) / np.linalg.norm(LIGHT_DIR)
    return _grey_rgb(255 * (AMBIENT + (1 - AMBIENT) * np.clip(normal @ light, 0.0, 1.0)))


def variant_image(frame, variant: str) -> np.ndarray:
    """(H, W, 3) uint8: the image of one variant for `frame`."""
    if variant == "photograph":
        return frame.rgb
    if variant == "grey":
        return np.full_like(frame.rgb, GREY)
    if variant == "edges":
        return _grey_rgb(np.where(depth_edges(frame.depth, frame.valid), EDGE_GREY, BACKGROUND_GREY))
    if variant == "shading":
        return shading_image(frame.depth, frame.valid, frame.intrinsics)
    if variant == "both":
        edges = depth_edges(frame.depth, frame.valid)[..., None]
        shading = shading_image(frame.depth, frame.valid, frame.intrinsics)
        return np.where(edges, EDGE_GREY, shading).astype(np.uint8)
    return cv2.pyrMeanShiftFiltering(np.ascontiguousarray(frame.rgb), MEAN_SHIFT_SP, MEAN_SHIFT_SR)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default=None, help="a model name or path (default: the default path's choice)")
    ap.add_argument("--synthetic", type=int, default=8, help="test renders of rooms (480x640)")
    ap.add_argument("--realdata", default=REALDATA)
    ap.add_argument("--variants", default=",".join(VARIANTS), help="comma-separated, from " + ", ".join(VARIANTS))
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    variants = [v.strip() for v in args.variants.split(",")]
    if set(variants) - set(VARIANTS) or not {"grey"} <= set(variants):
        ap.error(f"--variants must include grey (the worth's reference) and come from {VARIANTS}, got {variants}")
    frames = [("real", s, sparse) for group, s, sparse, _ in frames_and_inputs(os.path.abspath(args.realdata))
              if group == "indoor"]
    renders = SyntheticDataset("indoor", "test", size=args.synthetic, height=480, width=640)
    frames += [("renders", s, UniformSampler(INDOOR_POINTS)(s, 0)) for s in renders]
    linear, rows = get_completer("linear"), []
    for group, frame, sparse in frames:
        ratios = ratios_to_linear(args.model, linear, frame, lambda s, _, sparse=sparse: sparse,
                                  [variant_image(frame, v) for v in variants], cross_check=False)
        row = {"group": group, "frame": frame.id, **dict(zip(variants, ratios))}
        rows.append(row)
        print(f"{frame.id:34s} " + "  ".join(f"{v} {row[v]:.3f}" for v in variants), flush=True)
    others = [v for v in variants if v != "grey"]
    print("\n| frames | n | " + " | ".join(variants) + " | " + " | ".join(f"worth: {v}" for v in others) + " |")
    print("|---|---:|" + "---:|" * (len(variants) + len(others)))
    for group in ("real", "renders"):
        g = {v: geometric_mean([r[v] for r in rows if r["group"] == group]) for v in variants}
        n = sum(r["group"] == group for r in rows)
        print(f"| {group} | {n} | " + " | ".join(f"{g[v]:.3f}" for v in variants) + " | "
              + " | ".join(f"{g['grey'] / g[v]:.3f}" for v in others) + " |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
        print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
