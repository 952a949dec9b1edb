"""Which host fill to start the learned prox from (z_0): linear or nearest, against the samples' spacing.

The model's own estimate is scored (`cross_check=False`, `flip=False`): the default path's check against the
linear fill (lipjax.crosscheck) would mix that fill into what is measured here, and its flipped frame on scan lines
(lipjax.inference.flips) a second estimate.

    python -m benchmarks.initial_estimate [--model lip-any] [--frames 4]

For synthetic test renders (never trained on) with sparse and dense inputs, the model runs through the default path
(`lipjax.inference.complete_frame`, at its working size) twice: with z_0 the linear fill and with z_0 the nearest
fill (the same weights). The table gives the mean sample spacing at the working size (px) and each variant's
geometric-mean RMSE ratio to the full-size linear fill on the unsampled valid pixels, and its median time.
The rule read from it (lipjax.model.DENSE_SPACING_PX): nearest below the spacing where it stops being better.
"""
from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from benchmarks.common import rmse_unsampled
from lipjax.data.sampling import sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.inference import Completer, complete_frame, frame_size, reproject_sparse
from lipjax.methods import get_completer
from lipjax.resolution import sample_spacing_px

SETTINGS = (
    ("indoor", 480, 640, "uniform:200"),
    ("indoor", 480, 640, "uniform:1000"),
    ("indoor", 480, 640, "uniform:5000"),
    ("indoor", 256, 320, "uniform:5000"),
    ("indoor", 256, 320, "lidar:vlp16,azimuth_step_deg=0.4"),
    ("indoor", 256, 320, "lidar:hdl64,azimuth_step_deg=0.4"),
    ("outdoor", 352, 1216, "lidar:vlp16"),
    ("outdoor", 352, 1216, "lidar:hdl64"),
)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default=None, help="default: the default model")
    ap.add_argument("--frames", type=int, default=4)
    args = ap.parse_args(argv)
    base = get_completer(args.model)
    variants = {k: Completer(dataclasses.replace(base.config, initial_estimate=k), base.params, k)
                for k in ("linear", "nearest")}
    linear = get_completer("linear")
    print("| setting | spacing at working size px | z0 linear | z0 nearest | ms linear | ms nearest |")
    print("|---|---|---|---|---|---|")
    for kind, h, w, spec in SETTINGS:
        sampler = sampler_from_spec(spec)
        ratios, times, spacings = {k: [] for k in variants}, {k: [] for k in variants}, []
        for frame in SyntheticDataset(kind, "test", size=args.frames, height=h, width=w):
            sparse = sampler(frame, 0)
            ref = rmse_unsampled(linear(frame.rgb, sparse), frame, sparse)
            spacings.append(sample_spacing_px(reproject_sparse(sparse, frame_size(base, sparse))))
            for k, completer in variants.items():
                t = time.perf_counter()
                pred = complete_frame(completer, frame.rgb, sparse, flip=False, cross_check=False)
                times[k].append(time.perf_counter() - t)
                ratios[k].append(rmse_unsampled(pred, frame, sparse) / ref)
        gm = {k: float(np.exp(np.mean(np.log(r)))) for k, r in ratios.items()}
        ms = {k: 1e3 * float(np.median(t[1:] or t)) for k, t in times.items()}
        print(f"| {kind} {h}x{w} {spec} | {np.median(spacings):.1f} | {gm['linear']:.3f} | {gm['nearest']:.3f} | "
              f"{ms['linear']:.0f} | {ms['nearest']:.0f} |", flush=True)


if __name__ == "__main__":
    main()
