"""Training throughput: input pipeline frames/s per source and worker count, host cost per frame, train-step rate.

    python -m benchmarks.train_throughput [--steps 12] [--workers 1 2] [--models lip_cnn_indoor lip_fast_indoor ...]
    python -m benchmarks.train_throughput --sources --models lip_any     # the train step alone

1. Pipeline: frames/s of lipjax.data.pipeline.TrainLoader (reading, sparse sampling, augment + crop and the host
   z0 fill, all in the grain worker processes) for each source, with each worker count. Real formats are written
   first, at their real frame sizes, as a few fixture frames in a temporary folder (NYU h5 480x640, KITTI DC
   375x1242 PNGs, a folder of 480x640 PNGs, `lipjax data render` shards); frames repeat, so the page cache
   holds them, as it would for a data set on a local SSD. The first batch (worker start-up) is not timed; the
   worker counts are measured in turn, `--rounds` times, and the median is reported.
2. Host cost: milliseconds of CPU per frame for that work in one process, per source, at the 128x160 crop.
3. Train step: images/s of the jitted supervised step of each named config at batch 8 on its training crop
   (compilation not timed), on this machine's JAX backend.
Everything uses the configs' own samplers and initial estimates (lip_cnn_indoor: z0 = linear fill on the host).
The first line gives the machine's 2048x2048 matmul rate, measured in the same run (benchmarks.common.matmul_rate).
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import tempfile
import time
from pathlib import Path

import numpy as np

BATCH = 8
CROP = (128, 160)
SOURCES = ("synthetic", "rendered", "nyu_h5", "kitti_dc", "folder")


def _write_fixtures(root: Path, frames: int) -> dict[str, dict]:
    """DataConfig overrides of each source over `frames` fixture frames in its real format and size."""
    import cv2
    import h5py

    from lipjax.data.rendered import render_to_disk

    rng = np.random.default_rng(0)
    overrides: dict[str, dict] = {"synthetic": {}}
    out = render_to_disk("indoor", "train", frames, root / "rendered", workers=1, progress=False)
    overrides["rendered"] = {"root": str(out)}
    for i in range(frames):  # NYU h5 (Ma et al.): rgb (3, 480, 640) uint8, depth float32 metres
        path = root / "nyu/nyudepthv2/train/office_0001" / f"{i + 1}.h5"
        path.parent.mkdir(parents=True, exist_ok=True)
        with h5py.File(path, "w") as f:
            f["rgb"] = rng.integers(0, 256, (3, 480, 640), dtype=np.uint8)
            f["depth"] = rng.uniform(0.5, 9.5, (480, 640)).astype(np.float32)
    overrides["nyu_h5"] = {"root": str(root / "nyu"), "train_sampler": "uniform:200"}
    drive = "2011_09_26_drive_0001_sync"
    (root / "kitti/raw" / drive[:10]).mkdir(parents=True)
    (root / "kitti/raw" / drive[:10] / "calib_cam_to_cam.txt").write_text(
        "P_rect_02: 721.5 0 609.6 44.9 0 721.5 172.9 0.2 0 0 1 0.003\n")
    for i in range(frames):  # KITTI DC: 16-bit PNGs (metres * 256) and the raw drive's RGB
        gt = np.where(rng.random((375, 1242)) < 0.3, rng.integers(256, 80 * 256, (375, 1242)), 0).astype(np.uint16)
        velo = np.where(rng.random((375, 1242)) < 0.06, gt, 0).astype(np.uint16)
        name = f"{i:010d}.png"
        for sub, image in (("data_depth_annotated/train/{d}/proj_depth/groundtruth/image_02", gt),
                           ("data_depth_velodyne/train/{d}/proj_depth/velodyne_raw/image_02", velo)):
            path = root / "kitti/depth" / sub.format(d=drive) / name
            path.parent.mkdir(parents=True, exist_ok=True)
            cv2.imwrite(str(path), image)
        path = root / "kitti/raw" / drive[:10] / drive / "image_02/data" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(path), rng.integers(0, 256, (375, 1242, 3), dtype=np.uint8))
    overrides["kitti_dc"] = {"root": str(root / "kitti/depth"), "raw_root": str(root / "kitti/raw"),
                             "train_sampler": "input"}
    for i in range(frames):  # a folder: 8-bit RGB PNG + 16-bit depth PNG in millimetres
        for sub in ("rgb", "depth"):
            (root / "folder" / sub).mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(root / "folder/rgb" / f"{i:04d}.png"), rng.integers(0, 256, (480, 640, 3), dtype=np.uint8))
        cv2.imwrite(str(root / "folder/depth" / f"{i:04d}.png"), rng.integers(500, 9500, (480, 640)).astype(np.uint16))
    (root / "folder/intrinsics.txt").write_text("518.9 519.5 325.6 253.7\n")
    overrides["folder"] = {"root": str(root / "folder"), "depth_scale": 1000.0}
    return overrides


def _step_batches(data, model_config, total_steps: int):
    from lipjax.data.pipeline import BatchIterator, StepBatches
    from lipjax.data.sources import open_source

    source = open_source(data, "train")
    local = BatchIterator(source.dataset, BATCH, source.sampler, seed=0)
    return StepBatches(local, total_steps, data.augment, data.crop, 0, model_config)


def pipeline_rate(data, model_config, workers: int, steps: int) -> float:
    """Frames/s of a TrainLoader with `workers` processes, after its first batch."""
    from lipjax.data.pipeline import TrainLoader

    with TrainLoader(_step_batches(data, model_config, steps + 1), 0, workers) as loader:
        next(loader)
        start = time.perf_counter()
        for _ in range(steps):
            next(loader)
        return steps * BATCH / (time.perf_counter() - start)


def host_ms_per_frame(data, model_config, steps: int) -> float:
    """CPU milliseconds per frame of the per-step work (read, sample, crop, z0) in this process."""
    batches = _step_batches(data, model_config, steps + 1)
    batches[0]
    start = time.process_time()
    for s in range(1, steps + 1):
        batches[s]
    return (time.process_time() - start) * 1e3 / (steps * BATCH)


def fill_ms(kind: str, points: int = 200, repeats: int = 20) -> float:
    """CPU milliseconds of the host z0 fill (lipjax.model.host_initial_estimate) of one 128x160 frame."""
    from lipjax.model import host_initial_estimate

    rng = np.random.default_rng(0)
    sparse = np.zeros((1, *CROP), np.float32)
    sparse.reshape(-1)[rng.choice(sparse.size, points, replace=False)] = rng.uniform(1, 9, points)
    host_initial_estimate(kind, sparse)
    start = time.process_time()
    for _ in range(repeats):
        host_initial_estimate(kind, sparse)
    return (time.process_time() - start) * 1e3 / repeats


def train_step_rate(name: str, steps: int) -> tuple[float, tuple[int, int]]:
    """(images/s of the supervised step of config `name` at batch BATCH on its crop, the crop)."""
    import jax

    from experiments.configs import CONFIGS
    from lipjax.data.pipeline import shard_batch
    from lipjax.train.state import init_state
    from lipjax.train.steps import make_steps

    config = dataclasses.replace(CONFIGS[name], batch_size=BATCH, init_from=None)
    h, w = config.data.crop or (config.data.height, config.data.width)
    rng = np.random.default_rng(0)
    sparse = np.where(rng.random((BATCH, h, w)) < 0.01, rng.uniform(1, 9, (BATCH, h, w)), 0).astype(np.float32)
    arrays = {"rgb": rng.integers(0, 256, (BATCH, h, w, 3), dtype=np.uint8), "sparse": sparse,
              "gt": rng.uniform(1, 9, (BATCH, h, w)).astype(np.float32), "gt_valid": np.ones((BATCH, h, w), bool)}
    from lipjax.data.pipeline import with_host_inputs
    from lipjax.data.frame import Batch

    batch = shard_batch(with_host_inputs(config.model, Batch(**arrays)))
    state, step = init_state(config), make_steps(config).supervised
    for _ in range(2):  # compiles: once for the fresh state, once more for the state the step returns (placement)
        state, _ = step(state, batch, jax.random.key(0))
    jax.block_until_ready(state)
    start = time.perf_counter()
    for _ in range(steps):
        state, _ = step(state, batch, jax.random.key(0))
    jax.block_until_ready(state)
    return steps * BATCH / (time.perf_counter() - start), (h, w)


def pipeline_table(args, base, model) -> None:
    """The host z0 fill's cost, then the pipeline table: host ms/frame and frames/s per worker count, per source."""
    print(f"host z0 fill alone, one {CROP[0]}x{CROP[1]} frame, 200 points: linear {fill_ms('linear'):.1f} ms, "
          f"nearest {fill_ms('nearest'):.1f} ms of CPU")
    with tempfile.TemporaryDirectory() as tmp:
        overrides = _write_fixtures(Path(tmp), frames=4 * BATCH)
        print(f"\n| source | host ms/frame (1 process, {CROP[0]}x{CROP[1]} crop, z0 linear) | "
              + " | ".join(f"frames/s, {w} worker{'s' * (w > 1)}" for w in args.workers) + " | speed-up |")
        print("|---|---:|" + "---:|" * len(args.workers) + "---:|")
        for name in args.sources:
            data = dataclasses.replace(base, source=name, **overrides[name])
            host = host_ms_per_frame(data, model, max(2, args.steps // 4))
            rounds = [[pipeline_rate(data, model, w, args.steps) for w in args.workers]
                      for _ in range(args.rounds)]  # interleaved, so that a burst of other load hits all counts
            rates = [float(np.median(r)) for r in zip(*rounds)]
            print(f"| {name} | {host:.1f} | " + " | ".join(f"{r:.1f}" for r in rates)
                  + f" | {rates[-1] / rates[0]:.2f}x |", flush=True)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--steps", type=int, default=24, help="timed batches of 8 per measurement")
    p.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    p.add_argument("--rounds", type=int, default=3, help="measurements per worker count (median reported)")
    p.add_argument("--sources", nargs="*", default=list(SOURCES), choices=SOURCES, help="none: no pipeline table")
    p.add_argument("--models", nargs="*", default=["lip_cnn_indoor", "lip_fast_indoor", "ma2018_indoor",
                                                   "unet_indoor", "cspn_indoor"])
    p.add_argument("--model-steps", type=int, default=5)
    args = p.parse_args()

    from experiments.configs import LIP_CNN_INDOOR
    from lipjax.utils import enable_compilation_cache

    enable_compilation_cache()
    from benchmarks.common import matmul_rate  # the inference benchmarks' matmul yardstick

    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at start; 2048x2048 float32 "
          f"matmul {matmul_rate(10)[1]:.0f} GFLOP/s (divide rates by it to compare machines or loads)")
    if args.sources:
        pipeline_table(args, dataclasses.replace(LIP_CNN_INDOOR.data, crop=CROP), LIP_CNN_INDOOR.model)
    if args.models:
        import jax

        print(f"\n| config | train crop | train-step images/s (batch {BATCH}, {jax.devices()[0].platform}) |")
        print("|---|---|---:|")
        for name in args.models:
            rate, (h, w) = train_step_rate(name, args.model_steps)
            print(f"| {name} | {h}x{w} | {rate:.1f} |", flush=True)
    print(f"\nload average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    main()
