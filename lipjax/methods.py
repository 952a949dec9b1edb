"""Every depth-completion method by name, for experiments and the command line.

    get_method("lip-ad-indoor")       shipped LIP model (lipjax/weights), or any saved model path
    get_method("lip-wavelet")         LIP with the hand-crafted wavelet soft-thresholding prox (no training)
    get_method("colorization")        classical fills: nearest, linear, ip_basic, ip_basic_multiscale,
                                      ip_basic_adaptive, colorization

All are `DepthCompleter`s: completer(rgb (H,W,3) uint8, sparse (H,W) float32 metres) -> (H,W) float32 m, with
a `name`.
"""
from __future__ import annotations

from lipjax import model_io
from lipjax.baselines.completer import DepthCompleter
from lipjax.baselines.lip_wavelet import LIPWavelet
from lipjax.baselines.registry import COMPLETERS, make_completer
from lipjax.inference import load_model

SCENES = ("indoor", "outdoor")


def get_method(name: str) -> DepthCompleter:
    """A completer by name (see the module docstring)."""
    if name in COMPLETERS:
        return make_completer(name)
    if name == "lip-wavelet":
        return LIPWavelet()
    return load_model(name)


def available_methods(scene: str) -> list[str]:
    """Names of the methods that can run for a scene now: shipped learned models first, then the hand-crafted."""
    learned = [m for m in model_io.available() if m.endswith(f"-{scene}")]
    return learned + ["lip-wavelet"] + list(COMPLETERS)
