"""Every depth-completion method by name, for experiments and the command line.

    get_method("lip-ad-indoor")       shipped LIP model (lipjax/weights), or any saved model path
    get_method("lip-wavelet-indoor")  LIP with the hand-crafted wavelet soft-thresholding prox (no training)
    get_method("colorization")        classical fills: nearest, linear, ip_basic, colorization

All are `Completer`s: completer(rgb (H,W,3) uint8, sparse (H,W) float32 metres) -> (H,W) float32 metres, with
a `name`.
"""
from __future__ import annotations

import dataclasses

from lipjax import model_io
from lipjax.baselines.completer import Completer
from lipjax.baselines.registry import COMPLETERS, make_completer
from lipjax.inference import Completer as LIPCompleter
from lipjax.inference import load_model
from lipjax.model import LIPConfig
from lipjax.priors.wavelet import WaveletPrior

SCENES = ("indoor", "outdoor")

# LIP+Wavelet: Haar soft-thresholding with cycle spinning, K iterations, fixed rho. Thresholds (metres) were
# chosen on the synthetic *validation* split (benchmarks/tune_wavelet.py), never on the test split.
WAVELET_CONFIGS = {
    "indoor": LIPConfig(prior=WaveletPrior(levels=4, threshold_m=0.05, shifts=4), num_iterations=10,
                        rho_init=0.1, learn_rho=False),
    "outdoor": LIPConfig(prior=WaveletPrior(levels=4, threshold_m=0.5, shifts=4), num_iterations=10,
                         rho_init=0.1, learn_rho=False),
}


def lip_wavelet(scene: str) -> LIPCompleter:
    """The LIP+Wavelet baseline for a scene type (its threshold scales with the scene's depth range)."""
    if scene not in WAVELET_CONFIGS:
        raise ValueError(f"scene must be one of {SCENES}, got {scene!r}")
    return dataclasses.replace(LIPCompleter.random(WAVELET_CONFIGS[scene]), name=f"lip-wavelet-{scene}")


def get_method(name: str) -> Completer:
    """A completer by name (see the module docstring)."""
    if name in COMPLETERS:
        return make_completer(name)
    if name.startswith("lip-wavelet-"):
        return lip_wavelet(name.removeprefix("lip-wavelet-"))
    return load_model(name)


def available_methods(scene: str) -> list[str]:
    """Names of the methods that can run for a scene now: shipped learned models first, then the hand-crafted."""
    learned = [m for m in model_io.available() if m.endswith(f"-{scene}")]
    return learned + [f"lip-wavelet-{scene}"] + list(COMPLETERS)
