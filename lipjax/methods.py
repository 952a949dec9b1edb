"""The one registry of depth-completion methods: every method by name, for the library, experiments and the CLI.

    get_method("lip-ad-indoor")        a shipped learned model (lipjax/weights), or any saved model path
    get_method("lip-wavelet")          LIP with the hand-crafted wavelet soft-thresholding prox (no training)
    get_method("linear")               a hand-crafted fill (CLASSICAL): nearest, linear, ip_basic,
    get_method("ip_basic", extrapolate=True)   ip_basic_multiscale, ip_basic_adaptive, colorization; keyword
                                       arguments override the method's settings

All are `DepthCompleter`s: completer(rgb (H,W,3) uint8, sparse (H,W) float32 metres) -> (H,W) float32 m, with
a `name`. Learned models are `lipjax.inference.Completer`s over a `lipjax.interfaces.LearnedModel` (model types by
name: `lipjax.interfaces.MODEL_TYPES`, the table model files use).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

from lipjax import model_io
from lipjax.classical import (
    ColorizationFill,
    IPBasicAdaptiveFill,
    IPBasicFill,
    IPBasicMultiscaleFill,
    LinearFill,
    NearestFill,
)
from lipjax.classical.completer import DepthCompleter
from lipjax.classical.lip_wavelet import LIPWavelet
from lipjax.inference import load_model

SCENES = ("indoor", "outdoor")

# Methods without learned parameters, by name: their factories take the method's settings as keyword arguments.
CLASSICAL: dict[str, Callable[..., DepthCompleter]] = {
    "nearest": NearestFill,
    "linear": LinearFill,
    "ip_basic": IPBasicFill,
    "ip_basic_multiscale": IPBasicMultiscaleFill,
    "ip_basic_adaptive": IPBasicAdaptiveFill,
    "colorization": ColorizationFill,
    "lip-wavelet": LIPWavelet,
}


def get_method(name: str, **settings: Any) -> DepthCompleter:
    """A completer by name (see the module docstring); `settings` only for the hand-crafted methods."""
    if name in CLASSICAL:
        return CLASSICAL[name](**settings)
    if settings:
        raise ValueError(f"{name!r} is a learned model: its settings are in its model file, not keyword arguments")
    return load_model(name)


def available_methods(scene: str) -> list[str]:
    """Names of the methods that can run for a scene now: shipped learned models first, then the hand-crafted."""
    learned = [m for m in model_io.available() if m.endswith(f"-{scene}")]
    return learned + list(CLASSICAL)
