"""CSPN: Cheng, Wang & Yang 2018, "Depth Estimation via Affinity Learned with Convolutional Spatial Propagation
Network": a U-Net guidance network and K steps of spatial propagation with the samples replaced after each.
"""
from __future__ import annotations

import dataclasses

import flax.linen as nn
import jax
import jax.numpy as jnp

from lipjax.interfaces import SCENE_MAX_DEPTH_M, register_model_type
from lipjax.networks.common import NetworkModel, check_depth_scale, check_max_depth, depth_unit, network_input
from lipjax.networks.unet import UNetBody


# The 8 neighbours (dy, dx) of a 3x3 propagation kernel, in the order of the affinity channels.
NEIGHBOUR_OFFSETS: tuple[tuple[int, int], ...] = (
    (-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1),
)


def normalize_affinity(raw: jax.Array, eps: float = 1e-6) -> tuple[jax.Array, jax.Array]:
    """CSPN's affinity normalisation. raw (B, H, W, 8) -> (kappa (B, H, W, 8), centre (B, H, W)):

        kappa(a, b) = raw(a, b) / sum_{a,b} |raw(a, b)|          so  sum |kappa| <= 1
        centre      = 1 - sum_{a,b} kappa(a, b)                  so  centre + sum kappa = 1

    The first makes the propagation stable (Cheng et al., Sec. 3.1); the second makes it preserve constants.
    `eps` only guards 0 / 0.
    """
    kappa = raw / (jnp.sum(jnp.abs(raw), axis=-1, keepdims=True) + eps)
    return kappa, 1.0 - jnp.sum(kappa, axis=-1)


def _neighbours(h: jax.Array) -> jax.Array:
    """(B, H, W) -> (B, H, W, 8): the value at each of NEIGHBOUR_OFFSETS. Outside the image the border value is
    repeated (edge padding), so that a constant map stays constant up to the borders."""
    _, hh, ww = h.shape
    p = jnp.pad(h, ((0, 0), (1, 1), (1, 1)), mode="edge")
    return jnp.stack([p[:, 1 + dy : 1 + dy + hh, 1 + dx : 1 + dx + ww] for dy, dx in NEIGHBOUR_OFFSETS], axis=-1)


def propagate(h0: jax.Array, raw_affinity: jax.Array, sparse: jax.Array, mask: jax.Array,
              iterations: int) -> jax.Array:
    r"""Convolutional spatial propagation with replacement (Cheng et al. 2018, eq. 1 and its depth-completion form).

    With kappa, centre = normalize_affinity(raw_affinity), m = mask, s = sparse:

        H_0     = (1 - m) * h0 + m * s
        H_{t+1} = centre * H_0 + sum_{(a,b) != 0} kappa(a, b) * H_t(shifted by (a, b))      (eq. 1)
        H_{t+1} = (1 - m) * H_{t+1} + m * s                                                  (replacement)

    for t = 0 .. iterations - 1. The centre term anchors on the initial estimate H_0 as in the paper.

    Args:
      h0: (B, H, W) initial depth (any unit; s in the same unit).
      raw_affinity: (B, H, W, 8) unnormalised affinities, in NEIGHBOUR_OFFSETS order.
      sparse: (B, H, W) the measurements s.
      mask: (B, H, W) bool, True where s is measured.
      iterations: T >= 0 (static).

    Returns:
      (B, H, W) H_T, equal to `sparse` wherever `mask` is set.
    """
    kappa, centre = normalize_affinity(raw_affinity)
    h0 = jnp.where(mask, sparse, h0)
    anchor = centre * h0

    def step(h, _):
        h = anchor + jnp.sum(kappa * _neighbours(h), axis=-1)
        return jnp.where(mask, sparse, h), None

    h, _ = jax.lax.scan(step, h0, None, length=iterations)
    return h


class CSPNNet(nn.Module):
    """x (B, H, W, 4) -> (initial depth / max_depth (B, H, W), raw affinities (B, H, W, 8))."""

    base_width: int
    levels: int

    @nn.compact
    def __call__(self, x):
        h = UNetBody(self.base_width, self.levels)(x)
        depth = nn.Conv(1, (3, 3))(h)[..., 0]
        affinity = nn.Conv(len(NEIGHBOUR_OFFSETS), (3, 3))(h)
        return depth, affinity


@register_model_type("cspn")
@dataclasses.dataclass(frozen=True)
class CSPN(NetworkModel):
    """CSPN for depth completion: a U-Net backbone (UNetBody) on concat(RGB, sparse depth) predicts an initial
    depth and 8-neighbour affinities (3x3 kernel); `iterations` steps of spatial propagation with replacement
    (`propagate`) refine the depth, so the output equals the sparse input exactly on measured pixels.

    Cheng et al. use Ma et al.'s ResNet-50 up-projection network with skip connections as backbone; a U-Net-like
    backbone keeps this comparable to the `UNet` baseline. Propagation runs on the unpadded image.

    Attributes:
      base_width, levels: the backbone (as in `UNet`).
      iterations: T propagation steps (the paper: 24).
      max_depth_m: the depth range (metres), the depth unit under depth_scale "max_depth".
      depth_scale: the depth unit of the network's input and output (lipjax.networks.common.DEPTH_SCALES).
    """

    base_width: int = 64
    levels: int = 4
    iterations: int = 12
    max_depth_m: float = SCENE_MAX_DEPTH_M["indoor"]
    depth_scale: str = "max_depth"  # lipjax.networks.common.DEPTH_SCALES

    def __post_init__(self):
        check_max_depth(self.max_depth_m)
        check_depth_scale(self.depth_scale)
        if self.base_width < 1 or self.levels < 1 or self.iterations < 0:
            raise ValueError(f"need base_width, levels >= 1 and iterations >= 0, got "
                             f"{self.base_width}, {self.levels}, {self.iterations}")

    @property
    def multiple(self) -> int:
        return 2**self.levels

    def module(self) -> CSPNNet:
        return CSPNNet(self.base_width, self.levels)

    def apply(self, params, rgb, sparse, weights=None, *, return_trajectory: bool = False):
        """Dense depth (B, H, W) metres from rgb (B, H, W, 3) and sparse (B, H, W) metres. The replacement mask is
        `sparse > 0`, or `weights > 0` when weights are given. Returns (depth, None)."""
        del return_trajectory
        _, h, w = sparse.shape
        sparse = sparse.astype(jnp.float32)
        mask = (sparse > 0) if weights is None else (weights > 0)
        unit = depth_unit(sparse, self.depth_scale, self.max_depth_m)
        x = network_input(rgb, sparse, unit, self.multiple)
        d0, affinity = self.module().apply({"params": params}, x)
        d = propagate(d0[:, :h, :w], affinity[:, :h, :w], sparse / unit, mask, self.iterations)
        # The last replacement in metres: (s / u) * u need not round back to s exactly.
        return jnp.where(mask, sparse, d * unit), None


