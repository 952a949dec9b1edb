"""The interface every proximal operator (signal prior) of the LIP solver implements.

A prior is the z-update of ADMM (paper eqs. 7-9):  z_{k+1} = prox(x_{k+1} + u_k, R).
It knows nothing about the sampling operator A; the solver knows nothing about what the prior is.

A prior is a hashable frozen dataclass (a static jit argument; lipjax.model.LIPConfig.prior) that implements `Prior`:

    max_depth_m: float       the depth range of the scenes it is made for, metres (lipjax.interfaces)
    init(key, image_shape, guidance_channels=3) -> params
                             parameters of ONE iteration's operator, for (H, W) images and a guidance image of
                             `guidance_channels` channels (RGB, possibly with extra ones such as the sampling mask)
    apply(params, v, rgb) -> z
                             v: (B, H, W) float32 metres (x_{k+1} + u_k); rgb: (B, H, W, C) float32 in [0, 1], the
                             guidance image; z: (B, H, W) float32 metres

(lipjax.priors.network.NetworkPrior, lipjax.priors.wavelet.WaveletPrior). A prior whose guidance is encoded once per
frame implements `SharedEncoderPrior` below instead (lipjax.priors.fast.FastPrior).
"""
from __future__ import annotations

import abc
from typing import Any, NamedTuple

import jax

Params = Any  # a pytree of arrays


class Prior(abc.ABC):
    """A prior with one operator per iteration, guided by the image as it is (the module docstring's interface)."""

    max_depth_m: float  # the depth range of the scenes it is made for, metres

    @abc.abstractmethod
    def init(self, key: jax.Array, image_shape: tuple[int, int], guidance_channels: int = 3) -> Params:
        """Parameters of ONE iteration's operator, for (H, W) images and a `guidance_channels`-channel guidance."""

    @abc.abstractmethod
    def apply(self, params: Params, v: jax.Array, rgb: jax.Array) -> jax.Array:
        """z = prox(v): v (B, H, W) metres, rgb (B, H, W, C) guidance in [0, 1] -> z (B, H, W) metres."""


class EncodedGuidance(NamedTuple):
    """What a `SharedEncoderPrior` computes once per frame and every iteration's prox reuses.

    features: a tuple of (B, h, w, C) feature maps of the guidance image (any resolutions the prior chooses).
    scale: (B, 1, 1) metres, the frame's depth scale (the median of its samples) that normalises the prox's input.
    """

    features: tuple
    scale: jax.Array


class SharedEncoderPrior(abc.ABC):
    """A prior whose guidance image is encoded once per frame by a network shared by all K iterations.

    The LIP model keeps the encoder's parameters beside the per-iteration ones ({"guidance_encoder": ...}) and
    runs, once per frame, F = encode(encoder_params, guidance, y, m); then z_{k+1} = apply(params_k, x_{k+1} + u_k, F).
    """

    @abc.abstractmethod
    def init_encoder(self, key: jax.Array, guidance_channels: int = 3) -> Params:
        """Parameters of the shared guidance encoder."""

    @abc.abstractmethod
    def init(self, key: jax.Array, image_shape: tuple[int, int], guidance_channels: int = 3) -> Params:
        """Parameters of ONE iteration's prox (without the shared encoder)."""

    @abc.abstractmethod
    def encode(self, encoder_params: Params, guidance: jax.Array, y: jax.Array, weights: jax.Array) -> EncodedGuidance:
        """guidance (B, H, W, C) in [0, 1], sparse depth y (B, H, W) metres and its weights -> EncodedGuidance."""

    @abc.abstractmethod
    def apply(self, params: Params, v: jax.Array, guidance: EncodedGuidance) -> jax.Array:
        """z = prox(v, F): v (B, H, W) metres -> z (B, H, W) metres."""
