"""Helpers shared by several test modules (imported as `from helpers import ...`: tests/ is on sys.path)."""
from __future__ import annotations

import pathlib

import jax
import numpy as np

import lipjax


def perturbed(completer: lipjax.Completer, seed: int = 0, scale: float = 0.05) -> lipjax.Completer:
    """`completer` with N(0, scale^2) added to every weight.

    A freshly initialised LIP model's prox is the identity (its head starts at zero), so every seed gives the same
    output; tests that compare two paths through a model (CLI and library, save and load, ONNX and XLA) use
    perturbed weights, under which a wrong or re-initialised parameter changes the depth."""
    leaves, treedef = jax.tree_util.tree_flatten(completer.params)
    rng = np.random.default_rng(seed)
    leaves = [np.asarray(x) + scale * rng.standard_normal(np.shape(x)).astype(np.float32) for x in leaves]
    return lipjax.Completer(completer.config, jax.tree_util.tree_unflatten(treedef, leaves), completer.name,
                            completer.metadata)


def alive(pid: int) -> bool:
    """Whether process `pid` exists and is not a zombie (Linux /proc)."""
    try:
        return pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def children(pid: int) -> set[int]:
    """Pids of the live processes whose parent is `pid` (Linux /proc)."""
    kids = set()
    for stat in pathlib.Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid and fields[0] != "Z":
            kids.add(int(stat.parent.name))
    return kids
