"""Pieces shared by the end-to-end networks: the network input, GroupNorm, sub-pixel upsampling, the base class."""
from __future__ import annotations

import abc
import functools
import math

import flax.linen as nn
import jax
import jax.numpy as jnp

from lipjax.interfaces import LearnedModel, parameter_count
from lipjax.priors.fast import sample_scale

# The depth unit u of a network's input and output (`depth_unit`): the network sees sparse / u and predicts depth / u.
#   "max_depth": u = max_depth_m, one constant per model (the shipped baselines');
#   "metres":    u = 1 m, Ma et al.'s raw depth input, so samples are as strong as in the papers' inputs;
#   "samples":   u = the frame's own sample scale (the geometric mean of its samples, as the fast prox):
#                the network never needs a frame's absolute depth, which per-image normalisation (GroupNorm) erases.
DEPTH_SCALES = ("max_depth", "metres", "samples")


def group_norm(channels: int) -> nn.GroupNorm:
    """GroupNorm with up to 8 groups; the group count must divide the channels (12 channels -> 4 groups)."""
    return nn.GroupNorm(num_groups=math.gcd(8, channels))


@functools.partial(jax.jit, static_argnums=0)
def _init(network: "NetworkModel", key: jax.Array):
    """One compiled program per network config (eagerly, every random draw compiles on its own)."""
    n = network.multiple
    return network.module().init(key, jnp.zeros((1, n, n, 4), jnp.float32))["params"]


def depth_unit(sparse: jax.Array, depth_scale: str, max_depth_m: float) -> jax.Array:
    """(B, 1, 1) metres: the unit u of DEPTH_SCALES for each frame of sparse (B, H, W) metres."""
    if depth_scale == "samples":
        return sample_scale(sparse, jnp.ones_like(sparse))
    return jnp.full((sparse.shape[0], 1, 1), 1.0 if depth_scale == "metres" else max_depth_m, jnp.float32)


def check_depth_scale(depth_scale: str) -> None:
    if depth_scale not in DEPTH_SCALES:
        raise ValueError(f"depth_scale must be one of {DEPTH_SCALES}, got {depth_scale!r}")


def network_input(rgb: jax.Array, sparse: jax.Array, unit: jax.Array | float, multiple: int) -> jax.Array:
    """concat(sparse / unit, rgb - 0.5): (B, H', W', 4), H' and W' padded up to `multiple`; unit: metres, a
    number or (B, 1, 1) (`depth_unit`).

    RGB is edge-padded (keeps border statistics); sparse depth is zero-padded (0 = no sample: padding must not
    invent measurements).
    """
    rgb = rgb.astype(jnp.float32) / 255.0 if rgb.dtype == jnp.uint8 else rgb.astype(jnp.float32)
    _, h, w = sparse.shape
    pad = ((0, 0), (0, (-h) % multiple), (0, (-w) % multiple))
    d = jnp.pad(sparse.astype(jnp.float32) / unit, pad)
    c = jnp.pad(rgb, pad + ((0, 0),), mode="edge") - 0.5
    return jnp.concatenate([d[..., None], c], axis=-1)


class NetworkModel(LearnedModel):
    """init / apply / parameter_count shared by the end-to-end networks (each defines `module()` and `multiple`;
    CSPN overrides `apply` with its propagation)."""

    @property
    @abc.abstractmethod
    def multiple(self) -> int:
        """Inputs are padded to a multiple of this in H and W (the network's total downsampling)."""

    @abc.abstractmethod
    def module(self) -> nn.Module:
        """The Flax module: `network_input` (B, H', W', 4) -> depth / max_depth_m (B, H', W')."""

    def init(self, key: jax.Array):
        """Random parameters. Shapes do not depend on the image size (fully convolutional): init on the smallest
        input the network accepts."""
        return _init(self, key)

    def apply(self, params, rgb, sparse, weights=None, *, return_trajectory: bool = False):
        """Dense depth (B, H, W) metres from rgb (B, H, W, 3) and sparse (B, H, W) metres; `weights` is unused.
        Returns (depth, None)."""
        del weights, return_trajectory
        _, h, w = sparse.shape
        unit = depth_unit(sparse, self.depth_scale, self.max_depth_m)
        x = network_input(rgb, sparse, unit, self.multiple)
        d = self.module().apply({"params": params}, x)
        return d[:, :h, :w] * unit, None

    def parameter_count(self, params) -> int:
        return parameter_count(params)


def check_max_depth(max_depth_m: float) -> None:
    if not max_depth_m > 0:
        raise ValueError(f"max_depth_m must be > 0 metres, got {max_depth_m}")

