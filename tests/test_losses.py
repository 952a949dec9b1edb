"""Losses against values computed by hand; the discriminator never sees invalid ground-truth pixels."""
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from lipjax.discriminator import Discriminator
from lipjax.losses import (
    depth_loss,
    discriminator_loss,
    generator_adversarial_loss,
    masked_mean,
    supervised_loss,
)


def test_masked_losses_by_hand():
    pred = jnp.array([[[1.0, 2.0], [3.0, 10.0]]])
    gt = jnp.array([[[2.0, 2.0], [1.0, 0.0]]])
    valid = gt > 0  # the last pixel is invalid and must not count
    # errors on valid pixels: -1, 0, 2
    assert float(depth_loss(pred, gt, valid, kind="l2")) == pytest.approx((1 + 0 + 4) / 3)
    assert float(depth_loss(pred, gt, valid, kind="l1")) == pytest.approx((1 + 0 + 2) / 3)
    assert float(depth_loss(pred, gt, valid, kind="l2", scale_m=2.0)) == pytest.approx((1 + 0 + 4) / 3 / 4)
    assert float(masked_mean(pred, jnp.zeros_like(valid))) == 0.0
    with pytest.raises(ValueError, match="'l2' or 'l1'"):
        depth_loss(pred, gt, valid, kind="huber")


def test_deep_supervision_adds_weighted_iterate_losses():
    gt = jnp.ones((1, 2, 2))
    valid = jnp.ones((1, 2, 2), bool)
    final = gt + 1.0  # loss 1
    iterates = jnp.stack([gt + 2.0, gt + 3.0])  # losses 4, 9
    assert float(supervised_loss(final, iterates, gt, valid, iteration_weights=(0.5, 0.1))) == pytest.approx(1 + 2 + 0.9)
    assert float(supervised_loss(final, None, gt, valid)) == pytest.approx(1.0)


def test_adversarial_losses_by_hand():
    zeros = jnp.zeros((2, 3))
    # sigmoid(0) = 1/2: each cross-entropy term is log 2.
    assert float(discriminator_loss(zeros, zeros)) == pytest.approx(2 * math.log(2), rel=1e-6)
    assert float(generator_adversarial_loss(zeros)) == pytest.approx(math.log(2), rel=1e-6)
    confident = jnp.full((2, 3), 20.0)
    assert float(discriminator_loss(confident, -confident)) < 1e-6
    assert float(generator_adversarial_loss(-confident)) == pytest.approx(20.0, rel=1e-3)


def test_discriminator_ignores_depth_at_invalid_ground_truth_pixels():
    d = Discriminator(widths=(8, 8), max_depth_m=10.0)
    params = d.init(jax.random.key(0), (16, 16))
    rng = np.random.default_rng(0)
    valid = jnp.asarray(rng.random((1, 16, 16)) < 0.6)
    rgb = jnp.asarray(rng.random((1, 16, 16, 3)), jnp.float32)
    depth = jnp.asarray(rng.uniform(1, 9, (1, 16, 16)), jnp.float32)
    changed_where_invalid = jnp.where(valid, depth, 123.0)
    np.testing.assert_allclose(d.apply(params, depth, rgb, valid), d.apply(params, changed_where_invalid, rgb, valid), rtol=1e-6)
    changed_where_valid = jnp.where(valid, depth + 1.0, depth)
    assert float(jnp.abs(d.apply(params, depth, rgb, valid) - d.apply(params, changed_where_valid, rgb, valid)).max()) > 1e-6
