"""The training loop: resumable, data-parallel, logged, with periodic validation and NaN detection.

    train(config, workdir)   # resumes from workdir/checkpoints if present

Layout of `workdir`: checkpoints/<step>/ (orbax), metrics.jsonl (one JSON object per logged step or evaluation),
config.txt (the config's repr) and run.json (`run_record`, which a resume and an export of the workdir check). A
run writes nothing outside its workdir. Resume is exact: the state holds parameters, both optimiser states, the
step and the RNG key; the data position is the step (batch s is a pure function of (seed, s), see
lipjax.data.pipeline), recorded in each checkpoint's metadata, checked on resume, and where a resumed run's loader
starts.
"""
from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import os
import pathlib
import signal
import sys
import threading
import time
import warnings
from typing import Any

import jax
import numpy as np
from jax.sharding import NamedSharding, PartitionSpec
from tqdm.auto import tqdm

from lipjax import model_io
from lipjax.train.checkpoint import CheckpointManager, to_host
from lipjax.data.frame import Batch
from lipjax.data.pipeline import BatchIterator, StepBatches, TrainLoader, make_data_mesh, shard_batch
from lipjax.data.pipeline import validation_batches as source_validation_batches
from lipjax.data.sources import open_source
from lipjax.inference import compiled_apply
from lipjax.metrics import MetricAggregator, compute_metrics
from lipjax.train.config import TrainConfig, data_recipe
from lipjax.train.state import TrainState, init_state  # noqa: F401  (re-exported)
from lipjax.train.steps import make_steps


class TrainingDiverged(RuntimeError):
    """A non-finite loss: training stops and the last good checkpoint is kept."""


def validation_batches(config: TrainConfig) -> list[Batch]:
    """The fixed validation set of a run: the first `val_images` val frames of its source, with val_sampler."""
    return source_validation_batches(open_source(config.data, "val"), config.model)


def evaluate_params(model_config, params, batches: list[Batch], max_depth_m: float) -> dict[str, float]:
    """Per-image-then-mean metrics of a LIP model over batches (lipjax.metrics)."""
    apply = compiled_apply(model_config)
    agg = MetricAggregator()
    for b in batches:
        pred = np.asarray(apply(params, b.rgb, b.sparse, {} if b.z0 is None else {"z0": b.z0})[0])
        for i in range(len(pred)):
            agg.add(compute_metrics(pred[i], b.gt[i], b.gt_valid[i], b.sparse[i], min_depth_m=0.0,
                                    max_depth_m=max_depth_m))
    return agg.means()


def _to_float(metrics: dict) -> dict:
    return {k: float(v) for k, v in metrics.items()}


def _initial_g_params(config: TrainConfig):
    """The parameters of model `config.init_from`. Its config may differ from `config.model` only where the
    parameters do not (e.g. an indoor model fine-tuned outdoors: another depth range, initial estimate); a different
    parameter tree (names or shapes) is an error."""
    if config.init_from is None:
        return None
    init_config, params, init_meta = model_io.load(config.init_from)
    if any((s["train_config"], s["seed"]) == (config.name, config.seed) for s in data_streams(init_meta)):
        warnings.warn(f"init_from {config.init_from!r} already trained on {config.name}'s data with seed "
                      f"{config.seed}: this run reads the same frames, samples and crops again from step 0; give "
                      "it a seed of its own (--set seed=N) to train on new ones", stacklevel=2)
    if init_config != config.model:
        def shapes(tree):
            return jax.tree_util.tree_map(lambda a: tuple(a.shape), tree)

        want = jax.eval_shape(config.model.init, jax.random.key(0))
        if shapes(want) != shapes(params):
            raise ValueError(f"init_from {config.init_from!r} has model config {init_config}, whose parameters do "
                             f"not fit this run's {config.model}; train from scratch with --set init_from=None or "
                             "pick a model of the same architecture")
        had = {f.name: getattr(init_config, f.name) for f in dataclasses.fields(init_config)}
        differ = [f.name for f in dataclasses.fields(config.model)
                  if f.name not in had or had[f.name] != getattr(config.model, f.name)]
        print(f"[lipjax] init_from {config.init_from!r}: its parameters, this run's settings of {differ}")
    return params


class _Stop(threading.Event):
    """Set by the first SIGTERM or SIGINT (Ctrl-C) of a run; `signum` says which."""

    signum: int = signal.SIGTERM


@contextlib.contextmanager
def _signals_as_exit(save_first: bool):
    """SIGTERM and SIGINT (Ctrl-C) end a training run with SystemExit(128 + signal: 143, 130) so that the
    `finally` blocks run: the loader's worker processes stop with the run instead of outliving it; started
    again, the run resumes.

    Yields a _Stop event. save_first (a single-process run): the first signal only sets it; the loop then
    finishes the step it is in, saves a checkpoint of it and exits, so a preempted or interrupted run loses no
    step; a signal during the last step or the final validation exits once the run is done (never swallowed: a
    caller that trains run after run stops too). A second signal exits at once (SIGINT as KeyboardInterrupt; the
    last saved checkpoint is kept). A
    multi-process run exits at once on SIGTERM, and SIGINT keeps Python's KeyboardInterrupt: a checkpoint is a
    collective write that every process would have to reach at the same step. No-op outside the main thread."""
    stop = _Stop()
    if threading.current_thread() is not threading.main_thread():
        yield stop
        return

    def on_signal(signum, frame):
        if save_first and not stop.is_set():
            stop.signum = signum
            stop.set()
            return
        if signum == signal.SIGINT:
            raise KeyboardInterrupt
        raise SystemExit(128 + signum)

    previous = {s: signal.signal(s, on_signal) for s in ((signal.SIGTERM, signal.SIGINT) if save_first
                                                          else (signal.SIGTERM,))}
    try:
        yield stop
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    if stop.is_set():  # it came during the run's last step or final validation: the process stops all the same
        print(f"[lipjax] {signal.Signals(stop.signum).name}: the run ended with its last step saved; stopping",
              file=sys.stderr, flush=True)
        raise SystemExit(128 + stop.signum)


def _next_batch(loader: TrainLoader, stop: _Stop, step: int) -> Batch:
    """The loader's batch of `step`. A worker that was still starting when the run's stop signal reached its whole
    process group (Ctrl-C, `timeout`, a batch scheduler) dies of it, before it can ignore it (pipeline's worker
    init): with the stop already asked for, the run then stops as asked (SystemExit(128 + signal)), keeping its
    last checkpoint, instead of failing on the loader."""
    try:
        return next(loader)
    except Exception:
        if not stop.is_set():
            raise
        print(f"[lipjax] {signal.Signals(stop.signum).name}: a data loader worker ended with it before step {step}; "
              "stopping with the last checkpoint saved (run again to resume)", file=sys.stderr, flush=True)
        raise SystemExit(128 + stop.signum) from None


def _resume(config: TrainConfig, manager: CheckpointManager, is_main: bool) -> TrainState:
    """The latest checkpoint's state, else a fresh one."""
    state = init_state(config, _initial_g_params(config))
    if manager.latest_step() is not None:
        state, meta = manager.restore(state)
        if meta.get("data_position") != int(state.step):
            raise RuntimeError(f"checkpoint data position {meta.get('data_position')} != step {int(state.step)}")
        if is_main:
            print(f"[lipjax] resumed {config.name} from step {int(state.step)} in {manager.directory}")
    return state


def _train_loader(config: TrainConfig, start: int, process_index: int, process_count: int) -> TrainLoader:
    """This process's batches of every step from `start` (a resumed run's too: batch s depends on s alone)."""
    d = config.data
    source = open_source(d, "train")
    local = BatchIterator(source.dataset, config.batch_size, source.sampler, seed=config.seed,
                          process_index=process_index, process_count=process_count)
    step_batches = StepBatches(local, config.total_steps, d.augment, d.crop, config.seed, config.model)
    return TrainLoader(step_batches, start, d.num_workers)


class _Progress:
    """The progress bar, metrics.jsonl (main process only) and the images/s rate of a run."""

    def __init__(self, config: TrainConfig, workdir: pathlib.Path, start: int, end: int, show: bool, is_main: bool):
        self.log = open(workdir / "metrics.jsonl", "a") if is_main else None
        self.bar = tqdm(total=end, initial=start, desc=config.name, disable=not (show and is_main), dynamic_ncols=True)
        self.t_last, self.images = time.perf_counter(), 0

    def restart_clock(self) -> None:
        """After the first step, which compiles (a minute or more here): leave it out of the images/s rate."""
        self.t_last, self.images = time.perf_counter(), 0

    def train_step(self, done: int, phase: str, metrics: dict, manager: CheckpointManager) -> None:
        """Logs step `done`; TrainingDiverged on a non-finite loss."""
        metrics = _to_float(metrics)
        if not math.isfinite(metrics["loss"]):
            raise TrainingDiverged(
                f"non-finite loss {metrics['loss']} at step {done} ({phase}); stopped without saving. "
                f"The last good checkpoint is step {manager.latest_step()} in {manager.directory}; "
                f"lower the learning rate or check the data."
            )
        now = time.perf_counter()
        rate = self.images / (now - self.t_last) if self.images else None  # None: only the compiling step ran
        self.t_last, self.images = now, 0
        self.bar.set_postfix(loss=f"{metrics['loss']:.4g}", img_s="-" if rate is None else f"{rate:.1f}",
                             phase=phase[:3])
        if self.log:
            self.log.write(json.dumps({"step": done, "phase": phase, "images_per_s": rate, **metrics}) + "\n")
            self.log.flush()

    def validation(self, done: int, vm: dict, note: str = "") -> None:
        """Logs the validation metrics `vm` (metres) of step `done`; `note` follows the step in the printed line."""
        if self.log:
            self.log.write(json.dumps({"step": done, "split": "val", **vm}) + "\n")
            self.log.flush()
            self.bar.write(f"[lipjax] step {done}{note} val rmse_m={vm['rmse_m']:.4f} mae_m={vm['mae_m']:.4f}")

    def close(self) -> None:
        self.bar.close()
        if self.log:
            self.log.close()


def train(
    config: TrainConfig,
    workdir: str | os.PathLike,
    *,
    stop_at: int | None = None,
    progress: bool = True,
    mesh=None,
    process_index: int | None = None,
    process_count: int | None = None,
    validate_start: bool = False,
) -> TrainState:
    """Trains (or resumes) a run in `workdir` until config.total_steps (or `stop_at`, to split a run in parts).
    A resume with another init_from, seed, batch size or data setting than the run's record is a ValueError
    (`check_same_run`) before any step.
    validate_start: also validate (and log) the starting parameters at step 0 of a new run, the score that
    fine-tuning is to improve on.

    Data-parallel over all devices of `mesh` (default: every device): batches are sharded over the 'data' axis
    and the state is replicated. Multi-host: call lipjax.utils.start_processes (jax.distributed.initialize) first in
    every process (`python -m experiments.train --distributed` does); each process loads its own slice of every
    global batch.
    """
    workdir = pathlib.Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    mesh = make_data_mesh() if mesh is None else mesh
    process_index = jax.process_index() if process_index is None else process_index
    process_count = jax.process_count() if process_count is None else process_count
    is_main = process_index == 0

    val = validation_batches(config) if config.eval_every else []  # a missing data set fails before the model init
    manager = CheckpointManager(workdir / "checkpoints", keep=config.keep_checkpoints)
    if manager.latest_step() is not None:  # a resume: the steps so far read the recorded config's data
        try:
            check_same_run(config, workdir)
        except BaseException:
            manager.close()
            raise
    (workdir / "config.txt").write_text(repr(config) + "\n")
    (workdir / RUN_FILE).write_text(json.dumps(run_record(config)) + "\n")
    state = _resume(config, manager, is_main)
    start = int(state.step)
    rng = jax.random.wrap_key_data(np.asarray(state.rng))
    state = jax.device_put(state, NamedSharding(mesh, PartitionSpec()))  # replicated
    steps = make_steps(config)
    end = config.total_steps if stop_at is None else min(stop_at, config.total_steps)
    loader = _train_loader(config, start, process_index, process_count)
    shown = _Progress(config, workdir, start, end, progress, is_main)
    step = start
    if val and validate_start and start == 0:
        shown.validation(0, evaluate_params(config.model, state.g_params, val, config.model.max_depth_m), " (start)")
    try:
        with _signals_as_exit(save_first=process_count == 1) as stop, loader:
            for step in range(start, end):
                batch = _next_batch(loader, stop, step)
                phase = config.phase(step)
                state, metrics = getattr(steps, phase)(state, shard_batch(batch, mesh), jax.random.fold_in(rng, step))
                shown.images += config.batch_size
                done = step + 1
                if step == start:
                    jax.block_until_ready(state)
                    shown.restart_clock()
                if done % config.log_every == 0 or done == end:
                    shown.train_step(done, phase, metrics, manager)
                if done % config.checkpoint_every == 0 or done == end or stop.is_set():
                    manager.save(done, state, {"data_position": done, "phase": phase, "name": config.name})
                if stop.is_set() and done < end:
                    shown.bar.write(f"[lipjax] {signal.Signals(stop.signum).name}: saved step {done} in "
                                    f"{manager.directory}; stopping (run again to resume)")
                    raise SystemExit(128 + stop.signum)
                if val and (done % config.eval_every == 0 or done == end):
                    # every process evaluates (the parameters live on all of them); the main one logs
                    vm = evaluate_params(config.model, state.g_params, val, config.model.max_depth_m)
                    shown.validation(done, vm)
                shown.bar.update(1)
    finally:
        shown.close()
        manager.close()
    return state


def data_streams(metadata: dict) -> list[dict]:
    """The training data a saved model has read, oldest run first: one {"train_config", "seed", "steps", "data"} per
    run of its chain of warm starts (`init_from`); step s of a run reads the frames, samples and crops that its
    config, its data settings ("data": lipjax.train.config.data_recipe, --set overrides included) and its seed give
    step s, so two runs with the same three read the same data. Runs saved before "data" was recorded (2026-12-03)
    have none: their data settings are their config's (--set overrides, if any, are in their workdir's
    config.txt). A model saved before the streams were recorded gives its last run's config with the default seed
    0 (every run before then used it), steps unknown."""
    if "data_streams" in metadata:
        return list(metadata["data_streams"])
    if "train_config" in metadata:
        return [{"train_config": metadata["train_config"], "seed": 0, "steps": None}]
    return []


RUN_FILE = "run.json"  # in a workdir: run_record of the config that trained it


def run_record(config: TrainConfig) -> dict:
    """What of `config` an export's budget and data record (`export`: images_seen, data_streams) are made of: the
    model it started from, its name, seed, batch size and data settings, as JSON values. `train` writes it into the
    workdir (RUN_FILE), so that a resume or an export of that workdir can check that it is given the run's own
    config."""
    return json.loads(json.dumps({"init_from": config.init_from, "train_config": config.name, "seed": config.seed,
                                  "batch_size": config.batch_size, "data": data_recipe(config.data)}))


def check_same_run(config: TrainConfig, workdir: str | os.PathLike) -> None:
    """One-line ValueError unless `config` has the run record of the config that trained `workdir` (RUN_FILE; runs
    that started before it was written are not checked): resumed or exported with another init_from or seed, a
    model would carry a wrong images_seen and data_streams. `train` checks a resume, `run` an export."""
    path = pathlib.Path(workdir) / RUN_FILE
    if not path.exists():
        return
    recorded, given = json.loads(path.read_text()), run_record(config)
    differ = [key for key in given if recorded.get(key) != given[key]]
    if differ:
        raise ValueError(f"{workdir} was trained with {', '.join(f'{k}={recorded.get(k)!r}' for k in differ)}, "
                         f"this config has {', '.join(f'{k}={given[k]!r}' for k in differ)}: give the run's own "
                         "--set flags to resume or export it (a model's images_seen and data_streams come from "
                         "them), or another --workdir")


def export(config: TrainConfig, state: TrainState, path: str | os.PathLike,
           metadata: dict[str, Any] | None = None) -> None:
    """Saves the trained G as a loadable model (lipjax.load_model(path)), with its training budget: `images_seen`
    counts the training images of every step (batch size x steps), plus those of the model it started from; and
    with its training input, `train_sampler` (what lipjax.inputs checks scan lines against), and the data every
    run of its chain read, `data_streams`."""
    params = jax.tree_util.tree_map(to_host, state.g_params)
    init_meta = model_io.metadata(config.init_from) if config.init_from else {}
    meta = {"train_config": config.name, "steps": int(state.step),
            "images_seen": init_meta.get("images_seen", 0) + int(state.step) * config.batch_size,
            "data_streams": data_streams(init_meta) + [{"train_config": config.name, "seed": config.seed,
                                                        "steps": int(state.step), "data": data_recipe(config.data)}],
            "train_sampler": config.data.train_sampler, **(metadata or {})}
    model_io.save(path, config.model, params, meta)
