"""The jitted train steps (lipjax.train.steps): each loss term the config names reaches the loss, and the update is
AdamW's closed form."""
import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from lipjax.model import LIPConfig
from lipjax.priors.fast import sample_scale
from lipjax.priors.network import network_preset
from lipjax.train.config import DataConfig, TrainConfig
from lipjax.train.losses import LOG_RMSE_EPS, depth_loss, inverse_depth_loss
from lipjax.train.state import init_state
from lipjax.train.steps import make_steps

H, W = 16, 24
LR, WD = 1e-3, 0.01
CONFIG = TrainConfig(
    name="steps", model=LIPConfig(prior=network_preset("tiny"), num_iterations=1, initial_estimate="box_fill"),
    data=DataConfig(kind="indoor", height=H, width=W, crop=None, num_workers=0), batch_size=2, g_steps=4,
    warmup_steps=1, learning_rate=LR, weight_decay=WD, grad_clip_norm=0.5, loss="l1", loss_scale="samples",
    iteration_weights=(0.5,), inverse_depth_weight=0.1, inverse_depth_floor_m=1.5)


def _batch(seed=0):
    rng = np.random.default_rng(seed)
    gt = rng.uniform(0.8, 6.0, (2, H, W)).astype(np.float32)
    sparse = np.where(rng.random((2, H, W)) < 0.15, gt, 0.0).astype(np.float32)
    return {"rgb": rng.integers(0, 256, (2, H, W, 3), dtype=np.uint8), "sparse": sparse, "gt": gt,
            "gt_valid": rng.random((2, H, W)) < 0.8}


def _perturbed(params, seed=1, scale=0.05):
    """Non-zero weights everywhere: a fresh prox is the identity, under which the iterates carry no gradient."""
    rng = np.random.default_rng(seed)
    return jax.tree_util.tree_map(lambda x: x + scale * rng.standard_normal(np.shape(x)).astype(np.float32), params)


def _reference_terms(params, batch):
    """The config's loss written out term by term: L1 of the output in units of each image's sample scale, 0.5 x the
    same of the first iterate x_1, and 0.1 x the inverse-depth loss of the output (floor 1.5 m)."""
    out, trajectory = CONFIG.model.apply(params, batch["rgb"], batch["sparse"], return_trajectory=True)
    unit = sample_scale(jnp.asarray(batch["sparse"]), jnp.asarray(batch["sparse"]))
    return jnp.stack([depth_loss(out, batch["gt"], batch["gt_valid"], kind="l1", scale_m=unit),
                      0.5 * depth_loss(trajectory.x[0], batch["gt"], batch["gt_valid"], kind="l1", scale_m=unit),
                      0.1 * inverse_depth_loss(out, batch["gt"], batch["gt_valid"], floor_m=1.5)])


def _reference_loss(params, batch):
    terms = _reference_terms(params, batch)
    return jnp.sum(terms), terms


def test_supervised_step_loss_is_every_configured_term_and_its_update_is_adamw():
    batch = _batch()
    state = init_state(CONFIG, _perturbed(CONFIG.model.init(jax.random.key(0))))
    theta = jax.tree_util.tree_map(np.array, state.g_params)
    (expected_loss, terms), g = jax.jit(jax.value_and_grad(_reference_loss, has_aux=True))(theta, batch)
    terms = np.asarray(terms)
    assert (terms > 1e-3 * terms.sum()).all(), terms  # each term counts, so a step that dropped one would differ
    step = make_steps(CONFIG).supervised
    state, metrics = step(state, batch, jax.random.key(0))
    # the options (L1, per-image sample scale, deep supervision of x_1, inverse depth) all reach the step's loss
    np.testing.assert_allclose(float(metrics["loss"]), float(expected_loss), rtol=1e-5)
    norm = float(np.sqrt(sum(np.sum(np.square(x)) for x in jax.tree_util.tree_leaves(g))))
    np.testing.assert_allclose(float(metrics["g_grad_norm"]), norm, rtol=1e-4)
    assert norm > CONFIG.grad_clip_norm  # so the clipping below is exercised
    # warm-up from learning rate 0: the first step moves nothing
    for a, b in zip(jax.tree_util.tree_leaves(theta), jax.tree_util.tree_leaves(state.g_params), strict=True):
        np.testing.assert_array_equal(a, np.asarray(b))
    # The second step, on the same batch at the same parameters, sees the same gradient g, clipped to
    # c = g min(1, 0.5 / |g|). Adam's bias-corrected moments after two equal gradients are m = c and v = c^2, so at
    # learning rate LR (the end of the one-step warm-up) AdamW moves theta by -LR (c / (|c| + 1e-8) + WD theta).
    state, _ = step(state, batch, jax.random.key(0))
    clipped = jax.tree_util.tree_map(lambda x: x * min(1.0, CONFIG.grad_clip_norm / norm), g)
    for t, c, new in zip(*(jax.tree_util.tree_leaves(p) for p in (theta, clipped, state.g_params)), strict=True):
        t, c, new = np.asarray(t, np.float64), np.asarray(c, np.float64), np.asarray(new, np.float64)
        expected = t - LR * (c / (np.abs(c) + 1e-8) + WD * t)
        clear = np.abs(c) > 1e-5  # where c / (|c| + eps) is not at the mercy of float32 rounding in c
        np.testing.assert_allclose(new[clear], expected[clear], rtol=0, atol=LR * 1e-3)
        np.testing.assert_allclose(new, expected, rtol=0, atol=2.1 * LR)  # |c / (|c| + eps)| <= 1 everywhere


def test_the_log_rmse_loss_reaches_the_step_per_image_in_units_of_its_sample_scale():
    """loss="log_rmse": the step's loss is (1/B) sum_b log(RMSE_b / s_b + eps), RMSE_b over image b's valid pixels
    and s_b its sample scale, written out here in numpy from the model's output."""
    config = dataclasses.replace(CONFIG, loss="log_rmse", iteration_weights=(), inverse_depth_weight=0.0)
    batch = _batch(seed=3)
    state = init_state(config, _perturbed(config.model.init(jax.random.key(0))))
    out = np.asarray(config.model.apply(state.g_params, batch["rgb"], batch["sparse"])[0], np.float64)
    expected = []
    for b in range(2):
        v = batch["gt_valid"][b]
        s = np.exp(np.mean(np.log(batch["sparse"][b][batch["sparse"][b] > 0])))
        expected.append(np.log(np.sqrt(np.mean((out[b][v] - batch["gt"][b][v]) ** 2)) / s + LOG_RMSE_EPS))
    _, metrics = make_steps(config).supervised(state, batch, jax.random.key(0))
    np.testing.assert_allclose(float(metrics["loss"]), np.mean(expected), rtol=1e-5)
