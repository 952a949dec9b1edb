"""The discriminator D of LIP+AD (paper Sec. III-B): real vs generated depth, conditioned on the RGB image.

D is a small fully convolutional PatchGAN-style classifier on concat(depth / max_depth, rgb - 0.5, valid) that
returns one logit per patch ((B, H/16, W/16) for four stride-2 layers). Pixels where the ground truth is invalid are
zeroed in BOTH the real and the generated depth before D sees them, so D cannot tell them apart by the holes of the
sensor (the paper's masking); the valid mask is also an input channel, identical for both.
"""
from __future__ import annotations

import dataclasses

import flax.linen as nn
import jax
import jax.numpy as jnp


class _PatchDiscriminator(nn.Module):
    widths: tuple[int, ...]
    max_depth_m: float

    @nn.compact
    def __call__(self, depth, rgb, valid):
        valid = valid.astype(jnp.float32)
        d = depth * valid / self.max_depth_m
        h = jnp.concatenate([d[..., None], rgb - 0.5, valid[..., None]], axis=-1)
        for width in self.widths:
            h = nn.Conv(width, (4, 4), strides=2)(h)
            h = nn.leaky_relu(nn.GroupNorm(num_groups=min(8, width))(h), 0.2)
        return nn.Conv(1, (3, 3))(h)[..., 0]


@dataclasses.dataclass(frozen=True)
class Discriminator:
    """Config + functional init/apply. apply(params, depth (B,H,W) m, rgb (B,H,W,3) [0,1], valid (B,H,W)) -> logits."""

    widths: tuple[int, ...] = (16, 32, 64, 64)
    max_depth_m: float = 10.0

    def module(self) -> _PatchDiscriminator:
        return _PatchDiscriminator(tuple(self.widths), self.max_depth_m)

    def init(self, key: jax.Array, image_shape: tuple[int, int] = (64, 64)):
        z = jnp.zeros((1, *image_shape))
        return self.module().init(key, z, jnp.zeros((1, *image_shape, 3)), z)["params"]

    def apply(self, params, depth, rgb, valid):
        return self.module().apply({"params": params}, depth, rgb, valid)
