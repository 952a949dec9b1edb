"""Models run over files and folders on disk: what `lipjax complete` and `lipjax project` do.

    done = complete_files("frame.png", "sparse.npy", "dense.npy", model="linear")          # one frame
    done = complete_files("rgb/", "sparse/", "dense/", depth_scale=1000, out_format="png")   # a folder of frames
    print(done.summary())     # "wrote 100 frame(s) to dense in 12.3 s: 8.13 frames/s"
    print(explain_files("frame.png", "sparse.npy").summary())   # each frame's plan (--explain): nothing run or written
    print(project_file("image.png", "sweep.bin", "calib.txt", "sparse.npy").summary())      # a LiDAR sweep

Depth is in metres; 0 means no depth. The parameters of `complete_files` are the flags of `lipjax complete` (its
--help, lipjax.cli_help.COMPLETE_HELP, describes the formats), and its errors name those flags. By default a frame's
output is what `lipjax.complete` returns for it (lipjax.methods.complete: the model's or method's depth as it gives
it); `fill_all` and `blank_unsupported` change both the same way. The folders the outputs go to are checked
writable before anything is read or run (`check_writable`).

A folder overlaps reading, the model and writing: worker threads read and decode the next frames (OpenCV and numpy's
file reads release the GIL); the model runs on the first frame in the calling thread (one compilation), then on
MODEL_THREADS frames at once in threads of their own (XLA runs a model on about one core); one background thread
post-processes (uncertainty, the support mask) and writes each completed frame, in order. The model is loaded once and
compiled once per frame shape (jax.jit caches one executable per shape). On 100 KITTI-size frames (`python -m
benchmarks.folder_speed --keep DIR`, lip-any at 132x455) on the 2-core machine with training paused, a folder ran
at 1.06-1.18x the warm single-frame rate (3 runs; single frame 32-35 ms); one frame at a time it ran at 0.86-0.90x in
the same session (0.78-0.87 in an earlier one, median 0.86 of 7 runs). Since the default path averages in the flipped
frame on scan lines (lipjax.inference.flips), each frame keeps both cores busy itself, and the folder ran at
0.82-0.89x (3 runs; single frame 38-41 ms), 0.82-0.85x one frame at a time (2 runs, interleaved). Per frame a folder
adds 17.5 ms of CPU that one frame does not pay: PNG decoding 8.8, PNG encoding 5.6, the support mask 3.1. Every
output file is written under a temporary name beside it and renamed once whole (lipjax.utils.written_whole), so a
failing frame (an unreadable file, a full disk) leaves the frames before it written whole and nothing of itself or the
frames after it.
"""
from __future__ import annotations

import collections
import contextlib
import dataclasses
import functools
import itertools
import os
import sys
import time
import warnings
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from lipjax import defaults
from lipjax.data.folder import (KNOWN_DEPTH_SCALES, check_one_depth_format, output_format, pair_frames, read_frame,
                                read_intrinsics, read_rgb, write_depth)
from lipjax.data.frame import Intrinsics
from lipjax.data.lidar import project_sweep, read_lidar_frame
from lipjax.classical import fill_holes
from lipjax.defaults import CROSS_CHECK
from lipjax.inference import Completer, FramePlan, complete_frame, frame_size, one_frame, plan_frame
from lipjax.inputs import SCENE_MEDIAN_M, check_depth_scale, is_lidar_pattern, likely_units, unit_hint
from lipjax.interfaces import SCENE_MAX_DEPTH_M
from lipjax.methods import get_completer
from lipjax.pointcloud import IntrinsicsLike, ProjectionCounts, backproject_rgbd, write_ply
from lipjax.uncertainty import drop_uncertain, expected_error, support_mask, write_uncertainty
from lipjax.utils import holding_warnings_back, warn_user
from lipjax.viz import fitting_range

DEFAULT_PNG_OUT_SCALE = KNOWN_DEPTH_SCALES["kitti"]
"""PNG value per metre of .png output when no depth scale was given (KITTI's)."""
READ_WORKERS = 2
"""Threads that read and decode the next frames of a folder while the model runs."""
MODEL_THREADS = 2
"""Frames of a folder a learned model completes at once, each in a thread of its own: XLA runs a model on about one
core (two frames keep this machine's two busy; lipjax.crosscheck), and a frame's host work overlaps the other's."""
READ_AHEAD = 4
"""Frames read ahead of the model (they wait in memory: a KITTI frame with its depth takes about 3 MB)."""
WRITE_BACKLOG = 4
"""Completed frames that may wait for the writing thread before the model waits for it."""


@dataclasses.dataclass(frozen=True)
class Job:
    """One frame to complete: its input files and the files it is written to (None: not written)."""

    rgb: Path
    depth: Path  # sparse depth (.png / .npy), or a LiDAR sweep
    out: Path
    ply: Path | None = None
    uncertainty: Path | None = None


@dataclasses.dataclass(frozen=True)
class Plan:
    """The jobs of one `complete_files` call, the output format ("npy", "png", "color.png") and whether the
    sparse input is metres already (.npy depth or a sweep; never scaled)."""

    jobs: list[Job]
    fmt: str
    metres_in: bool


def plan_jobs(rgb: str | os.PathLike, depth: str | os.PathLike, out: str | os.PathLike, *,
              ply: str | os.PathLike | None = None, uncertainty: str | os.PathLike | None = None,
              out_format: str | None = None) -> Plan:
    """The frames of an RGB image and its depth, or of two folders of them (paired by `pair_frames`), with their
    output paths: with folders, out, ply and uncertainty are folders getting <rgb stem>.<format> per frame.

    Raises ValueError (a one-line message naming the `lipjax complete` flag) for missing inputs, a file given
    with a folder, a folder mixing .png and .npy depth, or an unknown output format."""
    pairs = frame_pairs(rgb, depth)
    rgb, depth, out = Path(rgb), Path(depth), Path(out)
    ply, uncertainty = ply and Path(ply), uncertainty and Path(uncertainty)
    if not rgb.is_dir():
        if out_format:
            raise ValueError("--out-format is for folders; for one frame the extension of --out chooses the format")
        fmt = output_format(out)
        if uncertainty and uncertainty.suffix.lower() not in (".npy", ".png"):
            raise ValueError(f"--uncertainty {uncertainty}: use .npy (metres) or .png (colour picture)")
        return Plan([Job(rgb, depth, out, ply or None, uncertainty or None)], fmt, depth.suffix.lower() != ".png")
    for flag, path in (("--out", out), ("--ply", ply), ("--uncertainty", uncertainty)):
        if path and path.exists() and not path.is_dir():
            raise ValueError(f"{flag} {path}: with input folders, {flag} must be a folder")
    depth_suffix = pairs[0][1].suffix.lower()
    fmt = out_format or ("png" if depth_suffix == ".png" else "npy")
    jobs = [Job(r, d, out / f"{r.stem}.{fmt}", ply / f"{r.stem}.ply" if ply else None,
                uncertainty / f"{r.stem}.npy" if uncertainty else None) for r, d in pairs]
    return Plan(jobs, fmt, depth_suffix == ".npy")


def frame_pairs(rgb: str | os.PathLike, depth: str | os.PathLike) -> list[tuple[Path, Path]]:
    """(rgb, depth) paths of one frame, or of the frames of two folders (paired by `pair_frames`, one depth format);
    ValueError, one line, for missing inputs or a file given with a folder."""
    rgb, depth = Path(rgb), Path(depth)
    for p in (rgb, depth):
        if not p.exists():
            raise ValueError(f"{p}: no such file or folder")
    if rgb.is_dir() != depth.is_dir():
        raise ValueError("--rgb and --depth must both be files or both be folders")
    if not rgb.is_dir():
        return [(rgb, depth)]
    pairs = [(r, d) for _, r, d in pair_frames(rgb, depth)]
    check_one_depth_format([d for _, d in pairs])
    return pairs


@dataclasses.dataclass(frozen=True)
class Completed:
    """What `complete_files` wrote.

    Attributes:
      outputs: the depth file of every frame, in order; plys: their point clouds (empty without ply).
      out: the `out` argument (a folder for folder inputs).
      seconds: wall-clock time of the whole call (reading, model loading and compilation, writing), seconds.
      unsupported: share of all pixels set to 0 for want of support (blank_unsupported; else 0).
      holes: share of all pixels the model or method gave no depth (0): written as 0, or given the nearest
        pixel's depth with fill_all (`filled`).
      method: the name of the model or method that ran.
      fitted_range_m: (0, top) metres of .color.png output fitted to the first frame; None when a range was
        given or the format is another.
    """

    outputs: list[Path]
    plys: list[Path]
    out: Path
    seconds: float
    unsupported: float
    fitted_range_m: tuple[float, float] | None
    holes: float = 0.0
    filled: bool = False
    method: str = ""

    def summary(self) -> str:
        """The line `lipjax complete` prints: what was written, frames/s for several frames, and notes."""
        notes = []
        if len(self.outputs) == 1:
            wrote = f"{self.outputs[0]}" + (f" and {self.plys[0]}" if self.plys else "")
        else:
            wrote = f"{len(self.outputs)} frame(s) to {self.out} in {self.seconds:.1f} s"
            notes.append(f"{len(self.outputs) / self.seconds:.3g} frames/s")
        if self.holes:
            share = f"{100 * self.holes:.1f}" if self.holes >= 0.001 else f"{100 * self.holes:.1g}"  # not "0.0 %"
            notes.append(f"{share} % of the pixels given the nearest depth (--fill-all)" if self.filled
                         else f"{share} % of the pixels left at 0 by {self.method}"
                         + ("" if self.unsupported else " (--fill-all fills them)"))
        if self.unsupported:
            notes.append(f"{100 * self.unsupported:.1f} % of the pixels without support set to 0 "
                         "(--blank-unsupported)")
        if self.fitted_range_m:
            notes.append(f"colours 0-{self.fitted_range_m[1]:.3g} m")
        return f"wrote {wrote}" + (f": {'; '.join(notes)}" if notes else "")


def check_writable(flag: str, given: str | os.PathLike, folder: Path) -> None:
    """Raises ValueError, one line naming `flag` and the folder, unless files can be written in `folder` (`given`:
    the flag's value). A folder not there yet is made by the writers (lipjax.utils.written_whole), so the nearest
    folder above it that is there must be writable. Run before any work: a read-only output folder would otherwise
    fail only after the computation, naming a temporary file."""
    there = Path(folder)
    while not there.exists() and there != there.parent:
        there = there.parent
    if not there.is_dir():
        raise ValueError(f"{flag} {given}: {there} is a file, not a folder; choose another {flag}")
    if not os.access(there, os.W_OK | os.X_OK):
        raise ValueError(f"{flag} {given}: cannot write in the folder {there} (read-only or no permission); choose "
                         f"another {flag} or make the folder writable")


def model_max_depth(completer: Any) -> float:
    """The depth range (metres) a completer was made for (10 m indoor, 85 m outdoor); 10 m when it has none (the
    hand-crafted fills)."""
    return completer.config.max_depth_m if isinstance(completer, Completer) else SCENE_MAX_DEPTH_M["indoor"]


@dataclasses.dataclass
class _Output:
    """The settings of the outputs, and what the writing thread learns while it writes (first frame's range,
    support counts). Only that thread changes it once frames are running."""

    fmt: str
    png_scale: float
    color_range: tuple[float, float] | None
    fill_all: bool
    blank_unsupported: bool
    max_uncertainty: float | None
    max_depth_m: float = SCENE_MAX_DEPTH_M["indoor"]
    method: str = ""
    fitted: bool = False
    unsupported: int = 0
    holes: int = 0
    pixels: int = 0

    def write(self, job: Job, rgb: np.ndarray, sparse: np.ndarray, dense: np.ndarray,
              intrinsics: Intrinsics | None) -> None:
        """Applies --fill-all, --max-uncertainty and --blank-unsupported to one completed frame, in the order
        lipjax.methods.complete applies them, and writes its files."""
        holes = dense <= 0
        self.holes += int(np.count_nonzero(holes))
        self.pixels += dense.size
        if self.fill_all and holes.any():
            dense = fill_holes(dense)
        if job.uncertainty or self.max_uncertainty is not None:
            u = expected_error(sparse, dense)
            if job.uncertainty:
                write_uncertainty(job.uncertainty, u, self.max_uncertainty or 0.1 * self.max_depth_m)
            if self.max_uncertainty is not None:
                dense = drop_uncertain(dense, u, self.max_uncertainty)
        if self.blank_unsupported:
            unsupported = ~support_mask(sparse)
            self.unsupported += int(np.count_nonzero(unsupported & (dense > 0)))
            dense = np.where(unsupported, np.float32(0), dense)
        if self.color_range is None:
            self.color_range, self.fitted = fitting_range(dense, self.max_depth_m), self.fmt == "color.png"
        write_depth(job.out, dense, self.fmt, self.png_scale, self.color_range)
        if job.ply is not None:
            write_ply(job.ply, *backproject_rgbd(dense, rgb, intrinsics))


def prefetched(read: Callable[[Any], Any], items: Iterable[Any], workers: int = READ_WORKERS,
               ahead: int = READ_AHEAD) -> Iterator[Any]:
    """read(item) for every item, in order, each computed up to `ahead` items in advance in `workers` threads.
    An error of read(item) is raised when that item's turn comes; closing the iterator cancels what is left."""
    items = iter(items)
    with ThreadPoolExecutor(workers, thread_name_prefix="lipjax-read") as pool:
        pending = collections.deque(pool.submit(read, item) for item in itertools.islice(items, ahead))
        try:
            while pending:
                result = pending.popleft().result()
                pending.extend(pool.submit(read, item) for item in itertools.islice(items, 1))
                yield result
        finally:
            for future in pending:
                future.cancel()


class _Writer:
    """Runs `_Output.write` on one background thread, in order; the model waits only when WRITE_BACKLOG frames
    wait. After a failed write the frames queued behind it are not written. Leaving the block waits for every
    queued frame, and raises the first error of a write."""

    def __init__(self, output: _Output):
        self.output, self.pending, self.failed = output, collections.deque(), False
        self.pool = ThreadPoolExecutor(1, thread_name_prefix="lipjax-write")

    def __enter__(self) -> "_Writer":
        return self

    def _write(self, *frame: Any) -> None:  # on the writing thread, one frame after the other
        if self.failed:
            return
        try:
            self.output.write(*frame)
        except BaseException:
            self.failed = True
            raise

    def submit(self, *frame: Any) -> None:
        while self.pending and (len(self.pending) >= WRITE_BACKLOG or self.pending[0].done()):
            self.pending.popleft().result()  # a failed write stops the run at once
        self.pending.append(self.pool.submit(self._write, *frame))

    def __exit__(self, *exc_info) -> None:
        self.pool.shutdown(wait=True)
        errors = [f.exception() for f in self.pending if not f.cancelled()]
        if exc_info[0] is None and any(errors):
            raise next(e for e in errors if e is not None)


def _load(model: Any, iterations: int | None, sparse: np.ndarray, rgb_file: Path, max_side: int | None,
          log: Callable[[str], None] | None):
    """The completer of `model` (the default when None: one for every input, named to `log`); warns when the frame
    is large enough to want --max-side."""
    completer = get_completer(model, iterations)
    if model is None and log is not None:
        log(f"model: {completer.name}, the default for every input; choose another with --model")
    h, w = frame_size(completer, sparse, max_side)
    if max_side is None and h * w > defaults.LARGE_FRAME_PIXELS:  # read here: tests lower it
        warnings.warn(f"{rgb_file}: a {sparse.shape[0]}x{sparse.shape[1]} frame ({sparse.size / 1e6:.1f} Mpixel) "
                      "runs slowly and needs gigabytes at full size; --max-side 1024 runs it downsized", stacklevel=2)
    return completer


def model_threads(completer: Any) -> int:
    """Frames of a folder completed at once: MODEL_THREADS for a learned model (a `Completer`), at most as many as
    the cores this process may use (`--threads`); one for anything else (a classical fill holds the GIL most of the
    time, and a model object of the user's is never called from two threads)."""
    if not isinstance(completer, Completer):
        return 1
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return max(1, min(MODEL_THREADS, cores))


def _run(plan: Plan, read: Callable[[Job], tuple], output: _Output, model: Any, iterations: int | None,
         max_side: int | None, flip: bool | None, cross_check: bool, progress: bool,
         log: Callable[[str], None] | None, workers: int) -> None:
    """Reads (prefetched), completes and writes (`_Writer`) every job of the plan, in order: the first frame in
    this thread, then `model_threads` frames at a time in threads of their own, whose warnings are shown from this
    thread (once, at the user's line). The model is loaded after the first frame is read (input errors come before
    the slow model load); the progress bar starts after the line naming it. A frame that fails (read or completed)
    is written never, nor are those after it; those before it are."""
    from tqdm import tqdm

    completer = bar = None
    threads = 1  # frames completed at once (`model_threads`), known once the model is
    complete = functools.partial(complete_frame, max_side=max_side, flip=flip, cross_check=cross_check)
    in_flight: collections.deque = collections.deque()  # (the frame's future, its job and inputs), in order

    def deliver(job, rgb, sparse, intrinsics, dense, held=()) -> None:  # in order: warnings shown, written, counted
        for message, category in held:
            warn_user(message, category)
        writer.submit(job, rgb, sparse, dense, intrinsics)
        bar.update()

    def finish() -> None:  # the oldest frame in flight, after every frame before it
        future, *frame = in_flight.popleft()
        deliver(*frame, *future.result())

    try:
        with contextlib.closing(prefetched(read, plan.jobs, workers)) as frames, _Writer(output) as writer, \
                ThreadPoolExecutor(MODEL_THREADS, thread_name_prefix="lipjax-model") as pool:
            while True:
                try:
                    job, rgb, sparse, intrinsics = next(frames)
                except StopIteration:
                    break
                except Exception:  # a frame that cannot be read: the frames before it are written whole
                    while in_flight:
                        finish()
                    raise
                first = completer is None
                if first:
                    completer = _load(model, iterations, sparse, job.rgb, max_side, log)
                    output.max_depth_m, output.method = model_max_depth(completer), completer.name
                    threads = model_threads(completer)
                    bar = tqdm(total=len(plan.jobs), desc="lipjax complete", unit="frame", file=sys.stderr,
                               disable=not progress or len(plan.jobs) < 2)
                if first or threads == 1:  # in this thread (the first frame alone: one compilation)
                    deliver(job, rgb, sparse, intrinsics, complete(completer, rgb, sparse))
                    continue
                in_flight.append((pool.submit(holding_warnings_back, complete, completer, rgb, sparse),
                                  job, rgb, sparse, intrinsics))
                if len(in_flight) == threads:
                    finish()
            while in_flight:
                finish()
    finally:
        if bar is not None:
            bar.close()


def complete_files(rgb: str | os.PathLike, depth: str | os.PathLike | None, out: str | os.PathLike | None, *,
                   lidar: str | os.PathLike | None = None, calib: str | os.PathLike | None = None, camera: int = 2,
                   depth_scale: float | None = None, model: Any = None, iterations: int | None = None,
                   max_side: int | None = None, flip: bool | None = None, cross_check: bool = CROSS_CHECK,
                   out_format: str | None = None,
                   color_range: tuple[float, float] | None = None, ply: str | os.PathLike | None = None,
                   intrinsics: IntrinsicsLike | str | os.PathLike | None = None,
                   uncertainty: str | os.PathLike | None = None, max_uncertainty: float | None = None,
                   fill_all: bool = False, blank_unsupported: bool = False, progress: bool = True,
                   log: Callable[[str], None] | None = None, workers: int = READ_WORKERS) -> Completed:
    """Completes the sparse depth of one frame or of a folder of frames and writes the results.

    Args:
      rgb, depth: an image and its sparse depth (16-bit .png, metres = value / depth_scale; .npy metres), or two
        folders of them; or, with `lidar` and its `calib` (and KITTI `camera`) instead of `depth`, one sweep.
      out: the output file (.npy metres, .png 16-bit at depth_scale or 256 per metre, .color.png a picture over
        `color_range` metres, by default fitted to the first frame), or a folder with `out_format`.
      model, iterations: anything lipjax.methods.get_completer takes; None: the default of the first frame.
      max_side: run frames downsized to this longer side, pixels (default: the working size of the samples).
      flip: average a learned model's estimate with that of the flipped frame (lipjax.inference.flip_averaged:
        more accurate, twice the model's work); None: on LiDAR scan lines (lipjax.inference.flips).
      cross_check: check a learned model against the linear fill on held-out samples (lipjax.crosscheck).
      ply, intrinsics: also write a coloured point cloud (metres), with the RGB camera's intrinsics (pixels: an
        Intrinsics, (fx, fy, cx, cy), K, or a file lipjax.data.folder.read_intrinsics reads; a sweep's calibration
        gives them otherwise).
      uncertainty, max_uncertainty: also write the expected absolute error (metres); depth 0 where it is above
        max_uncertainty metres.
      fill_all: depth at every pixel: the 0s the model or method leaves get the nearest pixel's depth
        (lipjax.classical.fill_holes). blank_unsupported: 0 where no sample supports the depth
        (lipjax.uncertainty.support_mask). Neither (the default): the depth as lipjax.complete returns it.
      progress: a progress bar on stderr for several frames. log: receives the line naming the default model.
      workers: threads reading the next frames of a folder while the model runs.

    Returns Completed (its `summary()` is the line the command prints). Raises ValueError / OSError with a
    one-line message for anything the user can fix, before any frame is read when it can (an output folder that
    cannot be written, contradicting flags, ...).
    """
    start = time.perf_counter()
    if out is None:
        raise ValueError("--out is required: the file (or folder) to write; only --explain writes nothing")
    if fill_all and blank_unsupported:
        raise ValueError("--fill-all (depth at every pixel) and --blank-unsupported (0 where no sample supports it) "
                         "contradict each other; pass one of them")
    check_sources(rgb, depth, lidar, calib)
    if max_uncertainty is not None and not max_uncertainty >= 0:
        raise ValueError(f"--max-uncertainty {max_uncertainty:g}: must be >= 0 metres")
    intrinsics = read_intrinsics(intrinsics, camera)
    if ply and intrinsics is None and lidar is None:
        raise ValueError("--ply needs the camera intrinsics: --intrinsics fx fy cx cy or --intrinsics-file F")
    if color_range and not color_range[1] > color_range[0]:
        raise ValueError(f"--color-range {color_range[0]:g} {color_range[1]:g}: MAX_M must be > MIN_M")
    plan = plan_jobs(rgb, depth if lidar is None else lidar, out, ply=ply, uncertainty=uncertainty,
                     out_format=out_format)
    for flag, given in (("--out", out), ("--ply", ply), ("--uncertainty", uncertainty)):  # before any work
        paths = [getattr(j, flag.lstrip("-")) for j in plan.jobs]  # Job.out, .ply, .uncertainty
        for folder in {p.parent for p in paths if p is not None}:
            check_writable(flag, given, folder)
    if depth_scale and plan.metres_in and plan.fmt != "png":
        warnings.warn(f"--depth-scale {depth_scale:g} is ignored: {'the sweep is' if lidar else '.npy depth is'} "
                      "metres, never scaled (--depth-scale applies to .png depth, in and out)", stacklevel=2)

    def read(job: Job) -> tuple[Job, np.ndarray, np.ndarray, Intrinsics | None]:
        frame_rgb, sparse, calibrated = read_inputs(job.rgb, job.depth, depth_scale, calib, camera)
        return job, frame_rgb, sparse, intrinsics or calibrated

    output = _Output(plan.fmt, depth_scale or DEFAULT_PNG_OUT_SCALE, tuple(color_range) if color_range else None,
                     fill_all, blank_unsupported, max_uncertainty)
    _run(plan, read, output, model, iterations, max_side, flip, cross_check, progress, log, workers)
    pixels = output.pixels or 1
    return Completed([j.out for j in plan.jobs], [j.ply for j in plan.jobs if j.ply], Path(out),
                     time.perf_counter() - start, output.unsupported / pixels,
                     output.color_range if output.fitted else None, output.holes / pixels, fill_all, output.method)


def check_sources(rgb: str | os.PathLike, depth: str | os.PathLike | None, lidar: str | os.PathLike | None,
                  calib: str | os.PathLike | None) -> None:
    """ValueError, one line, unless the sparse input comes one way: `depth` (a file, or a folder with an `rgb`
    folder), or one `lidar` sweep with its `calib` for one `rgb` image."""
    if (depth is None) == (lidar is None):
        raise ValueError("give the sparse depth as --depth SPARSE, or a LiDAR sweep as --lidar SWEEP --calib FILE")
    if (lidar is None) != (calib is None):
        raise ValueError("--lidar SWEEP and --calib FILE go together: the sweep, and its calibration with the camera")
    if lidar is not None and Path(rgb).is_dir():
        raise ValueError("--lidar takes one sweep with one --rgb image, not a folder")


def read_inputs(rgb: Path, depth: Path, depth_scale: float | None = None, calib: str | os.PathLike | None = None,
                camera: int = 2) -> tuple[np.ndarray, np.ndarray, Intrinsics | None]:
    """(rgb (H, W, 3) uint8, sparse (H, W) float32 metres, the intrinsics a calibration gives or None) of one frame
    as `lipjax complete` reads it: an image and its sparse depth (`read_depth_frame`), or with `calib` an image and
    the LiDAR sweep `depth` projected into it (lipjax.data.lidar.read_lidar_frame; KITTI `camera`)."""
    if calib is None:
        return (*read_depth_frame(rgb, depth, depth_scale), None)
    return read_lidar_frame(rgb, depth, calib, camera)


@dataclasses.dataclass(frozen=True)
class Explained:
    """What `explain_files` found: each frame's RGB file with its plan (lipjax.inference.FramePlan)."""

    frames: list[tuple[Path, FramePlan]]

    def summary(self) -> str:
        """What `lipjax complete --explain` prints: each frame's RGB file, then its plan, one decision a line."""
        return "\n".join(f"{path}:\n" + "\n".join(f"  {line}" for line in plan.describe())
                         for path, plan in self.frames)


def explain_files(rgb: str | os.PathLike, depth: str | os.PathLike | None = None, *,
                  lidar: str | os.PathLike | None = None, calib: str | os.PathLike | None = None, camera: int = 2,
                  depth_scale: float | None = None, model: Any = None, iterations: int | None = None,
                  max_side: int | None = None, flip: bool | None = None,
                  cross_check: bool = CROSS_CHECK) -> Explained:
    """The plan (lipjax.inference.plan_frame) of every frame that `complete_files` completes with the same
    arguments: each frame read and checked and its plan made; no model runs and nothing is written (`lipjax
    complete --explain`). Raises ValueError / OSError, one line, as `complete_files` does."""
    check_sources(rgb, depth, lidar, calib)
    completer, frames = None, []
    for rgb_path, depth_path in frame_pairs(rgb, depth if lidar is None else lidar):
        frame_rgb, sparse, _ = read_inputs(rgb_path, depth_path, depth_scale, calib, camera)
        _, sparse = one_frame(frame_rgb, sparse)
        if completer is None:  # after the first frame is read, as `complete_files` loads it
            completer = get_completer(model, iterations)
        frames.append((rgb_path, plan_frame(completer, sparse, max_side, flip=flip, cross_check=cross_check)))
    return Explained(frames)


def check_npy_depth_dtype(path: str | os.PathLike) -> None:
    """A one-line ValueError when a depth .npy holds integers: depth .npy is float metres, and integers are another
    unit (millimetres, centimetres: the likely one named, lipjax.inputs.likely_units) or metres cut to whole
    numbers (a median within the depth of real scenes). Files numpy cannot read are left to the reader's error."""
    try:
        raw = np.load(path, mmap_mode="r", allow_pickle=False)
    except Exception:  # noqa: BLE001 - lipjax.data.folder.read_depth names what is wrong with the file
        return
    if not np.issubdtype(raw.dtype, np.integer):
        return
    depth = np.asarray(raw, np.float64)
    depth = depth[..., 0] if depth.ndim == 3 and depth.shape[-1] == 1 else depth
    samples = depth[depth > 0]
    median = float(np.median(samples)) if samples.size else 0.0
    head = f"{path}: depth .npy holds {raw.dtype} (integer) values (median {median:.0f}), not float metres"
    if median <= SCENE_MEDIAN_M["outdoor"][1]:
        raise ValueError(f"{head}: metres cut to whole numbers? save the depth as float32 metres before any cast to "
                         "an integer type")
    lidar = depth.ndim == 2 and is_lidar_pattern(depth)
    units = likely_units(samples, lidar)
    per_metre = units[0][1] if units else "units_per_metre"
    raise ValueError(f"{head} ({unit_hint(samples, lidar)}): save it as float32 metres, e.g. "
                     f"depth.astype(np.float32) / {per_metre}")


def read_depth_frame(rgb_path: str | os.PathLike, depth_path: str | os.PathLike,
                     scale: float | None) -> tuple[np.ndarray, np.ndarray]:
    """lipjax.data.folder.read_frame (rgb (H, W, 3) uint8, sparse (H, W) float32 metres) with the checks of the depth
    file's numbers that `lipjax complete` makes: a .npy of integers is an error (`check_npy_depth_dtype`); a PNG
    whose --depth-scale puts many samples beyond every model's range warns, naming the scale that fits
    (lipjax.inputs.check_depth_scale)."""
    suffix = Path(depth_path).suffix.lower()
    if suffix == ".npy":
        check_npy_depth_dtype(depth_path)
    rgb, sparse = read_frame(rgb_path, depth_path, scale)
    if suffix == ".png":
        check_depth_scale(sparse, scale)
    return rgb, sparse


@dataclasses.dataclass(frozen=True)
class Projected:
    """What `project_file` wrote: the file, the (H, W) float32 sparse depth in it (metres, 0 = no point), and where
    every point of the sweep went."""

    path: Path
    sparse: np.ndarray
    counts: ProjectionCounts

    def summary(self) -> str:
        """The line `lipjax project` prints: the file, how many pixels have depth, their range (metres), and the
        sweep's points kept and dropped."""
        sparse, (h, w) = self.sparse, self.sparse.shape
        n = int((sparse > 0).sum())
        return (f"wrote {self.path}: depth at {n} pixels ({100 * n / sparse.size:.1f} % of {w}x{h}), "
                f"{sparse[sparse > 0].min():.2f} to {sparse.max():.2f} m; {self.counts.summary()}")


def project_file(rgb: str | os.PathLike, lidar: str | os.PathLike, calib: str | os.PathLike,
                 out: str | os.PathLike, *, camera: int = 2, depth_scale: float | None = None) -> Projected:
    """Projects a LiDAR sweep into the camera of `rgb` (lipjax.data.lidar.read_lidar_frame) and writes the sparse
    depth to `out` (.npy metres, .png 16-bit at depth_scale or 256 per metre, .color.png a picture from 0 to its
    farthest point)."""
    fmt = output_format(out)
    check_writable("--out", out, Path(out).parent)
    sparse, _, counts = project_sweep(lidar, calib, read_rgb(rgb).shape[:2], camera, return_counts=True,
                                      image_path=rgb)
    write_depth(out, sparse, fmt, depth_scale or DEFAULT_PNG_OUT_SCALE, (0.0, float(sparse.max())))
    return Projected(Path(out), sparse, counts)
