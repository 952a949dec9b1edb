"""Orbax checkpoints of a training run: every array needed to resume exactly, plus JSON metadata.

Each checkpoint is a step folder written by orbax to a temporary name and renamed when complete, so a run killed
at any moment leaves only whole checkpoints; the last `keep` are kept. The state is stored as its state dict
(`flax.serialization.to_state_dict`): plain nested dicts of arrays, restored into a template of the same structure.

A checkpoint damaged afterwards (a truncated or lost file) does not block resuming: `restore` reports it in one
line on stderr, moves it to `<directory>-unreadable/<step>` (nothing is deleted) and restores the newest one that
does restore. When none does, it raises CheckpointError, whose one-line message names the folder to move away.
"""
from __future__ import annotations

import contextlib
import os
import pathlib
import shutil
import sys
import time
from typing import Any, Iterator

import flax.serialization
import jax
import numpy as np
import orbax.checkpoint as ocp


def to_host(a) -> np.ndarray:
    """A numpy copy of a (replicated) array; in a multi-process run a replicated global array is not fully
    addressable from one process, but each process holds a complete copy of it."""
    if isinstance(a, jax.Array) and not a.is_fully_addressable:
        return np.asarray(a.addressable_data(0))
    return np.asarray(a)


class CheckpointError(ValueError):
    """No checkpoint of a run restores; the message (one line) names the folder to move away."""


def _first_line(exc: BaseException, limit: int = 160) -> str:
    text = next((line.strip() for line in str(exc).splitlines() if line.strip()), "")
    text = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
    return text if len(text) <= limit else text[: limit - 3] + "..."


# How long the reads left in flight by a failed restore get to finish (local files: milliseconds).
_DRAIN_S = 0.5


@contextlib.contextmanager
def _orbax_noise_silenced() -> Iterator[None]:
    """Silences stderr (file descriptor 2) while checkpoints are tried: a failed orbax restore leaves reads in
    flight whose completions each print a traceback ("Event loop is closed") from orbax's threads, hundreds of
    lines for one damaged file. The failure itself is reported in one line. LIPJAX_DEBUG=1 keeps everything."""
    if os.environ.get("LIPJAX_DEBUG"):
        yield
        return
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(os.devnull, "w") as devnull:
            os.dup2(devnull.fileno(), 2)
            yield
    finally:
        sys.stderr.flush()
        os.dup2(saved, 2)
        os.close(saved)


class CheckpointManager:
    """Saves and restores (state, metadata) pairs under `directory/<step>`."""

    def __init__(self, directory: str | os.PathLike, keep: int = 3):
        self.directory = pathlib.Path(directory).absolute()
        self._manager = ocp.CheckpointManager(
            self.directory,
            options=ocp.CheckpointManagerOptions(max_to_keep=keep, create=True, enable_async_checkpointing=False),
        )

    def latest_step(self) -> int | None:
        return self._manager.latest_step()

    def all_steps(self) -> list[int]:
        return list(self._manager.all_steps())

    def save(self, step: int, state: Any, metadata: dict) -> None:
        tree = jax.tree_util.tree_map(to_host, flax.serialization.to_state_dict(state))
        self._manager.save(
            step, args=ocp.args.Composite(state=ocp.args.PyTreeSave(tree), meta=ocp.args.JsonSave(metadata)),
            force=True,
        )
        self._manager.wait_until_finished()

    def restore(self, template: Any, step: int | None = None) -> tuple[Any, dict]:
        """(state with template's structure, metadata) of `step`, or by default of the newest checkpoint that
        restores: newer ones that do not are reported and moved aside (see the module docstring)."""
        if step is not None:
            return self._restore(template, step)
        steps = sorted(self.all_steps(), reverse=True)
        if not steps:
            raise FileNotFoundError(f"no checkpoint in {self.directory}")
        failures, restored = [], None
        with _orbax_noise_silenced():
            for candidate in steps:
                try:
                    restored = self._restore(template, candidate)
                    break
                except Exception as exc:  # noqa: BLE001 - any failure to read a checkpoint means it is unusable
                    failures.append((candidate, exc))
            if failures:
                time.sleep(_DRAIN_S)  # let the failed restore's reads in flight finish while stderr is silenced
        if restored is not None:
            for bad, exc in failures:
                moved = self._set_aside(bad)
                print(f"lipjax: warning: checkpoint step {bad} in {self.directory} does not restore "
                      f"({_first_line(exc)}); moved it to {moved}; resuming from step {candidate}", file=sys.stderr)
            return restored
        raise CheckpointError(
            f"no checkpoint in {self.directory} restores (step {steps[0]}: {_first_line(failures[0][1])}); "
            f"move {self.directory} away (or use another workdir) to start the run afresh"
        )

    def _restore(self, template: Any, step: int) -> tuple[Any, dict]:
        target = jax.tree_util.tree_map(np.asarray, flax.serialization.to_state_dict(template))
        restored = self._manager.restore(
            step, args=ocp.args.Composite(state=ocp.args.PyTreeRestore(target), meta=ocp.args.JsonRestore())
        )
        return flax.serialization.from_state_dict(template, restored["state"]), restored["meta"]

    def _set_aside(self, step: int) -> pathlib.Path:
        """Moves the step folder to <directory>-unreadable/<step>[.n] (the main process only); returns where."""
        aside = self.directory.with_name(self.directory.name + "-unreadable")
        target, n = aside / str(step), 1
        while target.exists():
            target, n = aside / f"{step}.{n}", n + 1
        if jax.process_index() == 0:
            aside.mkdir(exist_ok=True)
            shutil.move(self.directory / str(step), target)
        self._manager.reload()
        return target

    def close(self) -> None:
        self._manager.close()
