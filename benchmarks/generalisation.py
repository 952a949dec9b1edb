"""One model on every kind of synthetic input it should generalise to, through the default path: a ship check.

    python benchmarks/generalisation.py [--model PATH] [--frames 8] [--json OUT]

The mixed validation of training holds closed rooms and streets seen through the reference cameras at 256x320; a
model meant for any resolution, sensor and scene is judged here on the synthetic TEST split (never trained on), each
frame at its full size through `lipjax.inference.complete_frame` (the working-resolution rule, the default fill):

    rooms 480x640       50, 200, 1,000 and 5,000 uniform points; 200 points with a street through a window
                        (far views, lipjax.data.synthetic.far_view); 200 points at 0.7x and 1.4x the focal length
    streets 352x1216    HDL-64 and VLP-32 scans, 200 and 25,000 uniform points

Per setting it prints the geometric-mean RMSE ratio to the Delaunay linear fill (unsampled valid pixels; samples
drawn with seed 0), its wins, and the geometric mean over every frame of every setting.
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
from lipjax.data.synthetic.dataset import MixedSyntheticDataset  # noqa: E402
from lipjax.inference import CROSS_CHECK, complete_frame  # noqa: E402
from lipjax.methods import get_completer  # noqa: E402

ROOM, STREET = (480, 640), (352, 1216)
SETTINGS = (  # (name, scene kind, size, sampler spec, variant)
    ("rooms 50 points", "indoor", ROOM, "uniform:50", None),
    ("rooms 200 points", "indoor", ROOM, "uniform:200", None),
    ("rooms 1000 points", "indoor", ROOM, "uniform:1000", None),
    ("rooms 5000 points", "indoor", ROOM, "uniform:5000", None),
    ("rooms 200 points, far view", "indoor", ROOM, "uniform:200", "far_view"),
    ("rooms 200 points, focal 0.7x", "indoor", ROOM, "uniform:200", 0.7),
    ("rooms 200 points, focal 1.4x", "indoor", ROOM, "uniform:200", 1.4),
    ("streets HDL-64", "outdoor", STREET, "lidar:hdl64", None),
    ("streets VLP-32", "outdoor", STREET, "lidar:vlp32", None),
    ("streets 200 points", "outdoor", STREET, "uniform:200", None),
    ("streets 25000 points", "outdoor", STREET, "uniform:25000", None),
)


def frames(kind: str, size: tuple[int, int], variant, n: int):
    """The setting's n test frames."""
    if variant == "far_view":
        rooms = MixedSyntheticDataset("test", 2 * n, *size, far_view_prob=1.0)
        return [rooms[2 * i] for i in range(n)]
    focal = (variant, variant) if isinstance(variant, float) else (1.0, 1.0)
    return list(SyntheticDataset(kind, "test", size=n, height=size[0], width=size[1], focal_range=focal))


def ratio_to_linear(model, linear, sample, spec, cross_check: bool = CROSS_CHECK) -> float:
    """RMSE of `model` (name or path; None: the default path's choice) over that of `linear`, on the unsampled valid
    pixels, with the samples of `spec` (a sampler or its spec string, lipjax.data.sampling) drawn with seed 0;
    `cross_check` as in lipjax.inference.complete_at."""
    return ratios_to_linear(model, linear, sample, spec, (sample.rgb,), cross_check)[0]


def ratios_to_linear(model, linear, sample, spec, images, cross_check: bool = CROSS_CHECK) -> list[float]:
    """`ratio_to_linear` with each of `images` in place of the sample's own, the samples and the linear fill (which
    uses no image) computed once."""
    sparse = (sampler_from_spec(spec) if isinstance(spec, str) else spec)(sample, 0)
    keep = sample.valid & (sparse <= 0)

    def rmse(pred):
        return float(np.sqrt(np.mean((pred[keep] - sample.depth[keep]) ** 2)))

    completer, reference = get_completer(model, sparse=sparse), rmse(linear(sample.rgb, sparse))
    return [rmse(complete_frame(completer, rgb, sparse, cross_check=cross_check)) / reference for rgb in images]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default=None, help="a model name or path (default: the default path's choice)")
    ap.add_argument("--frames", type=int, default=8, help="test frames per setting")
    ap.add_argument("--json", default=None, help="write the per-frame ratios here")
    ap.add_argument("--no-cross-check", dest="cross_check", action="store_false",
                    help="the model's estimate itself, without lipjax.crosscheck (how model suites are compared)")
    args = ap.parse_args(argv)
    linear, table = get_completer("linear"), {}
    for name, kind, size, spec, variant in SETTINGS:
        samples = frames(kind, size, variant, args.frames)
        r = np.asarray([ratio_to_linear(args.model, linear, s, spec, args.cross_check) for s in samples])
        table[name] = r.tolist()
        print(f"{name:30s} geometric mean {np.exp(np.log(r).mean()):.3f}  wins {int((r < 1).sum())}/{len(r)}",
              flush=True)
    every = np.concatenate([np.asarray(v) for v in table.values()])
    print(f"\n{args.model or 'default model'}: geometric mean over {len(every)} frames of {len(table)} settings "
          f"{np.exp(np.log(every).mean()):.4f}, wins {int((every < 1).sum())}/{len(every)}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"model": args.model, "frames": args.frames, "cross_check": args.cross_check,
                       "ratios": table}, f, indent=1)


if __name__ == "__main__":
    main()
