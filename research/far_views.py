"""Far views inside rooms: does the default model follow samples tens of metres away in a room, or reject them?

The model's own estimate is scored (`cross_check=False`): the default path's check against the linear fill
(lipjax.crosscheck) would mix that fill into what is measured here.

    python -m research.far_views [--model PATH] [--frames 12] [--points 200] [--size 480x640]

Rooms of the synthetic test split (never trained on), each once closed, as `render` gives it, and once with a window
onto a street (`MixedSyntheticDataset("test", far_view_prob=1)`, lipjax.data.synthetic.far_view: a rectangle of a
street render, 1-80 m, pasted into the room, its choices drawn from the frame's own stream, so every run sees the
same windows). The same number of uniform samples is drawn from each frame (seed 0). Through the default path at
the given size (`lipjax.inference.complete_frame`), the table gives per frame the RMSE ratio to the Delaunay linear
fill on the unsampled valid pixels, and the geometric mean and wins over the frames.

A closed room never shows the prox a far sample among near ones: the 228,000-image lip-any, 0.781x linear on the 12
closed rooms (wins 11), is 1.014x with their windows (wins 5) (research/README.md).
"""
from __future__ import annotations

import argparse

import numpy as np

from benchmarks.common import ratio_to_linear
from lipjax.data.synthetic.dataset import MixedSyntheticDataset
from lipjax.methods import get_completer


def run(model: str | None, frames: int, points: int, size: tuple[int, int]) -> dict[str, list[float]]:
    """{"closed": [...], "window": [...]}: per-room RMSE ratios to linear (`generalisation.ratio_to_linear`)."""
    closed = MixedSyntheticDataset("test", 2 * frames, *size)
    windowed = MixedSyntheticDataset("test", 2 * frames, *size, far_view_prob=1.0)
    linear, out = get_completer("linear"), {"closed": [], "window": []}
    for i in range(frames):
        for name, frame in (("closed", closed[2 * i]), ("window", windowed[2 * i])):
            out[name].append(ratio_to_linear(model, linear, frame, f"uniform:{points}", cross_check=False))
        print(f"{closed[2 * i].id}  closed {out['closed'][-1]:.3f}  window {out['window'][-1]:.3f}", flush=True)
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default=None, help="a model name or path (default: the default path's choice)")
    ap.add_argument("--frames", type=int, default=12)
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--size", default="480x640", help="HxW of the renders")
    args = ap.parse_args(argv)
    size = tuple(int(v) for v in args.size.lower().split("x"))
    table = run(args.model, args.frames, args.points, size)
    print(f"\n{args.frames} test rooms at {size[0]}x{size[1]}, {args.points} points, RMSE ratio to linear:")
    for name, ratios in table.items():
        r = np.asarray(ratios)
        print(f"  {name:7s} geometric mean {np.exp(np.log(r).mean()):.3f}  median {np.median(r):.3f}  "
              f"wins {int((r < 1).sum())}/{len(r)}")


if __name__ == "__main__":
    main()
