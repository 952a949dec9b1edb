"""Classical depth-completion baselines: metrics and time per frame on the synthetic splits and on real frames.

Run by hand (never a test):

    python -m benchmarks.baselines [--limit N] [--json out.json] [--realdata ../shared/realdata]
                                   [--skip-synthetic] [--skip-real] [--methods nearest,linear,...]
                                   [--max-side N]

Data sets (each a Markdown table: rows = methods, columns = metrics with units, lipjax.metrics):
  synthetic indoor test split, 256x320, 200 uniform points (UniformSampler(200)), depth range (0, 10] m;
  synthetic outdoor test split, 256x320, simulated HDL-64 and VLP-16 scans (LidarSampler), (0, 80] m;
  real frames under --realdata when present (read here, not by the library; research-use licences):
    nyu_v2   3 Kinect frames, protocol NYU_PAPER (crop 464x580, resize 256x320), 200 uniform points, (0, 10] m;
    kitti    3 frames of semi-dense accumulated LiDAR ground truth, protocol KITTI_PAPER (bottom crop 256x1216),
             HDL-64 / VLP-16 patterns simulated on the ground truth, and 200 uniform points, (0, 80] m;
    middlebury2014_motorcycle  1 frame, 497x741 (full), depth from disparity, 200 and 500 uniform points,
             (0, 10] m.
  Sparse inputs are drawn from the ground truth with the seed 0 and the frame id (lipjax.data.sampling), so
  the sampled pixels are also scored: mae_unsampled_m is the error on the pixels the methods had to invent.
  Each real setting also gets a per-frame RMSE table, with the number of frames on which each method beats
  linear interpolation.

Methods: the four classical completers (lipjax.classical) and LIP+Wavelet: the unrolled ADMM solver
(lipjax.admm) with the wavelet soft-thresholding prox (lipjax.priors.wavelet), started from the box fill
(lipjax.fill), as lipjax.classical.lip_wavelet.LIPWavelet (settings chosen on val frames, see its docstring).

Times are wall-clock ms per frame of the completer call on this machine (one warm-up call excluded); they
depend on the machine and its load.
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time

import numpy as np

from benchmarks.common import INDOOR_RANGE_M, OUTDOOR_RANGE_M, REALDATA, load_real
from experiments.configs import OUTDOOR_DATA  # the outdoor evaluation size, 128x416
from lipjax.classical.lip_wavelet import LIPWavelet
from lipjax.evaluate import DEFAULT_COLUMNS, evaluate, markdown_table, save_json
from lipjax.methods import get_completer

# ------------------------------------------------------------------------------------------- runner


@dataclasses.dataclass
class Setting:
    title: str
    dataset: object
    sampler: object
    depth_range_m: tuple[float, float]
    synthetic: bool = False  # --limit applies to synthetic splits only


@dataclasses.dataclass
class Downsized:
    """A method run on the frame downsized to `max_side` (longer side), upsampled back with the measured pixels
    re-imposed (lipjax.inference.complete_frame): e.g. real KITTI frames at the scale of the outdoor training
    renders."""

    method: object
    max_side: int

    @property
    def name(self) -> str:
        return f"{self.method.name}@{self.max_side}"

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray:
        from lipjax.inference import complete_frame

        return complete_frame(self.method, rgb, sparse, self.max_side)


def run_setting(setting: Setting, methods, limit, progress: bool) -> dict:
    n = len(setting.dataset) if limit is None else min(limit, len(setting.dataset))
    points = [int((setting.sampler(setting.dataset[i], 0) > 0).sum()) for i in range(min(n, 5))]
    print(f"\n### {setting.title}\n\n{n} frames, {setting.dataset[0].shape[0]}x{setting.dataset[0].shape[1]}, "
          f"sparse points per frame (first {len(points)}): {points}, depth range {setting.depth_range_m} m\n")
    results = {}
    for m in methods:
        t0 = time.perf_counter()
        results[m.name] = evaluate(m, setting.dataset, setting.sampler, min_depth_m=setting.depth_range_m[0],
                                   max_depth_m=setting.depth_range_m[1], limit=limit, progress=progress)
        print(f"  {m.name}: {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    print(markdown_table(results, columns=DEFAULT_COLUMNS), flush=True)
    reference = next((name for name in results if name.split("@")[0] == "linear"), None)  # "linear@416" too
    if not setting.synthetic and reference is not None and len(results) > 1:
        print(per_frame_table(results, reference), flush=True)
    return results


def per_frame_table(results: dict, reference: str) -> str:
    """RMSE (m) of every method on each frame, and on how many frames each beats `reference`'s RMSE."""
    ids = [row["id"] for row in results[reference].per_image]
    ref = [row["rmse_m"] for row in results[reference].per_image]
    lines = ["", f"| method | {' | '.join(ids)} | frames better than {reference} |",
             "|---|" + "---:|" * (len(ids) + 1)]
    for name, res in results.items():
        rmse = [row["rmse_m"] for row in res.per_image]
        wins = sum(r < q for r, q in zip(rmse, ref))
        lines.append(f"| {name} | {' | '.join(f'{r:.3f}' for r in rmse)} | "
                     f"{'-' if name == reference else f'{wins} of {len(ids)}'} |")
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--limit", type=int, default=None, help="frames per synthetic split (default: all 200)")
    ap.add_argument("--realdata", default=REALDATA)
    ap.add_argument("--json", default=None, help="write all results (with per-image metrics) to this file")
    ap.add_argument("--skip-synthetic", action="store_true")
    ap.add_argument("--skip-real", action="store_true")
    ap.add_argument("--methods", default="nearest,linear,ip_basic,colorization,lip-wavelet",
                    help="comma-separated lipjax.methods names, e.g. add lip-cnn-indoor,lip-ad-indoor")
    ap.add_argument("--progress", action="store_true")
    ap.add_argument("--max-side", type=int, default=None, metavar="N",
                    help="run each method on frames downsized to this longer side, as `lipjax complete --max-side`")
    args = ap.parse_args(argv)

    wanted = args.methods.split(",")
    methods = [get_completer(name) for name in wanted]  # any lipjax.methods name: classical, lip-wavelet, learned
    if args.max_side:
        methods = [Downsized(m, args.max_side) for m in methods]
    print(f"methods: {[m.name for m in methods]}; LIP+Wavelet: {LIPWavelet()}")

    from lipjax.data.sampling import LidarSampler, UniformSampler

    settings = []
    if not args.skip_synthetic:
        from lipjax.data.synthetic import SyntheticDataset

        indoor = SyntheticDataset("indoor", "test", height=256, width=320)
        outdoor = SyntheticDataset("outdoor", "test", height=OUTDOOR_DATA.height, width=OUTDOOR_DATA.width)
        settings += [
            Setting("synthetic indoor test, 200 uniform points", indoor, UniformSampler(200), INDOOR_RANGE_M, True),
            Setting("synthetic outdoor test, HDL-64 pattern", outdoor, LidarSampler.hdl64(), OUTDOOR_RANGE_M, True),
            Setting("synthetic outdoor test, VLP-16 pattern", outdoor, LidarSampler.vlp16(), OUTDOOR_RANGE_M, True),
        ]
    root = os.path.abspath(args.realdata)
    if not args.skip_real and os.path.isdir(root):
        nyu, kitti, mb = load_real(root)
        settings += [
            Setting("real NYU v2 (3 frames, nyu_paper 256x320), 200 uniform points", nyu, UniformSampler(200),
                    INDOOR_RANGE_M),
            Setting("real KITTI (3 frames, kitti_paper 256x1216), HDL-64 pattern on GT", kitti, LidarSampler.hdl64(),
                    OUTDOOR_RANGE_M),
            Setting("real KITTI (3 frames, kitti_paper 256x1216), VLP-16 pattern on GT", kitti, LidarSampler.vlp16(),
                    OUTDOOR_RANGE_M),
            Setting("real KITTI (3 frames, kitti_paper 256x1216), 200 uniform points", kitti, UniformSampler(200),
                    OUTDOOR_RANGE_M),
            Setting("real Middlebury 2014 Motorcycle (1 frame, 497x741), 200 uniform points", mb, UniformSampler(200),
                    INDOOR_RANGE_M),
            Setting("real Middlebury 2014 Motorcycle (1 frame, 497x741), 500 uniform points", mb, UniformSampler(500),
                    INDOOR_RANGE_M),
        ]
    elif not args.skip_real:
        print(f"\n(no real data at {root}: skipped)")

    flat = {}
    for s in settings:
        results = run_setting(s, methods, args.limit if s.synthetic else None, args.progress)
        flat.update({f"{s.title} | {name}": res for name, res in results.items()})
    if args.json:
        save_json(flat, args.json)
        print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
