"""Fine-tuning a model on your own folder of RGB-D frames: the config behind `lipjax train --data DIR`.

    init, scene, why = default_init(root="my_frames", depth_scale=1000)   # the default model of the frames' scene
    config = folder_config(model_io.load(init)[0], init, root="my_frames", depth_scale=1000)
    lipjax.train.run.run(config, "runs/my_frames", export="models/my_model")   # check_frames first

Unreadable frames stop a run before it starts (`check_frames`, which run() calls for folder sources) rather than
being skipped: a skipped frame would change which frames every later batch holds (batch s is a pure function of
the seed and s, so that resume is exact) and would hide a broken copy; one pass reading every file costs a few
milliseconds a frame, and its error names every bad file at once.

`lipjax train --data DIR` starts from `default_init`; the named config lip_cnn_folder (experiments/configs/real.py) is
the same run started from lip-cnn-indoor, folder_config(LIP_CNN_INDOOR's model, "lip-cnn-indoor").
"""
from __future__ import annotations

import dataclasses
import functools
import os
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from lipjax.data.errors import DatasetError
from lipjax.data.sampling import DEFAULT_SAMPLER
from lipjax.train.config import DataConfig, TrainConfig

# Random 128x160 crops of the frames as they are (no protocol), a mixture of sparse densities; validation on the
# folder's val/ (or the last 5 % of its frames) with 200 uniform points.
FOLDER_DATA = DataConfig(
    source="folder", crop=(128, 160), train_sampler="uniform:200|uniform:500|bernoulli:200",
    val_sampler=DEFAULT_SAMPLER, val_images=32, num_workers=2,
)
FOLDER_STEPS, FOLDER_BATCH_SIZE = 2000, 8  # a fine-tuning run's length and frames per step


def folder_config(model, init_from: str | None, *, name: str = "lip-cnn-folder", **data) -> TrainConfig:
    """A FOLDER_STEPS-step L1 fine-tuning run of `model` (started from model `init_from`), FOLDER_BATCH_SIZE frames
    per step, on a folder source.

    data: DataConfig fields (root, depth_scale, crop, train_sampler, num_workers, ...) over FOLDER_DATA.
    """
    return TrainConfig(
        name=name, model=model, data=dataclasses.replace(FOLDER_DATA, **data), init_from=init_from,
        batch_size=FOLDER_BATCH_SIZE, g_steps=FOLDER_STEPS, learning_rate=2e-4, warmup_steps=100, loss="l1",
        eval_every=500, checkpoint_every=250,
    )


def default_init(**data) -> tuple[str, str, str]:
    """The model `lipjax train` fine-tunes by default: the shipped default model (lipjax.shipped.DEFAULT_MODELS) of
    the scene that the first training frame's input suggests (lipjax.inputs.scene_reason); both scenes' is lip-any,
    the model `lipjax complete` runs on every input. data: DataConfig fields over FOLDER_DATA, as folder_config takes
    them.

    Returns (model name, scene, the evidence in words)."""
    from lipjax.data.sources import open_source
    from lipjax.inputs import scene_reason
    from lipjax.shipped import DEFAULT_MODELS

    source = open_source(dataclasses.replace(FOLDER_DATA, **data), "train")
    scene, why = scene_reason(source.sampler(source.dataset[0], 0))
    return DEFAULT_MODELS[scene], scene, why


def fitted_batch_size(batch_size: int, frames: int, devices: int = 1) -> int:
    """The frames per step of a run over `frames` training frames: `batch_size` when they fill a batch of it (every
    step is a full batch: lipjax.data.pipeline.BatchIterator drops an incomplete one), else all of them, rounded
    down to a multiple of `devices` (each step's batch is split evenly over the devices). One-line ValueError when
    the frames are fewer than the devices."""
    if frames >= batch_size:
        return batch_size
    fitted = min(batch_size, frames) // devices * devices
    if fitted < 1:
        raise ValueError(f"{frames} training frame(s) make no batch of one frame for each of {devices} devices; add "
                         "frames to the folder (or run on fewer devices)")
    return fitted


def fitted_to_folder(config: TrainConfig, log=None) -> TrainConfig:
    """`config` with a batch its folder's training frames fill (`fitted_batch_size`), said in one line to `log` (a
    callable taking a line, or None) when it is smaller than asked."""
    import jax

    from lipjax.data.sources import open_source

    frames, asked = len(open_source(config.data, "train").dataset), config.batch_size
    if frames >= asked:
        return config
    config = dataclasses.replace(config, batch_size=fitted_batch_size(asked, frames, jax.device_count()))
    if log is not None:
        log(f"batch size {config.batch_size}: the folder's {frames} training frame(s) fill no batch of {asked}; "
            "add frames for larger batches")
    return config


def own_input_validation(data: dict) -> dict:
    """DataConfig fields over FOLDER_DATA for a run on a folder's own sparse input (train_sampler "input[:N]") that
    names no val_sampler: validation draws the same input (the sensor the model is tuned to) where the validation
    frames have their sparse/ maps, rather than FOLDER_DATA's uniform points, which would score the model on a
    pattern it was not trained on (a LiDAR-tuned model validated on 200 scattered points looks worse than its
    start). Other fields unchanged."""
    from lipjax.data.folder import SPARSE_DIR
    from lipjax.data.sampling import is_own_input
    from lipjax.data.sources import folder_split_root

    spec = data.get("train_sampler")
    if spec is None or not is_own_input(spec) or data.get("val_sampler") is not None:
        return data
    if not (folder_split_root(Path(data["root"]), "val")[0] / SPARSE_DIR).is_dir():
        return data
    return {**data, "val_sampler": spec}


def check_frames(data: DataConfig) -> int:
    """Reads every frame of a folder source once (RGB, depth, intrinsics, sizes; and sparse/ when a sampler is
    "input"), both splits, in threads; a self-supervised run's ("hide[:F]": lipjax.data.hidden) rgb/ and sparse/.
    Returns the number of frames; raises one DatasetError naming every unreadable file (path relative to data.root
    and the reason), so that a bad file stops the run before training rather than at the step that first draws it."""
    from lipjax.data.folder import SPARSE_DIR, FolderDataset, read_depth
    from lipjax.data.hidden import hide_share
    from lipjax.data.sources import folder_split_root, uses_intrinsics

    root = Path(data.root).resolve()
    folders = {folder_split_root(root, split)[0] for split in ("train", "val")}
    own_input = "input" in f"{data.train_sampler}|{data.val_sampler}"
    needed = uses_intrinsics(data.train_sampler) or uses_intrinsics(data.val_sampler)
    depth_dir = SPARSE_DIR if hide_share(data.train_sampler) is not None else "depth"
    jobs = []
    for folder in sorted(folders):
        dataset = FolderDataset(folder, depth_scale=data.depth_scale, intrinsics_needed=needed, depth_dir=depth_dir)
        jobs += [functools.partial(dataset.__getitem__, i) for i in range(len(dataset))]
        own = folder / SPARSE_DIR
        sparse = sorted(own.glob("*.*")) if own_input and own.is_dir() else []
        jobs += [functools.partial(read_depth, p, data.depth_scale if p.suffix.lower() == ".png" else None)
                 for p in sparse if p.suffix.lower() in (".png", ".npy")]

    def problem(read) -> str | None:
        try:
            read()
        except (ValueError, OSError) as exc:  # the first line names the problem and the file
            return (str(exc).splitlines() or [type(exc).__name__])[0].replace(f"{root}{os.sep}", "")
        return None

    with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        bad = [p for p in pool.map(problem, jobs) if p is not None]
    if bad:
        raise DatasetError(f"{len(bad)} unreadable file(s) in {root}, checked before training: {'; '.join(bad)}; "
                           "fix or remove them (with their partner files)")
    return len(jobs)
