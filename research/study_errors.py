"""Where the equal-budget study's models differ: RMSE on Table I's test rooms by a pixel's distance to the nearest
input sample, and by pixel class (depth edge, colour only, flat: research.common).

Run by hand (never a test; synthetic frames only):

    python -m research.study_errors [--models lip-cnn-indoor,cspn-indoor,...] [--limit 100] [--plot PNG]
                                    [--json OUT]

Every model completes the first --limit frames of the Table I test split (experiments.configs.study.test_split:
256x320 rooms, 200 uniform points, the sampler's seed 0) at the input's size, as the table scores them. Each valid
pixel of the ground truth within the protocol's depth range that is not an input sample falls in one distance band,
d = its Euclidean distance in pixels to the nearest input sample (200 points in 256x320: about 10 px on average),
and in one pixel class. Per band and class it prints each model's RMSE over all such pixels of all frames (metres),
and the band's share of the pixels. The default models are the study's seed-0 models at 30,000 images, shipped as
<method>-indoor (python -m experiments.ship_study), and the two fills.
"""
from __future__ import annotations

import argparse
import json
import pathlib

import cv2
import numpy as np

from experiments.configs.study import METHODS, test_split
from experiments.study_report import method_colour
from lipjax.data.protocols import get_protocol
from lipjax.data.sampling import sampler_from_spec
from lipjax.methods import get_completer
from research.common import CLASSES, pixel_classes

MODELS = ("lip-cnn-indoor", "lip-fast-indoor", "cspn-indoor", "unet-indoor", "ma2018-indoor", "linear", "nearest")
BANDS_PX = (0, 4, 8, 16, 32, np.inf)  # distance bands [a, b) to the nearest input sample, pixels
INPUT = "uniform:200"  # Table I's input
FILL_COLOURS = {"linear": "0.3", "nearest": "0.65"}  # the fills in grey, dashed


def band_labels() -> list[str]:
    return [f"{a:g}-{b:g} px" if np.isfinite(b) else f">= {a:g} px" for a, b in zip(BANDS_PX, BANDS_PX[1:])]


def distance_to_samples(sparse: np.ndarray) -> np.ndarray:
    """(H, W) float32: each pixel's Euclidean distance in pixels to the nearest pixel with a sample (> 0)."""
    return cv2.distanceTransform((sparse <= 0).astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)


def squared_errors(models: list[str], limit: int) -> dict:
    """{"pixels": {(band, class): count}, model: {(band, class): sum of squared errors m^2}} over the frames."""
    protocol = get_protocol("synthetic_indoor")
    dataset, sampler = test_split("indoor"), sampler_from_spec(INPUT)
    completers = {m: get_completer(m) for m in models}
    sums = {m: np.zeros((len(BANDS_PX) - 1, len(CLASSES))) for m in ["pixels", *models]}
    for i in range(min(limit, len(dataset))):
        frame = dataset[i]
        sparse = np.asarray(sampler(frame, 0), np.float32)
        gt = frame.depth
        keep = frame.valid & (gt > protocol.min_depth_m) & (gt <= protocol.max_depth_m) & (sparse <= 0)
        band = np.digitize(distance_to_samples(sparse), BANDS_PX[1:-1])
        cls = pixel_classes(frame.rgb, gt, frame.valid)
        cell = (band * len(CLASSES) + cls)[keep]
        size = sums["pixels"].size
        sums["pixels"] += np.bincount(cell, minlength=size).reshape(sums["pixels"].shape)
        for m, completer in completers.items():
            err = (np.asarray(completer(frame.rgb, sparse), np.float64) - gt)[keep]
            sums[m] += np.bincount(cell, weights=err ** 2, minlength=size).reshape(sums[m].shape)
        print(f"\r{i + 1} frames", end="", flush=True)
    print()
    return sums


def rmse_table(sums: dict, axis: int | None) -> dict:
    """{model: [RMSE per band (axis 1 summed: the classes), or per class (axis 0)]}, and "share" of the pixels."""
    pixels = sums["pixels"].sum(axis=axis)
    out = {m: np.sqrt(s.sum(axis=axis) / np.maximum(pixels, 1)).tolist() for m, s in sums.items() if m != "pixels"}
    out["share"] = (pixels / pixels.sum()).tolist()
    return out


def markdown(table: dict, labels: list[str]) -> str:
    lines = ["| model | " + " | ".join(labels) + " |", "|---|" + "---:|" * len(labels),
             "| share of the pixels | " + " | ".join(f"{s:.1%}" for s in table["share"]) + " |"]
    lines += [f"| {m} | " + " | ".join(f"{v:.3f}" for v in row) + " |" for m, row in table.items() if m != "share"]
    return "\n".join(lines)


def plot(path: pathlib.Path, by_band: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = band_labels()
    fig, ax = plt.subplots(figsize=(7, 4))
    for m, row in by_band.items():
        if m != "share":
            method = m.removesuffix("-indoor")
            colour = method_colour(method) if method in METHODS else FILL_COLOURS.get(m)
            ax.plot(range(len(row)), row, marker="o", label=m, color=colour,
                    linestyle="--" if m in FILL_COLOURS else "-")
    ax.set_xticks(range(len(labels)), labels)
    ax.set_xlabel("distance to the nearest input sample")
    ax.set_ylabel("RMSE m (unsampled pixels)")
    ax.set_title("Table I test rooms, 200 points: error by distance to the samples")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1))
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--models", default=",".join(MODELS), help="comma-separated names or paths (default: %(default)s)")
    ap.add_argument("--limit", type=int, default=100, help="test frames (default: Table I's 100)")
    ap.add_argument("--plot", type=pathlib.Path, help="write the figure of RMSE by distance band here (PNG)")
    ap.add_argument("--json", type=pathlib.Path, help="write both tables here")
    args = ap.parse_args(argv)
    sums = squared_errors([m.strip() for m in args.models.split(",") if m.strip()], args.limit)
    by_band, by_class = rmse_table(sums, axis=1), rmse_table(sums, axis=0)
    print("RMSE m by distance to the nearest input sample:\n" + markdown(by_band, band_labels()))
    print("\nRMSE m by pixel class:\n" + markdown(by_class, list(CLASSES)))
    if args.plot:
        plot(args.plot, by_band)
    if args.json:
        args.json.write_text(json.dumps({"bands_px": [str(b) for b in BANDS_PX], "classes": CLASSES,
                                         "rmse_m_by_band": by_band, "rmse_m_by_class": by_class}, indent=1) + "\n")


if __name__ == "__main__":
    main()
