"""U-Net (Ronneberger et al. 2015) on RGB-D."""
from __future__ import annotations

import dataclasses

import flax.linen as nn
import jax.numpy as jnp

from lipjax.interfaces import SCENE_MAX_DEPTH_M, register_model_type
from lipjax.networks.common import NetworkModel, check_depth_scale, check_max_depth, group_norm
from lipjax.priors.fast import depth_to_space


class _DoubleConv(nn.Module):
    features: int

    @nn.compact
    def __call__(self, h):
        for _ in range(2):
            h = nn.relu(group_norm(self.features)(nn.Conv(self.features, (3, 3), use_bias=False)(h)))
        return h


class UNetBody(nn.Module):
    """The U-Net trunk: (B, H, W, C_in), H and W multiples of 2**levels -> full-resolution features
    (B, H, W, base_width).

        level l = 0..levels-1:  double 3x3 conv (base * 2**l channels), kept as skip l, 2x2 max-pool
        bottom:                 double 3x3 conv (base * 2**levels)
        level l = levels-1..0:  2x2 up-convolution to base * 2**l, concat skip l, double 3x3 conv

    The 2x2 stride-2 up-convolution is written as a 1x1 convolution to 4x the channels followed by depth-to-space,
    which is the same linear map as a 2x2 stride-2 transposed convolution and cheaper on a CPU.
    """

    base_width: int
    levels: int

    @nn.compact
    def __call__(self, x):
        skips = []
        h = x
        for level in range(self.levels):
            h = _DoubleConv(self.base_width * 2**level)(h)
            skips.append(h)
            h = nn.max_pool(h, (2, 2), strides=(2, 2))
        h = _DoubleConv(self.base_width * 2**self.levels)(h)
        for level in reversed(range(self.levels)):
            c = self.base_width * 2**level
            h = depth_to_space(nn.Conv(4 * c, (1, 1))(h))
            h = _DoubleConv(c)(jnp.concatenate([h, skips[level]], axis=-1))
        return h


class UNetNet(nn.Module):
    base_width: int
    levels: int

    @nn.compact
    def __call__(self, x):
        h = UNetBody(self.base_width, self.levels)(x)
        return nn.Conv(1, (1, 1))(h)[..., 0]


@register_model_type("unet")
@dataclasses.dataclass(frozen=True)
class UNet(NetworkModel):
    """U-Net on concat(RGB, sparse depth): `levels` down / `levels` up with skip concatenations (UNetBody), then a
    1x1 convolution to depth / max_depth_m.

    Attributes:
      base_width: channels of the first level (Ronneberger et al.: 64); level l has base_width * 2**l.
      levels: number of 2x poolings (4 in the paper); inputs are padded to a multiple of 2**levels.
      max_depth_m: the depth range (metres), the depth unit under depth_scale "max_depth".
      depth_scale: the depth unit of the network's input and output (lipjax.networks.common.DEPTH_SCALES).
    """

    base_width: int = 64
    levels: int = 4
    max_depth_m: float = SCENE_MAX_DEPTH_M["indoor"]
    depth_scale: str = "max_depth"  # lipjax.networks.common.DEPTH_SCALES

    def __post_init__(self):
        check_max_depth(self.max_depth_m)
        check_depth_scale(self.depth_scale)
        if self.base_width < 1 or self.levels < 1:
            raise ValueError(f"base_width and levels must be >= 1, got {self.base_width}, {self.levels}")

    @property
    def multiple(self) -> int:
        return 2**self.levels

    def module(self) -> UNetNet:
        return UNetNet(self.base_width, self.levels)


