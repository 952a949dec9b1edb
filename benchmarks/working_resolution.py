"""Chooses the learned prox's working resolution on synthetic renders larger than the training frames.

The model's own estimate is scored (`cross_check=False`, `flip=False`): the default path's check against the
linear fill (lipjax.crosscheck) would mix that fill into what is measured here, and its flipped frame on scan lines
(lipjax.inference.flips) a second estimate.

    python -m benchmarks.working_resolution [--model lip-fast-indoor] [--frames 12] [--out runs/eval/working_res]

Rooms rendered at 480x640 (NYU's size) and streets at 352x1216 (KITTI's), from the test split (never trained on),
with 50, 200, 1,000 and 5,000 uniform points on the rooms, and 64- and 32-beam scans, 200 points or 25,000 points
(dense, like 30 % of KITTI's valid pixels) on the streets. For each target spacing T (pixels) and pixel cap P the model
runs at `lipjax.resolution.working_size(shape, spacing, T, P)`, and the table gives the geometric-mean RMSE ratio to
the full-size linear fill on the unsampled valid pixels (< 1: the model wins).

The rule, fixed before any real frame is scored: T (TARGET_SPACING_PX) and the pixel cap of scattered samples are the
(T, P) with the lowest geometric mean over the scattered settings; the cap of LiDAR scan lines (MAX_WORKING_PIXELS)
is the P with the lowest geometric mean over the scan-line settings at that T (`lipjax.inputs.is_lidar_pattern`
tells them apart, as the default path does). Among rules within 1 % of those, lipjax.resolution takes the most
accurate one whose frames keep 10 frames/s (benchmarks/speed.py): T=16 px, no cap for scattered samples, 60,000
pixels for scan lines. Real frames are scored afterwards (benchmarks/real_frames.py).
"""
from __future__ import annotations

import argparse
import json
import os

import numpy as np

from benchmarks.common import rmse_unsampled
from lipjax.data.sampling import sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.inference import complete_at
from lipjax.inputs import is_lidar_pattern
from lipjax.methods import get_completer
from lipjax.resolution import sample_spacing_px, working_size

SETTINGS = (  # (kind, height, width, sampler spec)
    ("indoor", 480, 640, "uniform:50"),
    ("indoor", 480, 640, "uniform:200"),
    ("indoor", 480, 640, "uniform:1000"),
    ("indoor", 480, 640, "uniform:5000"),
    ("outdoor", 352, 1216, "lidar:hdl64"),
    ("outdoor", 352, 1216, "lidar:vlp32"),
    ("outdoor", 352, 1216, "uniform:200"),
    ("outdoor", 352, 1216, "uniform:25000"),
)
TARGETS_PX = (8.0, 11.0, 16.0, 22.0, 32.0, 1e9)  # 1e9: no spacing rule
MAX_PIXELS = (40_000, 60_000, 100_000, 150_000, 250_000, 1e12)  # 1e12: no pixel cap
RULES = [(t, p) for t in TARGETS_PX for p in MAX_PIXELS]


def run(model: str, frames: int) -> dict:
    completer, linear = get_completer(model), get_completer("linear")
    table, scan_lines = {}, {}
    for kind, h, w, spec in SETTINGS:
        dataset, sampler = SyntheticDataset(kind, "test", size=frames, height=h, width=w), sampler_from_spec(spec)
        ratios, patterns = {rule: [] for rule in RULES}, set()
        for frame in dataset:
            sparse = sampler(frame, 0)
            patterns.add(is_lidar_pattern(sparse))
            ref = rmse_unsampled(linear(frame.rgb, sparse), frame, sparse)
            spacing, by_size = sample_spacing_px(sparse), {}
            for t, p in RULES:
                size = working_size((h, w), spacing, t, p)
                if size not in by_size:  # rules that give the same size share one run
                    pred = complete_at(completer, frame.rgb, sparse, size, flip=False, cross_check=False)
                    by_size[size] = rmse_unsampled(pred, frame, sparse) / ref
                ratios[(t, p)].append(by_size[size])
        key = f"{kind} {h}x{w} {spec}"
        if len(patterns) > 1:
            raise RuntimeError(f"{key}: is_lidar_pattern differs between frames; a setting must be one pattern")
        scan_lines[key] = patterns.pop()
        table[key] = {_name(rule): float(np.exp(np.mean(np.log(r)))) for rule, r in ratios.items()}
        print(key, {k: round(v, 3) for k, v in table[key].items()}, flush=True)
    return table, scan_lines


def _geomean(table: dict, keys: list[str], name: str) -> float:
    return float(np.exp(np.mean([np.log(table[k][name]) for k in keys])))


def _name(rule: tuple[float, float]) -> str:
    t, p = rule
    return f"T={'inf' if t >= 1e9 else f'{t:g}'},P={'inf' if p >= 1e12 else f'{p / 1e3:g}k'}"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--model", default=None, help="default: the default model")
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--out", default="runs/eval/working_resolution")
    args = parser.parse_args(argv)
    table, scan_lines = run(args.model, args.frames)
    names = [_name(rule) for rule in RULES]
    groups = {"scattered": [k for k in table if not scan_lines[k]], "scan lines": [k for k in table if scan_lines[k]]}
    overall = {g: {n: _geomean(table, keys, n) for n in names} for g, keys in groups.items() if keys}
    best_scattered = min(overall["scattered"], key=overall["scattered"].get)
    target = best_scattered.split(",")[0]
    at_target = {n: v for n, v in overall.get("scan lines", {}).items() if n.split(",")[0] == target}
    best_lines = min(at_target, key=at_target.get) if at_target else None
    for group, values in overall.items():
        print(f"\n{group}: geometric-mean RMSE ratio to linear; rows T (target spacing px), columns P (max pixels):")
        print("| T \\ P | " + " | ".join(n.split(",")[1] for n in names[:len(MAX_PIXELS)]) + " |")
        print("|---|" + "---|" * len(MAX_PIXELS))
        for i in range(len(TARGETS_PX)):
            row = names[i * len(MAX_PIXELS):(i + 1) * len(MAX_PIXELS)]
            print(f"| {row[0].split(',')[0]} | " + " | ".join(f"{values[n]:.3f}" for n in row) + " |")
    best = {k: best_lines if scan_lines[k] else best_scattered for k in table}
    print("\nPer setting at the chosen rule and with neither rule (native size):")
    for key, row in table.items():
        print(f"  {key}: {row[best[key]]:.3f} at {best[key]} (native {row['T=inf,P=inf']:.3f})")
    chosen = float(np.exp(np.mean([np.log(row[best[k]]) for k, row in table.items()])))
    print(f"\nchosen: scattered {best_scattered}, scan lines {best_lines}; geometric mean over all settings "
          f"{chosen:.3f}")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "working_resolution.json"), "w") as f:
        json.dump({"model": args.model, "frames": args.frames, "table": table, "scan_lines": scan_lines,
                   "overall": overall, "scattered": best_scattered, "scan lines": best_lines}, f, indent=1)


if __name__ == "__main__":
    main()
