"""One model on every kind of synthetic input it should generalise to, through the default path: a ship check.

    python benchmarks/generalisation.py [--model PATH] [--frames 8] [--json OUT] [--against SHIPPED.json]

The mixed validation of training holds closed rooms and streets seen through the reference cameras at 256x320; a
model meant for any resolution, sensor and scene is judged here on the synthetic TEST split (never trained on), each
frame at its full size through `lipjax.inference.complete_frame` (the working-resolution rule, the default fill):

    rooms 480x640       50, 200, 1,000 and 5,000 uniform points; 200 points with a street through a window
                        (far views, lipjax.data.synthetic.far_view); 200 points at 0.7x and 1.4x the focal length
    streets 352x1216    HDL-64 and VLP-32 scans, 200 and 25,000 uniform points

Per setting it prints the geometric-mean RMSE ratio to the Delaunay linear fill (unsampled valid pixels; samples
drawn with seed 0), its wins, and the geometric mean over every frame of every setting. With `--against`, the
`--json` file of the shipped model's suite, it also prints the ship check that every lip-any run is judged by
(docs/training.md, rule 16): (a') the geometric mean over every frame <= SHIP_FACTOR x the shipped model's (its
unrounded value), (b') no setting's geometric mean over SETTING_FACTOR x the shipped model's; then the synthetic
tables decide, (c), run apart (`python -m experiments.nyu_200pts --methods PATH`, `experiments.kitti_dc`).
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
SHIP_FACTOR = 0.99  # (a'): a new model ships only if its suite is at least 1 % below the shipped model's
SETTING_FACTOR = 1.05  # (b'): and no setting more than 5 % worse than the shipped model's
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
    `cross_check` as in lipjax.inference.complete_at; without it the model's estimate itself, how models are
    compared: neither the check nor the mirror image that the default path adds on scan lines (rule 54)."""
    return ratios_to_linear(model, linear, sample, spec, (sample.rgb,), cross_check)[0]


def ratios_to_linear(model, linear, sample, spec, images, cross_check: bool = CROSS_CHECK) -> list[float]:
    """`ratio_to_linear` with each of `images` in place of the sample's own, the samples and the linear fill (which
    uses no image) computed once."""
    sparse = (sampler_from_spec(spec) if isinstance(spec, str) else spec)(sample, 0)
    keep = sample.valid & (sparse <= 0)

    def rmse(pred):
        return float(np.sqrt(np.mean((pred[keep] - sample.depth[keep]) ** 2)))

    completer, reference = get_completer(model, sparse=sparse), rmse(linear(sample.rgb, sparse))
    mirror = None if cross_check else False  # the default path, or the model alone
    return [rmse(complete_frame(completer, rgb, sparse, mirror=mirror, cross_check=cross_check)) / reference
            for rgb in images]


def geometric_mean(ratios) -> float:
    """Geometric mean of positive ratios."""
    return float(np.exp(np.log(np.asarray(ratios, np.float64)).mean()))


def ship_check(table: dict[str, list[float]], shipped: dict[str, list[float]]) -> tuple[bool, bool, list[str]]:
    """((a') holds, (b') holds, report lines) for the per-setting ratios `table` of a candidate against those of the
    shipped model (the `ratios` of its --json file), as the module doc says; the settings must be the same."""
    if set(table) != set(shipped):
        raise ValueError(f"--against: its settings {sorted(shipped)} are not this suite's {sorted(table)}; "
                         "run the shipped model's suite again with this script")
    every = geometric_mean(np.concatenate([table[k] for k in table]))
    bound = SHIP_FACTOR * geometric_mean(np.concatenate([shipped[k] for k in table]))
    worse = {k: geometric_mean(table[k]) / geometric_mean(shipped[k]) for k in table}
    worst = max(worse, key=worse.get)
    a, b = every <= bound, worse[worst] <= SETTING_FACTOR
    return a, b, [f"(a') suite {every:.6f} <= {SHIP_FACTOR} x shipped = {bound:.6f}: {'holds' if a else 'fails'}",
                  f"(b') worst setting {worst!r}: {worse[worst]:.3f} x shipped <= {SETTING_FACTOR}: "
                  f"{'holds' if b else 'fails'}"]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default=None, help="a model name or path (default: the default path's choice)")
    ap.add_argument("--frames", type=int, default=8, help="test frames per setting")
    ap.add_argument("--json", default=None, help="write the per-frame ratios here")
    ap.add_argument("--no-cross-check", dest="cross_check", action="store_false",
                    help="the model's estimate itself, without lipjax.crosscheck nor the mirror image on scan lines "
                         "(how model suites are compared)")
    ap.add_argument("--against", default=None, metavar="SHIPPED.json",
                    help="the shipped model's --json suite (same --frames, --no-cross-check): print the ship check")
    args = ap.parse_args(argv)
    shipped = None
    if args.against:
        with open(args.against) as f:
            doc = json.load(f)
        if (doc["frames"], doc["cross_check"]) != (args.frames, args.cross_check):
            ap.error(f"--against {args.against}: measured with --frames {doc['frames']}, cross_check "
                     f"{doc['cross_check']}; run this suite the same way")
        shipped = doc["ratios"]
    linear, table = get_completer("linear"), {}
    for name, kind, size, spec, variant in SETTINGS:
        samples = frames(kind, size, variant, args.frames)
        r = np.asarray([ratio_to_linear(args.model, linear, s, spec, args.cross_check) for s in samples])
        table[name] = r.tolist()
        print(f"{name:30s} geometric mean {geometric_mean(r):.3f}  wins {int((r < 1).sum())}/{len(r)}",
              flush=True)
    every = np.concatenate([np.asarray(v) for v in table.values()])
    print(f"\n{args.model or 'default model'}: geometric mean over {len(every)} frames of {len(table)} settings "
          f"{geometric_mean(every):.6f}, wins {int((every < 1).sum())}/{len(every)}")
    if shipped is not None:
        print("\n".join(ship_check(table, shipped)[2]))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"model": args.model, "frames": args.frames, "cross_check": args.cross_check,
                       "ratios": table}, f, indent=1)


if __name__ == "__main__":
    main()
