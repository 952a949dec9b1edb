"""The x-update is the exact minimiser of eq. 6; the dual update is eq. 5's; data consistency holds."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lipjax.operators import dual_update, x_update


def _problem(seed, shape=(3, 4), weights=False):
    rng = np.random.default_rng(seed)
    mask = (rng.random(shape) < 0.4).astype(np.float32)
    w = rng.uniform(0.2, 3.0, shape).astype(np.float32) * mask if weights else mask
    y = (rng.uniform(0.5, 8.0, shape) * mask).astype(np.float32)
    z = rng.uniform(0.5, 8.0, shape).astype(np.float32)
    u = rng.normal(0, 0.3, shape).astype(np.float32)
    return y, w, z, u


def _objective(x, y, w, z, u, rho):
    """Eq. 6 with A = diag(sqrt(w)) so that ||y - A x||^2 weighs pixel i by w_i:
    1/2 sum w (y-x)^2 + rho/2 ||x-z+u||^2."""
    return 0.5 * jnp.sum(w * (y - x) ** 2) + 0.5 * rho * jnp.sum((x - z + u) ** 2)


@pytest.mark.parametrize("weights", [False, True])
@pytest.mark.parametrize("rho", [0.01, 0.3, 5.0])
def test_x_update_equals_dense_normal_equations_solve(weights, rho):
    y, w, z, u = _problem(0, weights=weights)
    n = y.size
    # Normal equations of eq. 6: (A^T A + rho I) x = A^T y + rho (z - u), with A^T A = diag(w).
    lhs = jnp.diag(jnp.asarray(w).ravel()) + rho * jnp.eye(n)
    rhs = jnp.asarray(w * y).ravel() + rho * jnp.asarray(z - u).ravel()
    x_dense = jnp.linalg.solve(lhs, rhs).reshape(y.shape)
    np.testing.assert_allclose(x_update(y, w, z, u, rho), x_dense, rtol=1e-5, atol=1e-5)


@pytest.mark.parametrize("weights", [False, True])
def test_gradient_of_objective_vanishes_at_x_update(weights):
    y, w, z, u = _problem(1, weights=weights)
    rho = 0.7
    x = x_update(y, w, z, u, rho)
    grad = jax.grad(_objective)(x, y, w, z, u, rho)
    assert float(jnp.abs(grad).max()) < 1e-5
    # ... and it is a minimum: perturbing x increases the objective.
    f0 = _objective(x, y, w, z, u, rho)
    for seed in range(3):
        dx = jax.random.normal(jax.random.key(seed), x.shape) * 1e-2
        assert _objective(x + dx, y, w, z, u, rho) > f0


@settings(max_examples=40, deadline=None)
@given(rho=st.floats(1e-4, 100.0), seed=st.integers(0, 1000))
def test_data_consistency_bound_on_measured_pixels(rho, seed):
    y, m, z, u = _problem(seed)
    x = np.asarray(x_update(y, m, z, u, rho))
    measured = m > 0
    bound = rho / (1 + rho) * np.abs(y - (z - u))
    assert np.all(np.abs(x - y)[measured] <= bound[measured] * (1 + 1e-5) + 1e-6)
    # Unmeasured pixels are left at the prox estimate z - u exactly.
    np.testing.assert_allclose(x[~measured], (z - u)[~measured], rtol=1e-6)


def test_data_consistency_goes_to_zero_with_rho():
    y, m, z, u = _problem(2)
    errs = [float(np.abs(np.asarray(x_update(y, m, z, u, rho)) - y)[m > 0].max()) for rho in (1.0, 1e-2, 1e-4)]
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 1e-3


def test_per_image_rho_broadcasts_like_scalar():
    y, m, z, u = _problem(3, shape=(2, 3, 4))
    rho = np.array([0.1, 2.0], np.float32)[:, None, None]
    x = x_update(y, m, z, u, rho)
    for b in range(2):
        np.testing.assert_allclose(x[b], x_update(y[b], m[b], z[b], u[b], float(rho[b, 0, 0])), rtol=1e-6)


def test_per_pixel_rho_is_the_minimiser_of_the_pixelwise_weighted_objective():
    """With rho varying over the pixels, eq. 6 becomes 1/2 ||y - A x||^2 + 1/2 ||diag(rho)^(1/2) (x - z + u)||^2:
    its normal equations (diag(m) + diag(rho)) x = m y + rho (z - u), solved densely, give the x-update."""
    y, w, z, u = _problem(4, shape=(3, 4), weights=True)
    rho = np.random.default_rng(5).uniform(0.05, 3.0, (3, 4)).astype(np.float32)
    n = y.size
    lhs = np.diag(w.ravel().astype(np.float64)) + np.diag(rho.ravel().astype(np.float64))
    rhs = w.ravel() * y.ravel() + rho.ravel() * (z.ravel() - u.ravel())
    expected = np.linalg.solve(lhs, rhs.astype(np.float64)).reshape(3, 4)
    assert n == 12 and len(np.unique(rho)) == n
    np.testing.assert_allclose(np.asarray(x_update(y, w, z, u, rho)), expected, rtol=1e-5)


def test_dual_update():
    """u_{k+1} = u_k + x_{k+1} - z_{k+1}: by hand (1 + 3 - 5 = -1), and from u_0 = 0 the dual after K steps is the
    running sum of the residuals x_k - z_k."""
    assert float(dual_update(np.float32(1.0), np.float32(3.0), np.float32(5.0))) == -1.0
    rng = np.random.default_rng(4)
    xs, zs = (rng.normal(size=(5, 2, 3)).astype(np.float32) for _ in range(2))
    u = np.zeros((2, 3), np.float32)
    for x, z in zip(xs, zs):
        u = dual_update(u, x, z)
    np.testing.assert_allclose(u, (xs - zs).sum(axis=0), rtol=1e-5, atol=1e-6)
