r"""End-to-end learned baselines the paper compares against: Ma et al. [2] (sparse-to-dense), U-Net [6], CSPN [7].

Written from the papers' descriptions, one module each (sparse_to_dense, unet, cspn). Each model is a flat, hashable
frozen dataclass implementing lipjax.interfaces.LearnedModel, registered there by type name, so that training
(lipjax.train), inference (lipjax.inference.Completer) and model files (lipjax.model_io) treat them like a LIP model:

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

Presets (PRESETS[model][size], or `baseline_preset(model, size, max_depth_m)`): "paper" (the published widths), "small"
(about LIP's small preset over 3 iterations, ~1.5 M parameters, trainable on a 2-core CPU), "tiny" (tests).
Their parameter counts are asserted in tests/test_networks.py.
"""
from __future__ import annotations

import dataclasses

from lipjax.interfaces import SCENE_MAX_DEPTH_M
from lipjax.networks.cspn import CSPN, CSPNNet, normalize_affinity, propagate
from lipjax.networks.sparse_to_dense import SparseToDense, SparseToDenseNet
from lipjax.networks.unet import UNet, UNetNet

__all__ = ["CSPN", "CSPNNet", "PRESETS", "SparseToDense", "SparseToDenseNet", "UNet", "UNetNet", "baseline_preset",
           "normalize_affinity", "propagate"]


# Parameter counts are asserted in tests/test_networks.py. LIP's small preset is 1.48 M over its 3 iterations.
PRESETS: dict[str, dict[str, object]] = {
    "sparse_to_dense": {
        "paper": SparseToDense(width_multiplier=1.0),       # ResNet-18 at full width (64)
        # ResNet-34 at a quarter width: 1.55 M, the parameter budget of LIP small
        # (ResNet-18 at a quarter width: 0.92 M).
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


def baseline_preset(model: str, size: str, max_depth_m: float = SCENE_MAX_DEPTH_M["indoor"]):
    """PRESETS[model][size] with the depth normalisation of the target scenes (10 m indoors, 85 m outdoors)."""
    if model not in PRESETS:
        raise ValueError(f"unknown baseline network {model!r}; choose one of {sorted(PRESETS)}")
    if size not in PRESETS[model]:
        raise ValueError(f"unknown preset {size!r} for {model}; choose one of {sorted(PRESETS[model])}")
    return dataclasses.replace(PRESETS[model][size], max_depth_m=max_depth_m)

