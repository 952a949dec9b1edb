"""Where the inverse-depth error (iRMSE) of each method comes from, split by true depth. Run by hand (not a test):

    python -m research.inverse_depth_bands --scene outdoor --methods lip-cnn-outdoor,colorization,nearest

On the scene's synthetic validation split (the frames and sampler of benchmarks/validation.py), for each depth band
of the ground truth: its share of the valid pixels, and each method's share of the summed squared inverse-depth
error (1/km)^2 over all pixels, as a sum over the band divided by the total number of valid pixels (so a row sums to
the pooled mean squared error). Predictions are floored at --floor-m first (default 1 m), so that a few pixels
near or below zero depth, which alone can dominate iRMSE, do not hide where the ordinary error lies.
"""
from __future__ import annotations

import argparse

import numpy as np

from experiments.configs import CONFIGS
from lipjax.data.protocols import get_protocol
from lipjax.data.sampling import sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.methods import get_completer

BAND_EDGES_M = (0.0, 3.0, 5.0, 8.0, 12.0, 20.0, 40.0, 80.0)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", choices=("indoor", "outdoor"), default="outdoor")
    ap.add_argument("--methods", default="lip-cnn-outdoor,colorization,nearest")
    ap.add_argument("--floor-m", type=float, default=1.0, help="predictions are floored here first (metres)")
    args = ap.parse_args(argv)
    data = CONFIGS[f"lip_cnn_{args.scene}"].data
    protocol = get_protocol(f"synthetic_{args.scene}")
    dataset = SyntheticDataset(data.kind, "val", size=data.val_images, height=data.height, width=data.width)
    sampler = sampler_from_spec(data.val_sampler)
    edges = [e for e in BAND_EDGES_M if e < protocol.max_depth_m] + [protocol.max_depth_m]
    names = args.methods.split(",")
    methods = {name: get_completer(name) for name in names}
    squared = {name: np.zeros(len(edges) - 1) for name in names}  # summed (1/km)^2 per band
    counts = np.zeros(len(edges) - 1)
    for i in range(len(dataset)):
        frame = dataset[i]
        sparse = sampler(frame, 0)
        valid = frame.valid & (frame.depth > protocol.min_depth_m) & (frame.depth <= protocol.max_depth_m)
        band = np.digitize(frame.depth[valid], edges[1:-1], right=True)
        counts += np.bincount(band, minlength=len(counts))
        for name, method in methods.items():
            pred = np.maximum(np.asarray(method(frame.rgb, sparse)).reshape(frame.depth.shape), args.floor_m)
            error = (1000.0 / pred[valid] - 1000.0 / frame.depth[valid]) ** 2
            squared[name] += np.bincount(band, weights=error, minlength=len(counts))
    total = counts.sum()
    header = [f"{lo:g}-{hi:g} m" for lo, hi in zip(edges[:-1], edges[1:])]
    print(f"[lipjax] synthetic {args.scene} val, {len(dataset)} frames, {data.val_sampler}, floor {args.floor_m} m")
    print("| | " + " | ".join(header) + " | pooled iRMSE 1/km |")
    print("|---|" + "---:|" * (len(header) + 1))
    print("| pixels % | " + " | ".join(f"{100 * c / total:.1f}" for c in counts) + " | |")
    for name in names:
        share = squared[name] / total
        print(f"| {name} | " + " | ".join(f"{v:.0f}" for v in share) + f" | {np.sqrt(share.sum()):.2f} |")


if __name__ == "__main__":
    main()
