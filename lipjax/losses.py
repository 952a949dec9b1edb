"""Training losses. Depth errors are computed on depth / `scale_m` (the prior's max depth), so that indoor
(10 m) and outdoor (85 m) models train with losses of the same magnitude; they are masked to valid ground truth.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import optax


def masked_mean(values: jax.Array, mask: jax.Array) -> jax.Array:
    """Mean of `values` over the pixels where `mask` is True (0 when the mask is empty)."""
    mask = mask.astype(values.dtype)
    return jnp.sum(values * mask) / jnp.maximum(jnp.sum(mask), 1.0)


def depth_loss(pred: jax.Array, gt: jax.Array, valid: jax.Array, *, kind: str = "l2", scale_m: float = 1.0) -> jax.Array:
    """Masked L2 (mean squared) or L1 (mean absolute) error of (B, H, W) depths, in units of scale_m."""
    err = (pred - gt) / scale_m
    if kind == "l2":
        return masked_mean(err**2, valid)
    if kind == "l1":
        return masked_mean(jnp.abs(err), valid)
    raise ValueError(f"loss kind must be 'l2' or 'l1', got {kind!r}")


def supervised_loss(
    final: jax.Array,
    iterates: jax.Array | None,
    gt: jax.Array,
    valid: jax.Array,
    *,
    kind: str = "l2",
    scale_m: float = 1.0,
    iteration_weights: tuple[float, ...] = (),
) -> jax.Array:
    """Loss on the final estimate plus optional deep supervision: sum_k w_k * loss(x_k) over the first
    len(iteration_weights) iterates (iterates: (K, B, H, W))."""
    loss = depth_loss(final, gt, valid, kind=kind, scale_m=scale_m)
    for k, w in enumerate(iteration_weights):
        if w:
            loss = loss + w * depth_loss(iterates[k], gt, valid, kind=kind, scale_m=scale_m)
    return loss


def discriminator_loss(real_logits: jax.Array, fake_logits: jax.Array) -> jax.Array:
    """Cross-entropy of D: real -> 1, generated -> 0 (mean over patches and batch)."""
    real = optax.sigmoid_binary_cross_entropy(real_logits, jnp.ones_like(real_logits))
    fake = optax.sigmoid_binary_cross_entropy(fake_logits, jnp.zeros_like(fake_logits))
    return jnp.mean(real) + jnp.mean(fake)


def generator_adversarial_loss(fake_logits: jax.Array) -> jax.Array:
    """Non-saturating generator loss: cross-entropy of D's output on generated depth against the label 'real'."""
    return jnp.mean(optax.sigmoid_binary_cross_entropy(fake_logits, jnp.ones_like(fake_logits)))
