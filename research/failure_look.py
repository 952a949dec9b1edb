"""Where the default model loses to a linear fill, per frame: at depth edges, at colour-only edges, or on flat ground.

The model's own estimate is scored (`cross_check=False`, `flip=False`): the default path's check against the
linear fill (lipjax.crosscheck) would mix that fill into what is measured here, and its flipped frame on scan lines
(lipjax.inference.flips) a second estimate.

Run by hand (never a test; the shared frames are read from ../shared/realdata, never copied):

    python -m research.failure_look [--model NAME] [--synthetic 8] [--realdata ../shared/realdata] [--plot PNG]
                                    [--json OUT]

Every frame is completed at its native size through the default path (`get_completer(None, sparse)`,
`complete_frame`; `--model` puts one model, a name or a path, through the same path), once with its photograph
and once with a uniform grey image, and by `linear`. Inputs are those of benchmarks/real_frames.py: 200 uniform
points indoors, the HDL-64 pattern on KITTI; the synthetic test renders get the same (rooms 256x320 with 200
points, streets 352x1216 with HDL-64). Each unsampled valid pixel falls in one
class, from the ground truth and the photograph at native size:

    depth edge    within CLASS_NEAR_PX of a pixel where |d log D| > DEPTH_EDGE along x or y (central differences
                  where both ends are valid: KITTI's semi-dense ground truth has few pixels with all four)
    colour only   within CLASS_NEAR_PX of a pixel with |grad I| > COLOUR_EDGE, and no depth edge near
    flat          the rest

(I: the grey image in [0, 1] after a Gaussian blur; the classes, gradients and thresholds: research.common,
shared with research/edge_statistics.py.)
Per class it prints the change of the squared-error sum against linear as a share of linear's total,

    model - linear     sum_class(e_model^2 - e_linear^2) / sum_all(e_linear^2)

so the three classes add up to ratio^2 - 1, and the same for the photograph against the grey image (what the RGB
guidance adds in each class: negative helps). --plot draws, for the frames that lose most, the photograph, the
ground truth and the map |e_linear| - |e_model| (blue: the model is better, red: worse).
"""
from __future__ import annotations

import argparse
import json
import os

import numpy as np

from benchmarks.common import GREY, REALDATA, frames_and_inputs
from lipjax.data.sampling import LidarSampler, UniformSampler
from lipjax.data.synthetic import SyntheticDataset
from lipjax.inference import complete_frame
from lipjax.methods import get_completer
from research.common import CLASSES, pixel_classes


def frame_row(name: str, input_name: str, rgb, depth, valid, sparse, linear,
              model: str | None = None) -> tuple[dict, np.ndarray]:
    completer = get_completer(model, sparse=sparse)
    keep = valid & (sparse <= 0) & (depth > 0)
    e_lin = np.where(keep, linear(rgb, sparse) - depth, 0.0)
    def error(image):  # the model's own estimate: neither the check nor the flipped frame
        return np.where(keep, complete_frame(completer, image, sparse, flip=False, cross_check=False) - depth, 0.0)

    e_rgb, e_grey = error(rgb), error(np.full_like(rgb, GREY))
    classes = pixel_classes(rgb, depth, valid)
    total = float((e_lin ** 2).sum())
    row = {"frame": name, "input": input_name, "ratio": float(np.sqrt((e_rgb ** 2).sum() / total)),
           "grey_ratio": float(np.sqrt((e_grey ** 2).sum() / total))}
    for c, label in enumerate(CLASSES):
        m = keep & (classes == c)
        row[f"share {label}"] = float(m.sum() / keep.sum())
        row[f"model-linear {label}"] = float(((e_rgb ** 2 - e_lin ** 2)[m]).sum() / total)
        row[f"rgb-grey {label}"] = float(((e_rgb ** 2 - e_grey ** 2)[m]).sum() / total)
    return row, np.where(keep, np.abs(e_lin) - np.abs(e_rgb), np.nan)


def synthetic_frames(n: int):
    rooms = SyntheticDataset("indoor", "test", size=n, height=256, width=320)
    streets = SyntheticDataset("outdoor", "test", size=n, height=352, width=1216)
    for kind, data, sampler, input_name in (("rooms", rooms, UniformSampler(200), "200 points"),
                                           ("streets", streets, LidarSampler.hdl64(), "HDL-64")):
        for s in data:
            yield f"synthetic {kind}", s, sampler(s, 0), input_name


def print_table(title: str, rows: list[dict]) -> None:
    print(f"\n{title}\n| frame | input | RMSE / linear | grey / linear | "
          + " | ".join(f"{c}: pixels, model-linear, rgb-grey" for c in CLASSES) + " |")
    print("|---|---|---:|---:|" + "---|" * len(CLASSES))
    for r in rows:
        cells = [f"{r[f'share {c}']:.0%}, {r[f'model-linear {c}']:+.3f}, {r[f'rgb-grey {c}']:+.3f}" for c in CLASSES]
        print(f"| {r['frame']} | {r['input']} | {r['ratio']:.3f} | {r['grey_ratio']:.3f} | " + " | ".join(cells)
              + " |")
    mean = {k: np.mean([r[k] for r in rows]) for k in rows[0] if k not in ("frame", "input")}
    print("| mean | | {ratio:.3f} | {grey_ratio:.3f} | ".format(**mean) + " | ".join(
        f"{mean[f'share {c}']:.0%}, {mean[f'model-linear {c}']:+.3f}, {mean[f'rgb-grey {c}']:+.3f}"
        for c in CLASSES) + " |")


def plot(worst: list[tuple[dict, np.ndarray, np.ndarray, np.ndarray]], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(worst), 3, figsize=(13, 3.2 * len(worst)), squeeze=False)
    for (row, rgb, depth, gain), ax in zip(worst, axes):
        ax[0].imshow(rgb)
        ax[0].set_title(f"{row['frame']} ({row['input']}): {row['ratio']:.3f}x linear", fontsize=9)
        ax[1].imshow(np.where(depth > 0, depth, np.nan), cmap="turbo")
        ax[1].set_title("ground truth (m)", fontsize=9)
        lim = float(np.nanpercentile(np.abs(gain), 99)) or 1.0
        im = ax[2].imshow(gain, cmap="coolwarm_r", vmin=-lim, vmax=lim)
        ax[2].set_title("|e linear| - |e model| (m): blue model better, red worse", fontsize=9)
        fig.colorbar(im, ax=ax[2], fraction=0.03)
        for a in ax:
            a.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    print(f"\nwrote {path}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default=None, help="a model name or path (default: the default path's choice)")
    ap.add_argument("--synthetic", type=int, default=8, help="synthetic test frames per kind")
    ap.add_argument("--realdata", default=REALDATA)
    ap.add_argument("--plot", default=None, help="write the worst frames' error maps here (PNG)")
    ap.add_argument("--worst", type=int, default=4, help="frames in the picture")
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    linear = get_completer("linear")
    real, pictures = [], []
    for group, s, sparse, input_name in frames_and_inputs(os.path.abspath(args.realdata)):
        if group == "kitti-30pct":
            continue
        row, gain = frame_row(s.id, input_name, s.rgb, s.depth, s.valid, sparse, linear, args.model)
        real.append(row)
        pictures.append((row, s.rgb, np.where(s.valid, s.depth, 0), gain))
        print(f"{s.id:30s} {row['ratio']:.3f}", flush=True)
    synthetic = [frame_row(f"{kind} {s.id}", input_name, s.rgb, s.depth, s.valid, sparse, linear, args.model)[0]
                 for kind, s, sparse, input_name in synthetic_frames(args.synthetic)]
    print_table("Shared real frames (native size, default path)", real)
    for kind in ("rooms", "streets"):
        print_table(f"Synthetic {kind}", [r for r in synthetic if r["frame"].startswith(f"synthetic {kind}")])
    if args.plot:
        plot(sorted(pictures, key=lambda p: -p[0]["ratio"])[:args.worst], args.plot)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"real": real, "synthetic": synthetic}, f, indent=1)


if __name__ == "__main__":
    main()
