r"""The learned, RGB-guided proximal operator G of the paper (Sec. III-B, eq. 9): z = G(x + u, R).

Architecture (early fusion encoder-decoder, paper Fig. 2):

    concat(v / max_depth, rgb - 0.5)                 (B, H, W, 4), H and W padded to a multiple of 8
    stem:  3x3 conv                                  (H,    W)    stem_width
    b1..b3: ResNet bottleneck blocks, stride 2       (H/2 .. H/8)  4 * bottleneck_widths[i]
    up1:   up-projection (Laina et al. 2016)         (H/4)  -> concat skip b2
    up2:   up-projection                             (H/2)  -> concat skip b1    (the paper's 2 skip connections)
    up3:   up-projection                             (H)
    head:  3x3 conv to 1 channel, zero-initialised, read as a residual on v in units of max_depth
           (depth_domain="log": the input channel is log(v / max_depth) and the residual is added to it, so
           z = v * exp(residual): a relative correction, and z > 0 whatever the network outputs)

Choices and why:
- Flax Linen applied functionally: the parameters are a plain pytree, so per-iteration networks are a `vmap` over
  `init` with split keys, stacked on a leading axis that `lax.scan` slices; optax and orbax take the pytree as is.
  Measured on this CPU, Linen ran as fast as NNX with the shortest training code.
- GroupNorm instead of BatchNorm: no running statistics to thread through the unrolled solver, and it behaves
  the same at batch 1 (inference) as at batch 8 (training).
- Up-projection: Laina's "fast up-convolution" replaces unpool + 5x5 conv by four small convolutions whose outputs
  are interleaved. We use its sub-pixel form: one 3x3 conv with 4C outputs followed by depth-to-space, whose
  3x3 support per output phase contains Laina's 3x3 / 3x2 / 2x3 / 2x2 kernels. It was ~4x faster to train here
  than a 5x5 transposed convolution.
- Zero-initialised residual head: an untrained G is the identity, so an untrained LIP model returns its initial
  fill with the measurements kept, instead of noise.
- The log domain is an option for outdoor scenes, where depth spans 1-80 m: an additive residual in units of
  max_depth must be 10x finer at 8 m than at 80 m for the same relative error (what REL and the inverse-depth metrics
  score), and nothing stops it from crossing zero (a few thin poles did,
  docs/decisions/0003-losses-and-log-depth-prox.md).

Units: v and z in metres; `max_depth_m` (10 m indoors, 80-90 m outdoors) only scales the network's inputs/outputs.
"""
from __future__ import annotations

import dataclasses

import flax.linen as nn
import jax
import jax.numpy as jnp

from lipjax.interfaces import SCENE_MAX_DEPTH_M, register_prior_type
from lipjax.priors.base import Prior

DOWNSAMPLING = 8  # three stride-2 bottleneck blocks
LOG_DOMAIN_FLOOR = 1e-3  # depth_domain="log": v is floored at this fraction of max_depth before the log
DEPTH_DOMAINS = ("linear", "log")


def _norm(channels: int) -> nn.GroupNorm:
    return nn.GroupNorm(num_groups=min(8, channels))


class Bottleneck(nn.Module):
    """ResNet bottleneck (1x1 -> 3x3 stride 2 -> 1x1, expansion 4) with a projection shortcut."""

    width: int

    @nn.compact
    def __call__(self, h):
        out = 4 * self.width
        shortcut = nn.Conv(out, (1, 1), strides=2)(h)
        h = nn.relu(_norm(self.width)(nn.Conv(self.width, (1, 1))(h)))
        h = nn.relu(_norm(self.width)(nn.Conv(self.width, (3, 3), strides=2)(h)))
        h = _norm(out)(nn.Conv(out, (1, 1))(h))
        return nn.relu(h + shortcut)


def _fast_upconv(h, features: int):
    """x2 upsampling convolution: 3x3 conv to 4*features channels, then depth-to-space (sub-pixel)."""
    b, hh, ww, _ = h.shape
    h = nn.Conv(4 * features, (3, 3))(h)
    h = h.reshape(b, hh, ww, 2, 2, features).transpose(0, 1, 3, 2, 4, 5)
    return h.reshape(b, 2 * hh, 2 * ww, features)


class UpProjection(nn.Module):
    """Laina et al.'s up-projection: relu(conv3x3(relu(upconv_a(h))) + upconv_b(h))."""

    features: int

    @nn.compact
    def __call__(self, h):
        a = nn.relu(_norm(self.features)(_fast_upconv(h, self.features)))
        a = _norm(self.features)(nn.Conv(self.features, (3, 3))(a))
        b = _norm(self.features)(_fast_upconv(h, self.features))
        return nn.relu(a + b)


class ProxNet(nn.Module):
    """G: (v (B,H,W) metres, guidance (B,H,W,C) in [0,1]: RGB, optionally + mask channels) -> z (B,H,W) metres."""

    stem_width: int
    bottleneck_widths: tuple[int, int, int]
    up_widths: tuple[int, int, int]
    max_depth_m: float
    depth_domain: str = "linear"

    @nn.compact
    def __call__(self, v, rgb):
        b, height, width = v.shape
        pad_h, pad_w = (-height) % DOWNSAMPLING, (-width) % DOWNSAMPLING
        # Edge padding keeps the border statistics of the image; the padding is cropped off the output.
        pad = ((0, 0), (0, pad_h), (0, pad_w))
        d = jnp.pad(v, pad, mode="edge") / self.max_depth_m
        if self.depth_domain == "log":
            d = jnp.log(jnp.maximum(d, LOG_DOMAIN_FLOOR))
        c = jnp.pad(rgb, pad + ((0, 0),), mode="edge") - 0.5
        h = jnp.concatenate([d[..., None], c], axis=-1)

        s = nn.relu(_norm(self.stem_width)(nn.Conv(self.stem_width, (3, 3))(h)))
        b1 = Bottleneck(self.bottleneck_widths[0])(s)
        b2 = Bottleneck(self.bottleneck_widths[1])(b1)
        b3 = Bottleneck(self.bottleneck_widths[2])(b2)
        u = UpProjection(self.up_widths[0])(b3)
        u = UpProjection(self.up_widths[1])(jnp.concatenate([u, b2], axis=-1))
        u = UpProjection(self.up_widths[2])(jnp.concatenate([u, b1], axis=-1))
        residual = nn.Conv(1, (3, 3), kernel_init=nn.initializers.zeros)(u)[..., 0]
        if self.depth_domain == "log":
            # clip: exp of an early wild residual must not overflow; +-8 is a factor of 3000 either way
            z = jnp.exp(d + jnp.clip(residual, -8.0, 8.0))
        else:
            z = d + residual
        return z[:, :height, :width] * self.max_depth_m


@register_prior_type("network")
@dataclasses.dataclass(frozen=True)
class NetworkPrior(Prior):
    """The learned prox as a prior (lipjax.priors.base): hashable config + init/apply on a parameter pytree."""

    stem_width: int = 16
    bottleneck_widths: tuple[int, int, int] = (8, 16, 24)
    up_widths: tuple[int, int, int] = (32, 24, 16)
    max_depth_m: float = SCENE_MAX_DEPTH_M["indoor"]
    depth_domain: str = "linear"  # "log": relative corrections, positive output (see the module docstring)

    def __post_init__(self):
        if self.depth_domain not in DEPTH_DOMAINS:
            raise ValueError(f"depth_domain must be one of {DEPTH_DOMAINS}, got {self.depth_domain!r}")

    def module(self) -> ProxNet:
        return ProxNet(self.stem_width, tuple(self.bottleneck_widths), tuple(self.up_widths), self.max_depth_m,
                       self.depth_domain)

    def init(self, key: jax.Array, image_shape: tuple[int, int] = (64, 64), guidance_channels: int = 3):
        """Parameters for guidance images of `guidance_channels` channels (3 = RGB; the LIP model may add more)."""
        # Parameter shapes do not depend on the image size (fully convolutional); a small dummy keeps init cheap.
        v = jnp.zeros((1, *image_shape), jnp.float32)
        rgb = jnp.zeros((1, *image_shape, guidance_channels), jnp.float32)
        return self.module().init(key, v, rgb)["params"]

    def apply(self, params, v, rgb):
        return self.module().apply({"params": params}, v, rgb)


# Presets. Parameter counts (per iteration) are asserted in tests/test_network.py.
PRESETS: dict[str, NetworkPrior] = {
    # ~0.5 M per iteration: trainable on a 2-core CPU at 128x160.
    "small": NetworkPrior(stem_width=16, bottleneck_widths=(8, 16, 24), up_widths=(32, 24, 16)),
    # ~2.6 M per iteration, ~7.7 M over K = 3 iterations: close to the paper's 7.88 M (its Table II).
    "paper": NetworkPrior(stem_width=32, bottleneck_widths=(16, 32, 48), up_widths=(80, 64, 32)),
    # A few thousand parameters, for tests only.
    "tiny": NetworkPrior(stem_width=8, bottleneck_widths=(4, 4, 4), up_widths=(8, 8, 8)),
}


def network_preset(name: str, max_depth_m: float = SCENE_MAX_DEPTH_M["indoor"]) -> NetworkPrior:
    """A preset by name, with the depth normalisation of the target scenes (metres)."""
    if name not in PRESETS:
        raise ValueError(f"unknown network preset {name!r}; choose one of {sorted(PRESETS)}")
    return dataclasses.replace(PRESETS[name], max_depth_m=max_depth_m)
