"""Ma & Karaman 2018, "Sparse-to-Dense: Depth Prediction from Sparse Depth Samples and a Single Image"."""
from __future__ import annotations

import dataclasses

import flax.linen as nn
import jax

from lipjax.interfaces import SCENE_MAX_DEPTH_M, register_model_type
from lipjax.networks.common import NetworkModel, check_depth_scale, check_max_depth, group_norm
from lipjax.priors.network import UpProjection


class BasicBlock(nn.Module):
    """ResNet-18/34 basic block: relu(norm(conv3x3(relu(norm(conv3x3_s(h))))) + shortcut), projection shortcut
    when the stride or the width changes."""

    features: int
    strides: int = 1

    @nn.compact
    def __call__(self, h):
        shortcut = h
        if self.strides != 1 or h.shape[-1] != self.features:
            shortcut = group_norm(self.features)(
                nn.Conv(self.features, (1, 1), strides=self.strides, use_bias=False)(h))
        y = nn.Conv(self.features, (3, 3), strides=self.strides, use_bias=False)(h)
        y = nn.relu(group_norm(self.features)(y))
        y = group_norm(self.features)(nn.Conv(self.features, (3, 3), use_bias=False)(y))
        return nn.relu(y + shortcut)


class SparseToDenseNet(nn.Module):
    """x (B, H, W, 4), H and W multiples of 32 -> depth / max_depth (B, H, W). See `SparseToDense`."""

    width: int
    blocks: tuple[int, ...]

    @nn.compact
    def __call__(self, x):
        w = self.width
        # ResNet encoder, its first convolution taking RGB-D (4 channels): /32 in all.
        h = nn.relu(group_norm(w)(nn.Conv(w, (7, 7), strides=2, use_bias=False)(x)))
        h = nn.max_pool(h, (3, 3), strides=(2, 2), padding="SAME")
        for stage, n_blocks in enumerate(self.blocks):
            for i in range(n_blocks):
                h = BasicBlock(w * 2**stage, strides=2 if (i == 0 and stage > 0) else 1)(h)
        # 1x1 convolution halving the channels, then 4 up-projections each halving them again: /32 -> /2.
        c = h.shape[-1] // 2
        h = group_norm(c)(nn.Conv(c, (1, 1), use_bias=False)(h))
        for _ in range(4):
            c //= 2
            h = UpProjection(c)(h)
        d = nn.Conv(1, (3, 3))(h)
        b, hh, ww, _ = d.shape
        d = jax.image.resize(d, (b, 2 * hh, 2 * ww, 1), method="bilinear")
        return d[..., 0]


@register_model_type("sparse_to_dense")
@dataclasses.dataclass(frozen=True)
class SparseToDense(NetworkModel):
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
      max_depth_m: the depth range (metres), the depth unit under depth_scale "max_depth".
      depth_scale: the depth unit of the network's input and output (lipjax.networks.common.DEPTH_SCALES).
    """

    width_multiplier: float = 1.0
    blocks: tuple[int, ...] = (2, 2, 2, 2)
    max_depth_m: float = SCENE_MAX_DEPTH_M["indoor"]
    depth_scale: str = "max_depth"  # lipjax.networks.common.DEPTH_SCALES

    multiple = 32  # the encoder's total downsampling (class attribute, not a field)

    def __post_init__(self):
        check_max_depth(self.max_depth_m)
        check_depth_scale(self.depth_scale)
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


