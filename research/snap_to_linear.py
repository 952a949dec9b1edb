"""Near the samples: where the default path and the linear fill agree, is the linear fill the better of the two?

    python -m research.snap_to_linear [--frames 6] [--taus 0.01,0.02,0.05,0.1]

At full LiDAR density the linear fill beats the default path at points held out of the input (20 %,
`benchmarks.common.hide_points`; `python -m benchmarks.real_frames --hidden-only` on real KITTI frames). Here, on
frames of the synthetic test split (never trained on): x the default path's map (`lipjax.complete`), L the
Delaunay linear fill of the same samples, and the map snapped to L where the two agree within tau:

    w = clip(1 - |x - L| / (tau L), 0, 1),          x_tau = w L + (1 - w) x

Per setting and tau: the geometric mean over frames of RMSE and MAE over those of L, once on the unsampled valid
pixels of the whole input ("suite") and once on the held-out points of the input without them ("hidden").
A probe, not a decision: the linear fill costs about 90 ms more per street frame and has no ONNX form.
"""
from __future__ import annotations

import argparse

import numpy as np

from benchmarks.common import geometric_mean, hide_points
from lipjax.classical.interpolate import linear_fill
from lipjax.data.sampling import LidarSampler, sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.methods import complete

SETTINGS = (  # (name, scene kind, size, sampler)
    ("streets 352x1216, HDL-64", "outdoor", (352, 1216), LidarSampler.hdl64()),
    ("rooms 480x640, 1000 points", "indoor", (480, 640), sampler_from_spec("uniform:1000")),
)


def snapped(x: np.ndarray, linear: np.ndarray, tau: float) -> np.ndarray:
    """x moved to the linear fill where they agree within tau (relative), linearly less up to 2 tau apart."""
    w = np.clip(1.0 - np.abs(x - linear) / (tau * np.maximum(linear, 1e-3)), 0.0, 1.0)
    return w * linear + (1.0 - w) * x


def ratios(frame, y: np.ndarray, mask: np.ndarray, taus) -> dict[str, tuple[float, float]]:
    """{variant: (RMSE / RMSE of L, MAE / MAE of L)} over `mask`."""
    x, lin = complete(frame.rgb, y), linear_fill(y)

    def errors(p):
        e = p[mask] - frame.depth[mask]
        return float(np.sqrt(np.mean(e ** 2))), float(np.mean(np.abs(e)))

    ref = errors(lin)
    out = {"default": errors(x), **{f"tau {t:g}": errors(snapped(x, lin, t)) for t in taus}}
    return {k: (r / ref[0], m / ref[1]) for k, (r, m) in out.items()}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=6)
    ap.add_argument("--taus", default="0.01,0.02,0.05,0.1")
    args = ap.parse_args(argv)
    taus = [float(t) for t in args.taus.split(",")]
    print(f"{'setting':28s} {'check':7s} {'variant':10s} {'RMSE / L':>9s} {'MAE / L':>9s}   (geometric means)")
    for name, kind, size, sampler in SETTINGS:
        rows: dict[tuple[str, str], list] = {}
        for frame in SyntheticDataset(kind, "test", size=args.frames, height=size[0], width=size[1]):
            sparse = sampler(frame, 0)
            checks = {"suite": (sparse, frame.valid & (sparse <= 0)), "hidden": hide_points(frame, sparse)}
            for check, (y, mask) in checks.items():
                for variant, r in ratios(frame, y, mask, taus).items():
                    rows.setdefault((check, variant), []).append(r)
        for (check, variant), r in rows.items():
            print(f"{name:28s} {check:7s} {variant:10s} {geometric_mean([a for a, _ in r]):9.4f} "
                  f"{geometric_mean([b for _, b in r]):9.4f}", flush=True)


if __name__ == "__main__":
    main()
