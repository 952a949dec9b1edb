"""Frames/s of `lipjax complete` on a folder against the model's single-frame rate (issue 23: target ratio >= 0.8).

Run by hand (never a test):

    python -m benchmarks.folder_speed [--frames 100] [--model NAME] [--repeats 5] [--threads N] [--keep DIR]

Writes --frames synthetic KITTI-size frames (outdoor test renders at 352x1216 with the HDL-64 scan pattern,
lipjax.data.synthetic.render and lipjax.data.sampling.LidarSampler.hdl64) into a temporary folder as KITTI ships
them (rgb/NNNNNN.png, depth/NNNNNN.png 16-bit at 256 per metre), then, in one process:

  single  lipjax.inference.complete_frame on the first frame, warm: the median of --repeats calls after one that
          compiles. That is the model's own rate: resizes, host fill and solver, nothing read or written.
  folder  the command `lipjax complete --rgb rgb/ --depth depth/ --depth-scale 256 --out out/` (lipjax.cli.main,
          in this process): PNG decoding, the model, the support mask and 16-bit PNG writes; the frames/s its
          summary line prints, over the whole command. The model is already compiled by `single` (one executable
          per shape, in memory), as it is after the first frame of a long folder.

It prints both rates, their ratio and the load average (other processes on the cores slow both runs, not always
equally). --threads N pins the process to N cores first (lipjax.utils.limit_cpu_threads, `lipjax complete
--threads N`).
"""
from __future__ import annotations

import argparse
import contextlib
import io
import os
import re
import statistics
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

from lipjax.data.folder import read_frame
from lipjax.data.sampling import LidarSampler
from lipjax.data.synthetic import render
from lipjax.cli import main as lipjax_main
from lipjax.inference import complete_frame, frame_size
from lipjax.methods import get_completer
from lipjax.utils import enable_compilation_cache, limit_cpu_threads

HEIGHT, WIDTH, PNG_SCALE = 352, 1216, 256.0


def write_frames(root: Path, count: int) -> None:
    """rgb/ and depth/ PNGs of outdoor test frames 0 .. count-1 (depth: the HDL-64 pattern, 1/256 m steps)."""
    for sub in ("rgb", "depth"):
        (root / sub).mkdir(parents=True, exist_ok=True)
    if all((root / sub / f"{i:06d}.png").exists() for sub in ("rgb", "depth") for i in range(count)):
        return  # kept from an earlier run (--keep)
    sampler = LidarSampler.hdl64()
    for i in range(count):
        frame = render("outdoor", "test", i, HEIGHT, WIDTH)
        sparse = sampler(frame, 0)
        cv2.imwrite(str(root / "rgb" / f"{i:06d}.png"), frame.rgb[..., ::-1])
        cv2.imwrite(str(root / "depth" / f"{i:06d}.png"), np.round(sparse * PNG_SCALE).astype(np.uint16))


def single_frame_ms(completer, rgb: np.ndarray, sparse: np.ndarray, repeats: int) -> float:
    """Median ms of complete_frame on one frame, after one untimed call (the compilation)."""
    complete_frame(completer, rgb, sparse)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        complete_frame(completer, rgb, sparse)
        times.append(1000 * (time.perf_counter() - t0))
    return statistics.median(times)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=100)
    ap.add_argument("--model", default=None, help="default: the model lipjax complete picks (the outdoor default)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--keep", default=None, metavar="DIR",
                    help="write the frames and outputs here, and keep them (frames already there are reused)")
    args = ap.parse_args(argv)
    if args.threads:
        limit_cpu_threads(args.threads)
    enable_compilation_cache()
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(args.keep or tmp)
        t0 = time.perf_counter()
        write_frames(root, args.frames)
        print(f"{args.frames} frames {WIDTH}x{HEIGHT} written in {time.perf_counter() - t0:.1f} s to {root}")
        rgb, sparse = read_frame(root / "rgb" / "000000.png", root / "depth" / "000000.png", PNG_SCALE)
        completer = get_completer(args.model, sparse=sparse)
        h, w = frame_size(completer, sparse)
        ms = single_frame_ms(completer, rgb, sparse, args.repeats)
        command = ["complete", "--rgb", str(root / "rgb"), "--depth", str(root / "depth"), "--depth-scale", "256",
                   "--out", str(root / "out")] + (["--model", args.model] if args.model else [])
        stderr = io.StringIO()
        with contextlib.redirect_stderr(stderr):
            assert lipjax_main(command) == 0, stderr.getvalue()
        summary = stderr.getvalue().strip().splitlines()[-1]
        single, folder = 1000 / ms, float(re.search(r"([\d.]+) frames/s", summary).group(1))
        print(f"model {completer.name} at {w}x{h}; load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
        print(f"single frame (complete_frame, warm): {ms:.0f} ms = {single:.2f} frames/s")
        print(f"folder (lipjax {' '.join(command[:1] + command[1:])}):\n  {summary}")
        print(f"ratio folder / single: {folder / single:.2f} (target >= 0.8)")


if __name__ == "__main__":
    main()
