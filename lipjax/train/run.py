"""A whole training run as one call: train (or resume) in a workdir, validate, plot, export only where asked.

    run(config, "runs/lip_cnn_nyu", export="runs/lip_cnn_nyu/model")
    soup(config, ["runs/export/a", "runs/export/b"], "runs/export/soup")   # the mean of saved models of one chain
    fine_tune_folder("my_frames", "models/mine", depth_scale=1000)   # `lipjax train`: the default model, fine-tuned
                                                                     # (the start, should the end validate worse)

Used by `python -m experiments.train` and (through `fine_tune_folder`) `lipjax train`. Nothing is written outside
`workdir` and `export`.
"""
from __future__ import annotations

import dataclasses
import errno
import json
import os
import pathlib
import tempfile
from collections.abc import Callable
from typing import Any

import jax
import numpy as np

from lipjax import model_io
from lipjax.interfaces import MIXED_SCENES
from lipjax.train.checkpoint import CheckpointManager, to_host
from lipjax.train.config import TrainConfig
from lipjax.train.curves import plot_curves
from lipjax.train.folder import check_frames, default_init, fitted_to_folder, folder_config
from lipjax.train.folder import own_input_validation
from lipjax.train.loop import check_same_run, data_streams, evaluate_params, export as export_model, train
from lipjax.train.loop import validation_batches
from lipjax.train.state import init_state


def logged_validation(metrics_path: pathlib.Path, step: int) -> dict | None:
    """The validation metrics the training loop logged at `step`, if any."""
    if not metrics_path.exists():
        return None
    rows = [json.loads(line) for line in metrics_path.read_text().splitlines() if line.strip()]
    found = [r for r in rows if r.get("split") == "val" and r["step"] == step]
    return {k: v for k, v in found[-1].items() if k not in ("split", "step")} if found else None


def averaged_params(config: TrainConfig, workdir: str | os.PathLike, template: Any,
                    count: int) -> tuple[Any, list[int]]:
    """Checkpoint averaging: the element-wise mean of G's parameters over the newest `count` checkpoints of the
    run in `workdir` (restored into `template`, a TrainState of the run's structure), and their steps. Late in a
    decaying schedule the checkpoints lie close together, and their mean is at least as good as the last one on
    validation (measured: docs/decisions/0006-checkpoint-averaging-and-soups.md)."""
    manager = CheckpointManager(pathlib.Path(workdir) / "checkpoints", keep=config.keep_checkpoints)
    try:
        steps = sorted(manager.all_steps())[-count:]
        if len(steps) < count:
            raise ValueError(f"--average {count}: {manager.directory} holds {len(steps)} checkpoint(s); average "
                             f"fewer, or keep more while training (--set keep_checkpoints=N)")
        trees = [manager.restore(template, step)[0].g_params for step in steps]
    finally:
        manager.close()
    return mean_params(trees), steps


def mean_params(trees: list) -> Any:
    """The element-wise mean of parameter trees of one structure, in each leaf's dtype."""
    return jax.tree_util.tree_map(lambda *leaves: np.mean(np.stack(leaves), axis=0).astype(leaves[0].dtype), *trees)


def soup(config: TrainConfig, models: list[str], export: str | os.PathLike) -> dict:
    """Model soup: saves to `export` the element-wise mean of G's parameters over saved `models` (names or paths)
    of one chain of warm starts, validated on `config`'s validation set; returns its validation metrics (metres).

    Each model's training data (`lipjax.train.loop.data_streams`) must be part of the last one's: the last model
    was warm-started, directly or through others, from each of the others (or is a sibling export of its run), so
    the mean lies between points of one basin, as checkpoint averaging's does across one run, and the soup has
    read exactly the last model's data. Its metadata is the last model's (images_seen, data_streams, ...) with the
    soup's validation and `soup`: the models it is the mean of.
    """
    if len(models) < 2:
        raise ValueError(f"--soup needs at least two models, got {models}")
    loaded = [model_io.load(m) for m in models]
    arch = {json.dumps(model_io.config_to_dict(c), sort_keys=True) for c, _, _ in loaded}
    if len(arch) > 1:
        raise ValueError(f"--soup: {', '.join(models)} differ in architecture; average models of one config")
    last_streams = data_streams(loaded[-1][2])
    for name, (_, _, meta) in zip(models, loaded):
        streams = data_streams(meta)
        if not streams or last_streams[:len(streams)] != streams:
            raise ValueError(f"--soup: {name} is not in {models[-1]}'s chain of warm starts (its training data is "
                             "not part of the last model's); list models of one chain, the newest last")
    check_writable(pathlib.Path(export).parent, "the soup (--export)")
    model = loaded[-1][0]
    mean = mean_params([params for _, params, _ in loaded])
    val = evaluate_params(model, mean, validation_batches(config), model.max_depth_m)
    model_io.save(export, model, mean, {**loaded[-1][2], "val_metrics": val, "soup": [str(m) for m in models]})
    print(f"[lipjax] exported the soup of {', '.join(map(str, models))} to {export}: val rmse_m={val['rmse_m']:.4f}")
    return val


def check_writable(folder: str | os.PathLike, what: str) -> None:
    """Raises OSError (one line) unless `folder` could be made and written: its nearest existing ancestor (itself,
    when it exists) is a folder where a file can be made. Checked before a run, so that a folder the run cannot
    write fails at once instead of after training; creates nothing."""
    folder = pathlib.Path(folder).absolute()
    existing = next(p for p in (folder, *folder.parents) if p.exists())
    try:
        if not existing.is_dir():
            raise NotADirectoryError(errno.ENOTDIR, "a file, not a folder")
        with tempfile.TemporaryFile(dir=existing):
            pass
    except OSError as exc:
        raise OSError(f"cannot write {what} into {folder} ({existing}: {exc.strerror or exc}); choose a writable "
                      "folder") from None


KEEPS = ("best", "last")  # what `run` exports when the end validates worse than the start: the start, or the end


def check_keep(keep: str) -> None:
    if keep not in KEEPS:
        raise ValueError(f"keep={keep!r}: choose 'best' (the start when the end validates worse) or 'last'")


def run(config: TrainConfig, workdir: str | os.PathLike, *, export: str | os.PathLike | None = None,
        export_only: bool = False, average: int = 1, progress: bool = True, validate_start: bool = False,
        keep: str = "last") -> dict:
    """Trains `config` in `workdir` (resuming), then validates and, when `export` is a path, saves the model there.
    Before training, the folder of `export` must be writable (`check_writable`) and a folder source's frames
    readable (lipjax.train.folder.check_frames).

    export_only: skip training and export the latest checkpoint (`config` must be the run's own:
    lipjax.train.loop.check_same_run, which `train` also checks when it resumes). average: validate and export the
    mean parameters of the newest `average` checkpoints instead (`averaged_params`; their steps go into the model's
    metadata as `checkpoints`).
    validate_start: validate the starting parameters too (lipjax.train.loop.train); the last line then gives both
    scores. keep (KEEPS), when the start was validated and the end validates worse (a higher val RMSE): "best"
    exports the starting parameters instead (`kept_start`), "last" the end; either way the last line says so.
    Returns the validation metrics (metres) of what was exported (or trained, when nothing is).

    Several processes (jax.distributed initialised, `start_processes`): every process trains; then process 0 alone
    validates, plots and exports, from the parameters on its host, and the others return {}.
    """
    workdir = pathlib.Path(workdir)
    if average < 1:
        raise ValueError(f"--average {average}: give a number of checkpoints >= 1")
    check_keep(keep)
    if jax.process_count() > 1 and (average > 1 or export_only):
        raise ValueError("--average and --export-only read checkpoints, not a run of several processes: run them in "
                         "one process")
    if export is not None:
        check_writable(pathlib.Path(export).parent, "the model (--out / --export)")
    if config.data.source == "folder" and not export_only:
        check_frames(config.data)
    if export_only:
        check_same_run(config, workdir)
        manager = CheckpointManager(workdir / "checkpoints", keep=config.keep_checkpoints)
        if manager.latest_step() is None:
            raise FileNotFoundError(f"no checkpoint in {manager.directory} to export; "
                                    "train first (drop --export-only)")
        init = model_io.load(config.init_from)[1] if config.init_from else None
        state, _ = manager.restore(init_state(config, init))
        manager.close()
    else:
        state = train(config, workdir, progress=progress, validate_start=validate_start)
    if jax.process_count() > 1:
        state = jax.tree_util.tree_map(to_host, state)  # each process holds a whole copy of the replicated state
        if jax.process_index() != 0:
            return {}
    averaged = {}
    if average > 1:
        params, steps = averaged_params(config, workdir, jax.device_get(state), average)
        state, averaged = state.replace(g_params=params), {"checkpoints": steps}
        val = evaluate_params(config.model, params, validation_batches(config), config.model.max_depth_m)
    else:  # --export-only evaluates again: its config may differ from the run's in what the model is given
        val = None if export_only else logged_validation(workdir / "metrics.jsonl", int(state.step))
    if val is None:
        val = evaluate_params(config.model, state.g_params, validation_batches(config), config.model.max_depth_m)
    if (workdir / "metrics.jsonl").exists():
        plot_curves(workdir / "metrics.jsonl", workdir / "curves.png", title=config.name)
    start = logged_validation(workdir / "metrics.jsonl", 0)
    before = f" ({start['rmse_m']:.4f} at step 0)" if start and int(state.step) > 0 else ""
    worse = bool(before) and val["rmse_m"] > start["rmse_m"]
    if export is not None:
        d = config.data
        what = f"mean of steps {averaged['checkpoints']}" if averaged else f"step {int(state.step)}"
        meta = {"val_metrics": val, "val_sampler": d.val_sampler, "val_images": d.val_images,
                "data": trained_on(config), **averaged}
        if worse and keep == "best":
            return kept_start(config, state, export, meta, start, what)
        export_model(config, state, export, meta)
        if worse:
            before = f", WORSE than {start['rmse_m']:.4f} at step 0 (the last, as asked; keep best exports the start)"
        print(f"[lipjax] exported {config.name} ({what}) to {export}: val rmse_m={val['rmse_m']:.4f}{before}")
    else:
        print(f"[lipjax] {config.name} at step {int(state.step)} in {workdir}: val rmse_m={val['rmse_m']:.4f}{before} "
              "(nothing exported; add --export PATH)")
    return val


def trained_on(config: TrainConfig) -> str:
    """A model's metadata "data": the synthetic scenes' kind, else the source; MIXED_SCENES for a model fine-tuned
    from one of both scenes (lip-any on your folder keeps serving rooms and streets without a warning that its
    input looks like the other scene's, lipjax.inference.Completer.both_scenes)."""
    d = config.data
    name = d.kind if d.source == "synthetic" else d.source
    if config.init_from and model_io.metadata(config.init_from).get("data") == MIXED_SCENES:
        return MIXED_SCENES
    return name


def kept_start(config: TrainConfig, state: Any, export: str | os.PathLike, meta: dict, start: dict,
               what: str) -> dict:
    """Exports the starting parameters of a run whose end (`state`, `what` in words, validation meta["val_metrics"])
    validates worse than its start (`start`: step 0's validation metrics), and says so in one line; returns
    `start`. The model records the start's budget (step 0: no image of this run), its training input
    (`train_sampler` of the model it started from) and validation, `kept`: "start", and the end it was kept over
    (`kept_over`: which, and its validation)."""
    if config.init_from:
        params, init_meta = model_io.load(config.init_from)[1], model_io.metadata(config.init_from)
    else:  # the run's own random start (init_state is a function of the config's seed)
        params, init_meta = init_state(config).g_params, {}
    end = meta["val_metrics"]
    meta = {**meta, "val_metrics": start, "train_sampler": init_meta.get("train_sampler"),
            "kept": "start", "kept_over": {"model": what, "val_metrics": end}}
    export_model(config, state.replace(g_params=params, step=np.zeros((), np.int32)), export, meta)
    print(f"[lipjax] exported {config.name} (its start: {what} validated worse, rmse_m={end['rmse_m']:.4f}; "
          f"keep last exports it) to {export}: val rmse_m={start['rmse_m']:.4f}")
    return start


def fine_tune_folder(root: str | os.PathLike, out: str | os.PathLike, *, init: str | None = None,
                     steps: int | None = None, batch_size: int | None = None, workdir: str | os.PathLike | None = None,
                     progress: bool = True, log: Callable[[str], None] | None = None, keep: str = "best",
                     **data: Any) -> dict:
    """`lipjax train`: fine-tunes a model on a folder of RGB-D frames (lipjax.train.folder) and exports it to
    `out` (a model path stem, also the run's name).

    Args:
      init: the model to start from (name or path); None: the default model of the frames' scene
        (lipjax.train.folder.default_init), named with its reason to `log` (a callable taking a line) if given.
      steps: training steps, batch_size: frames per step (None: folder_config's FOLDER_STEPS, FOLDER_BATCH_SIZE);
        a folder of fewer training frames trains on all of them per step (lipjax.train.folder.fitted_batch_size),
        said in one line to `log`.
      workdir: checkpoints and logs (default runs/train-<out name>).
      keep: "best" exports the starting model's parameters when the end validates worse than the start, "last"
        the end regardless; either way the last line says so (`run`).
      data: DataConfig fields over lipjax.train.folder.FOLDER_DATA (depth_scale, crop, train_sampler, num_workers);
        None keeps FOLDER_DATA's. Frames of several sizes train through the crop (each frame is cropped before
        batching) and validate whole, each at its own size (lipjax.data.pipeline). train_sampler "input[:N]" (the
        folder's sparse/ maps) validates on the same input unless val_sampler is given
        (lipjax.train.folder.own_input_validation).

    Returns the validation metrics (metres) of the exported model, as `run`.
    """
    data = own_input_validation({"root": os.fspath(root), **{k: v for k, v in data.items() if v is not None}})
    check_keep(keep)
    if init is None:
        init, scene, why = default_init(**data)
        if log is not None:
            log(f"init: {init}, the default for {scene} input ({why}); choose another with --init")
    name = pathlib.Path(out).name
    config = folder_config(model_io.load(init)[0], init, name=name, **data)
    config = dataclasses.replace(config, **{k: v for k, v in (("g_steps", steps), ("batch_size", batch_size)) if v})
    config = fitted_to_folder(config, log)
    return run(config, workdir or f"runs/train-{name}", export=out, progress=progress, validate_start=True, keep=keep)
