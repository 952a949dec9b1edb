"""The one interface every learned depth-completion model implements, and the one table of model types.

A learned model is a hashable, frozen dataclass config (a static jit argument) with functional init / apply on a
plain parameter pytree. The LIP model (lipjax.model.LIPConfig) and the end-to-end networks (lipjax.networks)
implement it; training, inference (lipjax.inference.Completer), export and model files (lipjax.model_io) use
only this interface, never the concrete classes. Model files name the type with `model_type_name`.

Depth ranges: each meaning of "max depth" has one home.
- A model's `max_depth_m` (here): the depth range it is made for, metres; the network's input normalisation and
  the unit of its training loss. Per scene: `SCENE_MAX_DEPTH_M`.
- The evaluation cap of a protocol: lipjax.data.protocols (EVAL_MAX_DEPTH_*_M).
- The synthetic renderer's far clip: lipjax.data.synthetic.constants.RENDER_FAR_CLIP_M.
"""
from __future__ import annotations

import abc
from typing import Any, Protocol, runtime_checkable

import jax
import numpy as np

Params = Any

# The depth range (metres) a model of each scene is made for: indoor rooms (Kinect, NYU) and streets (KITTI LiDAR).
SCENE_MAX_DEPTH_M: dict[str, float] = {"indoor": 10.0, "outdoor": 85.0}
# The synthetic data kind of rooms and streets interleaved (lipjax.data.synthetic.MixedSyntheticDataset), recorded
# as a model's training `data`: such a model serves both scenes.
MIXED_SCENES = "mixed"

MODEL_TYPES: dict[str, type] = {}
# Prior (prox) config types by the name written in model files ("prior_type"), filled by `register_prior_type`.
PRIOR_TYPES: dict[str, type] = {}


def _registrar(table: dict[str, type], what: str, name: str):
    """Class decorator recording a class in `table` under `name` (a `what`, e.g. "model type"); a second class under
    the same name is an error."""

    def register(cls: type) -> type:
        if name in table and table[name] is not cls:
            raise ValueError(f"{what} {name!r} is already registered to {table[name].__name__}")
        table[name] = cls
        return cls

    return register


def register_model_type(name: str):
    """Class decorator: records a LearnedModel subclass under `name`, the type name written in model files."""
    return _registrar(MODEL_TYPES, "model type", name)


def register_prior_type(name: str):
    """Class decorator: records a prior config class (lipjax.priors) under `name`, the prior type in model files."""
    return _registrar(PRIOR_TYPES, "prior type", name)


def parameter_count(params: Params) -> int:
    """Number of scalars in a parameter pytree (all iterations together)."""
    return int(sum(np.prod(leaf.shape) for leaf in jax.tree_util.tree_leaves(params)))


def model_type_name(config: "LearnedModel | type") -> str:
    """The registered type name of a model config (or of its class)."""
    kind = config if isinstance(config, type) else type(config)
    for name, cls in MODEL_TYPES.items():
        if kind is cls:
            return name
    raise ValueError(f"{kind.__name__} is not a registered model type (lipjax.interfaces.register_model_type)")


class LearnedModel(abc.ABC):
    """A learned completion model: config + init / apply over a parameter pytree.

    apply(params, rgb (B, H, W, 3) uint8 or [0, 1] float, sparse (B, H, W) metres (0 = no sample), weights=None,
    *, return_trajectory=False, **host_inputs) -> (depth (B, H, W) metres, trajectory or None). `host_inputs`
    are the arrays `host_inputs(sparse)` computes outside the compiled program (e.g. the LIP model's z0).
    """

    @abc.abstractmethod
    def init(self, key: jax.Array) -> Params:
        """Random parameters (shapes independent of the image size)."""

    @abc.abstractmethod
    def apply(self, params: Params, rgb, sparse, weights=None, *, return_trajectory: bool = False, **host_inputs):
        """Completes a batch (see the class docstring)."""

    @abc.abstractmethod
    def parameter_count(self, params: Params) -> int:
        """Learned network parameters."""

    @property
    @abc.abstractmethod
    def max_depth_m(self) -> float:
        """The depth range the model is made for, metres (see the module docstring)."""

    @property
    def host_input_names(self) -> tuple[str, ...]:
        """Names of the keyword inputs `host_inputs` returns (an exported model takes them as extra inputs)."""
        return ()

    def host_inputs(self, sparse: np.ndarray, scan_lines: bool | None = None) -> dict[str, np.ndarray]:
        """Extra keyword inputs of `apply` computed on the host from (B, H, W) sparse metres; none by default.
        `scan_lines`: whether the samples lie in LiDAR scan lines, where the caller knows it (None: not known)."""
        return {}

    def initial_estimate_for(self, scan_lines: bool) -> str | None:
        """The initial estimate the model starts from on samples in LiDAR scan lines or not (`scan_lines`), by
        name; None (the default): none, the model takes the sparse map itself (an end-to-end network)."""
        return None

    def with_iterations(self, params: Params, num_iterations: int) -> tuple["LearnedModel", Params]:
        """(config, params) of the same model run for `num_iterations` iterations; iterative models only."""
        raise ValueError(f"{type(self).__name__} is an end-to-end network: it has no iterations to choose "
                         "(--iterations is for LIP models)")


@runtime_checkable
class DepthCompleter(Protocol):
    """Anything that completes depth, classical or learned: the one completer interface.

        completer(rgb: (H, W, 3) uint8, sparse: (H, W) float32 metres, 0 = no sample) -> (H, W) float32 metres

    with a `name` (the row label of result tables). The classical fills (lipjax.classical), LIP+Wavelet and a loaded
    learned model (`lipjax.inference.Completer`: LIP or an end-to-end network, also taking batches, with its
    `parameter_count()` and its config's `max_depth_m`) are completers; `lipjax.methods.get_completer` builds any of
    them by name or path. Inputs are checked by lipjax.inputs. (A StableHLO export, `lipjax.export.load_exported`,
    is not one: it takes batches of the one size it was exported at, as a deployed graph does.)
    """

    name: str

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray: ...
