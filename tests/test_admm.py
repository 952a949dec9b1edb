"""The unrolled solver: scan equals a Python loop, shared and per-iteration parameters, convergence with an exact
prox to the closed-form solution of eq. 1, and gradients through the whole unroll."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from lipjax import model as lip_model
from lipjax.admm import unrolled_admm
from lipjax.operators import dual_update, x_update
from lipjax.priors.network import network_preset

H, W = 5, 6


def _sparse_problem(seed=0, batch=2):
    rng = np.random.default_rng(seed)
    gt = rng.uniform(1.0, 4.0, (batch, H, W)).astype(np.float32)
    mask = (rng.random((batch, H, W)) < 0.3).astype(np.float32)
    mask[:, 0, 0] = 1.0  # at least one sample per image
    rgb = rng.random((batch, H, W, 3)).astype(np.float32)
    return gt * mask, mask, rgb


def _toy_prox(params, v, rgb):
    """A parametrised, nonlinear, RGB-guided stand-in for G: z = a * v + b * tanh(v) + c * rgb[..., 0]."""
    return params["a"] * v + params["b"] * jnp.tanh(v) + params["c"] * rgb[..., 0]


def _python_loop(prox, params_per_iteration, y, m, rgb, rhos, z0):
    z, u = z0, jnp.zeros_like(y)
    xs, zs = [], []
    for params, rho in zip(params_per_iteration, rhos):
        x = x_update(y, m, z, u, rho)
        z = prox(params, x + u, rgb)
        u = dual_update(u, x, z)
        xs.append(x)
        zs.append(z)
    return x_update(y, m, z, u, rhos[-1]), jnp.stack(xs), jnp.stack(zs)


@pytest.mark.parametrize("unroll", [True, False])
def test_scan_equals_python_loop_per_iteration_params(unroll):
    y, m, rgb = _sparse_problem()
    k = 4
    params = {"a": jnp.linspace(0.5, 0.9, k), "b": jnp.linspace(0.1, 0.3, k), "c": jnp.linspace(-0.2, 0.2, k)}
    rhos = jnp.array([0.5, 0.2, 0.1, 0.05])
    out, traj = unrolled_admm(_toy_prox, params, y, m, rgb, rhos, return_trajectory=True, unroll=unroll)
    per_it = [jax.tree_util.tree_map(lambda a: a[i], params) for i in range(k)]
    ref, xs, zs = _python_loop(_toy_prox, per_it, y, m, rgb, rhos, z0=y)
    np.testing.assert_allclose(out, ref, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(traj.x, xs, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(traj.z, zs, rtol=1e-6, atol=1e-6)
    assert traj.x.shape == (k, *y.shape)


def test_output_without_the_final_dual_is_the_last_prox_with_measurements_reimposed():
    y, m, rgb = _sparse_problem(3)
    params = {"a": jnp.array([0.8, 1.3]), "b": jnp.array([0.2, -0.4]), "c": jnp.array([0.5, 1.0])}
    rhos = jnp.array([0.3, 0.2])
    out, traj = unrolled_admm(_toy_prox, params, y, m, rgb, rhos, return_trajectory=True, final_dual=False)
    z_last = traj.z[-1]
    np.testing.assert_allclose(out, x_update(y, m, z_last, jnp.zeros_like(y), rhos[-1]), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(out[m == 0], z_last[m == 0], rtol=1e-6)  # unmeasured: exactly z_K
    # the default reads z_K - u_K there, which differs once the last prox moved its input
    default, _ = unrolled_admm(_toy_prox, params, y, m, rgb, rhos)
    assert float(jnp.max(jnp.abs(default - out))) > 1e-2
    # through the model config: output="z" selects it, anything else is a clear error
    config = lip_model.LIPConfig(prior=network_preset("tiny"), num_iterations=2, output="z", initial_estimate="sparse")
    lip_params = config.init(jax.random.key(0))
    out_z, traj_z = config.apply(lip_params, rgb, y, return_trajectory=True)
    np.testing.assert_allclose(np.asarray(out_z)[m == 0], np.asarray(traj_z.z[-1])[m == 0], rtol=1e-6)
    with pytest.raises(ValueError, match="output must be"):
        lip_model.LIPConfig(output="u")


def test_shared_params_equal_repeated_per_iteration_params():
    y, m, rgb = _sparse_problem(1)
    shared = {"a": jnp.float32(0.7), "b": jnp.float32(0.2), "c": jnp.float32(0.1)}
    stacked = jax.tree_util.tree_map(lambda a: jnp.full((3,), a), shared)
    rhos = jnp.full((3,), 0.3)
    a, _ = unrolled_admm(_toy_prox, shared, y, m, rgb, rhos, shared_params=True)
    b, _ = unrolled_admm(_toy_prox, stacked, y, m, rgb, rhos, shared_params=False)
    np.testing.assert_allclose(a, b, rtol=1e-6)


def test_first_iteration_sees_the_sparse_input_when_z0_is_y():
    y, m, rgb = _sparse_problem(2)
    identity = lambda params, v, rgb: v  # noqa: E731
    _, traj = unrolled_admm(identity, {}, y, m, rgb, jnp.array([0.1]), shared_params=True, return_trajectory=True)
    np.testing.assert_allclose(traj.x[0], y, atol=1e-6)


def test_wrong_leading_axis_is_a_clear_error():
    y, m, rgb = _sparse_problem()
    with pytest.raises(ValueError, match="leading axis of size K=3"):
        unrolled_admm(_toy_prox, {"a": jnp.ones(2), "b": jnp.ones(2), "c": jnp.ones(2)}, y, m, rgb, jnp.ones(3))


def _difference_operator(h, w):
    """D: stacked horizontal and vertical forward differences of an (h, w) image, as a dense matrix."""
    idx = np.arange(h * w).reshape(h, w)
    rows = []
    for a, b in [(idx[:, :-1], idx[:, 1:]), (idx[:-1, :], idx[1:, :])]:
        for i, j in zip(a.ravel(), b.ravel()):
            r = np.zeros(h * w)
            r[i], r[j] = -1.0, 1.0
            rows.append(r)
    return np.array(rows)


def test_exact_quadratic_prox_converges_to_closed_form_solution():
    """phi(z) = 1/2 ||D z||^2 has prox z = (rho I + lam D^T D)^{-1} rho v, and eq. 1 has the closed-form
    solution x* = (A^T A + lam D^T D)^{-1} A^T y. The unrolled ADMM must approach x* as K grows."""
    y, m, rgb = _sparse_problem(3, batch=1)
    lam, rho = 0.5, 1.0
    d = _difference_operator(H, W)
    dtd = d.T @ d
    prox_matrix = jnp.asarray(np.linalg.solve(rho * np.eye(H * W) + lam * dtd, rho * np.eye(H * W)), jnp.float32)
    x_star = np.linalg.solve(np.diag(m[0].ravel()) + lam * dtd, (m[0] * y[0]).ravel()).reshape(H, W)

    def exact_prox(params, v, rgb):
        return (v.reshape(v.shape[0], -1) @ prox_matrix.T).reshape(v.shape)

    errors = []
    for k in (2, 20, 400):
        x, _ = unrolled_admm(exact_prox, {}, y, m, rgb, jnp.full((k,), rho), shared_params=True, unroll=False)
        errors.append(float(np.abs(np.asarray(x[0]) - x_star).max()))
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 1e-4, errors


def test_gradients_flow_to_every_iterations_network():
    # Every iteration's network and rho_k get a gradient, except rho_0: with u_0 = 0 and a fill that keeps the
    # measured pixels (z_0 = y there), x_1 = (m y + rho_0 z_0) / (m + rho_0) is y on measured pixels and z_0
    # elsewhere whatever rho_0, so its gradient is zero up to float32 rounding (of z_0 rho_0 / rho_0 and
    # (y + rho_0 y) / (1 + rho_0), ~1e-7 relative per pixel: 8e-7 here against 5e-3 for rho_1 with jax 0.10).
    config = lip_model.LIPConfig(prior=network_preset("tiny"), num_iterations=3, initial_estimate="box_fill")
    params = lip_model.init(config, jax.random.key(0))
    # The zero-initialised residual heads block gradients to the layers below them at init; give them small
    # random weights so every layer of every iteration is reachable.
    head = [k for k in params["prox"] if k.startswith("Conv_")][-1]
    kernel = params["prox"][head]["kernel"]
    params["prox"][head]["kernel"] = 0.01 * jax.random.normal(jax.random.key(1), kernel.shape)
    rng = np.random.default_rng(0)
    gt = rng.uniform(1, 5, (2, 16, 16)).astype(np.float32)
    sparse = gt * (rng.random(gt.shape) < 0.2)
    rgb = rng.integers(0, 255, (2, 16, 16, 3), dtype=np.uint8)

    def loss(p):
        out, _ = lip_model.apply(config, p, rgb, sparse)
        return jnp.mean((out - gt) ** 2)

    grads = jax.jit(jax.grad(loss))(params)
    for path, g in jax.tree_util.tree_leaves_with_path(grads):
        g = np.asarray(g)
        assert np.isfinite(g).all(), path
        per_iteration = np.abs(g.reshape(g.shape[0], -1)).max(axis=1)
        if jax.tree_util.keystr(path) == "['log_rho']":
            assert per_iteration[0] <= 1e-3 * per_iteration[1:].min(), per_iteration
            per_iteration = per_iteration[1:]
        assert (per_iteration > 0).all(), (jax.tree_util.keystr(path), per_iteration)
    # and the loss itself: rho_0 times e changes it only by rounding, rho_1 times e by far more
    base = float(jax.jit(loss)(params))
    moved = [float(jax.jit(loss)(dict(params, log_rho=params["log_rho"].at[k].add(1.0)))) for k in (0, 1)]
    assert abs(moved[0] - base) <= 1e-6 * base and abs(moved[1] - base) > 1e-4 * base, (base, moved)
