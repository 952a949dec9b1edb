r"""The sampling operator A = diag(m) and the two closed-form ADMM updates of the LIP (paper eqs. 5-6).

The data term is  1/2 ||y - A x||^2  with A = diag(m): m is 1 on measured pixels and 0 elsewhere. A noise-aware
variant replaces the binary mask by per-pixel confidence weights w >= 0, giving the data term
1/2 sum_i w_i (y_i - x_i)^2 (a weighted least squares; w = m recovers the paper). Everything here is elementwise,
so it works for any array shape, (H, W) or (B, H, W).

x-update (eq. 6), with v = z_k - u_k:

    x_{k+1} = argmin_x 1/2 ||y - A x||_W^2 + rho/2 ||x - v||^2  =  (w * y + rho * v) / (w + rho)

On a measured pixel (w = 1):  x - y = rho / (1 + rho) * (v - y),  so the estimate is pulled onto the measurement
as rho -> 0 (the data consistency the paper relies on, its Fig. 4c). On an unmeasured pixel (w = 0): x = v.

dual update (eq. 5):  u_{k+1} = u_k + x_{k+1} - z_{k+1}.

Units: y, x, z, u in metres; rho is dimensionless (it weighs two squared errors in metres^2).
"""
from __future__ import annotations

import jax
import jax.numpy as jnp


def x_update(y: jax.Array, mask: jax.Array, z: jax.Array, u: jax.Array, rho) -> jax.Array:
    """Exact minimiser of eq. 6: argmin_x 1/2 ||y - A x||_W^2 + rho/2 ||x - z + u||^2.

    Args:
      y: sparse depth in metres, 0 where unmeasured; any shape S, e.g. (B, H, W).
      mask: binary sampling mask m (1 = measured) or non-negative confidence weights w, broadcastable to S.
      z, u: the prox output and scaled dual variable of the previous iteration, shape S, metres.
      rho: ADMM penalty > 0, a scalar or an array broadcastable to S (e.g. per-image or per-pixel).

    Returns:
      x: shape S, metres.
    """
    mask = jnp.asarray(mask, dtype=y.dtype)
    return (mask * y + rho * (z - u)) / (mask + rho)


def dual_update(u: jax.Array, x: jax.Array, z: jax.Array) -> jax.Array:
    """Scaled dual ascent (eq. 5): u + x - z, the running sum of the constraint residuals x - z."""
    return u + x - z
