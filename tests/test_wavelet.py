import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy import optimize

from lipjax.priors.wavelet import (
    WaveletPrior,
    cycle_offsets,
    dwt2,
    idwt2,
    soft_threshold,
    wavelet_shrink,
)

WAVELETS = ["haar", "db2"]


def transform_matrix(shape: tuple[int, int], levels: int, wavelet: str = "haar") -> np.ndarray:
    """The (H W, H W) matrix of `dwt2` (rows: approximation first, then details finest level first)."""
    h, w = shape
    eye = jnp.eye(h * w, dtype=jnp.float32).reshape(h * w, h, w)
    approx, details = dwt2(eye, levels, wavelet)
    parts = [approx.reshape(h * w, -1)] + [d.reshape(h * w, -1) for lvl in details for d in lvl]
    return np.asarray(jnp.concatenate(parts, axis=1)).T


@pytest.mark.parametrize("wavelet", WAVELETS)
def test_perfect_reconstruction_and_parseval(wavelet):
    x = jnp.asarray(np.random.default_rng(0).normal(2.0, 1.0, (2, 16, 24)), jnp.float32)
    approx, details = dwt2(x, 3, wavelet)
    assert approx.shape == (2, 2, 3) and [d[0].shape for d in details] == [(2, 8, 12), (2, 4, 6), (2, 2, 3)]
    np.testing.assert_allclose(idwt2(approx, details, wavelet), x, atol=1e-5)
    energy = jnp.sum(approx**2) + sum(jnp.sum(c**2) for lvl in details for c in lvl)
    np.testing.assert_allclose(energy, jnp.sum(x**2), rtol=1e-5)


@pytest.mark.parametrize("wavelet", WAVELETS)
def test_transform_is_orthonormal(wavelet):
    w = transform_matrix((8, 8), 3, wavelet)
    np.testing.assert_allclose(w @ w.T, np.eye(64), atol=1e-5)
    np.testing.assert_allclose(w.T @ w, np.eye(64), atol=1e-5)


def test_haar_one_level_by_hand():
    a, b, c, d = 1.0, 2.0, 3.0, 5.0
    approx, [(lh, hl, hh)] = dwt2(jnp.array([[a, b], [c, d]]), 1, "haar")
    assert float(approx[0, 0]) == pytest.approx((a + b + c + d) / 2)
    assert float(lh[0, 0]) == pytest.approx((a - b + c - d) / 2)  # horizontal differences
    assert float(hl[0, 0]) == pytest.approx((a + b - c - d) / 2)  # vertical differences
    assert float(hh[0, 0]) == pytest.approx((a - b - c + d) / 2)


def test_soft_threshold_values():
    np.testing.assert_allclose(soft_threshold(jnp.array([-3.0, -0.5, 0.0, 0.5, 2.0]), 1.0), [-2.0, 0, 0, 0, 1.0])


def _brute_force_prox(v: np.ndarray, tau: float, wd: np.ndarray) -> np.ndarray:
    """argmin_z 1/2||z - v||^2 + tau ||wd z||_1 as a smooth QP: wd z = p - q, p, q >= 0, via SLSQP."""
    n, m = v.size, wd.shape[0]

    def f(u):
        z, p, q = u[:n], u[n : n + m], u[n + m :]
        return 0.5 * np.sum((z - v) ** 2) + tau * np.sum(p + q)

    def grad(u):
        return np.concatenate([u[:n] - v, np.full(2 * m, tau)])

    cons = {"type": "eq", "fun": lambda u: wd @ u[:n] - u[n : n + m] + u[n + m :],
            "jac": lambda u: np.hstack([wd, -np.eye(m), np.eye(m)])}
    u0 = np.concatenate([v, np.maximum(wd @ v, 0), np.maximum(-wd @ v, 0)])
    bounds = [(None, None)] * n + [(0, None)] * (2 * m)
    res = optimize.minimize(f, u0, jac=grad, constraints=[cons], bounds=bounds, method="SLSQP",
                            options={"ftol": 1e-12, "maxiter": 500})
    assert res.success, res.message
    return res.x[:n]


@pytest.mark.parametrize("wavelet,levels", [("haar", 2), ("db2", 1)])
def test_shrink_is_the_exact_prox_brute_force(wavelet, levels):
    v = np.random.default_rng(1).normal(3.0, 1.0, (4, 4))
    tau = 0.4
    w = transform_matrix((4, 4), levels, wavelet).astype(np.float64)
    n_approx = (4 // 2**levels) ** 2
    wd = w[n_approx:]  # detail rows only: the approximation is not penalised
    expected = _brute_force_prox(v.ravel(), tau, wd).reshape(4, 4)
    z = WaveletPrior(levels=levels, wavelet=wavelet).apply({"threshold": tau}, jnp.asarray(v, jnp.float32)[None])[0]
    np.testing.assert_allclose(z, expected, atol=1e-4)


@pytest.mark.parametrize("wavelet", WAVELETS)
def test_prox_optimality_conditions(wavelet):
    # z = prox(v) iff v - z is a subgradient of tau||W_d z||_1: W(v - z) is 0 on the approximation, tau sign(c)
    # on nonzero detail coefficients c of W z, and within [-tau, tau] on zero ones.
    rng = np.random.default_rng(2)
    v = rng.normal(5.0, 1.0, (8, 8)).astype(np.float32)
    tau, levels = 0.3, 2
    z = np.asarray(wavelet_shrink(jnp.asarray(v), tau, levels, wavelet), np.float64)
    w = transform_matrix((8, 8), levels, wavelet).astype(np.float64)
    r, c = w @ (v.ravel() - z.ravel()), w @ z.ravel()
    na = 4
    np.testing.assert_allclose(r[:na], 0, atol=1e-5)
    rd, cd = r[na:], c[na:]
    nz = np.abs(cd) > 1e-5
    assert nz.any() and (~nz).any()
    np.testing.assert_allclose(rd[nz], tau * np.sign(cd[nz]), atol=1e-5)
    assert np.all(np.abs(rd[~nz]) <= tau + 1e-5)


@pytest.mark.parametrize("wavelet", WAVELETS)
@pytest.mark.parametrize("shifts", [1, 3])
def test_threshold_zero_is_identity_any_shape(wavelet, shifts):
    v = jnp.asarray(np.random.default_rng(3).uniform(1, 9, (2, 13, 21)), jnp.float32)  # not multiples of 2^3
    z = WaveletPrior(levels=3, wavelet=wavelet, shifts=shifts).apply({"threshold": 0.0}, v, None)
    assert z.shape == v.shape and z.dtype == jnp.float32
    np.testing.assert_allclose(z, v, atol=1e-5)


def test_infinite_threshold_keeps_block_means():
    v = np.random.default_rng(4).uniform(1, 9, (1, 8, 12)).astype(np.float32)
    z = np.asarray(WaveletPrior(levels=2).apply({"threshold": 1e6}, jnp.asarray(v)))
    means = v.reshape(1, 2, 4, 3, 4).mean(axis=(2, 4))
    np.testing.assert_allclose(z, np.repeat(np.repeat(means, 4, 1), 4, 2), atol=1e-5)


def test_prior_protocol_init_jit_and_rgb_ignored():
    prior = WaveletPrior(levels=2, threshold_m=0.07)
    params = prior.init(jax.random.PRNGKey(0), (10, 14))
    assert set(params) == {"threshold"} and float(params["threshold"]) == pytest.approx(0.07)
    v = jnp.asarray(np.random.default_rng(5).uniform(1, 3, (2, 10, 14)), jnp.float32)
    rgb = jnp.zeros((2, 10, 14, 3))
    z = jax.jit(prior.apply)(params, v, rgb)
    np.testing.assert_allclose(z, prior.apply(params, v, rgb + 0.5), atol=1e-6)
    assert not np.allclose(z, v)
    # negative thresholds act as zero
    np.testing.assert_allclose(prior.apply({"threshold": -1.0}, v, rgb), v, atol=1e-5)
    with pytest.raises(ValueError):
        WaveletPrior(wavelet="sym8")
    with pytest.raises(ValueError):
        WaveletPrior(levels=2, shifts=5)


def test_cycle_spinning_reduces_blocky_error_when_denoising():
    h, w = 64, 64
    yy, xx = np.mgrid[0:h, 0:w]
    clean = (2 + 0.03 * xx + 0.02 * yy + 1.0 * ((xx - 30) ** 2 + (yy - 34) ** 2 < 200)).astype(np.float32)
    noisy = clean + np.random.default_rng(0).normal(0, 0.1, clean.shape).astype(np.float32)

    def rmse(shifts):
        z = WaveletPrior(levels=3, shifts=shifts).apply({"threshold": 0.2}, jnp.asarray(noisy)[None])[0]
        return float(np.sqrt(np.mean((np.asarray(z) - clean) ** 2)))

    assert rmse(4) < 0.8 * rmse(1) < 0.8 * 0.1  # both denoise; spinning by a further >= 20 %
    assert cycle_offsets(4, 3) == [0, 2, 4, 6] and cycle_offsets(1, 3) == [0]
