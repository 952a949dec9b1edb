"""What the benchmarks share, so that no script imports another: the shared real frames and their inputs, the
synthetic suite's settings with the ratio to the linear fill, and the timing yardstick.

  real frames     `REALDATA` (../shared/realdata beside the repository; research-use data, read in place, never
                  copied), the loaders of its data sets (`load_nyu`, `load_kitti`, `load_middlebury`,
                  `load_lingbot`; `load_real` with the paper's protocols) and the inputs every real-frame script
                  draws on them (`frames_and_inputs`: 200 uniform points indoors; the HDL-64 pattern and 30 % of the
                  valid pixels on KITTI, seed 0) and `hide_points` (a fifth of an input's points held out);
  the suite       the synthetic test settings of benchmarks/generalisation.py (`SETTINGS`, `frames`) and the RMSE
                  ratio to the Delaunay linear fill on the unsampled valid pixels (`ratio_to_linear`,
                  `ratios_to_linear`, `geometric_mean`);
  timing          `median_ms` of a call, and `matmul_rate`: a 2048x2048 float32 matmul timed in the same run, to
                  compare runs made on machines, or under loads, that differ.
"""
from __future__ import annotations

import os
import re
import statistics
import time

import cv2
import jax
import jax.numpy as jnp
import numpy as np

from lipjax.data import protocols
from lipjax.data.frame import Frame, Intrinsics
from lipjax.data.sampling import LidarSampler, UniformSampler, example_rng, sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.data.synthetic.dataset import MixedSyntheticDataset
from lipjax.inference import CROSS_CHECK, complete_frame
from lipjax.methods import get_completer

# ------------------------------------------------------------------------------------------- real frames

REALDATA = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared",
                                         "realdata"))
INDOOR_RANGE_M = (0.0, protocols.EVAL_MAX_DEPTH_INDOOR_M)
OUTDOOR_RANGE_M = (0.0, protocols.EVAL_MAX_DEPTH_OUTDOOR_M)
INDOOR_POINTS = 200  # uniform points on every indoor real frame
KITTI_FRACTION = 0.3  # of the valid pixels, the second KITTI input
GREY = 128  # the uniform grey image of the "grey" runs (the depth-only part of the prior)
HIDDEN_FRACTION = 0.2  # of an input's points, hidden at random (`hide_points`)


def read_rgb(path: str) -> np.ndarray:
    """An image file as (H, W, 3) uint8 RGB."""
    bgr = cv2.imread(path, cv2.IMREAD_COLOR)
    if bgr is None:
        raise FileNotFoundError(path)
    return np.ascontiguousarray(bgr[:, :, ::-1])


def read_png_depth(path: str, scale: float) -> np.ndarray:
    """A 16-bit depth PNG as float32 metres (value / scale; 0 stays 0 = invalid)."""
    raw = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if raw is None or raw.dtype != np.uint16:
        raise ValueError(f"{path}: expected a uint16 depth PNG")
    return raw.astype(np.float32) / scale


def read_pfm(path: str) -> np.ndarray:
    """A grey-scale PFM as float32 (H, W), top row first."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"Pf":
            raise ValueError(f"{path}: not a grey-scale PFM")
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.fromfile(f, dtype="<f4" if scale < 0 else ">f4", count=w * h)
    return np.flipud(data.reshape(h, w)).astype(np.float32)  # PFM rows are stored bottom-up


def load_nyu(root: str) -> list[Frame]:
    """NYU v2 frames: depth PNG / 1000 = metres; standard NYU RGB intrinsics (PROVENANCE.md)."""
    k = Intrinsics(518.8579, 519.46961, 325.58245, 253.73617)
    out = []
    for name in sorted(os.listdir(os.path.join(root, "rgb"))):
        idx = re.findall(r"\d+", name)[-1]
        rgb = read_rgb(os.path.join(root, "rgb", name))
        depth = read_png_depth(os.path.join(root, "depth", f"sync_depth_{idx}.png"), 1000.0)
        out.append(Frame.from_depth(rgb, depth, k, f"realdata/nyu_v2/{idx}"))
    return out


def load_kitti(root: str) -> list[Frame]:
    """KITTI frames: depth PNG / 256 = metres. Intrinsics: the 2011_09_26 P_rect_02 that matches the
    1242x375 size (the json's 2011_09_28 values are doubtful, see PROVENANCE.md)."""
    k = Intrinsics(721.5377, 721.5377, 609.5593, 172.854)
    out = []
    for name in sorted(os.listdir(os.path.join(root, "rgb"))):
        rgb = read_rgb(os.path.join(root, "rgb", name))
        depth = read_png_depth(os.path.join(root, "depth", name), 256.0)
        out.append(Frame.from_depth(rgb, depth, k, f"realdata/kitti/{os.path.splitext(name)[0]}"))
    return out


def load_middlebury(root: str) -> list[Frame]:
    """Middlebury 2014 Motorcycle (quarter size): Z [mm] = baseline * f / (d + doffs); inf disparity = unknown."""
    calib = dict(line.strip().split("=", 1) for line in open(os.path.join(root, "calib.txt")) if "=" in line)
    cam0 = [float(v) for v in re.findall(r"[-\d.]+", calib["cam0"])]
    f, cx, cy = cam0[0], cam0[2], cam0[5]
    doffs, baseline_mm = float(calib["doffs"]), float(calib["baseline"])
    disp = read_pfm(os.path.join(root, "disp0GT.pfm"))
    with np.errstate(divide="ignore", invalid="ignore"):
        depth_m = np.where(np.isfinite(disp), baseline_mm * f / (disp + doffs) / 1000.0, 0.0)
    rgb = read_rgb(os.path.join(root, "im0.png"))
    return [Frame.from_depth(rgb, depth_m.astype(np.float32), Intrinsics(f, f, cx, cy),
                             "realdata/middlebury/motorcycle")]


def load_lingbot(root: str) -> list[Frame]:
    """lingbot frames: depth PNG / 1000 = metres (raw sensor depth), a 3x3 K per frame (PROVENANCE.md)."""
    out = []
    for name in sorted(os.listdir(os.path.join(root, "rgb"))):
        stem = os.path.splitext(name)[0]
        k = np.loadtxt(os.path.join(root, "intrinsics", f"{stem}.txt")).reshape(3, 3)
        depth = read_png_depth(os.path.join(root, "depth", f"{stem}.png"), 1000.0)
        out.append(Frame.from_depth(read_rgb(os.path.join(root, "rgb", name)), depth,
                                    Intrinsics(k[0, 0], k[1, 1], k[0, 2], k[1, 2]), f"realdata/lingbot/{stem}"))
    return out


def load_real(root: str) -> tuple[list[Frame], list[Frame], list[Frame]]:
    """The real frames under `root` as the benchmarks score them: NYU v2 (protocol nyu_paper), KITTI (kitti_paper),
    Middlebury (full size)."""
    nyu = [protocols.NYU_PAPER(s) for s in load_nyu(os.path.join(root, "nyu_v2"))]
    kitti = [protocols.KITTI_PAPER(s) for s in load_kitti(os.path.join(root, "kitti"))]
    return nyu, kitti, load_middlebury(os.path.join(root, "middlebury2014_motorcycle"))


def indoor_frames(root: str) -> list[Frame]:
    """The 12 shared indoor frames at native size: NYU v2 (3), Middlebury Motorcycle (1), lingbot (8)."""
    indoor = load_nyu(os.path.join(root, "nyu_v2")) + load_middlebury(os.path.join(root, "middlebury2014_motorcycle"))
    return indoor + load_lingbot(os.path.join(root, "lingbot_rgbd"))


def hide_points(frame: Frame, sparse: np.ndarray, fraction: float = HIDDEN_FRACTION,
                seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(input without the hidden points, hidden mask): round(fraction x points) of the input's points, drawn by
    `example_rng(seed, frame.id, "hidden")`."""
    idx = np.flatnonzero(sparse > 0)
    chosen = example_rng(seed, frame.id, "hidden").choice(idx, int(round(fraction * idx.size)), replace=False)
    hidden = np.zeros(sparse.size, bool)
    hidden[chosen] = True
    hidden = hidden.reshape(sparse.shape)
    return np.where(hidden, 0.0, sparse).astype(np.float32), hidden


def frames_and_inputs(root: str) -> list[tuple[str, Frame, np.ndarray, str]]:
    """(group, frame, sparse input metres, input name) for every shared real frame at native size and input
    setting: "indoor" (INDOOR_POINTS uniform points), "kitti-hdl64" (LidarSampler.hdl64) and "kitti-30pct"
    (KITTI_FRACTION of the valid pixels), all drawn with seed 0."""
    out = [("indoor", s, UniformSampler(INDOOR_POINTS)(s, 0), f"{INDOOR_POINTS} points") for s in indoor_frames(root)]
    for s in load_kitti(os.path.join(root, "kitti")):
        out.append(("kitti-hdl64", s, LidarSampler.hdl64()(s, 0), "HDL-64"))
        n = int(round(KITTI_FRACTION * np.count_nonzero(s.valid)))
        out.append(("kitti-30pct", s, UniformSampler(n)(s, 0), f"30 % ({n} points)"))
    return out


# ------------------------------------------------------------------------------------------- the suite

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


def rmse_unsampled(pred: np.ndarray, frame: Frame, sparse: np.ndarray) -> float:
    """RMSE (m) of `pred` against the frame's depth on its valid pixels that hold no sample of `sparse`."""
    keep = frame.valid & (sparse <= 0)
    return float(np.sqrt(np.mean((pred[keep] - frame.depth[keep]) ** 2)))


def ratio_to_linear(model, linear, frame, spec, cross_check: bool = CROSS_CHECK) -> float:
    """RMSE of `model` (name or path; None: the default path's choice) over that of `linear`, on the unsampled valid
    pixels, with the samples of `spec` (a sampler or its spec string, lipjax.data.sampling) drawn with seed 0;
    `cross_check` as in lipjax.inference.complete_at; without it the model's estimate itself, how models are compared:
    neither the check nor the flip averaging that the default path adds on scan lines (docs/decisions/0020)."""
    return ratios_to_linear(model, linear, frame, spec, (frame.rgb,), cross_check)[0]


def ratios_to_linear(model, linear, frame, spec, images, cross_check: bool = CROSS_CHECK) -> list[float]:
    """`ratio_to_linear` with each of `images` in place of the frame's own, the samples and the linear fill (which
    uses no image) computed once."""
    sparse = (sampler_from_spec(spec) if isinstance(spec, str) else spec)(frame, 0)
    completer = get_completer(model, sparse=sparse)
    reference = rmse_unsampled(linear(frame.rgb, sparse), frame, sparse)
    flip = None if cross_check else False  # the default path, or the model alone
    return [rmse_unsampled(complete_frame(completer, rgb, sparse, flip=flip, cross_check=cross_check), frame, sparse)
            / reference for rgb in images]


def geometric_mean(ratios) -> float:
    """Geometric mean of positive ratios."""
    return float(np.exp(np.log(np.asarray(ratios, np.float64)).mean()))


# ------------------------------------------------------------------------------------------- timing


def median_ms(fn, repeats: int) -> float:
    """Median wall-clock ms of `repeats` calls of `fn()`, after one warm-up call."""
    fn()
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return 1e3 * statistics.median(times)


def matmul_rate(repeats: int) -> tuple[float, float]:
    """(ms, GFLOP/s) of a 2048x2048 float32 matmul on the default device."""
    a = jnp.asarray(np.random.default_rng(0).random((2048, 2048), np.float32))
    f = jax.jit(lambda x: x @ x)
    ms = median_ms(lambda: f(a).block_until_ready(), repeats)
    return ms, 2 * 2048**3 / (ms * 1e-3) / 1e9
