"""Where training stands on the 7 real frames: RMSE against linear interpolation per model, by images seen.

Run by hand (never a test; the real frames are research-only and stay in ../shared/realdata):

    python -m benchmarks.real_frames_curve --model RUN=PATH [--model RUN=PATH ...]
                                          [--out curve.png] [--json out.json]

Each PATH is a saved model (lipjax.model_io stem, or a shipped name) whose metadata records `images_seen`; models
with the same RUN label are one training run, drawn as one line. The frames and sparse inputs are those of
benchmarks/baselines.py's main real settings, drawn the same way (seed 0):
  3 NYU v2 frames (nyu_paper 256x320), 200 uniform points, (0, 10] m;
  3 KITTI frames (kitti_paper 256x1216), HDL-64 pattern simulated on the ground truth, (0, 80] m;
  Middlebury 2014 Motorcycle (497x741, full size), 200 uniform points, (0, 10] m.

Prints a Markdown table (per model: frames on which it beats linear interpolation's RMSE, the geometric mean of
its RMSE / linear's over the 7 frames, and each frame's ratio) and draws both numbers against images seen.
A model is not chosen by this table: with 7 frames it describes, it does not select.
"""
from __future__ import annotations

import argparse
import json
import math
import os

from benchmarks.common import INDOOR_RANGE_M, OUTDOOR_RANGE_M, REALDATA, load_real
from lipjax import model_io
from lipjax.data.sampling import LidarSampler, UniformSampler
from lipjax.evaluate import evaluate
from lipjax.methods import get_completer


def real_settings(root: str) -> list[tuple[list, object, tuple[float, float]]]:
    """(frames, sampler, depth range m) of the three main real settings of benchmarks/baselines.py."""
    nyu, kitti, mb = load_real(root)
    return [(nyu, UniformSampler(200), INDOOR_RANGE_M), (kitti, LidarSampler.hdl64(), OUTDOOR_RANGE_M),
            (mb, UniformSampler(200), INDOOR_RANGE_M)]


def frame_rmse(method, settings) -> dict[str, float]:
    """RMSE (m) of `method` on every frame of `settings`, by frame id."""
    out = {}
    for frames, sampler, (min_depth, max_depth) in settings:
        result = evaluate(method, frames, sampler, min_depth_m=min_depth, max_depth_m=max_depth, progress=False)
        out.update({row["id"]: row["rmse_m"] for row in result.per_image})
    return out


def plot(path: str, rows: list[dict]) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 3.6), dpi=120)
    FigureCanvasAgg(fig)
    wins_ax, ratio_ax = fig.subplots(1, 2)
    for run in dict.fromkeys(r["run"] for r in rows):
        mine = sorted((r for r in rows if r["run"] == run), key=lambda r: r["images_seen"])
        seen = [r["images_seen"] / 1000 for r in mine]
        wins_ax.plot(seen, [r["wins"] for r in mine], marker="o", label=run)
        ratio_ax.plot(seen, [r["geomean_ratio"] for r in mine], marker="o", label=run)
    n = len(rows[0]["ratios"])
    wins_ax.set_ylim(-0.3, n + 0.3)
    wins_ax.set_ylabel(f"frames better than linear (of {n})")
    ratio_ax.axhline(1.0, color="grey", linewidth=0.8)
    ratio_ax.set_ylabel("geometric mean RMSE / linear's")
    for ax in (wins_ax, ratio_ax):
        ax.set_xlabel("images seen (thousands)")
        ax.grid(alpha=0.3)
    ratio_ax.legend(fontsize=7)
    fig.suptitle("real frames (NYU v2 x3 200 pts, KITTI x3 HDL-64, Middlebury 200 pts)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--model", action="append", required=True, metavar="RUN=PATH",
                    help="a saved model and the run it belongs to (repeat)")
    ap.add_argument("--realdata", default=REALDATA)
    ap.add_argument("--out", default=None, help="write the plot here (PNG)")
    ap.add_argument("--json", default=None, help="write the rows here")
    args = ap.parse_args(argv)
    models = []
    for item in args.model:
        run, sep, path = item.partition("=")
        if not sep or not run or not path:
            ap.error(f"--model {item!r}: expected RUN=PATH, e.g. --model lidar=runs/cand/lidar_1000")
        models.append((run, path))
    root = os.path.abspath(args.realdata)
    if not os.path.isdir(root):
        ap.error(f"no real frames at {root}; give --realdata DIR")
    settings = real_settings(root)
    linear = frame_rmse(get_completer("linear"), settings)
    rows = []
    for run, path in models:
        seen = model_io.metadata(path).get("images_seen")
        if seen is None:
            ap.error(f"{path} records no images_seen; export it with `experiments.train --export`")
        rmse = frame_rmse(get_completer(path), settings)
        ratios = {k: rmse[k] / linear[k] for k in linear}
        rows.append({"run": run, "model": path, "images_seen": int(seen), "rmse_m": rmse, "ratios": ratios,
                     "wins": sum(r < 1.0 for r in ratios.values()),
                     "geomean_ratio": math.exp(sum(math.log(r) for r in ratios.values()) / len(ratios))})
    ids = list(linear)
    short = [i.removeprefix("realdata/") for i in ids]
    print(f"| run | model | images seen | wins of {len(ids)} | geo-mean ratio | {' | '.join(short)} |")
    print("|---|---|---:|---:|---:|" + "---:|" * len(ids))
    print(f"| linear | linear | - | - | 1 | {' | '.join(f'{linear[i]:.3f} m' for i in ids)} |")
    for r in rows:
        ratios = " | ".join(f"{r['ratios'][i]:.3f}" for i in ids)
        print(f"| {r['run']} | {r['model']} | {r['images_seen']:,} | {r['wins']} | {r['geomean_ratio']:.3f} | "
              f"{ratios} |")
    if args.out:
        plot(args.out, rows)
        print(f"\nwrote {args.out}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"linear_rmse_m": linear, "models": rows}, f, indent=1)
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
