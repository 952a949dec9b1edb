"""Runs any depth completer over a data set and reports metrics (lipjax.metrics) and time per frame.

    result = evaluate(NearestFill(), dataset, UniformSampler(200), min_depth_m=0.0, max_depth_m=10.0)
    print(markdown_table({"nearest": result}))

    source, protocol = open_eval_source("nyu_h5", "/data/nyudepthv2")   # a training source, read as training does
    result = evaluate(NearestFill(), source.dataset, source.sampler, min_depth_m=protocol.min_depth_m,
                      max_depth_m=protocol.max_depth_m)

    report = evaluate_methods(["nearest", "lip-fast-indoor"], data="my_frames", max_depth_m=10)   # `lipjax evaluate`
    print(report.header()); print(markdown_table(report.results))

`open_eval_data` opens what `lipjax evaluate --data` or `--source` names (the synthetic scenes, a folder, a training
source) in one place; `evaluate_methods` scores every method on it.

The evaluation protocol, in one place:
  - the sparse input of each frame is `sampler(frame, seed)`; samplers derive their randomness from the
    frame id and this seed, so every method sees the same inputs and reruns are identical;
  - metrics are per image over valid ground truth in (min_depth_m, max_depth_m], then averaged over images
    (see lipjax.metrics);
  - time per frame is the wall-clock time of the completer call alone (sampling and metrics excluded), including
    the conversion of its output to numpy, which waits for asynchronous JAX computations to finish. The first
    call on a new image shape of a jitted model compiles, so one untimed warm-up call on the first frame
    precedes the timed pass (that frame is then run again, timed). Times depend on the machine and its load.
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import statistics
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lipjax.interfaces import DepthCompleter
from lipjax.data.frame import Frame
from lipjax.data.protocols import EvalProtocol
from lipjax.data.sampling import DEFAULT_SAMPLER
from lipjax.data.sources import OWN_INPUT, Source, open_source, range_protocol
from lipjax.inference import AtWorkingSize
from lipjax.methods import get_completer
from lipjax.metrics import DEFAULT_PRED_FLOOR_M, MetricAggregator, compute_metrics

Sampler = Callable[[Frame, int], np.ndarray]  # (frame, seed) -> sparse (H, W) float32 metres, 0 = no sample

DEFAULT_COLUMNS = (
    "rmse_m",
    "mae_m",
    "rel",
    "delta1_pct",
    "delta2_pct",
    "delta3_pct",
    "irmse_1_per_km",
    "imae_1_per_km",
    "mae_sampled_m",
    "mae_unsampled_m",
    "mae_vs_input_m",
    "ms_per_frame",
)
# Decimal places per column in tables; others get 3.
_DECIMALS = {"rmse_mm": 1, "mae_mm": 1, "delta1_pct": 2, "delta2_pct": 2, "delta3_pct": 2, "ms_per_frame": 1,
             "irmse_1_per_km": 2, "imae_1_per_km": 2}


@dataclasses.dataclass
class EvalResult:
    """Metrics of one completer over one data set.

    Attributes:
      name: the completer's name.
      metrics: data-set metrics, each the mean over images of the per-image values (lipjax.metrics names).
      counts: number of images behind each mean; summed pixel counts under the "n_" keys.
      per_image: one dict per frame: "id", the per-image metrics and "ms" (completion time, milliseconds).
      ms_per_frame: mean completion time per frame in milliseconds (warm-up call excluded).
      ms_per_frame_median: median of the same.
      num_images: frames evaluated.
      min_depth_m, max_depth_m: the evaluated ground-truth depth range, metres.
      size: where the completer ran: "input" (the frame's size, as the tables) or "working" (lipjax.complete's
        default path, `lipjax.inference.AtWorkingSize`).
    """

    name: str
    metrics: dict[str, float]
    counts: dict[str, int]
    per_image: list[dict[str, Any]]
    ms_per_frame: float
    ms_per_frame_median: float
    num_images: int
    min_depth_m: float
    max_depth_m: float
    size: str = "input"

    def row(self) -> dict[str, float]:
        """The metrics plus "ms_per_frame", as one table row."""
        return {**self.metrics, "ms_per_frame": self.ms_per_frame}

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


def open_eval_source(
    source: str,
    root: str | os.PathLike | None,
    split: str = "val",
    *,
    sampler: str = DEFAULT_SAMPLER,
    protocol: str | None = None,
    raw_root: str | os.PathLike | None = None,
    depth_scale: float | None = None,
    kind: str | None = None,
) -> tuple[Source, EvalProtocol | None]:
    """Every frame of `split` of a training source, read by the code training reads it with
    (lipjax.data.sources.open_source), and the protocol whose depth range its evaluation uses.

    Args:
      source, root, raw_root, depth_scale: the data set, as lipjax.train.config.DataConfig names them.
      split: "val" or "train". source="rendered" evaluates the frames in `root` whatever the split (training
        validates on the synthetic val split instead); a comma-separated list of folders of one kind is one set.
      sampler: the sparse input, a lipjax.data.sampling spec or "input[:N]" (the data set's own sparse input).
      protocol: a lipjax.data.protocols name, "none" (frames as they are) or None (the source's default).
      kind: "indoor" or "outdoor", the synthetic scenes of source="synthetic" (default indoor), rendered at the
        kind's training size (lipjax.data.rendered.TRAINING_SIZES). source="rendered" reads its kind from the
        render's index.json (a different `kind` is an error); other sources take none.

    Returns:
      (Source with the frames and the sampler, the range protocol: lipjax.data.sources.range_protocol, which is
      synthetic_<kind> for the synthetic scenes; None for a folder, whose range the caller gives). Raises
      ValueError (DatasetError, naming the expected layout) for a missing or malformed root.
    """
    from lipjax.data.rendered import TRAINING_SIZES, open_rendered
    from lipjax.train.config import DataConfig

    if source == "rendered" and root is not None:
        kinds = sorted(set(open_rendered(root).kinds))
        if len(kinds) > 1:
            raise ValueError(f"{root} mixes {' and '.join(kinds)} renders, scored over different depth ranges; "
                             "evaluate one kind at a time")
        if kind not in (None, kinds[0]):
            raise ValueError(f"{root} holds {kinds[0]} renders, not {kind}")
        kind = kinds[0]
    elif kind is not None and source != "synthetic":
        raise ValueError(f"kind={kind!r} is for source 'synthetic' (or 'rendered'), not {source!r}")
    kind = kind or "indoor"
    if kind not in TRAINING_SIZES:
        raise ValueError(f"kind must be 'indoor' or 'outdoor', got {kind!r}")
    height, width = TRAINING_SIZES[kind]
    data = DataConfig(source=source, root=None if root is None else os.fspath(root),
                      raw_root=None if raw_root is None else os.fspath(raw_root), protocol=protocol,
                      depth_scale=depth_scale, train_sampler=sampler, val_sampler=sampler, val_images=None,
                      kind=kind, height=height, width=width)
    return open_source(data, split, render_frames=True), range_protocol(data)


def open_folder(root: str | os.PathLike, split: str | None = None, *, sampler: str | None = None,
                depth_scale: float | None = None, intrinsics: Any = None) -> tuple[Any, Sampler, str, str]:
    """The frames of a user's folder (lipjax.data.folder layout) to evaluate, with their sparse input.

    Args:
      root: holds rgb/ depth/ [sparse/] [intrinsics], or train/ and val/ subfolders that do.
      split: None: every frame (of val/ where root has train/ and val/); "train" / "val": the frames `lipjax
        train` trains / validates on (that subfolder, or else the last 5 % of the frames for val, the rest train).
      sampler: a lipjax.data.sampling spec or "input[:N]" (the folder's own sparse/<stem> maps, as depth/); by
        default "input" when the folder has sparse/, else DEFAULT_SAMPLER.
      depth_scale: PNG value per metre of the depth/ and sparse/ PNGs.
      intrinsics: overrides the folder's (lipjax.data.frame.Intrinsics); read only by a LiDAR-simulating sampler.

    Returns:
      (frames: an indexable of Frames, the sampler, its spec, which frames in words: "every frame",
      "val/: every frame", "val split: the last 5 % of the frames, as lipjax train holds them out", ...).
    """
    from lipjax.data.errors import dataset_error
    from lipjax.data.folder import SPARSE_DIR, FolderDataset
    from lipjax.data.sampling import sampler_from_spec
    from lipjax.data.sources import (VAL_TAIL_FRACTION, FolderInput, Subset, folder_split_root, own_points,
                                     tail_split, uses_intrinsics)

    if split not in (None, "train", "val"):
        raise ValueError(f"split must be None (every frame), 'train' or 'val', got {split!r}")
    folder, own_split = folder_split_root(Path(root), split or "val")
    own_dir = folder / SPARSE_DIR
    spec = sampler or (OWN_INPUT if own_dir.is_dir() else DEFAULT_SAMPLER)
    own = spec.split(":")[0].strip() == OWN_INPUT
    if own and not own_dir.is_dir():
        raise dataset_error(f"sampler {spec!r} reads the folder's own sparse maps ({SPARSE_DIR}/<stem>.png|.npy, as "
                            "depth/), and there are none; add them or use a sampler such as uniform:200, in",
                            own_dir)
    has_intrinsics = (folder / "intrinsics.txt").is_file() or (folder / "intrinsics").is_dir()
    if uses_intrinsics(spec) and intrinsics is None and not has_intrinsics:
        raise dataset_error(f"sampler {spec!r} simulates a LiDAR and needs the camera intrinsics of the frames: "
                            "pass them (lipjax evaluate --intrinsics fx fy cx cy or --intrinsics-file F) or write "
                            "intrinsics.txt (fx fy cx cy) in", folder)
    dataset = FolderDataset(folder, depth_scale, intrinsics, id_prefix=f"folder/{folder.name}",
                            intrinsics_needed=uses_intrinsics(spec))
    draw = (FolderInput(os.fspath(own_dir), depth_scale, dataset.id_prefix, own_points(spec)) if own
            else sampler_from_spec(spec))
    if own_split:
        return dataset, draw, spec, f"{folder.name}/: every frame"
    if split is None:
        return dataset, draw, spec, "every frame"
    tail = f"the last {100 * VAL_TAIL_FRACTION:g} %"
    share = tail if split == "val" else f"all but {tail}"
    return (Subset(dataset, tail_split(["all"] * len(dataset), split)), draw, spec,
            f"{split} split: {share} of the frames, as lipjax train holds them out")


@dataclasses.dataclass(frozen=True)
class EvalData:
    """Frames to evaluate on, as `open_eval_data` opens them.

    Attributes:
      dataset: an indexable of Frames, the protocol applied. sampler: (frame, seed) -> sparse (H, W) metres.
      spec: the sampler's spec. name: the data in words. range_from: the protocol whose depth range is evaluated,
        or None (a folder, frames as they are: the caller gives the range).
    """

    dataset: Any
    sampler: Sampler
    spec: str
    name: str
    range_from: EvalProtocol | None


def _check_eval_args(data: str | None, source: str | None, root, raw_root, split, kind, size, intrinsics) -> None:
    """The combinations of open_eval_data's arguments that mean nothing (errors name `lipjax evaluate`'s flags)."""
    if source is None and (root is not None or raw_root is not None):
        raise ValueError("--root and --raw-root go with --source NAME; --data takes the folder itself")
    if kind is not None and source != "synthetic":
        raise ValueError(f"--kind goes with --source synthetic; --source rendered reads the kind from the render's "
                         f"index.json, and --data synthetic-{kind} names it itself")
    if source is None:
        return
    if data is not None:
        raise ValueError("--data and --source name the frames twice; give one")
    if root is None and source != "synthetic":
        raise ValueError(f"--source {source} needs --root DIR, the folder holding the data set")
    if size is not None:
        raise ValueError(f"--size is for --data synthetic-*; --source {source} reads its frames at their own "
                         "(training) size")
    if intrinsics is not None:
        raise ValueError(f"--intrinsics / --intrinsics-file are for --data FOLDER; --source {source} reads the data "
                         "set's own")
    if split not in (None, "train", "val"):
        raise ValueError(f"--split {split}: with --source, the split is train or val")
    if source == "rendered" and split is not None:
        raise ValueError("--split: --source rendered evaluates the frames in --root (their split is the render's); "
                         "drop --split")


def open_eval_data(data: str | None = None, source: str | None = None, *, root: str | os.PathLike | None = None,
                   raw_root: str | os.PathLike | None = None, split: str | None = None, kind: str | None = None,
                   size: tuple[int, int] | None = None, sampler: str | None = None, protocol: str | None = None,
                   depth_scale: float | None = None, intrinsics: Any = None) -> EvalData:
    """The frames `lipjax evaluate` scores, named by `--data` or by `--source` (these parameters are its flags).

    Args:
      data: "synthetic-indoor" (the default when `source` is None) or "synthetic-outdoor": the synthetic `split`
        (default test) at `size` (H, W); or a FOLDER (lipjax.data.folder layout; `open_folder`, with `intrinsics`:
        (fx, fy, cx, cy), K or a file, pixels). The named `protocol` (or none) is applied to the frames.
      source, root, raw_root, kind: a training data source read as training reads it (`open_eval_source`), split
        train or val (default val).
      sampler: a lipjax.data.sampling spec or "input[:N]" (default: a FOLDER's own sparse/, else DEFAULT_SAMPLER).
      depth_scale: PNG value per metre of the folder's depth.

    Raises ValueError with a one-line message for arguments that do not go together or data that are not there.
    """
    from lipjax.data.folder import read_intrinsics
    from lipjax.data.protocols import ProtocolView, get_protocol
    from lipjax.data.rendered import RenderedMixture, open_rendered
    from lipjax.data.sources import NO_PROTOCOL

    _check_eval_args(data, source, root, raw_root, split, kind, size, intrinsics)
    if source is not None:
        split, spec = split or "val", sampler or DEFAULT_SAMPLER
        opened, range_from = open_eval_source(source, root, split, sampler=spec, protocol=protocol,
                                              raw_root=raw_root, depth_scale=depth_scale, kind=kind)
        if source == "rendered":
            render = open_rendered(root)
            parts = render.parts if isinstance(render, RenderedMixture) else [render]
            name = f"rendered {' + '.join(f'{p.kind}/{p.split}' for p in parts)} ({root})"
        else:
            scene = f" {kind or 'indoor'}" if source == "synthetic" else ""
            name = f"{source}{scene} {split}" + (f" ({root})" if root else "")
        return EvalData(opened.dataset, opened.sampler, spec, name, range_from)
    data = data or "synthetic-indoor"
    named = get_protocol(protocol) if protocol not in (None, NO_PROTOCOL) else None
    if data in ("synthetic-indoor", "synthetic-outdoor"):
        from lipjax.data.sampling import sampler_from_spec
        from lipjax.data.synthetic import SyntheticDataset

        scene, spec = data.split("-")[1], sampler or DEFAULT_SAMPLER
        dataset = SyntheticDataset(scene, split or "test", **({"height": size[0], "width": size[1]} if size else {}))
        draw, name, range_from = sampler_from_spec(spec), data, named or get_protocol(f"synthetic_{scene}")
    else:
        if not Path(data).is_dir():
            raise ValueError(f"--data {data}: not synthetic-indoor, synthetic-outdoor or a folder")
        if split == "test":
            raise ValueError(f"--split test: a folder has train and val frames (--split train|val), or leave --split "
                             f"out to score every frame of {data}")
        dataset, draw, spec, which = open_folder(data, split, sampler=sampler, depth_scale=depth_scale,
                                                 intrinsics=read_intrinsics(intrinsics))
        name, range_from = f"{data}, {which}", named
    return EvalData(ProtocolView(dataset, named) if named else dataset, draw, spec, name, range_from)


def evaluate(
    completer: DepthCompleter,
    dataset: Sequence[Frame],
    sampler: Sampler,
    *,
    min_depth_m: float,
    max_depth_m: float,
    limit: int | None = None,
    progress: bool = True,
    seed: int = 0,
    warmup: bool = True,
    pred_floor_m: float = DEFAULT_PRED_FLOOR_M,
) -> EvalResult:
    """Completes every frame of `dataset` (the first `limit` ones if given) and scores it.

    Args:
      completer: (rgb (H, W, 3) uint8, sparse (H, W) float32 m) -> (H, W) metres, with a `name`.
      dataset: an indexable of `Frame` with len().
      sampler: (frame, seed) -> sparse (H, W) float32 metres, 0 = no sample.
      min_depth_m, max_depth_m: evaluated ground-truth range (min, max] in metres; a named protocol of
        lipjax.data.protocols carries them (protocol.min_depth_m, protocol.max_depth_m).
      limit: evaluate only the first `limit` frames.
      progress: show a progress bar on stderr.
      seed: passed to the sampler with every frame.
      warmup: make one untimed call on the first frame first (compilation of jitted models).
      pred_floor_m: see lipjax.metrics.compute_metrics.

    Returns:
      EvalResult. Raises ValueError if the data set is empty or a prediction has the wrong shape.
    """
    n = len(dataset) if limit is None else min(limit, len(dataset))
    if n <= 0:
        raise ValueError("nothing to evaluate: the data set is empty (or limit <= 0)")
    name = getattr(completer, "name", type(completer).__name__)
    agg = MetricAggregator()
    per_image: list[dict[str, Any]] = []
    times_ms: list[float] = []
    indices = range(n)
    if progress:
        from tqdm import tqdm

        indices = tqdm(indices, desc=name, file=sys.stderr, leave=False)
    for i in indices:
        frame = dataset[i]
        sparse = np.asarray(sampler(frame, seed), dtype=np.float32)
        if warmup and i == 0:
            np.asarray(completer(frame.rgb, sparse))
        t0 = time.perf_counter()
        pred = np.asarray(completer(frame.rgb, sparse))
        dt_ms = 1000.0 * (time.perf_counter() - t0)
        if pred.shape != frame.depth.shape:
            raise ValueError(f"{name}: prediction shape {pred.shape} != ground truth {frame.depth.shape} "
                             f"({frame.id})")
        m = compute_metrics(
            pred, frame.depth, frame.valid, sparse,
            min_depth_m=min_depth_m, max_depth_m=max_depth_m, pred_floor_m=pred_floor_m,
        )
        agg.add(m)
        per_image.append({"id": frame.id, **m, "ms": dt_ms})
        times_ms.append(dt_ms)
    return EvalResult(
        name=name,
        metrics=agg.means(),
        counts=agg.counts(),
        per_image=per_image,
        ms_per_frame=float(np.mean(times_ms)),
        ms_per_frame_median=float(statistics.median(times_ms)),
        num_images=n,
        min_depth_m=float(min_depth_m),
        max_depth_m=float(max_depth_m),
    )


@dataclasses.dataclass(frozen=True)
class Evaluation:
    """The results of several methods on one EvalData over one depth range (metres): `lipjax evaluate`'s table."""

    results: dict[str, EvalResult]
    data: EvalData
    min_depth_m: float
    max_depth_m: float

    def header(self) -> str:
        """One line: the data, the number of frames, the sparse input, the depth range, and (with working_size)
        that the models ran as `lipjax complete` runs them."""
        first = next(iter(self.results.values()))
        own = " (the data's own sparse maps)" if self.data.spec.split(":")[0] == OWN_INPUT else ""
        path = ", models at the samples' working size (as lipjax complete)" if first.size == "working" else ""
        return (f"data: {self.data.name} ({first.num_images} frames), sampler: {self.data.spec}{own}, depth range: "
                f"({self.min_depth_m:g}, {self.max_depth_m:g}] m{path}")


def evaluate_methods(models: Sequence[Any] | None = None, *, iterations: int | None = None,
                     min_depth_m: float | None = None, max_depth_m: float | None = None, limit: int | None = None,
                     seed: int = 0, progress: bool = True, working_size: bool = False, **data: Any) -> Evaluation:
    """Opens the frames (`open_eval_data(**data)`) and `evaluate`s every model on them, in order.

    Args:
      models: what lipjax.methods.get_completer takes (names, paths, objects), each labelled by its name; None
        or empty: the default model of the first frame's input, labelled by its name ("untrained" for the
        untrained stand-in).
      iterations: run LIP models' first K iterations.
      min_depth_m, max_depth_m: the evaluated ground-truth range (min, max] metres; by default the data's range
        protocol's (a folder without --protocol has none: then max_depth_m is required).
      limit, seed, progress: as `evaluate` takes them.
      working_size: score each model as `lipjax.complete` runs it (`lipjax.inference.AtWorkingSize`): a learned
        model at the working size of each frame's samples, measured pixels set back. Default: at the input's size,
        as the paper's tables are measured.
    """
    frames = open_eval_data(**data)
    protocol = frames.range_from
    min_depth = min_depth_m if min_depth_m is not None else (protocol.min_depth_m if protocol else 0.0)
    max_depth = max_depth_m if max_depth_m is not None else (protocol.max_depth_m if protocol else None)
    if max_depth is None:
        raise ValueError("give the evaluated depth range: --max-depth-m M (e.g. 10 indoors, 80 outdoors) "
                         "or --protocol NAME")
    results = {}
    for model in models or [None]:
        first = None if model is not None else frames.sampler(frames.dataset[0], seed)
        completer = get_completer(model, iterations, sparse=first)
        label = (os.fspath(model) if isinstance(model, (str, os.PathLike))
                 else "untrained" if completer.name == "random" else completer.name)
        run = AtWorkingSize(completer) if working_size else completer
        result = evaluate(run, frames.dataset, frames.sampler, min_depth_m=min_depth, max_depth_m=max_depth,
                          limit=limit, progress=progress, seed=seed)
        results[label] = dataclasses.replace(result, size="working") if working_size else result
    return Evaluation(results, frames, min_depth, max_depth)


def _fmt(column: str, value: float | None) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return f"{value:.{_DECIMALS.get(column, 3)}f}"


def markdown_table(results: Mapping[str, EvalResult], columns: Sequence[str] = DEFAULT_COLUMNS) -> str:
    """A Markdown table: one row per method (the mapping's keys), one column per metric (names carry units).

    Missing or NaN values print as "n/a". "ms_per_frame" is the mean completion time in milliseconds.
    """
    lines = ["| method | " + " | ".join(columns) + " |", "|---|" + "---:|" * len(columns)]
    for method, res in results.items():
        row = res.row()
        lines.append(f"| {method} | " + " | ".join(_fmt(c, row.get(c)) for c in columns) + " |")
    return "\n".join(lines)


def save_json(results: Mapping[str, EvalResult], path: str | os.PathLike) -> None:
    """Writes {method: EvalResult.to_dict()} as JSON (NaN written as null)."""

    def clean(x):
        if isinstance(x, float) and not math.isfinite(x):
            return None
        if isinstance(x, dict):
            return {k: clean(v) for k, v in x.items()}
        if isinstance(x, list):
            return [clean(v) for v in x]
        return x

    with open(path, "w") as f:
        json.dump({k: clean(v.to_dict()) for k, v in results.items()}, f, indent=1)
