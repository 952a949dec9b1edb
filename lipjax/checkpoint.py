"""Orbax checkpoints of a training run: every array needed to resume exactly, plus JSON metadata.

Each checkpoint is a step folder written by orbax to a temporary name and renamed when complete, so a run killed
at any moment leaves only whole checkpoints; the last `keep` are kept. The state is stored as its state dict
(`flax.serialization.to_state_dict`): plain nested dicts of arrays, restored into a template of the same structure.
"""
from __future__ import annotations

import os
import pathlib
from typing import Any

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
            step, args=ocp.args.Composite(state=ocp.args.PyTreeSave(tree), meta=ocp.args.JsonSave(metadata)), force=True
        )
        self._manager.wait_until_finished()

    def restore(self, template: Any, step: int | None = None) -> tuple[Any, dict]:
        """(state with template's structure, metadata) of `step` (default: the latest)."""
        step = self.latest_step() if step is None else step
        if step is None:
            raise FileNotFoundError(f"no checkpoint in {self.directory}")
        target = jax.tree_util.tree_map(np.asarray, flax.serialization.to_state_dict(template))
        restored = self._manager.restore(
            step, args=ocp.args.Composite(state=ocp.args.PyTreeRestore(target), meta=ocp.args.JsonRestore())
        )
        return flax.serialization.from_state_dict(template, restored["state"]), restored["meta"]

    def close(self) -> None:
        self._manager.close()
