"""The interface every proximal operator (signal prior) of the LIP solver implements.

A prior is the z-update of ADMM (paper eqs. 7-9):  z_{k+1} = prox(x_{k+1} + u_k, R).
It knows nothing about the sampling operator A; the solver knows nothing about what the prior is.
"""
from __future__ import annotations

from typing import Any, Protocol

import jax

Params = Any  # a pytree of arrays


class Prior(Protocol):
    """A proximal operator z = prox(v, rgb) with (possibly empty) parameters.

    Shapes and units:
      v:   (B, H, W) float32 depth in metres (x_{k+1} + u_k).
      rgb: (B, H, W, C) float32 in [0, 1]: the RGB guidance image (C = 3), possibly with extra channels.
      returns z: (B, H, W) float32 depth in metres.
    """

    def init(self, key: jax.Array, image_shape: tuple[int, int], guidance_channels: int = 3) -> Params:
        """Parameters of ONE iteration's operator for images of size image_shape = (H, W) and a guidance image
        of `guidance_channels` channels (RGB, possibly with extra channels such as the sampling mask)."""
        ...

    def apply(self, params: Params, v: jax.Array, rgb: jax.Array) -> jax.Array:
        ...
