r"""Unrolled ADMM for the depth-completion LIP (paper eqs. 5-9), as one `jax.lax.scan` over K iterations.

For k = 0 .. K-1 (scaled form):

    x_{k+1} = (w * y + rho_k * (z_k - u_k)) / (w + rho_k)     # operators.x_update, exact argmin of eq. 6
    z_{k+1} = G_k(x_{k+1} + u_k, R)                           # the proximal operator (eq. 9), any prior
    u_{k+1} = u_k + x_{k+1} - z_{k+1}                         # operators.dual_update

and the returned estimate is one more x-update, x_out = x_update(y, w, z_K, u_K, rho_{K-1}), so that the output
always carries the data-consistency guarantee of the x-update on measured pixels. With final_dual=False it is
x_update(y, w, z_K, 0, rho_{K-1}) instead: the last prox's estimate with the measurements re-imposed. On
unmeasured pixels the default reads z_K - u_K = 2 z_K - x_K - u_{K-1}, which extrapolates the last prox's step;
after a truncated unroll a large last step can overshoot (see LIPConfig.output).

Initial state (z_0, u_0): u_0 = 0 (no constraint residual has been seen yet) and z_0 = an initial dense guess.
With z_0 = y (the paper's setting: the first prox "makes a rough estimate of the depth on vacant pixels") the first
x-update returns exactly y on measured pixels and 0 elsewhere, so G_0 sees the raw sparse map. Callers may instead
pass a cheap classical fill (see `lipjax.fill.box_fill`); the x-update then keeps the measurements and the fill is
only a starting point for the unmeasured pixels.

Prox parameters are either stacked on a leading axis of size K (one operator per iteration, the paper) or one
shared set (the paper's future work); the scan slices the stack, so both run the same code.
"""
from __future__ import annotations

from typing import Any, Callable, NamedTuple

import jax
import jax.numpy as jnp

from lipjax.operators import dual_update, x_update

Params = Any
ProxFn = Callable[[Params, jax.Array, jax.Array], jax.Array]  # (params, v (B,H,W) m, rgb (B,H,W,3)) -> z (B,H,W) m


class Trajectory(NamedTuple):
    """Every iteration's iterates, each (K, B, H, W) in metres: x[k] = x_{k+1}, z[k] = z_{k+1}."""

    x: jax.Array
    z: jax.Array


def unrolled_admm(
    prox: ProxFn,
    prox_params: Params,
    y: jax.Array,
    weights: jax.Array,
    rgb: jax.Array,
    rho: jax.Array,
    *,
    z0: jax.Array | None = None,
    shared_params: bool = False,
    return_trajectory: bool = False,
    unroll: bool = True,
    final_dual: bool = True,
) -> tuple[jax.Array, Trajectory | None]:
    """Runs K = len(rho) ADMM iterations.

    Args:
      prox: the z-update, prox(params, v, rgb) -> z.
      prox_params: a pytree; with shared_params=False every leaf has a leading axis of size K.
      y: (B, H, W) sparse depth in metres, 0 where unmeasured.
      weights: (B, H, W) sampling mask m in {0, 1}, or confidence weights >= 0.
      rgb: (B, H, W, 3) guidance image, float in [0, 1] (passed to the prox untouched).
      rho: (K,) positive penalties, one per iteration; K is its length.
      z0: (B, H, W) initial guess; defaults to y (see module docstring).
      shared_params: one parameter set used by every iteration.
      return_trajectory: also return every iteration's x and z.
      unroll: unroll the scan. On CPU the rolled loop made a training step about 9x slower (jax issue 12868);
        K is small, so the compile-time cost of unrolling is modest.
      final_dual: read the output with the last dual variable u_K (ADMM's x-iterate) or without it (see above).

    Returns:
      (x_out (B, H, W) metres, Trajectory or None).
    """
    rho = jnp.asarray(rho, dtype=y.dtype)
    if rho.ndim != 1:
        raise ValueError(f"rho must be a (K,) array of per-iteration penalties, got shape {rho.shape}")
    num_iterations = rho.shape[0]
    if not shared_params:
        for leaf in jax.tree_util.tree_leaves(prox_params):
            if leaf.shape[:1] != (num_iterations,):
                raise ValueError(
                    f"per-iteration prox parameters need a leading axis of size K={num_iterations}, "
                    f"found a leaf of shape {leaf.shape}; pass shared_params=True for one shared set"
                )
    z = y if z0 is None else z0
    u = jnp.zeros_like(y)

    def step(carry, per_iteration):
        z, u = carry
        params_k = prox_params if shared_params else per_iteration["params"]
        rho_k = per_iteration["rho"]
        x = x_update(y, weights, z, u, rho_k)
        z = prox(params_k, x + u, rgb)
        u = dual_update(u, x, z)
        return (z, u), ((x, z) if return_trajectory else None)

    xs = {"rho": rho} if shared_params else {"rho": rho, "params": prox_params}
    (z, u), history = jax.lax.scan(step, (z, u), xs, unroll=unroll)
    x_out = x_update(y, weights, z, u if final_dual else jnp.zeros_like(u), rho[-1])
    return x_out, (Trajectory(*history) if return_trajectory else None)
