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


# Parameter counts by hand (tests/test_network.py, tests/test_networks.py); a GroupNorm of c channels has 2c.
def conv_params(k: int, a: int, b: int, bias: bool = True) -> int:
    """A k x k convolution from a to b channels: k*k*a*b weights, and b biases."""
    return k * k * a * b + (b if bias else 0)


def up_projection_params(a: int, f: int) -> int:
    """lipjax.priors.network.UpProjection from a to f channels: two sub-pixel up-convolutions (3x3 to 4f channels)
    and a 3x3 convolution, each GroupNorm-ed."""
    return 2 * (conv_params(3, a, 4 * f) + 2 * f) + conv_params(3, f, f) + 2 * f
