r"""End-to-end learned baselines the paper compares against: Ma et al. [2] (sparse-to-dense), U-Net [6], CSPN [7].

Written from the papers' descriptions. Each model is a flat, hashable frozen dataclass with the model interface of
lipjax.model.LIPConfig, so that training (lipjax.train), inference (lipjax.inference.Completer) and model files
(lipjax.model_io, which reads MODEL_TYPES below) treat them like a LIP model:

    init(key) -> params                     a plain Flax parameter pytree
    apply(params, rgb, sparse, weights=None, *, return_trajectory=False) -> (depth (B, H, W) metres, None)
    parameter_count(params) -> int
    max_depth_m                             depth normalisation (metres): 10 indoors, 85 outdoors

Inputs: rgb (B, H, W, 3) uint8, or float in [0, 1]; sparse (B, H, W) float32 metres, 0 = no sample. Any H, W: the
input is padded to the network's multiple (edge padding for RGB, zeros = "no sample" for the sparse depth) and the
output cropped back. Inside, the network sees concat(sparse / max_depth_m, rgb - 0.5) and predicts depth in units of
max_depth_m; the output is in metres. There is no trajectory: the second output is always None.

Choices shared with lipjax.priors.network, and why:
- GroupNorm instead of the papers' BatchNorm: no running statistics in the parameter pytree (the shared train loop
  carries none), and the same behaviour at batch 1 (inference) as at batch 8 (training).
- No pretrained weights: Ma et al. and CSPN start their ResNet encoders from ImageNet weights; nothing can be
  downloaded here, so every network is trained from scratch.
- Up-projection is Laina et al.'s, through its sub-pixel "fast up-convolution" (lipjax.priors.network.UpProjection).

Presets (PRESETS[model][size], or `<Class>.preset(size, max_depth_m)`): "paper" (the published widths), "small"
(about LIP's small preset over 3 iterations, ~1.5 M parameters, trainable on a 2-core CPU), "tiny" (tests).
Their parameter counts are asserted in tests/test_networks.py.
"""
from __future__ import annotations

import dataclasses
import math

import flax.linen as nn
import jax
import jax.numpy as jnp

from lipjax.model import parameter_count as _count_scalars
from lipjax.priors.network import UpProjection


# ----------------------------------------------------------------------------------------------------------------
# Shared pieces
# ----------------------------------------------------------------------------------------------------------------

def _group_norm(channels: int) -> nn.GroupNorm:
    """GroupNorm with up to 8 groups; the group count must divide the channels (12 channels -> 4 groups)."""
    return nn.GroupNorm(num_groups=math.gcd(8, channels))


def _network_input(rgb: jax.Array, sparse: jax.Array, max_depth_m: float, multiple: int) -> jax.Array:
    """concat(sparse / max_depth_m, rgb - 0.5): (B, H', W', 4), H' and W' padded up to `multiple`.

    RGB is edge-padded (keeps border statistics); sparse depth is zero-padded (0 = no sample: padding must not
    invent measurements).
    """
    rgb = rgb.astype(jnp.float32) / 255.0 if rgb.dtype == jnp.uint8 else rgb.astype(jnp.float32)
    _, h, w = sparse.shape
    pad = ((0, 0), (0, (-h) % multiple), (0, (-w) % multiple))
    d = jnp.pad(sparse.astype(jnp.float32) / max_depth_m, pad)
    c = jnp.pad(rgb, pad + ((0, 0),), mode="edge") - 0.5
    return jnp.concatenate([d[..., None], c], axis=-1)


def _depth_to_space2(h: jax.Array, features: int) -> jax.Array:
    """(B, H, W, 4 * features) -> (B, 2H, 2W, features)."""
    b, hh, ww, _ = h.shape
    h = h.reshape(b, hh, ww, 2, 2, features).transpose(0, 1, 3, 2, 4, 5)
    return h.reshape(b, 2 * hh, 2 * ww, features)


class _ModelInterface:
    """init / parameter_count shared by the configs below (each defines `module()`, `multiple`, `apply`)."""

    def init(self, key: jax.Array):
        """Random parameters. Shapes do not depend on the image size (fully convolutional): init on the smallest
        input the network accepts."""
        n = self.multiple
        x = jnp.zeros((1, n, n, 4), jnp.float32)
        return self.module().init(key, x)["params"]

    def parameter_count(self, params) -> int:
        return _count_scalars(params)

    @classmethod
    def preset(cls, size: str, max_depth_m: float = 10.0):
        """A preset by size ('paper', 'small', 'tiny') with the depth normalisation of the target scenes (metres)."""
        return baseline_preset(_NAME_OF[cls], size, max_depth_m)


def _check_max_depth(max_depth_m: float) -> None:
    if not max_depth_m > 0:
        raise ValueError(f"max_depth_m must be > 0 metres, got {max_depth_m}")


# ----------------------------------------------------------------------------------------------------------------
# Ma & Karaman 2018, "Sparse-to-Dense: Depth Prediction from Sparse Depth Samples and a Single Image"
# ----------------------------------------------------------------------------------------------------------------

class BasicBlock(nn.Module):
    """ResNet-18/34 basic block: relu(norm(conv3x3(relu(norm(conv3x3_s(h))))) + shortcut), projection shortcut
    when the stride or the width changes."""

    features: int
    strides: int = 1

    @nn.compact
    def __call__(self, h):
        shortcut = h
        if self.strides != 1 or h.shape[-1] != self.features:
            shortcut = _group_norm(self.features)(nn.Conv(self.features, (1, 1), strides=self.strides, use_bias=False)(h))
        y = nn.Conv(self.features, (3, 3), strides=self.strides, use_bias=False)(h)
        y = nn.relu(_group_norm(self.features)(y))
        y = _group_norm(self.features)(nn.Conv(self.features, (3, 3), use_bias=False)(y))
        return nn.relu(y + shortcut)


class SparseToDenseNet(nn.Module):
    """x (B, H, W, 4), H and W multiples of 32 -> depth / max_depth (B, H, W). See `SparseToDense`."""

    width: int
    blocks: tuple[int, ...]

    @nn.compact
    def __call__(self, x):
        w = self.width
        # ResNet encoder, its first convolution taking RGB-D (4 channels): /32 in all.
        h = nn.relu(_group_norm(w)(nn.Conv(w, (7, 7), strides=2, use_bias=False)(x)))
        h = nn.max_pool(h, (3, 3), strides=(2, 2), padding="SAME")
        for stage, n_blocks in enumerate(self.blocks):
            for i in range(n_blocks):
                h = BasicBlock(w * 2**stage, strides=2 if (i == 0 and stage > 0) else 1)(h)
        # 1x1 convolution halving the channels, then 4 up-projections each halving them again: /32 -> /2.
        c = h.shape[-1] // 2
        h = _group_norm(c)(nn.Conv(c, (1, 1), use_bias=False)(h))
        for _ in range(4):
            c //= 2
            h = UpProjection(c)(h)
        d = nn.Conv(1, (3, 3))(h)
        b, hh, ww, _ = d.shape
        d = jax.image.resize(d, (b, 2 * hh, 2 * ww, 1), method="bilinear")
        return d[..., 0]


@dataclasses.dataclass(frozen=True)
class SparseToDense(_ModelInterface):
    """Ma & Karaman (ICRA 2018): a ResNet encoder on concat(RGB, sparse depth), a 1x1 convolution bottleneck, and a
    decoder of 4 up-projection blocks (Laina et al.) to one channel, bilinearly upsampled x2 to the input size.

        x (H, W, 4) -> conv7x7/2, maxpool/2 -> ResNet stages (w, 2w, 4w, 8w; strides 1, 2, 2, 2)   (H/32)
          -> conv1x1 to 4w -> up-projection x4 (2w, w, w/2, w/4)                                  (H/2)
          -> conv3x3 to 1 -> bilinear x2                                                          (H)

    The ResNet is built from scratch with random weights (Ma et al. start from ImageNet weights, which cannot be
    downloaded here), with GroupNorm instead of BatchNorm (see the module docstring).

    Attributes:
      width_multiplier: w = round(64 * width_multiplier) (ResNet's 64); 1.0 is the published width.
      blocks: basic blocks per stage; (2, 2, 2, 2) is ResNet-18, (3, 4, 6, 3) ResNet-34. (Ma et al. also use the
        bottleneck ResNet-50, not implemented here.)
      max_depth_m: depth normalisation (metres).
    """

    width_multiplier: float = 1.0
    blocks: tuple[int, ...] = (2, 2, 2, 2)
    max_depth_m: float = 10.0

    multiple = 32  # the encoder's total downsampling (class attribute, not a field)

    def __post_init__(self):
        _check_max_depth(self.max_depth_m)
        if len(self.blocks) != 4 or min(self.blocks) < 1:
            raise ValueError(f"blocks must be 4 positive block counts (ResNet stages), got {self.blocks}")
        w = self.width
        decoder = [4 * w >> i for i in range(1, 5)]  # 2w, w, w/2, w/4
        # The up-projection blocks normalise with min(8, C) groups, which must divide C.
        if w % 4 or any(c > 8 and c % 8 for c in decoder):
            raise ValueError(f"width 64 * {self.width_multiplier} = {w}: the decoder widths {decoder} must be "
                             "integers that are <= 8 or multiples of 8 (e.g. multipliers 0.125, 0.25, 0.5, 1)")

    @property
    def width(self) -> int:
        return int(round(64 * self.width_multiplier))

    def module(self) -> SparseToDenseNet:
        return SparseToDenseNet(self.width, tuple(self.blocks))

    def apply(self, params, rgb, sparse, weights=None, *, return_trajectory: bool = False):
        """Dense depth (B, H, W) metres from rgb (B, H, W, 3) and sparse (B, H, W) metres; `weights` is unused.
        Returns (depth, None)."""
        del weights, return_trajectory
        _, h, w = sparse.shape
        x = _network_input(rgb, sparse, self.max_depth_m, self.multiple)
        d = self.module().apply({"params": params}, x)
        return d[:, :h, :w] * self.max_depth_m, None


# ----------------------------------------------------------------------------------------------------------------
# U-Net (Ronneberger et al. 2015) on RGB-D
# ----------------------------------------------------------------------------------------------------------------

class _DoubleConv(nn.Module):
    features: int

    @nn.compact
    def __call__(self, h):
        for _ in range(2):
            h = nn.relu(_group_norm(self.features)(nn.Conv(self.features, (3, 3), use_bias=False)(h)))
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
            h = _depth_to_space2(nn.Conv(4 * c, (1, 1))(h), c)
            h = _DoubleConv(c)(jnp.concatenate([h, skips[level]], axis=-1))
        return h


class UNetNet(nn.Module):
    base_width: int
    levels: int

    @nn.compact
    def __call__(self, x):
        h = UNetBody(self.base_width, self.levels)(x)
        return nn.Conv(1, (1, 1))(h)[..., 0]


@dataclasses.dataclass(frozen=True)
class UNet(_ModelInterface):
    """U-Net on concat(RGB, sparse depth): `levels` down / `levels` up with skip concatenations (UNetBody), then a
    1x1 convolution to depth / max_depth_m.

    Attributes:
      base_width: channels of the first level (Ronneberger et al.: 64); level l has base_width * 2**l.
      levels: number of 2x poolings (4 in the paper); inputs are padded to a multiple of 2**levels.
      max_depth_m: depth normalisation (metres).
    """

    base_width: int = 64
    levels: int = 4
    max_depth_m: float = 10.0

    def __post_init__(self):
        _check_max_depth(self.max_depth_m)
        if self.base_width < 1 or self.levels < 1:
            raise ValueError(f"base_width and levels must be >= 1, got {self.base_width}, {self.levels}")

    @property
    def multiple(self) -> int:
        return 2**self.levels

    def module(self) -> UNetNet:
        return UNetNet(self.base_width, self.levels)

    def apply(self, params, rgb, sparse, weights=None, *, return_trajectory: bool = False):
        """Dense depth (B, H, W) metres from rgb (B, H, W, 3) and sparse (B, H, W) metres; `weights` is unused.
        Returns (depth, None)."""
        del weights, return_trajectory
        _, h, w = sparse.shape
        x = _network_input(rgb, sparse, self.max_depth_m, self.multiple)
        d = self.module().apply({"params": params}, x)
        return d[:, :h, :w] * self.max_depth_m, None


# ----------------------------------------------------------------------------------------------------------------
# CSPN: Cheng, Wang & Yang 2018, "Depth Estimation via Affinity Learned with Convolutional Spatial Propagation Network"
# ----------------------------------------------------------------------------------------------------------------

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


def propagate(h0: jax.Array, raw_affinity: jax.Array, sparse: jax.Array, mask: jax.Array, iterations: int) -> jax.Array:
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


@dataclasses.dataclass(frozen=True)
class CSPN(_ModelInterface):
    """CSPN for depth completion: a U-Net backbone (UNetBody) on concat(RGB, sparse depth) predicts an initial
    depth and 8-neighbour affinities (3x3 kernel); `iterations` steps of spatial propagation with replacement
    (`propagate`) refine the depth, so the output equals the sparse input exactly on measured pixels.

    Cheng et al. use Ma et al.'s ResNet-50 up-projection network with skip connections as backbone; a U-Net-like
    backbone keeps this comparable to the `UNet` baseline. Propagation runs on the unpadded image.

    Attributes:
      base_width, levels: the backbone (as in `UNet`).
      iterations: T propagation steps (the paper: 24).
      max_depth_m: depth normalisation (metres).
    """

    base_width: int = 64
    levels: int = 4
    iterations: int = 12
    max_depth_m: float = 10.0

    def __post_init__(self):
        _check_max_depth(self.max_depth_m)
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
        x = _network_input(rgb, sparse, self.max_depth_m, self.multiple)
        d0, affinity = self.module().apply({"params": params}, x)
        d = propagate(d0[:, :h, :w], affinity[:, :h, :w], sparse / self.max_depth_m, mask, self.iterations)
        # The last replacement in metres: (s / max_depth) * max_depth need not round back to s exactly.
        return jnp.where(mask, sparse, d * self.max_depth_m), None


# ----------------------------------------------------------------------------------------------------------------
# Registry and presets
# ----------------------------------------------------------------------------------------------------------------

# Model types by the name written in model files (lipjax.model_io).
MODEL_TYPES: dict[str, type] = {"sparse_to_dense": SparseToDense, "unet": UNet, "cspn": CSPN}
_NAME_OF = {cls: name for name, cls in MODEL_TYPES.items()}

# Parameter counts are asserted in tests/test_networks.py. LIP's small preset is 1.48 M over its 3 iterations.
PRESETS: dict[str, dict[str, object]] = {
    "sparse_to_dense": {
        "paper": SparseToDense(width_multiplier=1.0),       # ResNet-18 at full width (64)
        # ResNet-34 at a quarter width: 1.55 M, the parameter budget of LIP small (ResNet-18 at a quarter width: 0.92 M).
        "small": SparseToDense(width_multiplier=0.25, blocks=(3, 4, 6, 3)),
        "tiny": SparseToDense(width_multiplier=0.125, blocks=(1, 1, 1, 1)),
    },
    "unet": {
        "paper": UNet(base_width=64),
        "small": UNet(base_width=14),
        "tiny": UNet(base_width=4),
    },
    "cspn": {
        "paper": CSPN(base_width=64, iterations=24),  # the U-Net 64 backbone, not Cheng et al.'s ResNet-50
        "small": CSPN(base_width=14, iterations=12),
        "tiny": CSPN(base_width=4, iterations=3),
    },
}


def baseline_preset(model: str, size: str, max_depth_m: float = 10.0):
    """PRESETS[model][size] with the depth normalisation of the target scenes (10 m indoors, 85 m outdoors)."""
    if model not in PRESETS:
        raise ValueError(f"unknown baseline network {model!r}; choose one of {sorted(PRESETS)}")
    if size not in PRESETS[model]:
        raise ValueError(f"unknown preset {size!r} for {model}; choose one of {sorted(PRESETS[model])}")
    return dataclasses.replace(PRESETS[model][size], max_depth_m=max_depth_m)
