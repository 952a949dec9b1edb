"""Which model the default path should use: candidates through `complete_frame` on synthetic sensor-size frames.

    python benchmarks/default_choice.py [--frames 4]

The settings of benchmarks/working_resolution.py (rooms at 480x640 with 50, 200 and 1,000 points, streets at
352x1216 with a 64-beam scan and 200 points; the test split, never trained on), each model at its working size
(lipjax.resolution). Rows: the geometric-mean RMSE ratio to the full-size linear fill per setting. The rule, fixed
before the real frames were scored: the default is the candidate (one model for both scenes, or the per-scene pair)
with the lowest geometric mean over all settings.
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from benchmarks.working_resolution import SETTINGS, rmse_unsampled  # noqa: E402
from lipjax.data.sampling import sampler_from_spec  # noqa: E402
from lipjax.data.synthetic import SyntheticDataset  # noqa: E402
from lipjax.inference import complete_frame  # noqa: E402
from lipjax.methods import get_completer  # noqa: E402

CANDIDATES = {  # name -> (model for rooms, model for streets)
    "lip-any": ("lip-any", "lip-any"),
    "lip-fast-indoor + lip-ad-outdoor (the defaults before)": ("lip-fast-indoor", "lip-ad-outdoor"),
    "lip-fast-indoor + lip-ad-fast-outdoor": ("lip-fast-indoor", "lip-ad-fast-outdoor"),
}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=4)
    args = ap.parse_args(argv)
    linear = get_completer("linear")
    names = sorted({m for pair in CANDIDATES.values() for m in pair})
    table = {}
    for kind, h, w, spec in SETTINGS:
        sampler, ratios = sampler_from_spec(spec), {m: [] for m in names}
        for sample in SyntheticDataset(kind, "test", size=args.frames, height=h, width=w):
            sparse = sampler(sample, 0)
            ref = rmse_unsampled(linear(sample.rgb, sparse), sample.depth, sample.valid, sparse)
            for m in names:
                if m in (pair[0 if kind == "indoor" else 1] for pair in CANDIDATES.values()):
                    pred = complete_frame(get_completer(m), sample.rgb, sparse)
                    ratios[m].append(rmse_unsampled(pred, sample.depth, sample.valid, sparse) / ref)
        table[f"{kind} {h}x{w} {spec}"] = {m: float(np.exp(np.mean(np.log(r)))) for m, r in ratios.items() if r}
        print(f"{kind} {h}x{w} {spec}", {m: round(v, 3) for m, v in table[f'{kind} {h}x{w} {spec}'].items()},
              flush=True)
    print("\n| candidate | " + " | ".join(table) + " | geometric mean |")
    print("|---|" + "---|" * (len(table) + 1))
    for cand, (room, street) in CANDIDATES.items():
        vals = [row[room if key.startswith("indoor") else street] for key, row in table.items()]
        print(f"| {cand} | " + " | ".join(f"{v:.3f}" for v in vals) + f" | {np.exp(np.mean(np.log(vals))):.3f} |")


if __name__ == "__main__":
    main()
