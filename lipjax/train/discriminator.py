"""The discriminator D of LIP+AD (paper Sec. III-B): real vs generated depth, conditioned on the RGB image.

D is a small fully convolutional PatchGAN-style classifier on concat(depth features, rgb - 0.5, valid) that
returns one logit per patch ((B, H/16, W/16) for four stride-2 layers). Pixels where the ground truth is invalid are
zeroed in BOTH the real and the generated depth before D sees them, so D cannot tell them apart by the holes of the
sensor (the paper's masking); the valid mask is also an input channel, identical for both.

Depth features (`inputs`):
- "depth": depth / max_depth (the paper's D).
- "log_gradients": the horizontal and vertical differences of log depth between neighbouring valid pixels,
  scaled by LOG_GRADIENT_GAIN. A completion started from an interpolation differs from true depth mostly in its
  local shape (planar facets, blurred edges), not in its absolute value; differences of log depth show exactly
  that, at every depth range alike (research/discriminator_probe.py measures what D can learn from each).
"""
from __future__ import annotations

import dataclasses
import functools

import flax.linen as nn
import jax
import jax.numpy as jnp

from lipjax.interfaces import SCENE_MAX_DEPTH_M

DISCRIMINATOR_INPUTS = ("depth", "log_gradients")
LOG_GRADIENT_GAIN = 10.0  # a 10 % depth step between neighbours becomes ~1: unit-scale inputs for the convolutions
_LOG_FLOOR_M = 1e-3


def _log_gradients(depth, valid):
    """(B, H, W) metres, valid -> (B, H, W, 2): d log(depth) along x and y where both neighbours are valid, else 0."""
    log_d = jnp.log(jnp.maximum(depth, _LOG_FLOOR_M))
    dx = (log_d[:, :, 1:] - log_d[:, :, :-1]) * valid[:, :, 1:] * valid[:, :, :-1]
    dy = (log_d[:, 1:, :] - log_d[:, :-1, :]) * valid[:, 1:, :] * valid[:, :-1, :]
    dx = jnp.pad(dx, ((0, 0), (0, 0), (0, 1)))
    dy = jnp.pad(dy, ((0, 0), (0, 1), (0, 0)))
    return LOG_GRADIENT_GAIN * jnp.stack([dx, dy], axis=-1)


class _PatchDiscriminator(nn.Module):
    widths: tuple[int, ...]
    max_depth_m: float
    inputs: str

    @nn.compact
    def __call__(self, depth, rgb, valid):
        valid = valid.astype(jnp.float32)
        if self.inputs == "log_gradients":
            features = _log_gradients(depth, valid)
        else:
            features = (depth * valid / self.max_depth_m)[..., None]
        h = jnp.concatenate([features, rgb - 0.5, valid[..., None]], axis=-1)
        for width in self.widths:
            h = nn.Conv(width, (4, 4), strides=2)(h)
            h = nn.leaky_relu(nn.GroupNorm(num_groups=min(8, width))(h), 0.2)
        return nn.Conv(1, (3, 3))(h)[..., 0]


@functools.partial(jax.jit, static_argnums=(0, 2))
def _init(discriminator: "Discriminator", key: jax.Array, image_shape: tuple[int, int]):
    """One compiled program per config (eagerly, every random draw compiles on its own)."""
    z = jnp.zeros((1, *image_shape))
    return discriminator.module().init(key, z, jnp.zeros((1, *image_shape, 3)), z)["params"]


@dataclasses.dataclass(frozen=True)
class Discriminator:
    """Config + functional init/apply. apply(params, depth (B,H,W) m, rgb (B,H,W,3) [0,1], valid (B,H,W)) -> logits."""

    widths: tuple[int, ...] = (16, 32, 64, 64)
    max_depth_m: float = SCENE_MAX_DEPTH_M["indoor"]
    inputs: str = "depth"

    def __post_init__(self):
        if self.inputs not in DISCRIMINATOR_INPUTS:
            raise ValueError(f"discriminator inputs must be one of {DISCRIMINATOR_INPUTS}, got {self.inputs!r}")

    def module(self) -> _PatchDiscriminator:
        return _PatchDiscriminator(tuple(self.widths), self.max_depth_m, self.inputs)

    def init(self, key: jax.Array, image_shape: tuple[int, int] = (64, 64)):
        return _init(self, key, tuple(image_shape))

    def apply(self, params, depth, rgb, valid):
        return self.module().apply({"params": params}, depth, rgb, valid)
