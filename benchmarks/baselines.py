"""Classical depth-completion baselines: metrics and time per frame on the synthetic splits and on real frames.

Run by hand (never a test):

    .venv/bin/python benchmarks/baselines.py [--limit N] [--json out.json] [--realdata ../shared/realdata]
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
  Sparse inputs are drawn from the ground truth with the seed 0 and the sample id (lipjax.data.sampling), so
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
import re
import sys
import time

import cv2
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
from experiments.configs import OUTDOOR_DATA  # noqa: E402  (the outdoor evaluation size, 128x416)
from lipjax.data import protocols  # noqa: E402
from lipjax.methods import get_completer  # noqa: E402
from lipjax.classical.lip_wavelet import LIPWavelet  # noqa: E402
from lipjax.data.sample import Intrinsics, Sample  # noqa: E402
from lipjax.evaluate import DEFAULT_COLUMNS, evaluate, markdown_table, save_json  # noqa: E402

INDOOR_RANGE_M = (0.0, protocols.EVAL_MAX_DEPTH_INDOOR_M)
OUTDOOR_RANGE_M = (0.0, protocols.EVAL_MAX_DEPTH_OUTDOOR_M)

def _rgb(path: str) -> np.ndarray:
    bgr = cv2.imread(path, cv2.IMREAD_COLOR)
    if bgr is None:
        raise FileNotFoundError(path)
    return np.ascontiguousarray(bgr[:, :, ::-1])


def _png_depth(path: str, scale: float) -> np.ndarray:
    raw = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if raw is None or raw.dtype != np.uint16:
        raise ValueError(f"{path}: expected a uint16 depth PNG")
    return raw.astype(np.float32) / scale  # 0 stays 0 = invalid


def read_pfm(path: str) -> np.ndarray:
    """A grey-scale PFM as float32 (H, W), top row first."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"Pf":
            raise ValueError(f"{path}: not a grey-scale PFM")
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.fromfile(f, dtype="<f4" if scale < 0 else ">f4", count=w * h)
    return np.flipud(data.reshape(h, w)).astype(np.float32)  # PFM rows are stored bottom-up


def load_nyu(root: str) -> list[Sample]:
    """NYU v2 frames: depth PNG / 1000 = metres; standard NYU RGB intrinsics (PROVENANCE.md)."""
    k = Intrinsics(518.8579, 519.46961, 325.58245, 253.73617)
    out = []
    for name in sorted(os.listdir(os.path.join(root, "rgb"))):
        idx = re.findall(r"\d+", name)[-1]
        rgb = _rgb(os.path.join(root, "rgb", name))
        depth = _png_depth(os.path.join(root, "depth", f"sync_depth_{idx}.png"), 1000.0)
        out.append(Sample.from_depth(rgb, depth, k, f"realdata/nyu_v2/{idx}"))
    return out


def load_kitti(root: str) -> list[Sample]:
    """KITTI frames: depth PNG / 256 = metres. Intrinsics: the 2011_09_26 P_rect_02 that matches the
    1242x375 size (the json's 2011_09_28 values are doubtful, see PROVENANCE.md)."""
    k = Intrinsics(721.5377, 721.5377, 609.5593, 172.854)
    out = []
    for name in sorted(os.listdir(os.path.join(root, "rgb"))):
        rgb = _rgb(os.path.join(root, "rgb", name))
        depth = _png_depth(os.path.join(root, "depth", name), 256.0)
        out.append(Sample.from_depth(rgb, depth, k, f"realdata/kitti/{os.path.splitext(name)[0]}"))
    return out


def load_middlebury(root: str) -> list[Sample]:
    """Middlebury 2014 Motorcycle (quarter size): Z [mm] = baseline * f / (d + doffs); inf disparity = unknown."""
    calib = dict(line.strip().split("=", 1) for line in open(os.path.join(root, "calib.txt")) if "=" in line)
    cam0 = [float(v) for v in re.findall(r"[-\d.]+", calib["cam0"])]
    f, cx, cy = cam0[0], cam0[2], cam0[5]
    doffs, baseline_mm = float(calib["doffs"]), float(calib["baseline"])
    disp = read_pfm(os.path.join(root, "disp0GT.pfm"))
    with np.errstate(divide="ignore", invalid="ignore"):
        depth_m = np.where(np.isfinite(disp), baseline_mm * f / (disp + doffs) / 1000.0, 0.0)
    rgb = _rgb(os.path.join(root, "im0.png"))
    return [Sample.from_depth(rgb, depth_m.astype(np.float32), Intrinsics(f, f, cx, cy),
                              "realdata/middlebury/motorcycle")]


def load_real(root: str) -> tuple[list[Sample], list[Sample], list[Sample]]:
    """The real frames under `root` as the benchmarks score them: NYU v2 (protocol nyu_paper), KITTI (kitti_paper),
    Middlebury (full size)."""
    nyu = [protocols.NYU_PAPER(s) for s in load_nyu(os.path.join(root, "nyu_v2"))]
    kitti = [protocols.KITTI_PAPER(s) for s in load_kitti(os.path.join(root, "kitti"))]
    return nyu, kitti, load_middlebury(os.path.join(root, "middlebury2014_motorcycle"))


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
    ap.add_argument("--realdata", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "realdata"))
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
