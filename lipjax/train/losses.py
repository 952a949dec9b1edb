"""Training losses. Depth errors are computed on depth / `scale_m` (the prior's max depth), so that indoor
(10 m) and outdoor (85 m) models train with losses of the same magnitude; they are masked to valid ground truth.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import optax


def masked_mean(values: jax.Array, mask: jax.Array, axis=None) -> jax.Array:
    """Mean of `values` over the pixels where `mask` is True (0 when the mask is empty), over `axis` (all axes by
    default; (-2, -1): one mean per image of a (B, H, W) batch)."""
    mask = mask.astype(values.dtype)
    return jnp.sum(values * mask, axis=axis) / jnp.maximum(jnp.sum(mask, axis=axis), 1.0)


LOSS_KINDS = ("l2", "l1", "log_rmse")
LOG_RMSE_EPS = 1e-3  # added to each image's RMSE (in units of scale_m) before the log: finite at a perfect estimate


def depth_loss(pred: jax.Array, gt: jax.Array, valid: jax.Array, *, kind: str = "l2",
               scale_m: float = 1.0) -> jax.Array:
    """Masked error of (B, H, W) depths, in units of scale_m (metres: a number, or a (B, 1, 1) array with one unit
    per image). With e = (pred - gt) / scale_m over each image's valid pixels:

        "l2"        mean of e^2 over the batch's valid pixels
        "l1"        mean of |e|
        "log_rmse"  (1/B) sum_b log(RMSE_b + LOG_RMSE_EPS),  RMSE_b = sqrt(mean of e^2 over image b)

    "log_rmse" is what the suites score: their geometric-mean RMSE ratio to a fixed reference (the linear fill)
    is exp(mean_b log RMSE_b - mean_b log RMSE_ref,b), so up to a constant its log is this loss. Each image weighs
    alike whatever its scale (log RMSE_b moves by log 2 when image b's errors double), and like L2 it asks for the
    mean where the depth is uncertain (L1: the median, a sharp edge that RMSE punishes where it is misplaced).
    """
    err = (pred - gt) / scale_m
    if kind == "l2":
        return masked_mean(err**2, valid)
    if kind == "l1":
        return masked_mean(jnp.abs(err), valid)
    if kind == "log_rmse":
        mse = masked_mean(err**2, valid, axis=(-2, -1))
        # sqrt'(0) is infinite: an image without error (or without valid pixels) gets the eps-floored value
        rmse = jnp.sqrt(jnp.where(mse > 0, mse, 1.0)) * (mse > 0)
        return jnp.mean(jnp.log(rmse + LOG_RMSE_EPS))
    raise ValueError(f"loss kind must be one of {LOSS_KINDS}, got {kind!r}")


def soft_floored_inverse(depth: jax.Array, floor_m: float) -> jax.Array:
    """1 / depth (1/m) for depth >= floor_m, continued below the floor by its tangent line, 1/f + (f - depth)/f^2.

    The continuation keeps the value finite and the gradient pushing up for near-zero and negative depths, where
    a plain clamp max(depth, f) would have no gradient at all."""
    safe = jnp.where(depth >= floor_m, depth, floor_m)  # where, not maximum: maximum halves the gradient at f
    return jnp.where(depth >= floor_m, 1.0 / safe, 1.0 / floor_m + (floor_m - depth) / floor_m**2)


def inverse_depth_loss(pred: jax.Array, gt: jax.Array, valid: jax.Array, *, floor_m: float = 1.0) -> jax.Array:
    """Inverse-depth error of (B, H, W) depths in 1/m, with pred softly floored (`soft_floored_inverse`):
    mean |1/pred - 1/gt| over valid pixels, plus, over the pixels without ground truth, the mean of how far
    1/pred rises above 1/floor_m (0 for any depth >= floor_m: there only a too-small depth is known to be wrong).

    Why: a depth loss barely sees a few pixels predicted near zero or negative (thin structures far from any
    measurement), yet each dominates the inverse-depth metrics (iRMSE, iMAE) of KITTI; in inverse depth their
    error is large and the gradient strong. The second term keeps the output physical where no ground truth
    exists (sky), so the network has no unsupervised region in which it may learn negative depth. Ground truth
    nearer than floor_m asks for exactly the floor."""
    inverse = soft_floored_inverse(pred, floor_m)
    target = 1.0 / jnp.maximum(gt, floor_m)
    below_floor = jnp.maximum(inverse - 1.0 / floor_m, 0.0)
    return masked_mean(jnp.abs(inverse - target), valid) + masked_mean(below_floor, ~valid.astype(bool))


def supervised_loss(
    final: jax.Array,
    iterates: jax.Array | None,
    gt: jax.Array,
    valid: jax.Array,
    *,
    kind: str = "l2",
    scale_m: float = 1.0,
    iteration_weights: tuple[float, ...] = (),
    inverse_depth_weight: float = 0.0,
    inverse_depth_floor_m: float = 1.0,
) -> jax.Array:
    """Loss on the final estimate plus optional deep supervision: sum_k w_k * loss(x_k) over the first
    len(iteration_weights) iterates (iterates: (K, B, H, W)). With inverse_depth_weight > 0 the final estimate's
    `inverse_depth_loss` (1/m) is added with that weight."""
    loss = depth_loss(final, gt, valid, kind=kind, scale_m=scale_m)
    if inverse_depth_weight:
        loss = loss + inverse_depth_weight * inverse_depth_loss(final, gt, valid, floor_m=inverse_depth_floor_m)
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
