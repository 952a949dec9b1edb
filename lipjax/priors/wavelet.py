r"""LIP+Wavelet: the hand-crafted prior of the paper's ablation (Fig. 4), phi(z) = ||W_d z||_1, as a JAX prox.

W is an orthonormal 2-D discrete wavelet transform (separable, periodic boundary, `levels` levels; Haar or
Daubechies-2), W_d z its detail coefficients; the coarsest approximation is not penalised. Because W is
orthonormal (W^T W = W W^T = I), the proximal operator is exact and closed-form:

    prox_{tau ||W_d . ||_1}(v) = argmin_z 1/2 ||z - v||^2 + tau ||W_d z||_1
                               = W^T S_tau(W v),   S_tau(c) = sign(c) max(|c| - tau, 0) on details, identity on the
                                                   approximation.

In the ADMM z-update (eq. 7) tau = lambda / rho. tau is in metres (W is orthonormal, so coefficients carry the
units of depth).

Image sizes: the transform needs H and W divisible by 2^levels, so `apply` edge-pads v to the next multiple,
shrinks, and crops back. The formula above is then the exact prox for sizes that are multiples of 2^levels, and a
close approximation otherwise (padding is not orthonormal).

Cycle spinning (`shifts` > 1): the decimated transform is not shift invariant, which shows as blocky
2^j x 2^j artefacts. `apply` then averages the prox over shifts x shifts translations of the dyadic grid
(offsets spread evenly over [0, 2^levels) per axis, realised by extra edge padding before the grid starts, so no
pixel wraps around). An average of proximal operators is itself a proximal operator (of the "proximal average"
of the shifted priors), so ADMM keeps a well-defined prior.

The RGB image is ignored: this prior is the image-agnostic baseline.

Parameters: `init` returns {"threshold": float32 scalar tau in metres} (starting at `threshold_m`), so the
threshold can be swept or learned per iteration like any prox parameter (the solver stacks K of them); one
scalar serves the whole batch; negative values act as 0.
"""
from __future__ import annotations

import dataclasses
import functools
import math

import jax
import jax.numpy as jnp

from lipjax.interfaces import SCENE_MAX_DEPTH_M, register_prior_type
from lipjax.priors.base import Prior

_SQRT2 = math.sqrt(2.0)
_SQRT3 = math.sqrt(3.0)

# Orthonormal low-pass (scaling) filters; the high-pass filter is the quadrature mirror g[k] = (-1)^k h[L-1-k].
LOWPASS = {
    "haar": (1 / _SQRT2, 1 / _SQRT2),
    "db2": tuple(c / (4 * _SQRT2) for c in (1 + _SQRT3, 3 + _SQRT3, 3 - _SQRT3, 1 - _SQRT3)),
}


def wavelet_filters(wavelet: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(low-pass h, high-pass g) analysis filters of an orthonormal wavelet ("haar" or "db2")."""
    if wavelet not in LOWPASS:
        raise ValueError(f"unknown wavelet {wavelet!r}; choose one of {sorted(LOWPASS)}")
    h = LOWPASS[wavelet]
    g = tuple((-1) ** k * h[len(h) - 1 - k] for k in range(len(h)))
    return h, g


def _analysis_1d(x: jax.Array, axis: int, wavelet: str) -> tuple[jax.Array, jax.Array]:
    """One periodic analysis step along `axis` (even length N): lo[n] = sum_k h[k] x[(2n + k) mod N], same for g."""
    h, g = wavelet_filters(wavelet)
    lo = hi = 0.0
    for k in range(len(h)):
        shifted = jax.lax.slice_in_dim(jnp.roll(x, -k, axis=axis), 0, None, 2, axis=axis)
        lo = lo + h[k] * shifted
        hi = hi + g[k] * shifted
    return lo, hi


def _synthesis_1d(lo: jax.Array, hi: jax.Array, axis: int, wavelet: str) -> jax.Array:
    """Adjoint (= inverse, the step being orthonormal) of `_analysis_1d`: x = sum_k roll(up(h[k] lo + g[k] hi), k)."""
    h, g = wavelet_filters(wavelet)
    x = 0.0
    for k in range(len(h)):
        c = h[k] * lo + g[k] * hi
        # Upsample by 2 along `axis`: interleave c with zeros (c at even positions).
        up = jnp.stack([c, jnp.zeros_like(c)], axis=axis + 1 if axis >= 0 else axis)
        shape = list(c.shape)
        shape[axis] *= 2
        x = x + jnp.roll(up.reshape(shape), k, axis=axis)
    return x


Details = tuple[jax.Array, jax.Array, jax.Array]


# The transforms are jitted as a whole (static sizes, levels, wavelet): run eagerly, the dozens of small ops per
# level would each be compiled and dispatched separately, which is far slower than one fused computation.
# Inside an outer jit (the ADMM solver) the inner jit is simply inlined.
@functools.partial(jax.jit, static_argnums=(1, 2))
def dwt2(x: jax.Array, levels: int, wavelet: str = "haar") -> tuple[jax.Array, list[Details]]:
    """Orthonormal multi-level 2-D DWT over the last two axes.

    Args:
      x: (..., H, W) with H and W divisible by 2^levels.
    Returns:
      (approximation (..., H / 2^L, W / 2^L), [details of level 1 (finest), ..., level L]), each level a tuple
      (lh, hl, hh) of (..., H / 2^j, W / 2^j): low-pass rows & high-pass columns, the converse, both high-pass.
    """
    h, w = x.shape[-2:]
    if h % 2**levels or w % 2**levels:
        raise ValueError(f"dwt2 needs H, W divisible by 2^levels = {2**levels}, got {(h, w)}")
    details = []
    a = x
    for _ in range(levels):
        lo, hi = _analysis_1d(a, -1, wavelet)  # along columns (width)
        ll, hl = _analysis_1d(lo, -2, wavelet)  # then rows (height)
        lh, hh = _analysis_1d(hi, -2, wavelet)
        details.append((lh, hl, hh))
        a = ll
    return a, details


@functools.partial(jax.jit, static_argnums=(2,))
def idwt2(approx: jax.Array, details: list[Details], wavelet: str = "haar") -> jax.Array:
    """Inverse of `dwt2`."""
    a = approx
    for lh, hl, hh in reversed(details):
        lo = _synthesis_1d(a, hl, -2, wavelet)
        hi = _synthesis_1d(lh, hh, -2, wavelet)
        a = _synthesis_1d(lo, hi, -1, wavelet)
    return a


def soft_threshold(c: jax.Array, tau: jax.Array) -> jax.Array:
    """S_tau(c) = sign(c) * max(|c| - tau, 0), the prox of tau * |.|."""
    return jnp.sign(c) * jnp.maximum(jnp.abs(c) - tau, 0.0)


@functools.partial(jax.jit, static_argnums=(2, 3))
def wavelet_shrink(x: jax.Array, tau: jax.Array, levels: int, wavelet: str = "haar") -> jax.Array:
    """W^T S_tau(W x) with the approximation kept: the exact prox of tau ||W_d x||_1. x: (..., H, W), H, W
    divisible by 2^levels; tau >= 0 in the units of x."""
    approx, details = dwt2(x, levels, wavelet)
    details = [tuple(soft_threshold(d, tau) for d in lvl) for lvl in details]
    return idwt2(approx, details, wavelet)


@functools.partial(jax.jit, static_argnums=(2, 3, 4))
def cycle_spun_shrink(v: jax.Array, tau: jax.Array, levels: int, wavelet: str, shifts: int) -> jax.Array:
    """Mean over the shifts x shifts dyadic-grid offsets of the padded prox; v (..., H, W), any H, W.

    All shifted copies are edge-padded to one common multiple of 2^levels and transformed as one stacked batch,
    which keeps the compiled graph the size of a single transform.
    """
    h, w = v.shape[-2:]
    m = 2**levels
    offsets = cycle_offsets(shifts, levels)
    hp = -(-(h + offsets[-1]) // m) * m
    wp = -(-(w + offsets[-1]) // m) * m
    lead = [(0, 0)] * (v.ndim - 2)
    pairs = [(oy, ox) for oy in offsets for ox in offsets]
    stack = jnp.stack(
        [jnp.pad(v, lead + [(oy, hp - h - oy), (ox, wp - w - ox)], mode="edge") for oy, ox in pairs]
    )
    z = wavelet_shrink(stack, tau, levels, wavelet)
    crops = [z[i, ..., oy : oy + h, ox : ox + w] for i, (oy, ox) in enumerate(pairs)]
    return sum(crops[1:], crops[0]) / len(crops)


def cycle_offsets(shifts: int, levels: int) -> list[int]:
    """`shifts` offsets spread evenly over one period 2^levels of the coarsest dyadic grid."""
    return sorted({(i * 2**levels) // shifts for i in range(shifts)})


@register_prior_type("wavelet")
@dataclasses.dataclass(frozen=True)
class WaveletPrior(Prior):
    """Wavelet soft-thresholding prox (the prior interface of lipjax.priors.base).

    Attributes:
      levels: number of decomposition levels L (images are padded to multiples of 2^L).
      wavelet: "haar" or "db2".
      threshold_m: initial soft threshold tau in metres, returned by `init`.
      shifts: cycle-spinning shifts per axis (1 = none; shifts^2 transforms per call).
      max_depth_m: the depth range of the scenes (metres; part of the prior interface): the unit of a training loss.
    """

    levels: int = 4
    wavelet: str = "haar"
    threshold_m: float = 0.05
    shifts: int = 1
    max_depth_m: float = SCENE_MAX_DEPTH_M["indoor"]

    def __post_init__(self):
        wavelet_filters(self.wavelet)  # validates the name
        if self.levels < 1:
            raise ValueError(f"levels must be >= 1, got {self.levels}")
        if not 1 <= self.shifts <= 2**self.levels:
            raise ValueError(f"shifts must be in [1, 2^levels = {2**self.levels}], got {self.shifts}")

    def init(self, key: jax.Array, image_shape: tuple[int, int], guidance_channels: int = 3) -> dict[str, jax.Array]:
        """{"threshold": tau in metres}; the arguments are unused (the prior has no random state)."""
        del key, image_shape, guidance_channels
        return {"threshold": jnp.asarray(self.threshold_m, dtype=jnp.float32)}

    def apply(self, params: dict[str, jax.Array], v: jax.Array, rgb: jax.Array | None = None) -> jax.Array:
        """z = prox(v): v (B, H, W) (or any (..., H, W)) metres -> z of the same shape, metres. rgb is ignored."""
        del rgb
        v = jnp.asarray(v)
        tau = jnp.maximum(jnp.asarray(params["threshold"], dtype=v.dtype), 0.0)
        return cycle_spun_shrink(v, tau, self.levels, self.wavelet, self.shifts)
