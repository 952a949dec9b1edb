"""Losses against values computed by hand; the discriminator never sees invalid ground-truth pixels."""
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from lipjax.model import LIPConfig
from lipjax.priors.fast import sample_scale
from lipjax.priors.network import network_preset
from lipjax.train.config import TrainConfig
from lipjax.train.discriminator import Discriminator
from lipjax.train.losses import (
    LOG_RMSE_EPS,
    depth_loss,
    discriminator_loss,
    generator_adversarial_loss,
    inverse_depth_loss,
    masked_mean,
    soft_floored_inverse,
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
    with pytest.raises(ValueError, match="loss kind must be one of"):
        depth_loss(pred, gt, valid, kind="huber")


def test_log_rmse_is_the_mean_log_of_each_images_rmse():
    """kind="log_rmse": (1/B) sum_b log(RMSE_b + eps), each image's RMSE over its own valid pixels, so that the
    loss is, up to a constant, the log of the suites' geometric-mean RMSE ratio to a fixed reference."""
    gt = jnp.array([[[2.0, 2.0], [1.0, 0.0]], [[5.0, 5.0], [5.0, 5.0]]])
    valid = gt > 0
    pred = gt + jnp.array([[[-1.0, 0.0], [2.0, 7.0]], [[3.0, 3.0], [-3.0, 3.0]]])  # 7.0 on an invalid pixel
    rmse = np.array([math.sqrt((1 + 0 + 4) / 3), 3.0])
    expected = np.mean(np.log(rmse + LOG_RMSE_EPS))
    assert float(depth_loss(pred, gt, valid, kind="log_rmse")) == pytest.approx(expected, rel=1e-6)
    # units cancel but for eps: dividing by a scale s shifts the loss by -log s
    s = jnp.array([2.0, 4.0]).reshape(2, 1, 1)
    shifted = np.mean(np.log(rmse / np.array([2.0, 4.0]) + LOG_RMSE_EPS))
    assert float(depth_loss(pred, gt, valid, kind="log_rmse", scale_m=s)) == pytest.approx(shifted, rel=1e-6)
    # each image weighs alike: doubling one image's errors adds log(2) / B whatever their size
    doubled = gt + 2 * (pred - gt) * jnp.array([1.0, 0.0]).reshape(2, 1, 1) + (pred - gt) * jnp.array(
        [0.0, 1.0]).reshape(2, 1, 1)
    step = float(depth_loss(doubled, gt, valid, kind="log_rmse")) - float(depth_loss(pred, gt, valid, kind="log_rmse"))
    assert step == pytest.approx(math.log((2 * rmse[0] + LOG_RMSE_EPS) / (rmse[0] + LOG_RMSE_EPS)) / 2, rel=1e-5)


def test_log_rmse_gradient_in_closed_form_and_finite_at_zero_error():
    """d/dpred_i of log(RMSE + eps) = e_i / (N RMSE (RMSE + eps)) on valid pixels, 0 elsewhere (then / B); an
    image estimated exactly, or without valid pixels, has a finite loss and no gradient."""
    gt = jnp.array([[[1.0, 2.0, 3.0, 0.0]], [[1.0, 1.0, 1.0, 1.0]], [[0.0, 0.0, 0.0, 0.0]]])
    valid = gt > 0
    e = jnp.array([[[0.5, -1.0, 2.0, 9.0]], [[0.0, 0.0, 0.0, 0.0]], [[1.0, 1.0, 1.0, 1.0]]])
    grad = np.asarray(jax.grad(lambda p: depth_loss(p, gt, valid, kind="log_rmse"))(gt + e))
    r = math.sqrt((0.25 + 1 + 4) / 3)
    np.testing.assert_allclose(grad[0, 0], np.array([0.5, -1.0, 2.0, 0.0]) / (3 * r * (r + LOG_RMSE_EPS)) / 3,
                               rtol=1e-5)
    assert np.all(grad[1:] == 0)
    value = float(depth_loss(gt + e, gt, valid, kind="log_rmse"))
    assert value == pytest.approx((math.log(r + LOG_RMSE_EPS) + 2 * math.log(LOG_RMSE_EPS)) / 3, rel=1e-6)


def test_loss_in_units_of_each_images_sample_scale():
    """TrainConfig(loss_scale="samples"): errors over the geometric mean s of each image's samples, so a room at
    2 m and a street at 20 m with the same relative error weigh alike; "max_depth" divides by one constant."""
    gt = jnp.stack([jnp.full((2, 2), 2.0), jnp.full((2, 2), 20.0)])
    pred = gt * 1.1
    sparse = jnp.stack([jnp.array([[1.0, 0.0], [0.0, 4.0]]), jnp.array([[10.0, 0.0], [0.0, 40.0]])])
    s = sample_scale(sparse, sparse)  # sqrt(1 * 4) = 2 m and sqrt(10 * 40) = 20 m
    np.testing.assert_allclose(np.asarray(s).ravel(), [2.0, 20.0], rtol=1e-6)
    per_image = [float(depth_loss(pred[i:i + 1], gt[i:i + 1], gt[i:i + 1] > 0, scale_m=s[i:i + 1])) for i in range(2)]
    np.testing.assert_allclose(per_image, [0.01, 0.01], rtol=1e-5)  # (0.1 * 2 / 2)^2 = (0.1 * 20 / 20)^2
    assert float(depth_loss(pred, gt, gt > 0, scale_m=s)) == pytest.approx(0.01, rel=1e-5)
    assert float(depth_loss(pred, gt, gt > 0, scale_m=10.0)) == pytest.approx((0.04 + 4.0) / 2 / 100, rel=1e-5)
    with pytest.raises(ValueError, match="loss_scale must be one of"):
        TrainConfig(name="x", model=LIPConfig(prior=network_preset("tiny")), loss_scale="median")
    with pytest.raises(ValueError, match="loss must be one of"):
        TrainConfig(name="x", model=LIPConfig(prior=network_preset("tiny")), loss="huber")


def test_deep_supervision_adds_weighted_iterate_losses():
    gt = jnp.ones((1, 2, 2))
    valid = jnp.ones((1, 2, 2), bool)
    final = gt + 1.0  # loss 1
    iterates = jnp.stack([gt + 2.0, gt + 3.0])  # losses 4, 9
    assert (float(supervised_loss(final, iterates, gt, valid, iteration_weights=(0.5, 0.1)))
            == pytest.approx(1 + 2 + 0.9))
    assert float(supervised_loss(final, None, gt, valid)) == pytest.approx(1.0)


def test_soft_floored_inverse_is_c1_and_pushes_non_positive_depths_up():
    floor = 2.0
    d = jnp.array([-3.0, 0.0, 1.0, 2.0, 4.0])
    # tangent line of 1/d at d = 2 below the floor: 1/2 + (2 - d)/4; plain 1/d above it
    np.testing.assert_allclose(soft_floored_inverse(d, floor), [1.75, 1.0, 0.75, 0.5, 0.25], rtol=1e-6)
    grad = jax.vmap(jax.grad(lambda x: soft_floored_inverse(x, floor)))(d)
    np.testing.assert_allclose(grad, [-0.25, -0.25, -0.25, -0.25, -1 / 16], rtol=1e-6)  # continuous at the floor


def test_inverse_depth_loss_by_hand_and_in_the_supervised_loss():
    pred = jnp.array([[[0.5, 4.0], [-1.0, 3.0]]])
    gt = jnp.array([[[2.0, 2.0], [4.0, 0.0]]])
    valid = gt > 0
    # floor 1 m: |(1 + 0.5) - 0.5| = 1, |0.25 - 0.5| = 0.25, |(1 + 2) - 0.25| = 2.75 on the valid pixels; the
    # invalid one (depth 3 m >= floor) costs nothing
    assert float(inverse_depth_loss(pred, gt, valid, floor_m=1.0)) == pytest.approx((1 + 0.25 + 2.75) / 3)
    depth_l1 = (1.5 + 2.0 + 5.0) / 3
    total = supervised_loss(pred, None, gt, valid, kind="l1", inverse_depth_weight=0.5, inverse_depth_floor_m=1.0)
    assert float(total) == pytest.approx(depth_l1 + 0.5 * 4 / 3)
    # without ground truth only a depth below the floor is penalised: -1 m -> 1/f + (f + 1)/f^2 - 1/f = 2
    below = jnp.array([[[-1.0, 5.0]]])
    no_gt = jnp.zeros((1, 1, 2), bool)
    assert float(inverse_depth_loss(below, jnp.zeros((1, 1, 2)), no_gt, floor_m=1.0)) == pytest.approx(1.0)


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
    np.testing.assert_allclose(d.apply(params, depth, rgb, valid), d.apply(params, changed_where_invalid, rgb, valid),
                               rtol=1e-6)
    changed_where_valid = jnp.where(valid, depth + 1.0, depth)
    assert float(jnp.abs(d.apply(params, depth, rgb, valid)
                         - d.apply(params, changed_where_valid, rgb, valid)).max()) > 1e-6
