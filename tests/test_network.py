"""The proximal network: preset sizes, any input size, identity at initialisation, RGB guidance is used."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from lipjax import model as lip_model
from lipjax.priors.network import PRESETS, network_preset

from helpers import conv_params as conv, up_projection_params as up_projection

# Per-iteration parameter counts of the presets (the paper: 7.88 M over its iterations, Table II), as
# `counted_by_hand` derives them from the architecture.
EXPECTED_PER_ITERATION = {"small": 493_721, "paper": 2_559_377, "tiny": 41_025}


def counted_by_hand(prior) -> int:
    """ProxNet's parameters from its widths (convolutions and up-projections counted by tests/helpers.py, a GroupNorm
    of c channels 2c); the input is depth + RGB (4 channels)."""
    def bottleneck(a, w):  # 1x1 projection shortcut; 1x1 -> 3x3 -> 1x1 (expansion 4), each normalised
        return conv(1, a, 4 * w) + conv(1, a, w) + 2 * w + conv(3, w, w) + 2 * w + conv(1, w, 4 * w) + 8 * w

    s, (w1, w2, w3), (f1, f2, f3) = prior.stem_width, prior.bottleneck_widths, prior.up_widths
    return (conv(3, 4, s) + 2 * s + bottleneck(s, w1) + bottleneck(4 * w1, w2) + bottleneck(4 * w2, w3)
            + up_projection(4 * w3, f1) + up_projection(f1 + 4 * w2, f2) + up_projection(f2 + 4 * w1, f3)
            + conv(3, f3, 1))  # skips from the bottlenecks are concatenated; the residual head: 1 channel


@pytest.mark.parametrize("name", sorted(EXPECTED_PER_ITERATION))
def test_preset_parameter_counts(name):
    shapes = jax.eval_shape(PRESETS[name].init, jax.random.key(0))  # shapes only: no compile, no compute
    assert lip_model.parameter_count(shapes) == counted_by_hand(PRESETS[name]) == EXPECTED_PER_ITERATION[name]


def test_paper_preset_over_three_iterations_is_close_to_the_papers_size():
    config = lip_model.LIPConfig(prior=network_preset("paper"), num_iterations=3, learn_rho=False, guidance="rgb")
    shapes = jax.eval_shape(lambda k: lip_model.init(config, k), jax.random.key(0))
    total = lip_model.parameter_count(shapes)
    assert total == 3 * EXPECTED_PER_ITERATION["paper"]
    assert abs(total - 7.88e6) / 7.88e6 < 0.05


@pytest.mark.parametrize("shape", [(13, 21), (16, 24), (7, 9)])
def test_output_has_input_size_and_untrained_net_is_identity(shape):
    prior = network_preset("tiny", max_depth_m=10.0)
    params = prior.init(jax.random.key(0))
    rng = np.random.default_rng(0)
    v = jnp.asarray(rng.uniform(0.5, 9.0, (2, *shape)), jnp.float32)
    rgb = jnp.asarray(rng.random((2, *shape, 3)), jnp.float32)
    z = jax.jit(prior.apply)(params, v, rgb)  # one compile instead of op-by-op dispatch
    assert z.shape == v.shape
    # The residual head starts at zero, so G = identity before training.
    np.testing.assert_allclose(z, v, rtol=1e-6)


def test_output_depends_on_rgb_and_depth_once_head_is_nonzero():
    prior = network_preset("tiny", max_depth_m=10.0)
    params = prior.init(jax.random.key(0))
    params = jax.tree_util.tree_map(lambda a: a, params)
    head = [k for k in params if k.startswith("Conv_")][-1]
    params[head]["kernel"] = 0.1 * jax.random.normal(jax.random.key(2), params[head]["kernel"].shape)
    v = jnp.full((1, 16, 16), 3.0)
    rgb0 = jnp.zeros((1, 16, 16, 3))
    rgb1 = rgb0.at[:, :, 8:].set(1.0)
    z0, z1 = prior.apply(params, v, rgb0), prior.apply(params, v, rgb1)
    assert float(jnp.abs(z0 - z1).max()) > 1e-4
    z2 = prior.apply(params, v + 1.0, rgb0)
    assert float(jnp.abs(z2 - z0 - 1.0).max()) > 1e-5  # not just a shift: depth passes through the network


def test_unknown_preset_is_a_clear_error():
    with pytest.raises(ValueError, match="unknown network preset 'huge'"):
        network_preset("huge")


def test_log_domain_prox_starts_as_the_identity_and_is_positive_for_any_weights(tmp_path):
    import dataclasses

    from lipjax import model_io
    from lipjax.priors.network import LOG_DOMAIN_FLOOR, NetworkPrior

    prior = dataclasses.replace(network_preset("tiny", max_depth_m=80.0), depth_domain="log")
    params = prior.init(jax.random.key(0))
    rng = np.random.default_rng(0)
    v = jnp.asarray(rng.uniform(1.0, 79.0, (2, 16, 24)), jnp.float32)
    rgb = jnp.asarray(rng.random((2, 16, 24, 3)), jnp.float32)
    apply = jax.jit(prior.apply)
    np.testing.assert_allclose(apply(params, v, rgb), v, rtol=1e-5)  # exp(log v + 0) = v
    # Scrambled weights (head included) and inputs at or below zero: depth stays positive and finite, and the
    # output is v times exp(residual), so an input below the floor starts from the floor.
    keys = iter(jax.random.split(jax.random.key(1), 100))
    wild = jax.tree_util.tree_map(lambda p: 3.0 * jax.random.normal(next(keys), p.shape), params)
    v_bad = v.at[:, :4].set(-5.0).at[:, 4:6].set(0.0)
    z = np.asarray(apply(wild, v_bad, rgb))
    assert np.all(np.isfinite(z)) and np.all(z > 0)
    assert np.any(np.abs(z - np.asarray(v_bad)) > 1.0)  # the scrambled net does change the depth
    floor_m = LOG_DOMAIN_FLOOR * prior.max_depth_m
    np.testing.assert_allclose(apply(params, v_bad, rgb)[:, :6], floor_m, rtol=1e-5)
    # the option survives a model file, and a wrong name is a clear error
    config = lip_model.LIPConfig(prior=prior, num_iterations=1)
    model_io.save(tmp_path / "m", config, lip_model.init(config, jax.random.key(0)))
    assert model_io.load(tmp_path / "m")[0].prior.depth_domain == "log"
    with pytest.raises(ValueError, match="depth_domain"):
        NetworkPrior(depth_domain="inverse")
