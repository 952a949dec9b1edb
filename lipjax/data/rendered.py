"""The synthetic scenes rendered once into shard files on disk, and a data set that reads them back.

    render_to_disk("indoor", "train", 20000, "runs/data/indoor-train", workers=2)
    RenderedDataset("runs/data/indoor-train")[i]   # == render("indoor", "train", i, H, W), depth quantised

Layout of a rendered folder (no pickle anywhere; every array file is a plain .npy, memory-mapped on read):

    <root>/index.json                 {"format", "kind", "split", "height", "width", "count", "shard_size",
                                       "depth_dtype": "uint16", "depth_scale": value per metre,
                                       "intrinsics": {fx, fy, cx, cy} of the full frame in pixels,
                                       "window": [h, w] or null, "shards": [file stems]}
    <root>/shard-00000.rgb.npy        (n, h, w, 3) uint8
    <root>/shard-00000.depth.npy      (n, h, w) uint16, metres = value / depth_scale, 0 = invalid
    <root>/shard-00000.window.npy     (n, 2) int32 (top, left) of each frame's window (only with a window)

Frame i lives in shard i // shard_size. Frame ids are those of the on-the-fly set (frame_id(kind, split, i)),
so a sampler draws the same sparse points from a rendered frame as from the on-the-fly one.

Window. With `window=(h, w)`, each frame is a h x w window of the height x width camera, rendered directly
(the window's intrinsics are the full frame's, cropped), at a position drawn from the frame's id: the same
pixel scale as a random crop of the full frame at a quarter of the cost for a 2x2 crop, but one fixed crop
per frame instead of a new one per epoch. The camera model's vignetting is centred on the window.
"""
from __future__ import annotations

import contextlib
import dataclasses
import functools
import json
import multiprocessing
import os
import signal
import sys
import threading
from pathlib import Path

import numpy as np

from lipjax.data.errors import dataset_error
from lipjax.data.folder import KNOWN_DEPTH_SCALES
from lipjax.data.frame import Frame, Intrinsics
from lipjax.data.sampling import example_rng
from lipjax.utils import die_with_parent

FORMAT = "lipjax-rendered-v1"
INDEX = "index.json"
# Full-frame size per kind, as the shipped training configs render them (experiments/configs/base.py).
TRAINING_SIZES = {"indoor": (256, 320), "outdoor": (128, 416)}
# uint16 depth: value per metre. Indoor 1 mm steps up to 65.5 m; outdoor KITTI's 1/256 m up to 256 m.
DEPTH_SCALES = {"indoor": KNOWN_DEPTH_SCALES["nyu"], "outdoor": KNOWN_DEPTH_SCALES["kitti"]}
DEFAULT_SHARD_SIZE = 256
RENDERED_LAYOUT = """\
<root>/index.json
<root>/shard-NNNNN.rgb.npy  (n, h, w, 3) uint8
<root>/shard-NNNNN.depth.npy (n, h, w) uint16, metres = value / depth_scale"""
RENDERED_SOURCE = "lipjax data render --kind indoor|outdoor --split train --count N --out DIR"


@dataclasses.dataclass(frozen=True)
class RenderSpec:
    """What to render: frames [0, count) of (kind, split) at height x width, optionally one window per frame."""

    kind: str
    split: str
    count: int
    height: int
    width: int
    window: tuple[int, int] | None = None
    shard_size: int = DEFAULT_SHARD_SIZE

    @property
    def num_shards(self) -> int:
        return -(-self.count // self.shard_size)

    @property
    def frame_size(self) -> tuple[int, int]:
        return self.window or (self.height, self.width)


def window_corner(spec: RenderSpec, index: int) -> tuple[int, int]:
    """(top, left) of frame `index`'s window, drawn from its frame id (0, 0 without a window)."""
    from lipjax.data.synthetic import frame_id

    if spec.window is None:
        return 0, 0
    h, w = spec.window
    top, left = example_rng(0, frame_id(spec.kind, spec.split, index), "window").integers(
        0, (spec.height - h + 1, spec.width - w + 1))
    return int(top), int(left)


def _render_frame(spec: RenderSpec, index: int) -> tuple[np.ndarray, np.ndarray]:
    """(rgb (h, w, 3) uint8, depth (h, w) float32 metres) of one frame (its window when spec.window is set)."""
    from lipjax.data.synthetic import build_scene, frame_rngs, intrinsics_for, render, render_scene, frame_id

    if spec.window is None:
        frame = render(spec.kind, spec.split, index, spec.height, spec.width)
        return frame.rgb, frame.depth
    top, left = window_corner(spec, index)
    scene_rng, noise_rng = frame_rngs(spec.kind, spec.split, index)
    scene = build_scene(spec.kind, scene_rng)
    intr = intrinsics_for(spec.kind, spec.height, spec.width).cropped(top, left)
    with np.errstate(all="ignore"):
        rgb, depth, _ = render_scene(scene, spec.window[0], spec.window[1], intr, noise_rng)
    frame = Frame.from_depth(rgb, depth, intr, frame_id(spec.kind, spec.split, index))
    return frame.rgb, frame.depth


def _shard_stem(shard: int) -> str:
    return f"shard-{shard:05d}"


def _render_shard(spec: RenderSpec, shard: int, out: str) -> int:
    """Renders and writes one shard (atomically: temporary names, then rename); returns its frame count.

    A shard whose files already exist is kept, so an interrupted render continues where it stopped."""
    out_dir, stem = Path(out), _shard_stem(shard)
    names = ["rgb", "depth"] + (["window"] if spec.window else [])
    if all((out_dir / f"{stem}.{n}.npy").is_file() for n in names):
        return 0
    first, last = shard * spec.shard_size, min(spec.count, (shard + 1) * spec.shard_size)
    h, w = spec.frame_size
    scale = DEPTH_SCALES[spec.kind]
    rgb = np.empty((last - first, h, w, 3), np.uint8)
    depth = np.empty((last - first, h, w), np.uint16)
    for row, index in enumerate(range(first, last)):
        frame_rgb, frame_depth = _render_frame(spec, index)
        raw = np.rint(frame_depth.astype(np.float64) * scale)
        if raw.max() > np.iinfo(np.uint16).max:
            raise ValueError(f"frame {index}: depth {frame_depth.max():.1f} m exceeds uint16 at {scale} per metre")
        rgb[row], depth[row] = frame_rgb, raw.astype(np.uint16)
    arrays = {"rgb": rgb, "depth": depth}
    if spec.window:
        arrays["window"] = np.array([window_corner(spec, i) for i in range(first, last)], np.int32)
    for name, array in arrays.items():
        tmp = out_dir / f".{stem}.{name}.{os.getpid()}.npy"
        np.save(tmp, array, allow_pickle=False)
        os.replace(tmp, out_dir / f"{stem}.{name}.npy")
    return last - first


def _render_worker_init() -> None:
    """A render worker ignores SIGINT (a terminal's Ctrl-C reaches the whole process group; the parent stops the
    workers) and, on Linux, gets SIGTERM when its parent dies, even by SIGKILL: no worker outlives the render."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent()


@contextlib.contextmanager
def _sigterm_as_exit():
    """SIGTERM raises SystemExit(143) and Ctrl-C KeyboardInterrupt in the main thread while rendering, so that the
    worker processes are stopped on the way out; Ctrl-C does so even in a process started with SIGINT ignored (as
    `nohup` and background jobs of scripts start). No-op outside the main thread."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    previous_int = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
        signal.signal(signal.SIGINT, previous_int)


@contextlib.contextmanager
def _sigint_ignored():
    """SIGINT ignored while processes are spawned: a spawned process inherits the ignored signal through exec and
    Python keeps it ignored at start-up, so a Ctrl-C can never reach a worker before `_render_worker_init` runs.
    No-op outside the main thread."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _index(spec: RenderSpec) -> dict:
    from lipjax.data.synthetic import intrinsics_for

    return {
        "format": FORMAT, "kind": spec.kind, "split": spec.split, "height": spec.height, "width": spec.width,
        "count": spec.count, "shard_size": spec.shard_size, "depth_dtype": "uint16",
        "depth_scale": DEPTH_SCALES[spec.kind], "depth_unit": "metres = value / depth_scale",
        "intrinsics": dataclasses.asdict(intrinsics_for(spec.kind, spec.height, spec.width)),
        "window": list(spec.window) if spec.window else None,
        "shards": [_shard_stem(s) for s in range(spec.num_shards)],
    }


def render_to_disk(kind: str, split: str, count: int, out: str | os.PathLike, *, height: int | None = None,
                   width: int | None = None, window: tuple[int, int] | None = None, workers: int | None = None,
                   shard_size: int = DEFAULT_SHARD_SIZE, progress: bool = True) -> Path:
    """Renders frames [0, count) of the synthetic (kind, split) set into `out` with `workers` processes.

    Args:
      height, width: full-frame size in pixels (default TRAINING_SIZES[kind]).
      window: (h, w) to store one window per frame instead (module docstring); None stores full frames.
      workers: processes (default: every core). Each renders whole shards; the shards are independent.
    Returns the folder. Re-running with the same arguments finishes an interrupted render; different
    arguments in a folder that holds a render are an error. SIGTERM (SystemExit 143), Ctrl-C (KeyboardInterrupt)
    or a failing shard stop every worker process before the exception leaves; finished shards stay.
    """
    from lipjax.data.synthetic import check_kind_split, check_size

    check_kind_split(kind, split)
    default_h, default_w = TRAINING_SIZES[kind]
    height, width = check_size(height or default_h, width or default_w)
    if count < 1 or shard_size < 1:
        raise ValueError(f"count and shard_size must be >= 1, got {count} and {shard_size}")
    if window is not None and not (8 <= window[0] <= height and 8 <= window[1] <= width):
        raise ValueError(f"window {window} must fit in the {height}x{width} frame (and be >= 8 pixels)")
    spec = RenderSpec(kind, split, int(count), height, width, tuple(window) if window else None, int(shard_size))
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    index = _index(spec)
    partial = out / f"{INDEX}.partial"
    for existing in (out / INDEX, partial):
        if existing.is_file() and json.loads(existing.read_text()) != index:
            raise ValueError(f"{out} already holds a different render ({existing.name}); choose another --out")
    partial.write_text(json.dumps(index, indent=1) + "\n")
    for stale in out.glob(".shard-*.npy"):  # the half-written shards of a stopped render
        stale.unlink()
    workers = max(1, min(workers or os.cpu_count() or 1, spec.num_shards))
    from tqdm.auto import tqdm

    bar = tqdm(total=spec.count, desc=f"render {kind}/{split}", disable=not progress, unit="frame")
    with _sigterm_as_exit(), bar:
        if workers == 1:
            for shard in range(spec.num_shards):
                bar.update(_render_shard(spec, shard, str(out)))
        else:
            context = multiprocessing.get_context("spawn")  # no inherited threads or jax state
            with _sigint_ignored():  # a worker still starting up would print a KeyboardInterrupt traceback
                pool = context.Pool(workers, initializer=_render_worker_init)
            try:
                for done in pool.imap_unordered(functools.partial(_render_shard, spec, out=str(out)),
                                                range(spec.num_shards)):
                    bar.update(done)
            except BaseException:
                pool.terminate()
                raise
            else:
                pool.close()
            finally:
                pool.join()
    os.replace(partial, out / INDEX)
    return out


class RenderedDataset:
    """A folder written by render_to_disk, as Frames (memory-mapped shards; loads only the frames asked for).

    dataset[i] has rgb uint8, depth float32 metres (the stored uint16 / depth_scale), valid = depth > 0, the
    frame's intrinsics (its window's when rendered with one) and id = frame_id(kind, split, i).

    Args:
      root: the folder holding index.json.
    """

    def __init__(self, root: str | os.PathLike):
        self.root = Path(root)
        path = self.root / INDEX
        if not path.is_file():
            hint = " (the render did not finish; run it again)" if (self.root / f"{INDEX}.partial").is_file() else ""
            raise dataset_error(f"No rendered data set{hint}: index.json not found in", self.root, RENDERED_LAYOUT,
                                RENDERED_SOURCE)
        self.index = json.loads(path.read_text())
        if self.index.get("format") != FORMAT:
            raise dataset_error(f"Unknown rendered format {self.index.get('format')!r} (expected {FORMAT!r})", path)
        self.kind, self.split = self.index["kind"], self.index["split"]
        self.count, self.shard_size = int(self.index["count"]), int(self.index["shard_size"])
        self.depth_scale = float(self.index["depth_scale"])
        self.intrinsics = Intrinsics(**self.index["intrinsics"])
        self.window = tuple(self.index["window"]) if self.index["window"] else None
        self._shards: dict[int, dict[str, np.ndarray]] = {}

    def __len__(self) -> int:
        return self.count

    @property
    def kinds(self) -> tuple[str, ...]:
        """The kinds of scene in the data set (as RenderedMixture.kinds)."""
        return (self.kind,)

    @property
    def frame_size(self) -> tuple[int, int]:
        """(h, w) of every stored frame."""
        return self.window or (int(self.index["height"]), int(self.index["width"]))

    def _shard(self, shard: int) -> dict[str, np.ndarray]:
        if shard not in self._shards:  # memory maps are cheap: keep them open
            stem = self.index["shards"][shard]
            names = ["rgb", "depth"] + (["window"] if self.window else [])
            arrays = {}
            for name in names:
                file = self.root / f"{stem}.{name}.npy"
                if not file.is_file():
                    raise dataset_error("Rendered shard file missing", file, RENDERED_LAYOUT, RENDERED_SOURCE)
                arrays[name] = np.load(file, mmap_mode="r", allow_pickle=False)
            self._shards[shard] = arrays
        return self._shards[shard]

    def __getitem__(self, index: int) -> Frame:
        from lipjax.data.synthetic import frame_id

        if not 0 <= int(index) < self.count:
            raise IndexError(f"index {index} out of range for {self.count} rendered frames in {self.root}")
        shard, row = divmod(int(index), self.shard_size)
        arrays = self._shard(shard)
        depth = np.asarray(arrays["depth"][row], np.float32) / np.float32(self.depth_scale)
        intrinsics = self.intrinsics
        if self.window:
            top, left = (int(v) for v in arrays["window"][row])
            intrinsics = intrinsics.cropped(top, left)
        return Frame.from_depth(np.array(arrays["rgb"][row]), depth, intrinsics,
                                frame_id(self.kind, self.split, int(index)))

    def __getstate__(self) -> dict:  # worker processes reopen the memory maps themselves
        return {**self.__dict__, "_shards": {}}

    def __repr__(self) -> str:
        where = os.fspath(self.root)
        return f"RenderedDataset({where!r}: {self.kind}/{self.split}, {self.count} frames {self.frame_size})"


class RenderedMixture:
    """Several rendered folders of one frame size as one data set: their frames one folder after another.

    For training one model on several kinds of scene (rooms and streets), e.g. `data.root=A,B` with
    `source="rendered"` (lipjax.data.sources). Frames keep their own folder's intrinsics and frame ids.

    Args:
      parts: the RenderedDatasets, every one with the same frame_size (batches stack frames of one size).
    """

    def __init__(self, parts: list[RenderedDataset]):
        sizes = {part.frame_size for part in parts}
        if len(sizes) != 1:
            listed = ", ".join(f"{part.root} {part.frame_size[0]}x{part.frame_size[1]}" for part in parts)
            raise ValueError(f"rendered folders of different frame sizes cannot share batches ({listed}); render them "
                             "at one size, e.g. `lipjax data render ... --window 256 320`")
        self.parts = list(parts)
        self.kinds = tuple(part.kind for part in parts)
        self.frame_size = sizes.pop()
        self._ends = np.cumsum([len(part) for part in parts])

    def __len__(self) -> int:
        return int(self._ends[-1])

    def __getitem__(self, index: int) -> Frame:
        if not 0 <= int(index) < len(self):
            raise IndexError(f"index {index} out of range for {len(self)} rendered frames")
        part = int(np.searchsorted(self._ends, int(index), side="right"))
        start = int(self._ends[part - 1]) if part else 0
        return self.parts[part][int(index) - start]

    def __repr__(self) -> str:
        return f"RenderedMixture({self.parts!r})"


def open_rendered(root: str | os.PathLike) -> RenderedDataset | RenderedMixture:
    """The rendered folder at `root`, or, for a comma-separated list of folders, their RenderedMixture."""
    roots = [part.strip() for part in os.fspath(root).split(",") if part.strip()]
    if len(roots) == 1:
        return RenderedDataset(roots[0])
    return RenderedMixture([RenderedDataset(r) for r in roots])
