"""One model on every kind of synthetic input it should generalise to, through the default path: a ship check.

    python -m benchmarks.generalisation [--model PATH] [--frames 8] [--json OUT] [--against SHIPPED.json]

The mixed validation of training holds closed rooms and streets seen through the reference cameras at 256x320; a
model meant for any resolution, sensor and scene is judged here on the synthetic TEST split (never trained on), each
frame at its full size through `lipjax.inference.complete_frame` (the working-resolution rule, the default fill):

    rooms 480x640       50, 200, 1,000 and 5,000 uniform points; 200 points with a street through a window
                        (far views, lipjax.data.synthetic.far_view); 200 points at 0.7x and 1.4x the focal length
    streets 352x1216    HDL-64 and VLP-32 scans, 200 and 25,000 uniform points

Per setting it prints the geometric-mean RMSE ratio to the Delaunay linear fill (unsampled valid pixels; samples
drawn with seed 0), its wins, and the geometric mean over every frame of every setting. With `--against`, the
`--json` file of the shipped model's suite, it also prints the ship check that every lip-any run is judged by
(docs/decisions/0008-lip-any-ship-check.md): (a') the geometric mean over every frame <= SHIP_FACTOR x the shipped
model's (its unrounded value), (b') no setting's geometric mean over SETTING_FACTOR x the shipped model's; then the
synthetic tables decide, (c), run apart (`python -m experiments.nyu_200pts --methods PATH`, `experiments.kitti_dc`).
"""
from __future__ import annotations

import argparse
import json

import numpy as np

from benchmarks.common import SETTINGS, frames, geometric_mean, ratio_to_linear
from lipjax.methods import get_completer

SHIP_FACTOR = 0.99  # (a'): a new model ships only if its suite is at least 1 % below the shipped model's
SETTING_FACTOR = 1.05  # (b'): and no setting more than 5 % worse than the shipped model's


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
                    help="the model's estimate itself, without lipjax.crosscheck nor the flipped frame on scan lines "
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
        test_frames = frames(kind, size, variant, args.frames)
        r = np.asarray([ratio_to_linear(args.model, linear, s, spec, args.cross_check) for s in test_frames])
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
