"""Frames per second of the procedural renderer (lipjax.data.synthetic), one process, one core.

Run by hand (not a test); pin to one core so the number means "per core":

    taskset -c 0 python -m benchmarks.synthetic_fps [--frames 40] [--split train]

Prints frames/s for indoor and outdoor at 256x320 and 128x160: mean over `--frames` consecutive indices
(different scenes) after 2 warm-up frames, whole `render()` calls (scene building, ray casting, shading,
camera model, Frame construction). Two numbers: wall-clock frames/s, and frames/s of CPU time
(time.process_time): on a machine shared with other jobs the process is descheduled part of the time, and
the CPU-time figure is then the better estimate of what one dedicated core delivers. The load average is
printed so the numbers can be judged.
"""
from __future__ import annotations

import argparse
import os
import time

# numpy's elementwise work is single-threaded anyway; keep any BLAS pool from spreading over cores.
for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

from lipjax.data import synthetic

SIZES = ((256, 320), (128, 160))


def measure(kind: str, split: str, height: int, width: int, frames: int, start: int) -> tuple[float, float, float]:
    """-> (wall-clock frames/s, CPU-time frames/s, slowest frame in CPU ms) over `frames` consecutive indices."""
    for i in range(2):
        synthetic.render(kind, split, start + frames + i, height, width)
    worst = 0.0
    t0, c0 = time.perf_counter(), time.process_time()
    for i in range(start, start + frames):
        c = time.process_time()
        synthetic.render(kind, split, i, height, width)
        worst = max(worst, time.process_time() - c)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return frames / wall, frames / cpu, worst * 1e3


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--split", default="train", choices=synthetic.SPLITS)
    ap.add_argument("--start", type=int, default=0)
    args = ap.parse_args(argv)
    affinity = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else "?"
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"lipjax.data.synthetic: {args.frames} frames per row, split={args.split}, CPUs allowed: {affinity}, "
          f"machine: {os.cpu_count()} CPUs, load average {load:.2f}")
    for height, width in SIZES:
        for kind in synthetic.SYNTHETIC_KINDS:
            fps, cpu_fps, worst = measure(kind, args.split, height, width, args.frames, args.start)
            print(f"{kind:8s} {height:4d}x{width:<4d} {fps:7.1f} frames/s wall  {cpu_fps:7.1f} frames/s CPU time"
                  f"   (slowest frame {worst:6.1f} ms CPU)")


if __name__ == "__main__":
    main()
