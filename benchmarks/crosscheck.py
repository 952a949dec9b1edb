"""The default path with and without its check against the linear fill (lipjax.crosscheck), on synthetic frames.

    python -m benchmarks.crosscheck [--model lip-any] [--frames 8] [--json OUT] [--only TEXT]

The settings of benchmarks/generalisation.py that the check applies to (100 or more scattered samples; the scan-line
settings are unchanged by construction), and two where the model does not fit its input: lip-fast-outdoor (trained
on streets only) on rooms at 480x640 with 200 points, and --model on rooms with dense depth with holes (`holes:0.3`;
dense maps are not checked (docs/decisions/0016-dense-input-not-checked.md), so both columns are equal there). Per
setting: the geometric-mean RMSE ratio to the Delaunay linear fill of the plain path (`cross_check=False`) and of the
checked one, and their wins. The rules that adopted the check, and their numbers: docs/decisions/0013 to 0016.
"""
from __future__ import annotations

import argparse
import json

import numpy as np

from benchmarks.common import ROOM, SETTINGS, frames, ratio_to_linear
from lipjax.crosscheck import MIN_SAMPLES
from lipjax.methods import get_completer


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default="lip-any", help="a model name or path")
    ap.add_argument("--frames", type=int, default=8, help="test frames per setting")
    ap.add_argument("--json", default=None, help="write the per-frame ratios here")
    ap.add_argument("--only", default="", help="run only the settings whose name holds this text")
    args = ap.parse_args(argv)
    settings = [(name, args.model, kind, size, spec, variant) for name, kind, size, spec, variant in SETTINGS
                if not spec.startswith("lidar") and int(spec.split(":")[1]) >= MIN_SAMPLES]
    settings += [("rooms 200 points, street model", "lip-fast-outdoor", "indoor", ROOM, "uniform:200", None),
                 ("rooms, holes (not checked)", args.model, "indoor", ROOM, "holes:0.3", None)]
    settings = [s for s in settings if args.only in s[0]]
    linear, table = get_completer("linear"), {}
    print(f"{'setting':34s} {'model':18s} plain (wins)   checked (wins)")
    for name, model, kind, size, spec, variant in settings:
        test_frames = frames(kind, size, variant, args.frames)
        r = np.asarray([[ratio_to_linear(model, linear, s, spec, check) for check in (False, True)]
                        for s in test_frames])
        table[name] = {"model": model, "plain": r[:, 0].tolist(), "checked": r[:, 1].tolist()}
        gm = np.exp(np.log(r).mean(axis=0))
        wins = (r < 1).sum(axis=0)
        print(f"{name:34s} {model:18s} {gm[0]:.4f} ({wins[0]}/{len(r)})  {gm[1]:.4f} ({wins[1]}/{len(r)})", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"frames": args.frames, "settings": table}, f, indent=1)


if __name__ == "__main__":
    main()
