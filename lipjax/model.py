"""The LIP model: wires the unrolled ADMM solver (lipjax.admm) to a prior (lipjax.priors) and a rho schedule.

Parameters are a plain pytree:
    {"prox": <prior params, stacked (K, ...) per iteration or one shared set>,
     "guidance_encoder": <params>,                 # only for a SharedEncoderPrior (run once per frame)
     "log_rho": (K,) float32}                      # only when rho is learned; rho = exp(log_rho) > 0

Inputs and outputs (see `apply`): rgb (B, H, W, 3) uint8 or float in [0, 1]; sparse depth (B, H, W) float32 in
metres with 0 = no sample; output (B, H, W) float32 metres.
"""
from __future__ import annotations

import dataclasses
import functools
import math
from typing import Any, Literal

import jax
import jax.numpy as jnp
import numpy as np

from lipjax.admm import Trajectory, unrolled_admm
from lipjax.fill import box_fill_with_radius, sample_radius
from lipjax.inputs import is_lidar_pattern
from lipjax.interfaces import SCENE_MAX_DEPTH_M, LearnedModel, parameter_count, register_model_type
from lipjax.priors.base import SharedEncoderPrior
from lipjax.priors.network import network_preset

Params = Any
InitialEstimate = Literal["sparse", "box_fill", "linear", "nearest", "auto"]
# Initial estimates computed with numpy/scipy on the host (a Delaunay triangulation is not jit-able): the caller
# passes them to `apply` as z0 (see `host_initial_estimate`); training computes them per batch in the loop.
HOST_INITIAL_ESTIMATES = ("linear", "nearest", "auto")
INITIAL_ESTIMATES = ("sparse", "box_fill") + HOST_INITIAL_ESTIMATES
Guidance = Literal["rgb", "rgb+mask"]
Output = Literal["x", "z"]


@register_model_type("lip")
@dataclasses.dataclass(frozen=True)
class LIPConfig(LearnedModel):
    """Everything that defines a LIP model except its learned parameters. Hashable (a static jit argument).

    Attributes:
      prior: the proximal operator (a frozen dataclass with the prior interface of lipjax.priors.base).
      num_iterations: K, the number of unrolled ADMM iterations.
      shared_prox: one prox parameter set for every iteration (the paper's future work) instead of one each.
      rho_init: initial (or fixed) ADMM penalty, dimensionless, > 0; small rho trusts the measurements more.
      learn_rho: learn one rho_k per iteration (kept positive as exp(log_rho)); else rho_k = rho_init.
      initial_estimate: z_0. "sparse": z_0 = y (the paper). "box_fill": a multi-scale normalised box filter fill
        (lipjax.fill, jit-able), so the first learned prox refines a dense map; measured pixels are kept by the
        x-update. "linear" / "nearest": Delaunay piecewise-linear / nearest-sample fill, computed on the host
        (`host_initial_estimate`) and passed to `apply` as z0. "auto": per frame, nearest for LiDAR scan lines
        (`lipjax.inputs.is_lidar_pattern`), linear otherwise (benchmarks/initial_estimate.py: with the same weights,
        nearest is both better and ~8x cheaper on scan lines, linear better on scattered points of any density).
        With the zero-initialised residual prox an
        untrained model returns exactly this fill, so training starts from that classical baseline.
      guidance: what the prox sees besides depth. "rgb": the image (the paper). "rgb+mask": also the sampling
        mask and the fill's distance to the nearest sample, log2(1 + r) / 8 — with a dense z_0 the prox could
        otherwise not tell measured depth from extrapolated depth.
      output: how the estimate is read after the K iterations. "x": one more x-update with z_K - u_K (ADMM's
        x-iterate; the paper, and the shipped indoor models). "z": the x-update with z_K alone, i.e. the last
        prox's estimate with the measurements re-imposed (the shipped outdoor models). Measured pixels keep the
        x-update's guarantee either way; on the others "x" reads 2 z_K - x_K - u_{K-1}, which extrapolates the
        last prox's step and can cross zero where that step is large. With a log-depth prox
        (NetworkPrior.depth_domain="log") "z" makes depth <= 0 impossible; see experiments/configs/.
    """

    prior: Any = dataclasses.field(default_factory=lambda: network_preset("small"))
    num_iterations: int = 3
    shared_prox: bool = False
    rho_init: float = 0.1
    learn_rho: bool = True
    initial_estimate: InitialEstimate = "box_fill"
    guidance: Guidance = "rgb+mask"
    output: Output = "x"

    def init(self, key: jax.Array) -> "Params":
        """Random parameters for this config from a jax.random key (module function `init`): the pytree of the
        module docstring; their shapes do not depend on the image size."""
        return init(self, key)

    def apply(self, params, rgb, sparse, weights=None, *, return_trajectory: bool = False, z0=None):
        """(depth (B, H, W) float32 metres, Trajectory or None) from rgb (B, H, W, 3) uint8 or float in [0, 1] and
        sparse (B, H, W) float32 metres (0 = no sample); weights (B, H, W) >= 0, z0 (B, H, W) metres for a host
        initial estimate (`host_inputs`). Jit-able, no input checks: the module function `apply`."""
        return apply(self, params, rgb, sparse, weights, z0=z0, return_trajectory=return_trajectory)

    @property
    def needs_host_initial_estimate(self) -> bool:
        """Whether `apply` needs z0 from `host_initial_estimate` (not jit-able)."""
        return self.initial_estimate in HOST_INITIAL_ESTIMATES

    @property
    def host_input_names(self) -> tuple[str, ...]:
        return ("z0",) if self.needs_host_initial_estimate else ()

    def host_inputs(self, sparse: np.ndarray, scan_lines: bool | None = None) -> dict[str, np.ndarray]:
        """Extra keyword inputs of `apply` computed on the host from (B, H, W) sparse depth: {"z0": ...} or {}.
        `scan_lines`: the samples' pattern where the caller knows it (the default path's plan, asked of the full-size
        frame), for the "auto" fill; None: "auto" asks lipjax.inputs.is_lidar_pattern of each map."""
        if not self.needs_host_initial_estimate:
            return {}
        kind = self.initial_estimate if scan_lines is None else self.initial_estimate_for(scan_lines)
        return {"z0": host_initial_estimate(kind, sparse)}

    def initial_estimate_for(self, scan_lines: bool) -> str:
        """z_0's kind on samples in LiDAR scan lines or not: `initial_estimate`, with "auto" resolved (nearest on
        scan lines, linear otherwise)."""
        if self.initial_estimate != "auto":
            return self.initial_estimate
        return "nearest" if scan_lines else "linear"

    def with_iterations(self, params, num_iterations: int) -> tuple["LIPConfig", Any]:
        """(config, params) for the first K = num_iterations iterations: the first K per-iteration proxes and rho_k
        (a shared prox also runs for more than it trained with, repeating its rho)."""
        if num_iterations == self.num_iterations:
            return self, params
        if num_iterations < 1 or (num_iterations > self.num_iterations and not self.shared_prox):
            raise ValueError(f"this model has {self.num_iterations} iterations; got {num_iterations}")
        params = dict(params)
        if not self.shared_prox:
            params["prox"] = jax.tree_util.tree_map(lambda a: a[:num_iterations], params["prox"])
        if "log_rho" in params:
            log_rho = np.asarray(params["log_rho"])
            params["log_rho"] = np.resize(log_rho, num_iterations) if self.shared_prox else log_rho[:num_iterations]
        return dataclasses.replace(self, num_iterations=num_iterations), params

    def parameter_count(self, params) -> int:
        """Learned network parameters (the prox networks of all iterations and a shared encoder; rho excluded)."""
        return parameter_count({k: v for k, v in params.items() if k != "log_rho"})

    @property
    def max_depth_m(self) -> float:
        """The depth range of the prior (metres): its normalisation and the unit of the training loss."""
        return float(self.prior.max_depth_m)

    def __post_init__(self):
        if self.num_iterations < 1:
            raise ValueError(f"num_iterations must be >= 1, got {self.num_iterations}")
        if not self.rho_init > 0:
            raise ValueError(f"rho_init must be > 0, got {self.rho_init}")
        if self.guidance not in ("rgb", "rgb+mask"):
            raise ValueError(f"guidance must be 'rgb' or 'rgb+mask', got {self.guidance!r}")
        if self.output not in ("x", "z"):
            raise ValueError(f"output must be 'x' or 'z', got {self.output!r}")
        if self.initial_estimate not in INITIAL_ESTIMATES:
            raise ValueError(f"initial_estimate must be one of {INITIAL_ESTIMATES}, got {self.initial_estimate!r}")


@functools.partial(jax.jit, static_argnums=0)
def init(config: LIPConfig, key: jax.Array) -> Params:
    """Random parameters: one prox set per iteration (independent keys), or one shared set.

    Compiled as one program (cached per config): run eagerly, each random draw compiled on its own (~40 s for the
    default config here, against ~20 s, and nothing on a second run with the persistent cache)."""
    # Parameter shapes never depend on the image size (fully convolutional priors); a small one keeps init cheap.
    channels = 5 if config.guidance == "rgb+mask" else 3
    init_one = functools.partial(config.prior.init, image_shape=(64, 64), guidance_channels=channels)
    if isinstance(config.prior, SharedEncoderPrior):
        key, encoder_key = jax.random.split(key)
    if config.shared_prox:
        prox = init_one(key)
    else:
        prox = jax.vmap(init_one)(jax.random.split(key, config.num_iterations))
    params = {"prox": prox}
    if isinstance(config.prior, SharedEncoderPrior):
        params["guidance_encoder"] = config.prior.init_encoder(encoder_key, guidance_channels=channels)
    if config.learn_rho:
        params["log_rho"] = jnp.full((config.num_iterations,), math.log(config.rho_init), jnp.float32)
    return params


def rho_schedule(config: LIPConfig, params: Params) -> jax.Array:
    """(K,) positive ADMM penalties."""
    if config.learn_rho:
        return jnp.exp(params["log_rho"])
    return jnp.full((config.num_iterations,), config.rho_init, jnp.float32)


def _rgb_to_unit(rgb: jax.Array) -> jax.Array:
    if rgb.dtype == jnp.uint8:
        return rgb.astype(jnp.float32) / 255.0
    return rgb.astype(jnp.float32)


def apply(
    config: LIPConfig,
    params: Params,
    rgb: jax.Array,
    sparse: jax.Array,
    weights: jax.Array | None = None,
    *,
    z0: jax.Array | None = None,
    return_trajectory: bool = False,
) -> tuple[jax.Array, Trajectory | None]:
    """Completes depth. Pure and jit-able (config static); no input checks here (see lipjax.inference).

    Args:
      rgb: (B, H, W, 3) uint8, or float in [0, 1].
      sparse: (B, H, W) float32 sparse depth in metres, 0 = no sample.
      weights: (B, H, W) per-pixel confidence >= 0 (noise-aware data term); defaults to the mask sparse > 0.
      z0: (B, H, W) metres, the initial estimate, required when config.initial_estimate is computed on the host
        ("linear", "nearest": `config.host_inputs(sparse)`), ignored otherwise.
      return_trajectory: also return every iteration's (x, z), each (K, B, H, W).

    Returns:
      (depth (B, H, W) metres, Trajectory or None).
    """
    sparse = sparse.astype(jnp.float32)
    if weights is None:
        weights = (sparse > 0).astype(jnp.float32)
    guidance = _rgb_to_unit(rgb)
    if config.initial_estimate == "box_fill":
        fill, radius = box_fill_with_radius(sparse, weights)
    else:
        radius = sample_radius(weights)  # the same radius map, without computing the fill
    if config.needs_host_initial_estimate:
        if z0 is None:
            raise ValueError(f"initial_estimate={config.initial_estimate!r} is computed on the host: pass "
                             "z0=config.host_inputs(sparse)['z0'] (lipjax.inference.Completer does this)")
        if z0.shape != sparse.shape:
            raise ValueError(f"z0 {z0.shape} must have the shape of sparse {sparse.shape}")
        z0 = z0.astype(jnp.float32)
    else:
        z0 = fill if config.initial_estimate == "box_fill" else sparse
    if config.guidance == "rgb+mask":
        extra = [(weights > 0).astype(jnp.float32), jnp.log2(1.0 + radius) / 8.0]
        guidance = jnp.concatenate([guidance] + [e[..., None] for e in extra], axis=-1)
    if isinstance(config.prior, SharedEncoderPrior):
        guidance = config.prior.encode(params["guidance_encoder"], guidance, sparse, weights)  # once per frame
    return unrolled_admm(
        config.prior.apply,
        params["prox"],
        sparse,
        weights,
        guidance,
        rho_schedule(config, params),
        z0=z0,
        shared_params=config.shared_prox,
        return_trajectory=return_trajectory,
        final_dual=config.output == "x",
    )


def host_initial_estimate(kind: str, sparse: np.ndarray) -> np.ndarray:
    """(B, H, W) float32 metres: the "linear", "nearest" or "auto" (nearest for scan lines, else linear) fill of
    each image of (B, H, W) sparse depth (0 = none).

    Images without any sample get zeros (the model's input checks reject them before this in inference).
    """
    from lipjax.classical.interpolate import linear_fill  # scipy-based; imported lazily (host only)
    from lipjax.classical.nearest import nearest_fill

    def auto_fill(s):  # LIPConfig.initial_estimate_for, its pattern asked of each map
        return nearest_fill(s) if is_lidar_pattern(s) else linear_fill(s)

    fill = {"linear": linear_fill, "nearest": nearest_fill, "auto": auto_fill}[kind]
    sparse = np.asarray(sparse, np.float32)
    out = np.zeros(sparse.shape, np.float32)
    for i, s in enumerate(sparse):
        if (s > 0).any():
            out[i] = fill(s)
    return out


def presets(name: str) -> LIPConfig:
    """Named model configurations: '<network preset>-<indoor|outdoor>', e.g. 'small-indoor', 'paper-outdoor'."""
    try:
        net, scene = name.split("-")
        max_depth = SCENE_MAX_DEPTH_M[scene]
    except (ValueError, KeyError):
        raise ValueError(f"model preset must look like 'small-indoor' or 'paper-outdoor', got {name!r}") from None
    return LIPConfig(prior=network_preset(net, max_depth_m=max_depth))
