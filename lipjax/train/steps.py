"""jit-compiled, pure train steps: `step(state, batch, key) -> (state, metrics)`.

`batch` is a dict of arrays: rgb (B,H,W,3) uint8, sparse (B,H,W) float32 m, gt (B,H,W) float32 m,
gt_valid (B,H,W) bool, and z0 (B,H,W) float32 m for models with a host-computed initial estimate.
Sharded over a 'data' mesh axis, the same jitted step runs data-parallel: XLA inserts the
gradient all-reduce, parameters stay replicated.
"""
from __future__ import annotations

import dataclasses
import functools
from typing import Callable

import jax
import jax.numpy as jnp
import optax

from lipjax.priors.fast import sample_scale
from lipjax.train.losses import discriminator_loss, generator_adversarial_loss, supervised_loss
from lipjax.train.config import DataConfig, TrainConfig
from lipjax.train.state import TrainState, make_optimizers

StepFn = Callable[[TrainState, dict, jax.Array], tuple[TrainState, dict]]


@dataclasses.dataclass(frozen=True)
class Steps:
    supervised: StepFn
    discriminator: StepFn
    adversarial: StepFn


def _rgb01(rgb):
    return rgb.astype(jnp.float32) / 255.0


def make_steps(config: TrainConfig) -> Steps:
    """The three jitted steps of a config; runs whose configs differ only in what the steps do not read (name,
    data, logging, checkpointing, initialisation) share them and their compilations."""
    return _make_steps(dataclasses.replace(config, name="", data=DataConfig(), log_every=1, eval_every=0,
                                           checkpoint_every=1, keep_checkpoints=1, init_from=None))


@functools.lru_cache(maxsize=None)
def _make_steps(config: TrainConfig) -> Steps:
    g_opt, d_opt = make_optimizers(config)
    model_config = config.model
    scale = model_config.max_depth_m
    want_trajectory = bool(config.iteration_weights)

    def g_forward(g_params, batch):
        extra = {"z0": batch["z0"]} if "z0" in batch else {}  # host-computed initial estimate (LIPConfig.host_inputs)
        out, traj = model_config.apply(g_params, batch["rgb"], batch["sparse"], return_trajectory=want_trajectory,
                                       **extra)
        return out, (traj.x if want_trajectory else None)

    def g_supervised(g_params, batch):
        out, iterates = g_forward(g_params, batch)
        unit = scale if config.loss_scale == "max_depth" else sample_scale(batch["sparse"], batch["sparse"])
        loss = supervised_loss(out, iterates, batch["gt"], batch["gt_valid"], kind=config.loss, scale_m=unit,
                               iteration_weights=config.iteration_weights,
                               inverse_depth_weight=config.inverse_depth_weight,
                               inverse_depth_floor_m=config.inverse_depth_floor_m)
        return loss, out

    def d_logits(d_params, depth, batch):
        return config.discriminator.apply(d_params, depth, _rgb01(batch["rgb"]), batch["gt_valid"])

    def apply_g(state, grads):
        updates, g_opt_state = g_opt.update(grads, state.g_opt_state, state.g_params)
        return state.replace(g_params=optax.apply_updates(state.g_params, updates), g_opt_state=g_opt_state)

    def apply_d(state, grads):
        updates, d_opt_state = d_opt.update(grads, state.d_opt_state, state.d_params)
        return state.replace(d_params=optax.apply_updates(state.d_params, updates), d_opt_state=d_opt_state)

    def supervised_step(state, batch, key):
        del key  # deterministic step; the argument keeps all steps interchangeable
        (loss, _), grads = jax.value_and_grad(g_supervised, has_aux=True)(state.g_params, batch)
        state = apply_g(state, grads)
        metrics = {"loss": loss, "g_supervised_loss": loss, "g_grad_norm": optax.tree_utils.tree_norm(grads)}
        return state.replace(step=state.step + 1), metrics

    def d_step_on(state, batch, fake):
        fake = jax.lax.stop_gradient(fake)

        def loss_fn(d_params):
            real_logits = d_logits(d_params, batch["gt"], batch)
            fake_logits = d_logits(d_params, fake, batch)
            acc = 0.5 * (jnp.mean(real_logits > 0) + jnp.mean(fake_logits < 0))
            return discriminator_loss(real_logits, fake_logits), acc

        (loss, acc), grads = jax.value_and_grad(loss_fn, has_aux=True)(state.d_params)
        return apply_d(state, grads), {"d_loss": loss, "d_accuracy": acc}

    def discriminator_step(state, batch, key):
        del key
        fake, _ = g_forward(state.g_params, batch)
        state, metrics = d_step_on(state, batch, fake)
        metrics["loss"] = metrics["d_loss"]
        return state.replace(step=state.step + 1), metrics

    def adversarial_step(state, batch, key):
        del key

        def g_loss_fn(g_params):
            sup, fake = g_supervised(g_params, batch)
            adv = generator_adversarial_loss(d_logits(state.d_params, fake, batch))
            return sup + config.adv_weight * adv, (sup, adv, fake)

        (loss, (sup, adv, fake)), grads = jax.value_and_grad(g_loss_fn, has_aux=True)(state.g_params)
        state = apply_g(state, grads)
        state, d_metrics = d_step_on(state, batch, fake)
        metrics = {"loss": loss, "g_supervised_loss": sup, "g_adversarial_loss": adv,
                   "g_grad_norm": optax.tree_utils.tree_norm(grads), **d_metrics}
        return state.replace(step=state.step + 1), metrics

    return Steps(
        supervised=jax.jit(supervised_step, donate_argnums=0),
        discriminator=jax.jit(discriminator_step, donate_argnums=0),
        adversarial=jax.jit(adversarial_step, donate_argnums=0),
    )
