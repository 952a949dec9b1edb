"""Per-frame RMSE ratios to a linear fill on the 15 shared real frames, at native size, through the default path.

Run by hand (never a test; the frames are research-use data read from ../shared/realdata, never copied):

    python benchmarks/real_frames.py [--model NAME] [--realdata ../shared/realdata] [--json out.json]
                                     [--mirror | --no-mirror] [--sweep]
                                     [--plot docs/results/real_frames_working_res.png]

Frames at their native size: NYU v2 (3, 480x640), KITTI (3, 375x1242), Middlebury 2014 Motorcycle (1, 497x741),
lingbot (8, 480x640, raw consumer RGB-D depth). Inputs drawn from the valid ground truth with seed 0 and the frame
id (lipjax.data.sampling): 200 uniform points indoors; on KITTI the HDL-64 pattern (LidarSampler.hdl64, as
benchmarks/baselines.py draws it) and, in a second table, 30 % of the valid pixels. RMSE (m) on the unsampled valid
pixels. The reference is `linear` (Delaunay piecewise-linear, nearest outside the hull).

Columns: the default path (`lipjax complete` without flags: `get_completer(None, sparse)` picks the model and
`complete_frame` its working size), the same with a uniform grey image (the RGB guidance's worth: grey / RGB),
ip_basic and colorization. `--model` scores one model through the same path instead of the default choice;
`--mirror` runs the path with mirror averaging on every input (`lipjax complete --mirror`; by default on scan lines
only) for the model and its grey run, `--no-mirror` on none.
`--sweep` also runs the model at several target sample spacings (lipjax.resolution, with its pixel cap) and at the
native size ("full"), and plots the geometric-mean ratio against the working resolution.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from benchmarks.baselines import _png_depth, _rgb, load_kitti, load_middlebury, load_nyu  # noqa: E402
from lipjax.data.sample import Intrinsics, Sample  # noqa: E402
from lipjax.data.sampling import LidarSampler, UniformSampler  # noqa: E402
from lipjax.inference import complete_at, complete_frame, frame_size  # noqa: E402
from lipjax.inputs import is_lidar_pattern  # noqa: E402
from lipjax.methods import get_completer  # noqa: E402
from lipjax.resolution import sample_spacing_px, working_size  # noqa: E402

KITTI_FRACTION = 0.3  # of the valid pixels, the second KITTI input
INDOOR_POINTS = 200
GREY = 128
SWEEP_TARGETS_PX = (6.0, 8.0, 11.0, 16.0, 22.0, 32.0, 1e9)


def load_lingbot(root: str) -> list[Sample]:
    """lingbot frames: depth PNG / 1000 = metres (raw sensor depth), a 3x3 K per frame (PROVENANCE.md)."""
    out = []
    for name in sorted(os.listdir(os.path.join(root, "rgb"))):
        stem = os.path.splitext(name)[0]
        k = np.loadtxt(os.path.join(root, "intrinsics", f"{stem}.txt")).reshape(3, 3)
        depth = _png_depth(os.path.join(root, "depth", f"{stem}.png"), 1000.0)
        out.append(Sample.from_depth(_rgb(os.path.join(root, "rgb", name)), depth,
                                     Intrinsics(k[0, 0], k[1, 1], k[0, 2], k[1, 2]), f"realdata/lingbot/{stem}"))
    return out


def frames_and_inputs(root: str) -> list[tuple[str, Sample, np.ndarray, str]]:
    """(group, sample, sparse input metres, input name) for every frame and input setting."""
    indoor = load_nyu(os.path.join(root, "nyu_v2")) + load_middlebury(os.path.join(root, "middlebury2014_motorcycle"))
    indoor += load_lingbot(os.path.join(root, "lingbot_rgbd"))
    out = [("indoor", s, UniformSampler(INDOOR_POINTS)(s, 0), f"{INDOOR_POINTS} points") for s in indoor]
    for s in load_kitti(os.path.join(root, "kitti")):
        out.append(("kitti-hdl64", s, LidarSampler.hdl64()(s, 0), "HDL-64"))
        n = int(round(KITTI_FRACTION * np.count_nonzero(s.valid)))
        out.append(("kitti-30pct", s, UniformSampler(n)(s, 0), f"30 % ({n} points)"))
    return out


def rmse(pred: np.ndarray, sample: Sample, sparse: np.ndarray) -> float:
    keep = sample.valid & (sparse <= 0)
    return float(np.sqrt(np.mean((pred[keep] - sample.depth[keep]) ** 2)))


def summary(ratios: list[float]) -> str:
    r = np.asarray(ratios)
    gm = np.exp(np.log(r).mean())
    return f"wins {int((r < 1).sum())}/{len(r)}, median {np.median(r):.3f}, geometric mean {gm:.3f}"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default=None, help="a model name or path (default: the default path's choice)")
    ap.add_argument("--realdata", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "realdata"))
    ap.add_argument("--json", default=None)
    ap.add_argument("--mirror", action=argparse.BooleanOptionalAction,
                    help="the path with (--mirror) or without (--no-mirror) mirror averaging on every input")
    ap.add_argument("--sweep", action="store_true", help="also sweep the working resolution")
    ap.add_argument("--plot", default=None, help="with --sweep: write the ratio-vs-resolution picture here")
    ap.add_argument("--classical", default="ip_basic,colorization", help="comma-separated classical methods")
    args = ap.parse_args(argv)

    linear, classical = get_completer("linear"), [get_completer(m) for m in args.classical.split(",") if m]
    rows = []
    for group, sample, sparse, input_name in frames_and_inputs(os.path.abspath(args.realdata)):
        completer = get_completer(args.model, sparse=sparse)
        grey = np.full_like(sample.rgb, GREY)
        ref = rmse(linear(sample.rgb, sparse), sample, sparse)
        t0 = time.perf_counter()
        pred = complete_frame(completer, sample.rgb, sparse, mirror=args.mirror)
        ms = 1e3 * (time.perf_counter() - t0)
        row = {"group": group, "frame": sample.id, "input": input_name, "size": list(sample.shape),
               "model": completer.name, "working_size": list(frame_size(completer, sparse)),
               "linear_rmse_m": ref, "default": rmse(pred, sample, sparse) / ref,
               "grey": rmse(complete_frame(completer, grey, sparse, mirror=args.mirror), sample, sparse) / ref,
               "ms": ms}
        for method in classical:
            row[method.name] = rmse(method(sample.rgb, sparse), sample, sparse) / ref
        if args.sweep:
            spacing, lines = sample_spacing_px(sparse), is_lidar_pattern(sparse)
            row["sweep"] = {str(t): rmse(complete_at(completer, sample.rgb, sparse, _sweep_size(
                sample.shape, spacing, t, lines), mirror=args.mirror), sample, sparse) / ref for t in SWEEP_TARGETS_PX}
        rows.append(row)
        print(f"{sample.id:32s} {input_name:20s} {row['model']:22s} work {row['working_size']} "
              f"linear {ref:.3f} m  default {row['default']:.3f}  grey {row['grey']:.3f}  "
              + "  ".join(f"{m.name} {row[m.name]:.3f}" for m in classical) + f"  {ms:.0f} ms", flush=True)

    names = ["default", "grey"] + [m.name for m in classical]
    print("\n| frame | input | model | working size | linear RMSE m | " + " | ".join(names) + " |")
    print("|---|---|---|---|---|" + "---|" * len(names))
    for r in rows:
        print(f"| {r['frame']} | {r['input']} | {r['model']} | {r['working_size'][0]}x{r['working_size'][1]} | "
              f"{r['linear_rmse_m']:.3f} | " + " | ".join(f"{r[n]:.3f}" for n in names) + " |")
    for kitti in ("kitti-hdl64", "kitti-30pct"):
        chosen = [r for r in rows if r["group"] in ("indoor", kitti)]
        print(f"\n15 frames (KITTI input: {kitti[6:]}), RMSE ratio to linear:")
        for n in names:
            print(f"  {n:14s} {summary([r[n] for r in chosen])}")
        worth = np.exp(np.mean([np.log(r["grey"]) for r in chosen]) - np.mean([np.log(r["default"]) for r in chosen]))
        print(f"  image's worth (geometric-mean RMSE grey / RGB): {worth:.3f}")
    if args.sweep:
        sweep_table(rows, args.plot)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
        print(f"\nwrote {args.json}")


def _sweep_size(shape: tuple[int, int], spacing: float, target: float, scan_lines: bool) -> tuple[int, int]:
    """The working size with target spacing `target` (and the pixel cap of the pattern); >= 1e9: the native size."""
    return tuple(shape) if target >= 1e9 else working_size(shape, spacing, target, capped=scan_lines)


def sweep_table(rows: list[dict], plot: str | None) -> None:
    """Geometric-mean ratio per group against the target spacing (the working resolution)."""
    groups = sorted({r["group"] for r in rows})
    print("\n| group | " + " | ".join("full" if t == 1e9 else f"T={t:g} px" for t in SWEEP_TARGETS_PX) + " |")
    print("|---|" + "---|" * len(SWEEP_TARGETS_PX))
    curves = {}
    for g in groups:
        vals = [float(np.exp(np.mean([np.log(r["sweep"][str(t)]) for r in rows if r["group"] == g])))
                for t in SWEEP_TARGETS_PX]
        curves[g] = vals
        print(f"| {g} | " + " | ".join(f"{v:.3f}" for v in vals) + " |")
    if plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        xs = [t if t < 1e9 else 48 for t in SWEEP_TARGETS_PX]
        for g, vals in curves.items():
            ax.plot(xs, vals, marker="o", label=g)
        ax.axhline(1.0, color="grey", lw=0.8, ls="--")
        ax.set_xscale("log")
        ax.minorticks_off()
        ax.set_xticks(xs, [f"{t:g}" if t < 1e9 else "full" for t in SWEEP_TARGETS_PX])
        ax.set_xlabel("target sample spacing at the working size (px); 'full' = native size")
        ax.set_ylabel("RMSE / linear (geometric mean)")
        ax.set_title("Shared real frames: working resolution")
        ax.legend()
        fig.tight_layout()
        fig.savefig(plot, dpi=110)
        print(f"wrote {plot}")


if __name__ == "__main__":
    main()
