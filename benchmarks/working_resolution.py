"""Chooses the learned prox's working resolution on synthetic renders larger than the training frames.

    python benchmarks/working_resolution.py [--model lip-fast-indoor] [--frames 12] [--out runs/eval/working_res]

Rooms rendered at 480x640 (NYU's size) and streets at 352x1216 (KITTI's), from the test split (never trained on),
with 50, 200 and 1,000 uniform points on the rooms and a 64-beam scan or 200 points on the streets. For each target
spacing T (pixels) the model runs at `lipjax.resolution.working_size(shape, spacing, T)`, and the table gives the
geometric-mean RMSE ratio to the full-size linear fill on the unsampled valid pixels (< 1: the model wins).

The rule, fixed before any real frame is scored: TARGET_SPACING_PX is the T with the lowest geometric mean over all
the settings together. Real frames are scored afterwards, with that T (benchmarks/real_frames.py).
"""
from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from lipjax.data.sampling import sampler_from_spec  # noqa: E402
from lipjax.data.synthetic import SyntheticDataset  # noqa: E402
from lipjax.inference import complete_at, get_completer  # noqa: E402
from lipjax.methods import get_method  # noqa: E402
from lipjax.resolution import sample_spacing_px, working_size  # noqa: E402

SETTINGS = (  # (kind, height, width, sampler spec)
    ("indoor", 480, 640, "uniform:50"),
    ("indoor", 480, 640, "uniform:200"),
    ("indoor", 480, 640, "uniform:1000"),
    ("outdoor", 352, 1216, "lidar:hdl64"),
    ("outdoor", 352, 1216, "uniform:200"),
)
TARGETS_PX = (2.5, 4.0, 6.0, 8.0, 11.0, 16.0, 22.0, 32.0, 1e9)  # 1e9: always full size


def rmse_unsampled(pred: np.ndarray, gt: np.ndarray, valid: np.ndarray, sparse: np.ndarray) -> float:
    keep = valid & (sparse <= 0)
    return float(np.sqrt(np.mean((pred[keep] - gt[keep]) ** 2)))


def run(model: str, frames: int, upsample: str) -> dict:
    completer, linear = get_completer(model), get_method("linear")
    table = {}
    for kind, h, w, spec in SETTINGS:
        dataset, sampler = SyntheticDataset(kind, "test", size=frames, height=h, width=w), sampler_from_spec(spec)
        ratios = {t: [] for t in TARGETS_PX}
        for sample in dataset:
            sparse = sampler(sample, 0)
            ref = rmse_unsampled(linear(sample.rgb, sparse), sample.depth, sample.valid, sparse)
            spacing = sample_spacing_px(sparse)
            for t in TARGETS_PX:
                size = working_size((h, w), spacing, t)
                pred = complete_at(completer, sample.rgb, sparse, size, upsample)
                ratios[t].append(rmse_unsampled(pred, sample.depth, sample.valid, sparse) / ref)
        key = f"{kind} {h}x{w} {spec}"
        table[key] = {str(t): float(np.exp(np.mean(np.log(r)))) for t, r in ratios.items()}
        print(key, " ".join(f"{t:g}:{v:.3f}" for t, v in zip(TARGETS_PX, table[key].values())), flush=True)
    return table


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--model", default=None, help="default: the default model")
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--out", default="runs/eval/working_resolution")
    parser.add_argument("--upsample", default="bilinear", choices=("bilinear", "residual"))
    args = parser.parse_args(argv)
    table = run(args.model, args.frames, args.upsample)
    overall = {str(t): float(np.exp(np.mean([np.log(row[str(t)]) for row in table.values()]))) for t in TARGETS_PX}
    best = min(overall, key=overall.get)
    print("\n| setting | " + " | ".join("full" if t == 1e9 else f"T={t:g}" for t in TARGETS_PX) + " |")
    print("|---|" + "---|" * len(TARGETS_PX))
    for key, row in {**table, "all (geometric mean)": overall}.items():
        print(f"| {key} | " + " | ".join(f"{row[str(t)]:.3f}" for t in TARGETS_PX) + " |")
    print(f"\nbest target spacing: {best} px (geometric mean {overall[best]:.3f})")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "working_resolution.json"), "w") as f:
        json.dump({"model": args.model, "upsample": args.upsample, "frames": args.frames, "table": table, "overall": overall, "best": best}, f,
                  indent=1)


if __name__ == "__main__":
    main()
