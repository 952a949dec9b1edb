"""Validation of lipjax.uncertainty: rank correlation of the expected error with the actual error.

Run by hand (never a test):

    python -m benchmarks.uncertainty [--limit N] [--realdata ../shared/realdata] [--skip-real]
    python -m benchmarks.uncertainty --calibrate [--limit N]     # refit the constants on VAL splits

Completions: `linear` and the shipped `lip-cnn-indoor` / `lip-cnn-outdoor` (lipjax.methods), each frame's sparse
input drawn from its ground truth with seed 0 (lipjax.data.sampling). Settings: the synthetic TEST splits (indoor
256x320 with 200 uniform points; outdoor 128x416 with the HDL-64 pattern; the first N frames) and the real frames
under --realdata, read in place as benchmarks/baselines.py reads them (NYU v2 nyu_paper with 200 uniform points,
KITTI kitti_paper with the HDL-64 pattern on its ground truth, Middlebury Motorcycle with 500 uniform points).

Scored pixels: valid ground truth within the setting's depth range and not sampled (measured pixels have zero
expected error). Columns: Spearman rho between expected and actual |error|, pooled over all scored pixels of the
setting and the mean of per-frame values; mean actual and expected |error| (m); the share of scored pixels
"above the samples" (lipjax.uncertainty) and their mean actual |error| against the other pixels'.

--calibrate fits RANGE_GAIN (least squares of |error| / z on the supported pixels)
and ABOVE_GAIN (least squares of |error| = gain * z above the samples) on the synthetic VALIDATION splits,
never on test or real frames, and prints them.
"""
from __future__ import annotations

import argparse
import os

import numpy as np
from scipy.stats import spearmanr

from benchmarks.common import INDOOR_RANGE_M, OUTDOOR_RANGE_M, REALDATA, load_kitti, load_middlebury, load_nyu
from experiments.configs import OUTDOOR_DATA  # the outdoor evaluation size, 128x416
from lipjax import uncertainty
from lipjax.data import protocols
from lipjax.data.sampling import LidarSampler, UniformSampler
from lipjax.methods import get_completer


def synthetic_settings(split: str, limit: int):
    """[(title, scene, frames, sampler, depth range)] of the synthetic split."""
    from lipjax.data.synthetic import SyntheticDataset

    indoor = SyntheticDataset("indoor", split, height=256, width=320)
    outdoor = SyntheticDataset("outdoor", split, height=OUTDOOR_DATA.height, width=OUTDOOR_DATA.width)
    return [(f"synthetic indoor {split}, uniform:200", "indoor", [indoor[i] for i in range(limit)],
             UniformSampler(200), INDOOR_RANGE_M),
            (f"synthetic outdoor {split}, lidar:hdl64", "outdoor", [outdoor[i] for i in range(limit)],
             LidarSampler.hdl64(), OUTDOOR_RANGE_M)]


def real_settings(root: str):
    nyu = [protocols.NYU_PAPER(s) for s in load_nyu(os.path.join(root, "nyu_v2"))]
    kitti = [protocols.KITTI_PAPER(s) for s in load_kitti(os.path.join(root, "kitti"))]
    mb = load_middlebury(os.path.join(root, "middlebury2014_motorcycle"))
    return [("real NYU v2 (3, 256x320), uniform:200", "indoor", nyu, UniformSampler(200), INDOOR_RANGE_M),
            ("real KITTI (3, 256x1216), lidar:hdl64 on GT", "outdoor", kitti, LidarSampler.hdl64(), OUTDOOR_RANGE_M),
            ("real Middlebury Motorcycle (1, 497x741), uniform:500", "indoor", mb, UniformSampler(500),
             INDOOR_RANGE_M)]


def frame_rows(method, frame, sampler, depth_range):
    """(features, |error|) of one frame's scored pixels: columns r, depth range (m), height above (spacings), z (m),
    expected error (m)."""
    sparse = sampler(frame, 0)
    depth = np.asarray(method(frame.rgb, sparse), np.float32)
    f = uncertainty.support_features(sparse)
    u = uncertainty.expected_error(sparse, depth)
    gt = frame.depth
    scored = frame.valid & (gt > depth_range[0]) & (gt <= depth_range[1]) & (sparse == 0)
    cols = [f["distance"], f["depth_range"], f["height_above"], depth, u]
    return np.stack([c[scored] for c in cols], axis=1), np.abs(depth - gt)[scored]


def run(settings, method_names):
    """Markdown table of the validation numbers, one row per (setting, method)."""
    print("| setting | method | frames | Spearman pooled | Spearman per frame | mean abs err m | mean expected m "
          "| % px above samples | abs err above / other |")
    print("|---|---|---|---|---|---|---|---|---|")
    for title, scene, frames, sampler, depth_range in settings:
        for name in method_names:
            method = get_completer(name.format(scene=scene))
            per_frame = [frame_rows(method, s, sampler, depth_range) for s in frames]
            x = np.concatenate([f for f, _ in per_frame])
            err = np.concatenate([e for _, e in per_frame])
            above = x[:, 2] > 1.0
            ratio = f"{err[above].mean() / err[~above].mean():.1f}" if above.any() else "-"
            rho_frames = np.mean([spearmanr(f[:, 4], e)[0] for f, e in per_frame])
            print(f"| {title} | {method.name} | {len(frames)} | {spearmanr(x[:, 4], err)[0]:.3f} | {rho_frames:.3f} "
                  f"| {err.mean():.3f} | {x[:, 4].mean():.3f} | {100 * above.mean():.1f} | {ratio} |", flush=True)


def calibrate(settings, method_names):
    """Fits and prints RANGE_GAIN and ABOVE_GAIN (see the module docstring). Every (setting, method)
    weighs the same in the fit of the supported pixels, whatever its pixel count."""
    design, target, above_err, above_z = [], [], [], []
    for _, scene, frames, sampler, depth_range in settings:
        for name in method_names:
            method = get_completer(name.format(scene=scene))
            x, err = map(np.concatenate, zip(*(frame_rows(method, s, sampler, depth_range) for s in frames)))
            r, depth_range, height, z = x[:, 0], x[:, 1], x[:, 2], np.maximum(x[:, 3], 1e-3)
            supported = height <= 1.0
            weight = 1.0 / np.sqrt(supported.sum())
            design.append(weight * (r * depth_range / z)[supported])
            target.append(weight * (err / z)[supported])
            above_err.append(err[~supported])
            above_z.append(z[~supported])
    design, target = np.concatenate(design), np.concatenate(target)
    range_gain = float(design @ target / (design @ design))  # least squares: |error| / z = gain * r * range / z
    above_err, above_z = np.concatenate(above_err), np.concatenate(above_z)
    above_gain = float(np.sum(above_err * above_z) / np.sum(above_z**2))  # least squares of |error| = gain * z
    print(f"RANGE_GAIN = {range_gain:.4f}\nABOVE_GAIN = {above_gain:.4f}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--limit", type=int, default=20, help="frames per synthetic split (the first N)")
    ap.add_argument("--realdata", default=REALDATA)
    ap.add_argument("--skip-real", action="store_true")
    ap.add_argument("--calibrate", action="store_true", help="fit the constants on the synthetic val splits")
    ap.add_argument("--methods", default="linear,lip-cnn-{scene}",
                    help="lipjax.methods names; {scene} = indoor|outdoor")
    args = ap.parse_args(argv)
    methods = args.methods.split(",")
    if args.calibrate:
        calibrate(synthetic_settings("val", args.limit), methods)
        return
    settings = synthetic_settings("test", args.limit)
    root = os.path.abspath(args.realdata)
    if not args.skip_real and os.path.isdir(root):
        settings += real_settings(root)
    elif not args.skip_real:
        print(f"(no real data at {root}: skipped)\n")
    run(settings, methods)


if __name__ == "__main__":
    main()
