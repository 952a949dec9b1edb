"""The training state: one pytree holding everything needed to resume exactly."""
from __future__ import annotations

from typing import Any

import flax.struct
import jax
import jax.numpy as jnp
import optax

from lipjax.train.config import TrainConfig


@flax.struct.dataclass
class TrainState:
    """step: () int32 global step; g_*/d_*: parameters and optimiser states of G (the LIP model) and D;
    rng: (2,) uint32 raw PRNG key data (stored raw so that checkpoints hold plain arrays)."""

    step: jax.Array
    g_params: Any
    g_opt_state: Any
    d_params: Any
    d_opt_state: Any
    rng: jax.Array


def g_learning_rate(config: TrainConfig) -> optax.Schedule:
    """G's learning rate by step: a linear warm-up from 0 over `warmup_steps` (at most the run's steps - 1), then
    `config.schedule`: "cosine" decays to 5 % of learning_rate at the run's last step, "constant" holds it, "linear"
    decays linearly to 0 at G's last update (the step counts G's updates, g_steps + adv_steps: D's pretraining steps
    leave G's optimiser alone)."""
    warmup = max(1, min(config.warmup_steps, config.total_steps - 1))
    if config.schedule == "constant":
        return optax.linear_schedule(0.0, config.learning_rate, warmup)
    if config.schedule == "linear":
        updates = max(warmup + 1, config.g_steps + config.adv_steps)
        return optax.join_schedules([optax.linear_schedule(0.0, config.learning_rate, warmup),
                                     optax.linear_schedule(config.learning_rate, 0.0, updates - warmup)], [warmup])
    return optax.warmup_cosine_decay_schedule(0.0, config.learning_rate, warmup, max(2, config.total_steps),
                                              end_value=0.05 * config.learning_rate)


def make_optimizers(config: TrainConfig) -> tuple[optax.GradientTransformation, optax.GradientTransformation]:
    """AdamW with `g_learning_rate`, after global-norm clipping, for G; Adam for D."""
    g_opt = optax.chain(optax.clip_by_global_norm(config.grad_clip_norm),
                        optax.adamw(g_learning_rate(config), weight_decay=config.weight_decay))
    d_opt = optax.chain(optax.clip_by_global_norm(config.grad_clip_norm), optax.adam(config.d_learning_rate, b1=0.5))
    return g_opt, d_opt


def init_state(config: TrainConfig, g_params: Any | None = None) -> TrainState:
    """A fresh state; `g_params` (e.g. a pretrained LIP+CNN) replaces the random G parameters when given."""
    key = jax.random.key(config.seed)
    g_key, d_key, rng = jax.random.split(key, 3)
    if g_params is None:
        g_params = config.model.init(g_key)
    g_params = jax.tree_util.tree_map(jnp.asarray, g_params)
    d_params = config.discriminator.init(d_key) if config.adversarial else {}
    g_opt, d_opt = make_optimizers(config)
    return TrainState(
        step=jnp.zeros((), jnp.int32),
        g_params=g_params,
        g_opt_state=g_opt.init(g_params),
        d_params=d_params,
        d_opt_state=d_opt.init(d_params),
        rng=jax.random.key_data(rng),
    )
