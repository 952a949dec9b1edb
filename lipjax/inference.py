"""The jit-compiled inference entry point: `Completer` (a model with its parameters) and input checks.

`Completer.__call__` takes RGB uint8 (H, W, 3) or (B, H, W, 3) and sparse depth in metres (0 = missing) of the
same size, and returns dense depth in metres. The solver is compiled once per (config, input shape): jit caches
one executable per shape, and `_compiled` caches the jitted function per config.
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
from lipjax.model import LIPConfig

DEFAULT_MODEL = "lip-ad-indoor"


class InputError(ValueError):
    """Bad input to the completer: the message names the problem."""


def check_inputs(rgb: np.ndarray, sparse: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    """Validates and batches inputs. Returns (rgb (B,H,W,3) uint8|float32, sparse (B,H,W) float32, was_batched)."""
    rgb = np.asarray(rgb)
    sparse = np.asarray(sparse)
    batched = rgb.ndim == 4
    if rgb.ndim not in (3, 4) or rgb.shape[-1] != 3:
        raise InputError(f"rgb must be (H, W, 3) or (B, H, W, 3), got shape {rgb.shape}")
    if rgb.dtype != np.uint8 and not np.issubdtype(rgb.dtype, np.floating):
        raise InputError(f"rgb must be uint8 (0-255) or float in [0, 1], got dtype {rgb.dtype}")
    if np.issubdtype(rgb.dtype, np.floating) and (not np.isfinite(rgb).all() or rgb.min() < 0 or rgb.max() > 1):
        raise InputError("float rgb must be finite and in [0, 1]; pass uint8 for 0-255 images")
    if sparse.ndim != rgb.ndim - 1:
        raise InputError(f"sparse depth must be (H, W) or (B, H, W) to match rgb {rgb.shape}, got {sparse.shape}")
    if sparse.shape != rgb.shape[:-1]:
        raise InputError(f"sparse depth {sparse.shape} and rgb {rgb.shape[:-1]} differ in size; align them first")
    if not np.issubdtype(sparse.dtype, np.floating):
        raise InputError(f"sparse depth must be float metres, got dtype {sparse.dtype} (raw PNG? divide by its scale)")
    if not np.isfinite(sparse).all():
        raise InputError("sparse depth contains NaN or inf; use 0 for missing samples")
    if (sparse < 0).any():
        raise InputError("sparse depth contains negative values; depth is in metres with 0 = missing")
    if not batched:
        rgb, sparse = rgb[None], sparse[None]
    empty = [i for i in range(sparse.shape[0]) if not (sparse[i] > 0).any()]
    if empty:
        raise InputError(f"sparse depth has no samples (all zeros) in image(s) {empty}; nothing to complete from")
    if sparse.max() > 1000:
        raise InputError(f"sparse depth reaches {sparse.max():.0f}: that is not metres (millimetres? divide by 1000)")
    if np.issubdtype(rgb.dtype, np.floating):
        rgb = rgb.astype(np.float32)
    return rgb, sparse.astype(np.float32), batched


@functools.lru_cache(maxsize=None)
def _compiled(config: LIPConfig, return_trajectory: bool):
    def run(params, rgb, sparse, extra):
        return config.apply(params, rgb, sparse, return_trajectory=return_trajectory, **extra)

    return jax.jit(run)


def _host_inputs(config, sparse: np.ndarray) -> dict:
    """Inputs computed outside jit (a Delaunay initial estimate, ...); {} for models that need none."""
    return config.host_inputs(sparse) if hasattr(config, "host_inputs") else {}


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
        depth, _ = _compiled(self.config, False)(self.params, rgb, sparse, _host_inputs(self.config, sparse))
        depth = np.maximum(np.asarray(depth), 0.0)
        return depth if batched else depth[0]

    def trajectory(self, rgb: np.ndarray, sparse: np.ndarray):
        """(final depth, Trajectory) for a batch; each trajectory array is (K, B, H, W) metres."""
        rgb, sparse, _ = check_inputs(rgb, sparse)
        return _compiled(self.config, True)(self.params, rgb, sparse, _host_inputs(self.config, sparse))

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
