"""The LIP+AD discriminator's depth features: log-depth differences are exact and scale-invariant."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from lipjax.train.discriminator import LOG_GRADIENT_GAIN, Discriminator, _log_gradients


def test_log_gradients_of_an_exponential_ramp_are_constant_and_masked():
    x = jnp.arange(6, dtype=jnp.float32)
    depth = jnp.broadcast_to(2.0 * jnp.exp(0.05 * x), (1, 4, 6))
    valid = jnp.ones((1, 4, 6)).at[0, 1, 3].set(0.0)
    g = np.asarray(_log_gradients(depth, valid))
    assert g.shape == (1, 4, 6, 2)
    expect_dx = np.full((4, 6), 0.05 * LOG_GRADIENT_GAIN)
    expect_dx[:, 5] = 0.0  # no right neighbour
    expect_dx[1, 2:4] = 0.0  # pairs touching the invalid pixel
    np.testing.assert_allclose(g[0, ..., 0], expect_dx, atol=1e-5)
    np.testing.assert_allclose(g[0, ..., 1], 0.0, atol=1e-6)  # constant along y


def test_log_gradient_discriminator_ignores_the_depth_scale():
    d = Discriminator(widths=(4, 8), inputs="log_gradients")
    params = d.init(jax.random.key(0), (16, 16))
    rng = np.random.default_rng(0)
    depth = jnp.asarray(rng.uniform(1, 5, (2, 16, 16)), jnp.float32)
    rgb = jnp.asarray(rng.random((2, 16, 16, 3)), jnp.float32)
    valid = jnp.asarray(rng.random((2, 16, 16)) > 0.2)
    a, b = d.apply(params, depth, rgb, valid), d.apply(params, 7.0 * depth, rgb, valid)
    np.testing.assert_allclose(a, b, atol=1e-4)
    paper = Discriminator(widths=(4, 8))
    p2 = paper.init(jax.random.key(0), (16, 16))
    assert float(jnp.abs(paper.apply(p2, depth, rgb, valid) - paper.apply(p2, 7.0 * depth, rgb, valid)).max()) > 1e-3


def test_unknown_inputs_is_a_clear_error():
    with pytest.raises(ValueError, match="discriminator inputs must be one of"):
        Discriminator(inputs="rgb")
