"""Synthetic streets scored where KITTI's ground truth would lie: near the LiDAR's own scan lines.

    python -m benchmarks.kitti_like_gt [--model lip-any] [--frames 24] [--start 8] [--sampler lidar:hdl64]
                                       [--figure docs/results/kitti_like_gt.png]

KITTI's depth ground truth is LiDAR too: 11 sweeps accumulated around each frame, so its valid pixels lie near
scan lines, where the input's samples are, and nowhere above the top beam. The synthetic suite
(benchmarks/generalisation.py) scores every valid pixel, which weighs the gaps between the lines far more. Here each
test street (352x1216) is scored twice, through the default path (`lipjax.inference.complete_frame`) against the
Delaunay linear fill, on the unsampled pixels:
  - every valid pixel;
  - the KITTI-like mask: the union of SWEEPS HDL-64 patterns, the LiDAR from FORWARD_M[0] to FORWARD_M[1] metres
    ahead of the camera and pitched PITCH_DEG[0] to PITCH_DEG[1] degrees, azimuth steps of AZIMUTH_STEP_DEG
    (about half the synthetic test pixels).
It prints each frame's two ratios to linear and their geometric means (< 1: the model wins).
docs/decisions/0018-residual-spreading.md says why it was written and what it decided. `--figure` draws the first
street: the image, the KITTI-like mask, and where the default path's squared error exceeds linear's (red) or falls
below it (blue) on that mask, with and without the samples' residuals spread (`lipjax.spread`).
"""
from __future__ import annotations

import argparse

import numpy as np
from tqdm import tqdm

from benchmarks.common import STREET, geometric_mean
from lipjax.data.sampling import LidarSampler, sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.inference import complete_at, complete_frame, frame_size
from lipjax.methods import get_completer

SWEEPS = 11  # KITTI accumulates 11 LiDAR sweeps around each frame
FORWARD_M = (-0.27, 5.0)  # the accumulated sweeps' LiDAR positions ahead of the camera (KITTI mounts it 0.27 m behind)
PITCH_DEG = (-0.2, 0.2)  # and their pitch: the car rocks, so beams do not fall on the same rows twice
AZIMUTH_STEP_DEG = 0.09  # the HDL-64's finest azimuth step


def kitti_like_mask(frame) -> np.ndarray:
    """(H, W) bool: the frame's valid pixels that one of the SWEEPS accumulated HDL-64 patterns hits."""
    hit = np.zeros(frame.valid.shape, bool)
    for forward, pitch in zip(np.linspace(*FORWARD_M, SWEEPS), np.linspace(*PITCH_DEG, SWEEPS)):
        sweep = LidarSampler.hdl64(mount_forward_m=float(forward), mount_pitch_deg=float(pitch),
                                   azimuth_step_deg=AZIMUTH_STEP_DEG)
        hit |= sweep(frame, 0) > 0
    return hit & frame.valid


def ratio(pred: np.ndarray, ref: np.ndarray, gt: np.ndarray, keep: np.ndarray) -> float:
    """RMSE of pred over RMSE of ref on the pixels `keep`."""
    return float(np.sqrt(np.mean((pred[keep] - gt[keep]) ** 2) / np.mean((ref[keep] - gt[keep]) ** 2)))


def draw(path: str, model, frame, sparse: np.ndarray, pred: np.ndarray, ref: np.ndarray, mask: np.ndarray) -> None:
    """The --figure of one street (module docstring); `pred` is the default path's estimate, with the spread."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keep = mask & (sparse <= 0)
    plain = complete_at(model, frame.rgb, sparse, frame_size(model, sparse), spread=False)
    panels = [("the image", frame.rgb), ("KITTI-like mask (white)", keep)]
    for name, estimate in (("without", plain), ("with", pred)):
        diff = np.where(keep, (estimate - frame.depth) ** 2 - (ref - frame.depth) ** 2, np.nan)
        rmse = ratio(estimate, ref, frame.depth, keep)
        panels.append((f"model SE - linear SE, {name} spreading ({rmse:.3f}x linear RMSE)", diff))
    fig, axes = plt.subplots(len(panels), 1, figsize=(12, 3.4 * len(panels)))
    for ax, (title, image) in zip(axes, panels):
        if image.ndim == 2 and image.dtype != bool:
            ax.imshow(image, cmap="bwr", vmin=-4.0, vmax=4.0)  # m^2: red, the model is worse there
        else:
            ax.imshow(image, cmap="gray" if image.ndim == 2 else None)
        ax.set_title(title)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=60)
    print(f"wrote {path}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="lip-any", help="a shipped model's name or an exported model's path")
    parser.add_argument("--frames", type=int, default=24)
    parser.add_argument("--start", type=int, default=8,
                        help="the first test street (residual spreading was prototyped on 0-7)")
    parser.add_argument("--sampler", default="lidar:hdl64", help="the input pattern (lipjax.data.sampling spec)")
    parser.add_argument("--figure", help="draw the first street to this PNG (module docstring)")
    args = parser.parse_args(argv)
    model, linear = get_completer(args.model), get_completer("linear")
    streets = SyntheticDataset("outdoor", "test", size=args.start + args.frames, height=STREET[0], width=STREET[1])
    sampler = sampler_from_spec(args.sampler)
    every, kitti = [], []
    for i in tqdm(range(args.start, args.start + args.frames), desc="streets", unit="frame"):
        frame = streets[i]
        sparse = sampler(frame, 0)
        pred, ref = complete_frame(model, frame.rgb, sparse), linear(frame.rgb, sparse)
        unsampled = sparse <= 0
        every.append(ratio(pred, ref, frame.depth, frame.valid & unsampled))
        mask = kitti_like_mask(frame)
        kitti.append(ratio(pred, ref, frame.depth, mask & unsampled))
        if args.figure and i == args.start:
            draw(args.figure, model, frame, sparse, pred, ref, mask)
        tqdm.write(f"frame {i:3d}: every pixel {every[-1]:.4f}, KITTI-like mask {kitti[-1]:.4f} "
                   f"({mask.mean():.0%} of the pixels)")
    print(f"{args.model} on {args.frames} test streets {STREET[0]}x{STREET[1]}, {args.sampler}, RMSE ratio to linear "
          f"(geometric mean): every pixel {geometric_mean(every):.4f}, KITTI-like mask {geometric_mean(kitti):.4f}")


if __name__ == "__main__":
    main()
