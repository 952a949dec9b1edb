"""Self-supervised adaptation (lipjax.train.adapt.adapt_folder) on the 15 shared real frames' sparse inputs alone,
scored on their dense ground truth through the default path.

Run by hand (never a test; the frames are research-use data read from ../shared/realdata, never copied: their RGB
and sparse inputs are written to a temporary folder, deleted at the end):

    python -m benchmarks.adapt [--steps 150] [--batch-size 4] [--hide 0.2] [--realdata ../shared/realdata]

The frames and inputs are benchmarks/real_frames.py's (benchmarks.common.frames_and_inputs, seed 0): 200 uniform
points on the 12 indoor frames (NYU v2 3, Middlebury 1, lingbot 8), the HDL-64 pattern on the 3 KITTI frames. Each
adaptation starts from the default model and trains on a folder of rgb/ and sparse/ (.npy metres) without depth/:
`--steps` steps of `--batch-size` 128x160 crops at the working size (lipjax.train.adapt.ADAPT_DATA: the shipped fast
models' augmentation; a folder of fewer frames trains on all of them a step), `--hide` of each frame's samples hidden
from its input and the loss at them alone (whole scan-line segments on KITTI). The augmentation and learning rate
were chosen on (a)'s scores (lipjax.train.adapt), which makes (a) the optimistic one. Its validation split (val/)
is its own training frames with a fixed hidden draw, so the two validation numbers printed are in-sample (training
hides other samples each epoch, these among them): a model is scored here on the dense ground truth, never on them.
Every adaptation is kept as trained (keep="last"); the line says what keep="best" would have exported.

    (a) all 15 frames: adapt on all, score all (the frames it adapted on: "transductive")
    (b) by sensor: adapt on some frames of a sensor, score the others (lingbot 0-3 / 4-7, KITTI 2 / 1, NYU v2 2 / 1):
        does it learn the sensor, or the frames?

Scores: the RMSE ratio to the linear fill on the unsampled valid pixels (benchmarks.common.ratio_to_linear: the
default path, `lipjax.complete` with the model given), per frame for the adapted model and the default model (the
unadapted start); summaries as benchmarks/real_frames.py gives them (wins below 1, median, geometric mean). The
time of each adaptation is wall-clock and this process's CPU time (all threads), compilation included.
"""
from __future__ import annotations

import argparse
import contextlib
import io
import os
import pathlib
import tempfile
import time

import cv2
import numpy as np

from benchmarks.common import REALDATA, frames_and_inputs, geometric_mean, ratio_to_linear
from lipjax.methods import get_completer
from lipjax.shipped import DEFAULT_MODEL
from lipjax.train.adapt import adapt_folder

SPLITS = (  # (name, the frames adapted on, the frames scored): ids without "realdata/"
    ("lingbot", [f"lingbot/{i}" for i in range(4)], [f"lingbot/{i}" for i in range(4, 8)]),
    ("kitti", ["kitti/0000000005", "kitti/0000000050"], ["kitti/0000000100"]),
    ("nyu_v2", ["nyu_v2/00000", "nyu_v2/00050"], ["nyu_v2/00100"]),
)


def write_folder(root: pathlib.Path, frames) -> None:
    """train/ and val/ (the same frames), each rgb/<i>.png and sparse/<i>.npy (metres): no depth/."""
    for split in ("train", "val"):
        for d in ("rgb", "sparse"):
            (root / split / d).mkdir(parents=True)
        for i, (_, frame, sparse, _) in enumerate(frames):
            cv2.imwrite(str(root / split / "rgb" / f"{i:02d}.png"), cv2.cvtColor(frame.rgb, cv2.COLOR_RGB2BGR))
            np.save(root / split / "sparse" / f"{i:02d}.npy", sparse.astype(np.float32))


def adapt(frames, name: str, tmp: pathlib.Path, args) -> str:
    """Adapts the default model on `frames`; prints the run's last line and its time; returns the model's path."""
    folder, out = tmp / f"{name}-frames", tmp / "models" / name
    write_folder(folder, frames)
    wall, cpu = time.perf_counter(), time.process_time()
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        adapt_folder(folder, out, steps=args.steps, batch_size=args.batch_size, hide=args.hide, keep="last",
                     workdir=tmp / f"{name}-run", progress=False, num_workers=0)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    last = printed.getvalue().strip().splitlines()[-1]
    best = "the start" if "WORSE than" in last else "the adapted model"
    print(f"adapted on {len(frames)} frame(s) [{name}]: {wall / 60:.1f} min wall, {cpu / 60:.1f} CPU min; "
          f"keep best would export {best}\n  {last}", flush=True)
    return str(out)


def scores(frames, models: dict[str, str | None]) -> dict[str, list[float]]:
    """RMSE ratio to linear of each of `models` (label -> model name or path) on each frame, printed a line a frame."""
    linear = get_completer("linear")
    out: dict[str, list[float]] = {label: [] for label in models}
    for _, frame, sparse, input_name in frames:
        given = lambda s, seed, sparse=sparse: sparse  # noqa: E731 - the frame's own input, as a sampler
        for label, model in models.items():
            out[label].append(ratio_to_linear(model, linear, frame, given))
        print(f"  {frame.id.removeprefix('realdata/'):20s} {input_name:11s} "
              + "  ".join(f"{label} {out[label][-1]:.3f}" for label in models), flush=True)
    return out


def summary(ratios: list[float]) -> str:
    r = np.asarray(ratios)
    return f"wins {int((r < 1).sum())}/{len(r)}, median {np.median(r):.3f}, geometric mean {geometric_mean(r):.3f}"


def report(title: str, ratios: dict[str, list[float]]) -> None:
    print(f"{title}:")
    for label, values in ratios.items():
        print(f"  {label:9s} {summary(values)}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=150)
    ap.add_argument("--batch-size", type=int, default=4)
    ap.add_argument("--hide", type=float, default=0.2)
    ap.add_argument("--realdata", default=REALDATA)
    args = ap.parse_args(argv)
    frames = [f for f in frames_and_inputs(os.path.abspath(args.realdata)) if f[0] != "kitti-30pct"]
    by_id = {f[1].id.removeprefix("realdata/"): f for f in frames}
    print(f"{len(frames)} frames; from {DEFAULT_MODEL}: {args.steps} steps of {args.batch_size} 128x160 crops at the "
          f"working size, {args.hide:g} of the samples hidden; ratios: RMSE / linear's on the dense ground truth")
    with tempfile.TemporaryDirectory(prefix="lipjax-adapt-") as tmp:
        tmp = pathlib.Path(tmp)
        print("\n(a) adapted on all 15 frames, scored on them")
        model = adapt(frames, "all", tmp, args)
        report("(a) all 15 frames", scores(frames, {"adapted": model, "default": None}))
        pooled: dict[str, list[float]] = {"adapted": [], "default": []}
        for name, adapt_ids, score_ids in SPLITS:
            print(f"\n(b) {name}: adapted on {', '.join(adapt_ids)}; scored on {', '.join(score_ids)}")
            model = adapt([by_id[i] for i in adapt_ids], name, tmp, args)
            got = scores([by_id[i] for i in score_ids], {"adapted": model, "default": None})
            for label in pooled:
                pooled[label] += got[label]
        report("\n(b) the 6 frames scored by models adapted on other frames of their sensor", pooled)


if __name__ == "__main__":
    main()
