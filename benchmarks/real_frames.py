"""Per-frame RMSE ratios to a linear fill on the 15 shared real frames, at native size, through the default path;
and on the KITTI frames, the scores near the samples: at LiDAR points hidden from the input.

Run by hand (never a test; the frames are research-use data read from ../shared/realdata, never copied):

    python -m benchmarks.real_frames [--model NAME] [--realdata ../shared/realdata] [--json out.json]
                                     [--flip | --no-flip] [--sweep]
                                     [--plot docs/results/real_frames_working_res.png]
    python -m benchmarks.real_frames --hidden-only [--model NAME] [--json out.json]   # the KITTI checks alone

Frames at their native size: NYU v2 (3, 480x640), KITTI (3, 375x1242), Middlebury 2014 Motorcycle (1, 497x741),
lingbot (8, 480x640, raw consumer RGB-D depth). Inputs drawn from the valid ground truth with seed 0 and the frame
id (lipjax.data.sampling): 200 uniform points indoors; on KITTI the HDL-64 pattern (LidarSampler.hdl64, as
benchmarks/baselines.py draws it) and, in a second table, 30 % of the valid pixels. RMSE (m) on the unsampled valid
pixels. The reference is `linear` (Delaunay piecewise-linear, nearest outside the hull).

Columns: the default path (`lipjax complete` without flags: `get_completer(None, sparse)` picks the model and
`complete_frame` its working size), the same with a uniform grey image (the RGB guidance's worth: grey / RGB),
ip_basic and colorization. `--model` scores one model through the same path instead of the default choice;
`--flip` runs the path with flip averaging on every input (`lipjax complete --flip`; by default on scan lines
only) for the model and its grey run, `--no-flip` on none.
`--sweep` also runs the model at several target sample spacings (lipjax.resolution, with its pixel cap) and at the
native size ("full"), and plots the geometric-mean ratio against the working resolution.

Near the samples (issue 55: "never worse than linear"), on the 3 KITTI frames with their HDL-64 input, three checks
of the default path (`lipjax.complete`, with `--model` and `--flip` as above), `linear` and `ip_basic`, each as RMSE
and MAE (m) and the default path's ratio to linear:

    dense ground truth   the whole input; scored on the unsampled valid ground-truth pixels (the table above)
    hidden points        benchmarks.common.HIDDEN_FRACTION (20 %) of the input's points, drawn at random by
                         `example_rng(0, frame id, "hidden")` (seed 0), removed from the input; the rest (80 %)
                         completed, scored on the hidden points alone (their depth: the ground truth there)
    hidden beams         every HIDDEN_BEAM_EVERY-th (4th) scan line of the input removed: the beams present in the
                         input ranked from the top (highest elevation) down, ranks 3, 7, 11, ... hidden, never the
                         lowest beam, so each hidden line lies between two kept ones; scored on its points alone

The input carries no beam labels, so `beam_index` derives them from the geometry that drew them: every input point
is back-projected with the frame's intrinsics into the LiDAR frame of LidarSampler.hdl64 (KITTI's mount), and its
elevation is binned to the nearest of the 64 beam elevations (LidarSampler.angles and the rounding of
LidarSampler.__call__): the sampler keeps only pixels within half a beam spacing of a beam, so the labels are
exactly the beams that drew the points.
"""
from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from benchmarks.common import (GREY, REALDATA, frames_and_inputs, geometric_mean, hide_points, load_kitti,
                               rmse_unsampled)
from lipjax.data.frame import Frame
from lipjax.data.sampling import LidarSampler
from lipjax.inference import complete_at, complete_frame, frame_size
from lipjax.inputs import is_lidar_pattern
from lipjax.methods import complete, get_completer
from lipjax.resolution import sample_spacing_px, working_size

SWEEP_TARGETS_PX = (6.0, 8.0, 11.0, 16.0, 22.0, 32.0, 1e9)
KITTI_LIDAR = LidarSampler.hdl64()  # the KITTI input's pattern (frames_and_inputs)
HIDDEN_BEAM_EVERY = 4  # every 4th scan line hidden
HIDDEN_METHODS = ("linear", "ip_basic")
CHECKS = ("dense ground truth", "hidden points", "hidden beams")


def summary(ratios: list[float]) -> str:
    r = np.asarray(ratios)
    gm = np.exp(np.log(r).mean())
    return f"wins {int((r < 1).sum())}/{len(r)}, median {np.median(r):.3f}, geometric mean {gm:.3f}"


def beam_index(frame: Frame, sparse: np.ndarray, sampler: LidarSampler = KITTI_LIDAR) -> np.ndarray:
    """(H, W) int64: the beam (0 = the lowest) that drew each input point of `sparse`, -1 where there is none.

    As `sampler` draws them: the valid ground-truth pixel back-projected into the LiDAR frame (LidarSampler.angles),
    its elevation rounded to the nearest beam elevation. The sampler keeps a pixel only within half a beam spacing
    of a beam, so every input point gets the beam that drew it."""
    idx, elevation, _, _ = sampler.angles(frame)
    beams = np.radians(sampler.beam_elevations_deg())
    spacing = (beams[-1] - beams[0]) / (sampler.beams - 1)
    label = np.full(sparse.size, -1, np.int64)
    label[idx] = np.clip(np.rint((elevation - beams[0]) / spacing), 0, sampler.beams - 1)
    label = np.where(sparse.reshape(-1) > 0, label, -1).reshape(sparse.shape)
    if np.any((sparse > 0) & (label < 0)):
        raise ValueError(f"{frame.id}: input points off the valid ground truth, so off the sampler's pixels")
    return label


def hide_beams(beams: np.ndarray, sparse: np.ndarray,
               every: int = HIDDEN_BEAM_EVERY) -> tuple[np.ndarray, np.ndarray, int, int]:
    """(input without the hidden beams, hidden mask, beams in the input, beams hidden): the beams present ranked
    from the top down, ranks every-1, 2 every-1, ... hidden, the lowest beam never (each hidden line lies between
    two kept ones)."""
    present = np.unique(beams[beams >= 0])[::-1]  # the highest elevation first
    hidden_beams = present[every - 1:-1:every]
    hidden = np.isin(beams, hidden_beams) & (sparse > 0)
    return np.where(hidden, 0.0, sparse).astype(np.float32), hidden, len(present), len(hidden_beams)


def errors(pred: np.ndarray, frame: Frame, mask: np.ndarray) -> tuple[float, float]:
    """(RMSE, MAE) in metres of `pred` against the ground truth on `mask`."""
    e = pred[mask] - frame.depth[mask]
    return float(np.sqrt(np.mean(e ** 2))), float(np.mean(np.abs(e)))


def hidden_checks(kitti: list[tuple[Frame, np.ndarray]], model, flip) -> list[dict]:
    """The checks near the samples (module docstring) on each (KITTI frame, its HDL-64 input): one row per frame
    and check, with (RMSE, MAE) of "default" and of each of HIDDEN_METHODS."""
    methods = [get_completer(m) for m in HIDDEN_METHODS]
    rows = []
    for frame, sparse in kitti:
        beams = beam_index(frame, sparse)
        kept, hidden, n_beams, n_hidden = hide_beams(beams, sparse)
        inputs = {"dense ground truth": (sparse, frame.valid & (sparse <= 0), ""),
                  "hidden points": (*hide_points(frame, sparse), ""),
                  "hidden beams": (kept, hidden, f"{n_hidden} of {n_beams} beams")}
        for check, (given, mask, note) in inputs.items():
            completer = get_completer(model, sparse=given)
            row = {"frame": frame.id, "check": check, "input_points": int((given > 0).sum()),
                   "scored_points": int(mask.sum()), "note": note, "model": completer.name,
                   "working_size": list(frame_size(completer, given)),
                   "default": errors(complete(frame.rgb, given, model, flip=flip), frame, mask)}
            for m in methods:
                row[m.name] = errors(m(frame.rgb, given), frame, mask)
            rows.append(row)
            print(f"{frame.id:24s} {check:19s} {note:16s} input {row['input_points']:6d} scored "
                  f"{row['scored_points']:6d}  " + "  ".join(
                      f"{n} {row[n][0]:.3f}/{row[n][1]:.3f} m" for n in ("default", *HIDDEN_METHODS)), flush=True)
    return rows


def hidden_table(rows: list[dict]) -> None:
    """The checks near the samples as a Markdown table, and per check the geometric means over the frames."""
    other = [m for m in HIDDEN_METHODS if m != "linear"]
    paths = sorted({f"{r['model']} at {r['working_size'][0]}x{r['working_size'][1]}" for r in rows})
    print(f"\ndefault path (lipjax.complete): {', '.join(paths)}; RMSE and MAE in metres on the scored points\n")
    print("| frame | check | input points | scored points | default RMSE m | linear RMSE m | RMSE ratio | "
          "default MAE m | linear MAE m | MAE ratio | " + " | ".join(f"{m} RMSE m | {m} MAE m" for m in other) + " |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|" + "---:|---:|" * len(other))
    for r in rows:
        d, lin = r["default"], r["linear"]
        check = r["check"] + (f" ({r['note']})" if r["note"] else "")
        print(f"| {r['frame'].removeprefix('realdata/')} | {check} | {r['input_points']} | {r['scored_points']} | "
              f"{d[0]:.3f} | {lin[0]:.3f} | {d[0] / lin[0]:.3f} | {d[1]:.3f} | {lin[1]:.3f} | {d[1] / lin[1]:.3f} | "
              + " | ".join(f"{r[m][0]:.3f} | {r[m][1]:.3f}" for m in other) + " |")
    print("\nPer check, over the KITTI frames: geometric mean of the ratio to linear (wins: frames below 1)\n")
    print("| check | default RMSE | default MAE | " + " | ".join(f"{m} RMSE | {m} MAE" for m in other) + " |")
    print("|---|---:|---:|" + "---:|---:|" * len(other))
    for check in CHECKS:
        chosen = [r for r in rows if r["check"] == check]
        cells = []
        for name in ("default", *other):
            for k in (0, 1):
                ratios = [r[name][k] / r["linear"][k] for r in chosen]
                cells.append(f"{geometric_mean(ratios):.3f} (wins {sum(x < 1 for x in ratios)}/{len(ratios)})")
        print(f"| {check} | " + " | ".join(cells) + " |")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", default=None, help="a model name or path (default: the default path's choice)")
    ap.add_argument("--realdata", default=REALDATA)
    ap.add_argument("--json", default=None,
                    help="write the rows here (with --hidden-only: the rows of the checks near the samples)")
    ap.add_argument("--flip", action=argparse.BooleanOptionalAction,
                    help="the path with (--flip) or without (--no-flip) flip averaging on every input")
    ap.add_argument("--sweep", action="store_true", help="also sweep the working resolution")
    ap.add_argument("--plot", default=None, help="with --sweep: write the ratio-vs-resolution picture here")
    ap.add_argument("--classical", default="ip_basic,colorization", help="comma-separated classical methods")
    ap.add_argument("--hidden-only", action="store_true",
                    help="only the KITTI checks near the samples (hidden points, hidden beams), not the 15 frames")
    args = ap.parse_args(argv)
    root = os.path.abspath(args.realdata)
    if args.hidden_only:
        print("Near the samples: the KITTI frames with their HDL-64 input")
        hidden = hidden_checks([(s, KITTI_LIDAR(s, 0)) for s in load_kitti(os.path.join(root, "kitti"))],
                               args.model, args.flip)
        hidden_table(hidden)
        _write_json(args.json, hidden)
        return
    inputs = frames_and_inputs(root)
    rows = frame_rows(inputs, args)
    frames_table(rows, [m for m in args.classical.split(",") if m])
    if args.sweep:
        sweep_table(rows, args.plot)
    print("\nNear the samples: the KITTI frames with their HDL-64 input")
    hidden = hidden_checks([(s, sparse) for group, s, sparse, _ in inputs if group == "kitti-hdl64"],
                           args.model, args.flip)
    hidden_table(hidden)
    for r in rows:  # the checks ride on their frame's HDL-64 row
        if r["group"] == "kitti-hdl64":
            r["near_samples"] = [h for h in hidden if h["frame"] == r["frame"]]
    _write_json(args.json, rows)


def _write_json(path: str | None, doc) -> None:
    if path:
        with open(path, "w") as f:
            json.dump(doc, f, indent=1)
        print(f"\nwrote {path}")


def frame_rows(inputs, args) -> list[dict]:
    """One row per (frame, input) of `frames_and_inputs`: RMSE ratios to linear of the default path, its grey run
    and the --classical methods (and the --sweep)."""
    linear, classical = get_completer("linear"), [get_completer(m) for m in args.classical.split(",") if m]
    rows = []
    for group, frame, sparse, input_name in inputs:
        completer = get_completer(args.model, sparse=sparse)
        grey = np.full_like(frame.rgb, GREY)
        ref = rmse_unsampled(linear(frame.rgb, sparse), frame, sparse)
        t0 = time.perf_counter()
        pred = complete_frame(completer, frame.rgb, sparse, flip=args.flip)
        ms = 1e3 * (time.perf_counter() - t0)
        row = {"group": group, "frame": frame.id, "input": input_name, "size": list(frame.shape),
               "model": completer.name, "working_size": list(frame_size(completer, sparse)),
               "linear_rmse_m": ref, "default": rmse_unsampled(pred, frame, sparse) / ref,
               "grey": rmse_unsampled(complete_frame(completer, grey, sparse, flip=args.flip), frame, sparse) / ref,
               "ms": ms}
        for method in classical:
            row[method.name] = rmse_unsampled(method(frame.rgb, sparse), frame, sparse) / ref
        if args.sweep:
            spacing, lines = sample_spacing_px(sparse), is_lidar_pattern(sparse)
            row["sweep"] = {str(t): rmse_unsampled(complete_at(completer, frame.rgb, sparse, _sweep_size(
                frame.shape, spacing, t, lines), flip=args.flip), frame, sparse) / ref for t in SWEEP_TARGETS_PX}
        rows.append(row)
        print(f"{frame.id:32s} {input_name:20s} {row['model']:22s} work {row['working_size']} "
              f"linear {ref:.3f} m  default {row['default']:.3f}  grey {row['grey']:.3f}  "
              + "  ".join(f"{m.name} {row[m.name]:.3f}" for m in classical) + f"  {ms:.0f} ms", flush=True)
    return rows


def frames_table(rows: list[dict], classical: list[str]) -> None:
    """The per-frame table of RMSE ratios to linear, and the summaries over the 15 frames."""
    names = ["default", "grey"] + classical
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
