"""The one registry of depth-completion methods, and the one resolver that turns a name, path or object into a
completer: for the library, experiments and the CLI. It sits above everything it builds (lipjax.inference,
lipjax.classical), and nothing it builds imports it.

    get_completer("lip-ad-indoor")     a shipped learned model (lipjax/weights), or any saved model path
    get_completer("lip-wavelet")       LIP with the hand-crafted wavelet soft-thresholding prox (no training)
    get_completer("linear")            a hand-crafted fill (CLASSICAL): nearest, linear, ip_basic,
    get_completer("ip_basic", extrapolate=True)   ip_basic_multiscale, ip_basic_adaptive, colorization; keyword
                                       arguments override the method's settings
    get_completer(None)                the shipped default model, one for every input (lipjax.defaults)
    get_completer(obj)                 a completer object, returned as is
    listing()                          what `lipjax models` prints: the shipped models, then the hand-crafted ones

All are `DepthCompleter`s: completer(rgb (H,W,3) uint8, sparse (H,W) float32 metres) -> (H,W) float32 m, with
a `name`. Learned models are `lipjax.inference.Completer`s over a `lipjax.interfaces.LearnedModel` (model types by
name: `lipjax.interfaces.MODEL_TYPES`, the table model files use). `complete` is the one-call front end, with the
default `lipjax complete` has too: the depth as the model or method returns it (`fill_all` fills the 0s a method
leaves, `blank_unsupported` sets 0 where no sample supports the depth).
"""
from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import numpy as np

from lipjax import model_io
from lipjax.classical import (
    ColorizationFill,
    IPBasicAdaptiveFill,
    IPBasicFill,
    IPBasicMultiscaleFill,
    LinearFill,
    NearestFill,
    fill_holes,
)
from lipjax.interfaces import DepthCompleter
from lipjax.classical.lip_wavelet import LIPWavelet
from lipjax.defaults import CROSS_CHECK
from lipjax.inference import Completer, complete_frame, default_model, load_model
from lipjax.interfaces import MIXED_SCENES
from lipjax.shipped import available
from lipjax.uncertainty import drop_uncertain, expected_error, mask_unsupported

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
# What each is, in the words of `lipjax models`.
CLASSICAL_SUMMARY = {
    "nearest": "the nearest sample's depth (Voronoi cells)",
    "linear": "Delaunay piecewise-linear; the nearest sample's outside the samples' hull",
    "ip_basic": "IP-Basic fill_in_fast (Ku et al. 2018) as published; 0 out of reach of its dilations",
    "ip_basic_multiscale": "IP-Basic fill_in_multiscale as published; 0 out of reach of its dilations",
    "ip_basic_adaptive": "IP-Basic with kernels sized to the samples' density; depth everywhere",
    "colorization": "Levin et al. 2004 colourisation, guided by the RGB image",
    "lip-wavelet": "the LIP solver with a wavelet soft-thresholding prox in place of the learned one",
}


def get_completer(model: Any = None, iterations: int | None = None, sparse: np.ndarray | None = None,
                  **settings: Any) -> DepthCompleter:
    """A completer (see the module docstring).

    Args:
      model: a completer object; a name (CLASSICAL, a shipped model) or a saved model path; or None for
        `lipjax.inference.default_model`, the one default for every input.
      iterations: run a LIP model's first K iterations only.
      sparse: unused; from when the default model followed the scene the samples suggested (both scenes' default is
        one model now, lipjax.shipped.DEFAULT_MODELS).
      settings: keyword settings of a hand-crafted method; learned models keep theirs in their model file.
    """
    if settings and not (isinstance(model, str) and model in CLASSICAL):
        raise ValueError(f"settings apply to hand-crafted methods; {model!r} is a learned model (its settings are in "
                         "its model file) or a completer object")
    if model is None:
        completer = default_model()
    elif isinstance(model, (str, os.PathLike)):
        name = os.fspath(model)
        completer = CLASSICAL[name](**settings) if name in CLASSICAL else load_model(name)
    else:
        completer = model
    if iterations is not None:
        if not isinstance(completer, Completer):
            raise ValueError(f"iterations apply to LIP models; {getattr(completer, 'name', model)!r} is not one")
        completer = completer.with_iterations(iterations)
    return completer


def available_methods(scene: str) -> list[str]:
    """Names of the methods that can run for a scene now: shipped learned models first (those of the scene and those
    trained on both scenes), then the hand-crafted."""
    learned = [m for m in available() if m.endswith(f"-{scene}") or model_io.metadata(m).get("data") == MIXED_SCENES]
    return learned + list(CLASSICAL)


def complete(rgb: np.ndarray, sparse: np.ndarray, model: Any = None, *, fill_all: bool = False,
             blank_unsupported: bool = False, max_uncertainty: float | None = None, return_uncertainty: bool = False,
             flip: bool | None = None, cross_check: bool = CROSS_CHECK):
    """Completes depth: RGB uint8 (H,W,3) or (B,H,W,3), sparse depth in metres (0 = missing) -> dense metres.

    `model`: anything `get_completer` takes; by default the shipped default model. Each frame runs through the
    default path (`lipjax.inference.complete_frame`, as its `plan_frame` says): a learned model at the working size
    of the samples' spacing, every measured pixel set back; a hand-crafted method (CLASSICAL) returns exactly what
    it returns itself, as published (IP-Basic leaves 0 out of reach of its dilations). `flip` also runs a learned
    model on the flipped frame and averages (more accurate, twice the model's work; None: on LiDAR scan lines,
    lipjax.inference.flips); `cross_check` checks it against the linear fill on held-out samples
    (lipjax.crosscheck; CROSS_CHECK).
    By default the depth is the model's or method's, at every pixel it gives depth, as `lipjax complete` writes it.
    `fill_all`: depth at every pixel, the 0s left filled with the nearest pixel's depth
    (`lipjax.classical.fill_holes`; --fill-all). `blank_unsupported`: 0 where no sample supports the depth
    (`lipjax.uncertainty.mask_unsupported`; --blank-unsupported); not with `fill_all`. With `max_uncertainty`
    (metres), depth is 0 (none) where the expected absolute error (`lipjax.uncertainty.expected_error`) is above
    it; `return_uncertainty` returns (depth, expected error m), the error of every pixel.
    """
    if fill_all and blank_unsupported:
        raise ValueError("fill_all (depth at every pixel) and blank_unsupported (0 where no sample supports it) "
                         "contradict each other; pass one of them")
    completer = get_completer(model)
    rgb, sparse = np.asarray(rgb), np.asarray(sparse)
    if sparse.ndim == 3:
        dense = np.stack([complete_frame(completer, c, y, flip=flip, cross_check=cross_check)
                          for c, y in zip(rgb, sparse)])
    else:
        dense = complete_frame(completer, rgb, sparse, flip=flip, cross_check=cross_check)
    if fill_all:
        dense = fill_holes(dense)
    u = expected_error(sparse, dense) if max_uncertainty is not None or return_uncertainty else None
    if max_uncertainty is not None:
        dense = drop_uncertain(dense, u, max_uncertainty)
    if blank_unsupported:
        dense = mask_unsupported(dense, sparse)
    return (dense, u) if return_uncertainty else dense


def listing() -> str:
    """What `lipjax models` prints: the shipped models (`lipjax.model_io.listing`), then the hand-crafted methods
    that --model also takes (CLASSICAL: no weights, nothing to ship)."""
    width = max(map(len, CLASSICAL))
    rows = [f"{name:<{width}}  {CLASSICAL_SUMMARY[name]}" for name in CLASSICAL]
    return (model_io.listing() + "\n\nHAND-CRAFTED (no weights, no training; --model NAME runs each as the method "
            "returns it):\n" + "\n".join(rows))
