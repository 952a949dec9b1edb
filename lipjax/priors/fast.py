r"""A cheaper learned prox: the RGB guidance is encoded once per frame, each iteration runs a light depth branch.

The paper's G_k (lipjax.priors.network) re-encodes the RGB image at every ADMM iteration, although R does not
change between iterations. Here the work is split in two:

    F = E(R, m, r)                                  guidance encoder, once per frame, shared by every iteration
                                                   F = (F_1, F_2, F_3) at 1/2, 1/4 and 1/8 of the image size
    d = log(max(v, eps s) / s)                      v = x_{k+1} + u_k; s = geometric mean of the frame's samples
    z_{k+1} = G_k(v, F) = v * exp(D_k(d, F))        D_k: per-iteration depth branch (encoder-decoder at <= 1/2)

Why each piece:
- **Shared encoder.** The image features are computed once, so K iterations cost one encoder + K light branches.
- **No layer at full resolution.** Full-resolution input enters by space-to-depth (each 2x2 block of pixels as
  one pixel of 4x the channels at 1/2 resolution) and the output leaves by depth-to-space. On a CPU thin
  full-resolution layers cost more in memory passes than in arithmetic: a first version with two 8-channel
  full-resolution convolutions per iteration ran at 37 GFLOP/s against 120 for a 2048x2048 matmul.
- **Scale-aware input.** The branch sees log depth relative to the mean log depth s of the frame's own samples, so a
  1-10 m room and a 1-80 m street give inputs of the same range (OMNI-DC normalises its network input the same
  way), and the output is v * exp(residual): a relative correction, positive for any weights, independent of the
  metric scale. No max depth enters the network.
- **Zero-initialised head**: an untrained G_k is the identity, so an untrained model returns its initial estimate.
- **GroupNorm**, as in the paper-style G: no running statistics, the same at batch 1 and 8.

Units: v, z and s in metres; the network works on dimensionless log ratios.
"""
from __future__ import annotations

import dataclasses

import flax.linen as nn
import jax
import jax.numpy as jnp

from lipjax.interfaces import SCENE_MAX_DEPTH_M, register_prior_type
from lipjax.priors.base import EncodedGuidance, SharedEncoderPrior

DOWNSAMPLING = 8  # space-to-depth, then two stride-2 stages
RELATIVE_FLOOR = 1e-3  # v is floored at this fraction of the sample median s before the log
RESIDUAL_CLIP = 4.0  # |log correction| <= 4: a factor of 55 either way; keeps exp finite early in training
GROUPNORM_EPS = 1e-6  # nn.GroupNorm's default, which the trained weights were fitted with


class _ConvParams(nn.Module):
    """The parameters of nn.Conv(features, (3, 3)), with its names, shapes and initialisers: kernel
    (3, 3, in_features, features), bias (features,). Applied by the caller (`_conv`), so that the bias can be folded
    into the GroupNorm that follows."""

    features: int

    @nn.compact
    def __call__(self, in_features: int):
        kernel = self.param("kernel", nn.linear.default_kernel_init, (3, 3, in_features, self.features))
        return kernel, self.param("bias", nn.initializers.zeros_init(), (self.features,))


class _NormParams(nn.Module):
    """The parameters of nn.GroupNorm over `features` channels: scale (ones) and bias (zeros), (features,)."""

    features: int

    @nn.compact
    def __call__(self):
        return (self.param("scale", nn.initializers.ones_init(), (self.features,)),
                self.param("bias", nn.initializers.zeros_init(), (self.features,)))


def _conv(h, kernel, strides: int = 1, padding="SAME"):
    """Convolution without bias, (B, H, W, C_in) -> (B, H', W', C_out), as nn.Conv computes it; padding as lax's."""
    return jax.lax.conv_general_dilated(h, kernel, (strides, strides), padding,
                                        dimension_numbers=("NHWC", "HWIO", "NHWC"))


def _norm_relu(c, conv_bias, scale, bias):
    """relu(GroupNorm(c + conv_bias)): nn.GroupNorm with min(8, C) groups of the biased convolution output c.

    The convolution's bias is folded into the statistics and the affine map instead of being added in a pass of
    its own. With per-channel sums over the n pixels S1 = sum c and S2 = sum c^2, the biased map has sums
    S1 + n b and S2 + 2 b S1 + n b^2; its group mean mu and variance var (E[y^2] - mu^2, as nn.GroupNorm's fast
    variance) give relu(c a + beta + (b - mu) a) with a = gamma / sqrt(var + eps). On the 2-core CPU this costs a
    third of nn.Conv + nn.GroupNorm's time beyond the convolution: no bias pass, and per-channel sums, which XLA
    reduces faster than sums over (pixels, channels of a group).
    """
    _, height, width, channels = c.shape
    groups = min(8, channels)
    n = height * width
    s1, s2 = c.sum(axis=(1, 2)), (c * c).sum(axis=(1, 2))  # (B, C)

    def group_mean(s):  # (B, C) per-channel sums -> (B, C): the mean over each channel's group, repeated
        per_group = s.reshape(-1, groups, channels // groups).sum(axis=-1) / (n * (channels // groups))
        return jnp.repeat(per_group, channels // groups, axis=-1)

    mu = group_mean(s1 + n * conv_bias)
    var = jnp.maximum(0.0, group_mean(s2 + 2 * conv_bias * s1 + n * conv_bias**2) - mu**2)
    a = scale * jax.lax.rsqrt(var + GROUPNORM_EPS)
    return nn.relu(c * a[:, None, None] + (bias + (conv_bias - mu) * a)[:, None, None])


def _conv_norm_relu(h, features: int, index: int, strides: int = 1):
    """relu(GroupNorm(Conv(h))); `index` names the parameters Conv_<index> and GroupNorm_<index>, as the
    auto-named nn.Conv and nn.GroupNorm did (the trained weights load unchanged)."""
    kernel, conv_bias = _ConvParams(features, name=f"Conv_{index}")(h.shape[-1])
    return _norm_relu(_conv(h, kernel, strides), conv_bias, *_NormParams(features, name=f"GroupNorm_{index}")())


def _upsampled_kernel(kernel):
    """(3, 3, C_in, C_out) -> (2, 2, C_in, 4 C_out): the 2x2 kernels of the four phases (`_upsampled_conv`).

    Along each axis, phase 0 of the upsampled map reads low-resolution offsets (-1, 0) with the taps
    (k_-1, k_0 + k_+1), phase 1 reads (0, +1) with (k_-1 + k_0, k_+1). Output channels are ordered (a, b, C_out).
    """
    def phases(k):  # (3 taps, ...) -> (2 phases, 2 taps, ...)
        return jnp.stack([jnp.stack([k[0], k[1] + k[2]]), jnp.stack([k[0] + k[1], k[2]])])

    rows = phases(kernel)  # (a, r, 3, C_in, C_out)
    both = phases(jnp.moveaxis(rows, 2, 0))  # (b, s, a, r, C_in, C_out)
    return both.transpose(3, 1, 4, 2, 0, 5).reshape(2, 2, kernel.shape[2], 4 * kernel.shape[3])


def _upsampled_conv_plain(low, kernel):
    """_conv(upsample2(low), kernel) as written: the x2 nearest-upsampled map, then the 3x3 convolution."""
    return _conv(jnp.repeat(jnp.repeat(low, 2, axis=1), 2, axis=2), kernel)


@jax.custom_vjp
def _upsampled_conv(low, kernel):
    """_conv(upsample2(low), kernel) computed at the low resolution: (B, h, w, C_in) -> (B, 2h, 2w, C_out).

    Output pixel (2i + a, 2j + b) of a 3x3 convolution of the x2 nearest-upsampled map reads only the
    low-resolution rows i - 1 + a, i + a and columns j - 1 + b, j + b: a 2x2 convolution per phase (a, b), with
    the kernel's taps summed (`_upsampled_kernel`). The four run as one 2x2 convolution of 4 C_out channels over the
    low map padded by one zero pixel (the upsampled map's zero padding), with 4/9 of the multiply-adds and no
    upsampled map in memory; phase (a, b) is read at offset (a, b) of its output.

    The gradient is that of the same map written plainly (`_upsampled_conv_plain`, equal in exact arithmetic):
    XLA's CPU backward of the phase form (its kernel sums, the 2x2 convolution, the phase slices) took 4-8x as long
    (a training step of lip_any 2.3 s, against 0.2 s for its forward), the plain form's is an ordinary
    convolution's (`python -m benchmarks.train_throughput --sources --models lip_any`).
    """
    b, h, w, _ = low.shape
    c = kernel.shape[3]
    y = _conv(low, _upsampled_kernel(kernel), padding=((1, 1), (1, 1))).reshape(b, h + 1, w + 1, 2, 2, c)
    phases = jnp.stack([jnp.stack([y[:, a:a + h, p:p + w, a, p] for p in (0, 1)], axis=3) for a in (0, 1)], axis=2)
    return phases.reshape(b, 2 * h, 2 * w, c)  # (B, h, a, w, b, C) -> (B, 2h, 2w, C)


def _upsampled_conv_fwd(low, kernel):
    return _upsampled_conv(low, kernel), (low, kernel)


def _upsampled_conv_bwd(residuals, g):
    return jax.vjp(_upsampled_conv_plain, *residuals)[1](g)


_upsampled_conv.defvjp(_upsampled_conv_fwd, _upsampled_conv_bwd)


def _up_conv_norm_relu(low, skip, features: int, index: int):
    """_conv_norm_relu(concat([upsample2(low), skip])) without forming the upsampled or the concatenated map:
    the kernel's first low.shape[-1] input channels act on upsample2(low) (`_upsampled_conv`), the others on skip."""
    kernel, conv_bias = _ConvParams(features, name=f"Conv_{index}")(low.shape[-1] + skip.shape[-1])
    c = _upsampled_conv(low, kernel[:, :, :low.shape[-1]]) + _conv(skip, kernel[:, :, low.shape[-1]:])
    return _norm_relu(c, conv_bias, *_NormParams(features, name=f"GroupNorm_{index}")())


def _pad_to_multiple(a, height: int, width: int):
    pad = ((0, 0), (0, (-height) % DOWNSAMPLING), (0, (-width) % DOWNSAMPLING)) + ((0, 0),) * (a.ndim - 3)
    return jnp.pad(a, pad, mode="edge")  # edge padding keeps the border statistics; cropped off the output


def space_to_depth(a):
    """(B, H, W, C) -> (B, H/2, W/2, 4C): each 2x2 block of pixels becomes one pixel of 4x the channels."""
    b, h, w, c = a.shape
    return a.reshape(b, h // 2, 2, w // 2, 2, c).transpose(0, 1, 3, 2, 4, 5).reshape(b, h // 2, w // 2, 4 * c)


def depth_to_space(a):
    """(B, H/2, W/2, 4C) -> (B, H, W, C): the inverse of `space_to_depth`."""
    b, h, w, c4 = a.shape
    c = c4 // 4
    return a.reshape(b, h, w, 2, 2, c).transpose(0, 1, 3, 2, 4, 5).reshape(b, 2 * h, 2 * w, c)


class GuidanceEncoder(nn.Module):
    """E: guidance (B, H, W, C) in [0, 1] -> features at 1/2, 1/4 and 1/8 resolution.

    The full-resolution detail is kept by space-to-depth (each 2x2 block as 4C channels), not by convolutions at
    full resolution, which on a CPU cost more in memory passes than in arithmetic.
    """

    widths: tuple[int, int, int]

    @nn.compact
    def __call__(self, guidance):
        w1, w2, w3 = self.widths
        h = space_to_depth(guidance - 0.5)
        f1 = _conv_norm_relu(_conv_norm_relu(h, w1, 0), w1, 1)
        f2 = _conv_norm_relu(_conv_norm_relu(f1, w2, 2, strides=2), w2, 3)
        f3 = _conv_norm_relu(_conv_norm_relu(f2, w3, 4, strides=2), w3, 5)
        return f1, f2, f3


class DepthBranch(nn.Module):
    """D_k: (d (B, H, W) log ratio, features) -> log correction (B, H, W); H, W multiples of 8.

    d enters by space-to-depth at 1/2 resolution; the output leaves by depth-to-space (4 sub-pixel values per
    1/2-resolution pixel), so no layer runs at full resolution. The decoder's x2 nearest upsampling and the
    convolution after it run as one convolution at the lower resolution (`_upsampled_conv`).
    """

    widths: tuple[int, int, int]

    @nn.compact
    def __call__(self, d, features):
        f1, f2, f3 = features
        w1, w2, w3 = self.widths
        h1 = _conv_norm_relu(jnp.concatenate([space_to_depth(d[..., None]), f1], axis=-1), w1, 0)
        h2 = _conv_norm_relu(_conv_norm_relu(h1, w2, 1, strides=2) + f2, w2, 2)
        h3 = _conv_norm_relu(_conv_norm_relu(h2, w3, 3, strides=2) + f3, w3, 4)
        u2 = _up_conv_norm_relu(h3, h2, w2, 5)
        u1 = _up_conv_norm_relu(u2, h1, w1, 6)
        out = nn.Conv(4, (3, 3), kernel_init=nn.initializers.zeros, name="Conv_7")(u1)
        return depth_to_space(out)[..., 0]


def sample_scale(y: jax.Array, weights: jax.Array) -> jax.Array:
    """(B, 1, 1) geometric mean depth of each image's samples (y > 0 and weights > 0), metres; 1 m if none.

    The geometric mean (the mean of log depth) rather than the median: one masked sum instead of a sort of every
    pixel (10 ms per 256x320 frame on the 2-core CPU, as much as the guidance encoder).
    """
    m = ((weights > 0) & (y > 0)).astype(y.dtype)
    count = m.sum(axis=(1, 2), keepdims=True)
    log_mean = (m * jnp.log(jnp.where(m > 0, y, 1.0))).sum(axis=(1, 2), keepdims=True) / jnp.maximum(count, 1.0)
    return jnp.where(count > 0, jnp.exp(log_mean), 1.0)


@register_prior_type("fast")
@dataclasses.dataclass(frozen=True)
class FastPrior(SharedEncoderPrior):
    """The fast prox as a `SharedEncoderPrior`: `encode` once per frame, then `apply` per iteration.

    encoder_widths / branch_widths: channels at 1/2, 1/4 and 1/8 resolution.
    max_depth_m: the depth range of the scenes it is trained for (metres). The network never sees it (its input
      is relative to the samples); it sets the unit of the training loss and the evaluation cap.
    """

    encoder_widths: tuple[int, int, int] = (32, 48, 64)
    branch_widths: tuple[int, int, int] = (24, 48, 64)
    max_depth_m: float = SCENE_MAX_DEPTH_M["indoor"]

    def __post_init__(self):
        for name in ("encoder_widths", "branch_widths"):
            if len(getattr(self, name)) != 3:
                raise ValueError(f"{name} must give 3 widths (1/2, 1/4, 1/8 resolution), got {getattr(self, name)}")
        if tuple(self.encoder_widths[1:]) != tuple(self.branch_widths[1:]):
            raise ValueError("encoder_widths and branch_widths must agree at 1/4 and 1/8 resolution "
                             "(features are added)")

    def _encoder(self) -> GuidanceEncoder:
        return GuidanceEncoder(tuple(self.encoder_widths))

    def _branch(self) -> DepthBranch:
        return DepthBranch(tuple(self.branch_widths))

    def init_encoder(self, key: jax.Array, guidance_channels: int = 3):
        return self._encoder().init(key, jnp.zeros((1, 16, 16, guidance_channels), jnp.float32))["params"]

    def init(self, key: jax.Array, image_shape: tuple[int, int] = (64, 64), guidance_channels: int = 3):
        enc = self._encoder()
        dummy = jnp.zeros((1, *image_shape, guidance_channels), jnp.float32)
        features = enc.apply({"params": enc.init(key, dummy)["params"]}, dummy)
        return self._branch().init(key, jnp.zeros((1, *image_shape), jnp.float32), features)["params"]

    def encode(self, encoder_params, guidance: jax.Array, y: jax.Array, weights: jax.Array) -> EncodedGuidance:
        _, height, width, _ = guidance.shape
        features = self._encoder().apply({"params": encoder_params}, _pad_to_multiple(guidance, height, width))
        return EncodedGuidance(features=features, scale=sample_scale(y, weights))

    def apply(self, params, v: jax.Array, guidance: EncodedGuidance) -> jax.Array:
        _, height, width = v.shape
        s = guidance.scale
        v_pos = jnp.maximum(v, RELATIVE_FLOOR * s)
        d = jnp.log(_pad_to_multiple(v_pos / s, height, width))
        residual = self._branch().apply({"params": params}, d, guidance.features)[:, :height, :width]
        return v_pos * jnp.exp(jnp.clip(residual, -RESIDUAL_CLIP, RESIDUAL_CLIP))


PRESETS: dict[str, FastPrior] = {
    # 5.9 GFLOP per 256x320 frame at K = 3 (benchmarks/prox_speed.py), against 18 for the paper-style "small".
    "fast": FastPrior(),
    # For tests only.
    "tiny": FastPrior(encoder_widths=(4, 8, 8), branch_widths=(4, 8, 8)),
}
