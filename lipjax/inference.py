"""The jit-compiled inference entry point: `Completer` (a model with its parameters); inputs checked by lipjax.inputs.

`Completer.__call__` takes RGB uint8 (H, W, 3) or (B, H, W, 3) and sparse depth in metres (0 = missing) of the
same size, and returns dense depth in metres. The solver is compiled once per (config, input shape): jit caches
one executable per shape, and `compiled_apply` caches the jitted function per config (the training loop's
validation uses it too, so one compilation serves both).
"""
from __future__ import annotations

import dataclasses
import functools
import os
import warnings
from typing import Any

import jax
import numpy as np

from lipjax import model_io
from lipjax.inputs import InputError, check_inputs  # noqa: F401  (re-exported: lipjax.InputError)
from lipjax.model import LIPConfig, host_inputs_of

DEFAULT_MODEL = "lip-ad-indoor"


@functools.lru_cache(maxsize=None)
def compiled_apply(config: LIPConfig, return_trajectory: bool = False):
    """jit(config.apply) as (params, rgb, sparse, extra) -> (depth, trajectory or None); extra holds the
    host-computed inputs (`lipjax.model.host_inputs_of`), e.g. {"z0": ...}, or is empty."""

    def run(params, rgb, sparse, extra):
        return config.apply(params, rgb, sparse, return_trajectory=return_trajectory, **extra)

    return jax.jit(run)



@dataclasses.dataclass(frozen=True, eq=False)
class Completer:
    """A LIP model with its parameters, callable on images. Build with `load_model` or `Completer.random`."""

    config: Any  # LIPConfig, or an end-to-end baseline's config (same init / apply interface)
    params: Any
    name: str = "lip"
    metadata: dict = dataclasses.field(default_factory=dict)

    @classmethod
    def random(cls, config: LIPConfig | None = None, seed: int = 0) -> "Completer":
        """An untrained model (its network prox is the identity, so it returns the initial fill)."""
        config = config or LIPConfig()
        return cls(config, config.init(jax.random.key(seed)), name="random")

    def with_iterations(self, num_iterations: int) -> "Completer":
        """The same model run for fewer iterations (uses the first K of its per-iteration operators)."""
        if not hasattr(self.config, "num_iterations"):
            raise ValueError(f"{self.name} is an end-to-end network, not an iterative LIP model: it has no iterations")
        if num_iterations == self.config.num_iterations:
            return self
        if num_iterations < 1 or (num_iterations > self.config.num_iterations and not self.config.shared_prox):
            raise ValueError(f"this model has {self.config.num_iterations} iterations; got {num_iterations}")
        config = dataclasses.replace(self.config, num_iterations=num_iterations)
        params = dict(self.params)
        if not self.config.shared_prox:
            params["prox"] = jax.tree_util.tree_map(lambda a: a[:num_iterations], params["prox"])
        if "log_rho" in params:
            log_rho = np.asarray(params["log_rho"])
            params["log_rho"] = np.resize(log_rho, num_iterations) if self.config.shared_prox else log_rho[:num_iterations]
        return Completer(config, params, self.name, self.metadata)

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray:
        """Dense depth in metres, (H, W) or (B, H, W) like the input."""
        rgb, sparse, batched = check_inputs(rgb, sparse)
        depth, _ = compiled_apply(self.config, False)(self.params, rgb, sparse, host_inputs_of(self.config, sparse))
        depth = np.maximum(np.asarray(depth), 0.0)
        return depth if batched else depth[0]

    def trajectory(self, rgb: np.ndarray, sparse: np.ndarray):
        """(final depth, Trajectory) for a batch; each trajectory array is (K, B, H, W) metres."""
        rgb, sparse, _ = check_inputs(rgb, sparse)
        return compiled_apply(self.config, True)(self.params, rgb, sparse, host_inputs_of(self.config, sparse))

    def parameter_count(self) -> int:
        return self.config.parameter_count(self.params)


def load_model(name_or_path: str | os.PathLike = DEFAULT_MODEL) -> Completer:
    """A shipped model by name (see `lipjax.available_models()`) or a saved model by path."""
    config, params, metadata = model_io.load(name_or_path)
    return Completer(config, params, name=str(name_or_path), metadata=metadata)


@functools.lru_cache(maxsize=1)
def _default_model() -> Completer:
    if DEFAULT_MODEL in model_io.available():
        return load_model(DEFAULT_MODEL)
    warnings.warn(f"no trained weights shipped ({DEFAULT_MODEL!r}); using an untrained model", stacklevel=3)
    return Completer.random()


def complete(rgb: np.ndarray, sparse: np.ndarray, model: Completer | str | None = None) -> np.ndarray:
    """Completes depth: RGB uint8 (H,W,3) or (B,H,W,3), sparse depth in metres (0 = missing) -> dense metres.

    `model` is a Completer, a shipped model name or a path; by default the shipped DEFAULT_MODEL (loaded once),
    or, while no weights are shipped, an untrained model (with a warning).
    """
    if isinstance(model, Completer):
        return model(rgb, sparse)
    if model is not None:
        return load_model(model)(rgb, sparse)
    return _default_model()(rgb, sparse)
