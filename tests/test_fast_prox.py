"""The fast prox (lipjax.priors.fast): identity at init, scale equivariance, encoder run once."""
import dataclasses

import flax.linen as nn
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from lipjax import model as lip_model
from lipjax import model_io
from lipjax.priors.fast import (PRESETS, DepthBranch, GuidanceEncoder, FastPrior, depth_to_space, sample_scale,
                                  space_to_depth)

TINY = PRESETS["tiny"]


def _scramble(params, key=1, scale=0.3):
    """Non-zero weights everywhere (the zero head would make every prox the identity)."""
    leaves, tree = jax.tree_util.tree_flatten(params)
    keys = jax.random.split(jax.random.key(key), len(leaves))
    return jax.tree_util.tree_unflatten(tree, [scale * jax.random.normal(k, a.shape) for k, a in zip(keys, leaves)])


def _frame(rng, shape=(2, 20, 28), n=30):
    sparse = np.zeros(shape, np.float32)
    for b in range(shape[0]):
        idx = rng.choice(shape[1] * shape[2], n, replace=False)
        sparse[b].reshape(-1)[idx] = rng.uniform(1.0, 6.0, n)
    rgb = rng.integers(0, 256, (*shape, 3), dtype=np.uint8)
    return rgb, sparse


def test_space_to_depth_round_trip_and_layout():
    a = jnp.arange(2 * 4 * 6 * 3, dtype=jnp.float32).reshape(2, 4, 6, 3)
    s = space_to_depth(a)
    assert s.shape == (2, 2, 3, 12)
    np.testing.assert_array_equal(s[0, 0, 0, :3], a[0, 0, 0])  # top-left pixel of the first 2x2 block
    np.testing.assert_array_equal(s[0, 0, 0, 9:], a[0, 1, 1])  # bottom-right pixel of the same block
    np.testing.assert_array_equal(depth_to_space(s), a)


class _ReferenceEncoder(nn.Module):
    """GuidanceEncoder as first written (nn.Conv + nn.GroupNorm), as the trained weights were fitted."""

    widths: tuple

    @nn.compact
    def __call__(self, guidance):
        block = lambda h, c, s=1: nn.relu(nn.GroupNorm(min(8, c))(nn.Conv(c, (3, 3), strides=s)(h)))  # noqa: E731
        f1 = block(block(space_to_depth(guidance - 0.5), self.widths[0]), self.widths[0])
        f2 = block(block(f1, self.widths[1], 2), self.widths[1])
        return f1, f2, block(block(f2, self.widths[2], 2), self.widths[2])


class _ReferenceBranch(nn.Module):
    """DepthBranch as first written: nearest upsampling, concatenation, then the convolution."""

    widths: tuple

    @nn.compact
    def __call__(self, d, features):
        block = lambda h, c, s=1: nn.relu(nn.GroupNorm(min(8, c))(nn.Conv(c, (3, 3), strides=s)(h)))  # noqa: E731
        up = lambda h: jnp.repeat(jnp.repeat(h, 2, axis=1), 2, axis=2)  # noqa: E731
        (f1, f2, f3), (w1, w2, w3) = features, self.widths
        h1 = block(jnp.concatenate([space_to_depth(d[..., None]), f1], axis=-1), w1)
        h2 = block(block(h1, w2, 2) + f2, w2)
        h3 = block(block(h2, w3, 2) + f3, w3)
        u2 = block(jnp.concatenate([up(h3), h2], axis=-1), w2)
        u1 = block(jnp.concatenate([up(u2), h1], axis=-1), w1)
        return depth_to_space(nn.Conv(4, (3, 3), kernel_init=nn.initializers.zeros)(u1))[..., 0]


@pytest.mark.parametrize("widths", [((8, 16, 16), (8, 16, 16)), ((32, 48, 64), (24, 48, 64))], ids=["small", "fast"])
def test_encoder_and_branch_equal_the_nn_conv_groupnorm_formulation(widths):
    """Folded GroupNorm bias and upsampling convolutions at low resolution: the same parameter tree (names, shapes
    and initial values) and the same outputs as nn.Conv + nn.GroupNorm on the upsampled, concatenated maps."""
    rng = np.random.default_rng(0)
    g = jnp.asarray(rng.random((2, 24, 40, 5)), jnp.float32)
    d = jnp.asarray(rng.normal(0, 0.5, (2, 24, 40)), jnp.float32)

    def check(new, ref, *args):
        params = ref.init(jax.random.key(0), *args)["params"]
        np.testing.assert_equal(jax.tree_util.tree_map(np.asarray, new.init(jax.random.key(0), *args)["params"]),
                                jax.tree_util.tree_map(np.asarray, params))
        params = _scramble(params)  # a non-zero head, non-trivial GroupNorm scales and biases
        out, expected = (jax.jit(m.apply)({"params": params}, *args) for m in (new, ref))
        for a, b in zip(jax.tree_util.tree_leaves(out), jax.tree_util.tree_leaves(expected), strict=True):
            np.testing.assert_allclose(a, b, rtol=1e-4, atol=1e-5 * float(np.abs(b).max()))
        # and the same gradients, for training (relative to the largest: some are zero up to rounding)
        def grads(m):
            def loss(p):
                return sum((a**2).mean() for a in jax.tree_util.tree_leaves(m.apply({"params": p}, *args)))

            return jax.tree_util.tree_leaves(jax.jit(jax.grad(loss))(params))

        expected = grads(ref)
        scale = max(float(np.abs(b).max()) for b in expected)
        for a, b in zip(grads(new), expected, strict=True):
            np.testing.assert_allclose(a, b, rtol=1e-3, atol=1e-5 * scale)
        return params

    encoder_params = check(GuidanceEncoder(widths[0]), _ReferenceEncoder(widths[0]), g)
    features = _ReferenceEncoder(widths[0]).apply({"params": encoder_params}, g)
    check(DepthBranch(widths[1]), _ReferenceBranch(widths[1]), d, features)


def test_the_upsampling_convolution_and_its_gradient_are_those_of_upsample_then_convolve():
    """_upsampled_conv (phase form forward, the plain form's gradient, a custom VJP) equals upsample2 then a 3x3
    convolution, and its gradient in both arguments matches finite differences."""
    from jax.test_util import check_grads

    from lipjax.priors.fast import _conv, _upsampled_conv

    rng = np.random.default_rng(3)
    low = jnp.asarray(rng.normal(size=(2, 5, 7, 3)), jnp.float32)
    kernel = jnp.asarray(rng.normal(size=(3, 3, 3, 4)) * 0.3, low.dtype)
    plain = _conv(jnp.repeat(jnp.repeat(low, 2, axis=1), 2, axis=2), kernel)
    np.testing.assert_allclose(_upsampled_conv(low, kernel), plain, rtol=1e-5, atol=1e-5)
    check_grads(_upsampled_conv, (low, kernel), order=1, modes=["rev"], atol=2e-2, rtol=2e-2)  # float32 steps
    weights = jnp.asarray(rng.normal(size=plain.shape), low.dtype)
    got = jax.grad(lambda a, k: (_upsampled_conv(a, k) * weights).sum(), argnums=(0, 1))(low, kernel)
    want = jax.grad(lambda a, k: (_conv(jnp.repeat(jnp.repeat(a, 2, axis=1), 2, axis=2), k) * weights).sum(),
                    argnums=(0, 1))(low, kernel)
    for a, b in zip(got, want):
        np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-5)
    # the gradient in `low` sums each 2x2 block's: a linear map's adjoint, checked by <Ax, y> = <x, A* y>
    np.testing.assert_allclose((plain * weights).sum(), (got[0] * low).sum(), rtol=1e-4)


@dataclasses.dataclass(frozen=True)
class _ReferencePrior(FastPrior):
    def _encoder(self):
        return _ReferenceEncoder(tuple(self.encoder_widths))

    def _branch(self):
        return _ReferenceBranch(tuple(self.branch_widths))


def test_shipped_model_gives_the_depth_of_the_formulation_it_was_trained_in():
    """lip-fast-indoor's weights at its 128x160 training crop size: the same depth (within 1e-4 m) as through nn.Conv +
    nn.GroupNorm."""
    config, params, _ = model_io.load("lip-fast-indoor")
    reference = dataclasses.replace(config, prior=_ReferencePrior(**dataclasses.asdict(config.prior)))
    rng = np.random.default_rng(0)
    yy, xx = np.mgrid[0:128, 0:160]
    depth = 2.0 + 0.02 * xx + 0.008 * yy  # a slanted wall with a box in front of it
    depth[40:90, 50:110] = 1.3
    rgb = np.clip(40 * depth[..., None] + rng.normal(0, 8, (128, 160, 3)), 0, 255).astype(np.uint8)
    sparse = np.zeros((1, 128, 160), np.float32)
    idx = rng.choice(128 * 160, 100, replace=False)
    sparse.reshape(-1)[idx] = depth.reshape(-1)[idx]
    z0 = config.host_inputs(sparse)["z0"]
    out, expected = (np.asarray(jax.jit(lambda p, c=c: c.apply(p, rgb[None], sparse, z0=z0)[0])(params))
                     for c in (config, reference))
    np.testing.assert_allclose(out, expected, rtol=0, atol=1e-4)
    assert np.abs(out - z0).max() > 0.05  # the trained prox does change the fill


def test_sample_scale_is_the_geometric_mean_of_the_samples():
    y = jnp.asarray([[[0.0, 2.0], [8.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]]])
    s = sample_scale(y, (y > 0).astype(jnp.float32))
    np.testing.assert_allclose(s[:, 0, 0], [4.0, 1.0], rtol=1e-6)  # sqrt(2 * 8); no samples -> 1 m


@pytest.mark.parametrize("shape", [(13, 21), (16, 24)])
def test_untrained_prox_is_identity_at_any_size(shape):
    rng = np.random.default_rng(0)
    v = jnp.asarray(rng.uniform(0.5, 9.0, (2, *shape)), jnp.float32)
    g = jnp.asarray(rng.random((2, *shape, 5)), jnp.float32)
    enc = TINY.init_encoder(jax.random.key(0), guidance_channels=5)
    params = TINY.init(jax.random.key(1), guidance_channels=5)
    features = TINY.encode(enc, g, v, jnp.ones_like(v))
    z = jax.jit(TINY.apply)(params, v, features)
    assert z.shape == v.shape
    np.testing.assert_allclose(z, v, rtol=1e-6)


def _model(initial_estimate="linear", output="z"):
    return lip_model.LIPConfig(prior=TINY, num_iterations=2, initial_estimate=initial_estimate, output=output)


def test_lip_model_is_scale_equivariant():
    """Input relative to the samples' scale and a relative correction: depth x c in gives depth x c out."""
    config = _model()
    params = _scramble(config.init(jax.random.key(0)))
    params["log_rho"] = jnp.log(jnp.asarray([0.1, 0.2]))
    rgb, sparse = _frame(np.random.default_rng(0))
    run = jax.jit(lambda p, r, s, z0: config.apply(p, r, s, z0=z0)[0])
    base = np.asarray(run(params, rgb, sparse, config.host_inputs(sparse)["z0"]))
    for c in (0.1, 8.5):
        scaled = np.asarray(run(params, rgb, c * sparse, config.host_inputs(c * sparse)["z0"]))
        np.testing.assert_allclose(scaled, c * base, rtol=2e-4)
    assert np.abs(base - config.host_inputs(sparse)["z0"]).max() > 1e-3  # the scrambled prox does change the fill


def test_output_is_positive_for_any_weights_and_inputs():
    config = _model(initial_estimate="sparse")
    params = _scramble(config.init(jax.random.key(0)), scale=3.0)
    rgb, sparse = _frame(np.random.default_rng(1))
    out = np.asarray(jax.jit(lambda p, r, s: config.apply(p, r, s)[0])(params, rgb, sparse))
    assert np.isfinite(out).all() and (out > 0).all()


def test_encoder_is_shared_and_runs_once_per_frame():
    config = _model()
    params = config.init(jax.random.key(0))
    assert set(params) == {"prox", "guidance_encoder", "log_rho"}
    # per-iteration branches are stacked on a leading axis of size K; the encoder is not
    assert all(a.shape[0] == 2 for a in jax.tree_util.tree_leaves(params["prox"]))
    rgb, sparse = _frame(np.random.default_rng(2))
    z0 = config.host_inputs(sparse)["z0"]
    closed = jax.make_jaxpr(lambda p: config.apply(p, rgb, sparse, z0=z0)[0])(params)
    scans = [e for e in closed.jaxpr.eqns if e.primitive.name == "scan"]
    assert len(scans) == 1
    in_loop = str(scans[0].params["jaxpr"]).count("conv_general_dilated")
    total = str(closed).count("conv_general_dilated")
    n_enc = sum(1 for a in jax.tree_util.tree_leaves(params["guidance_encoder"]) if a.ndim == 4)  # conv kernels
    n_branch = sum(1 for a in jax.tree_util.tree_leaves(params["prox"]) if a.ndim == 5)  # (K, kh, kw, in, out)
    # the loop body holds one depth branch and no encoder; its two upsampling layers run as two convolutions each
    assert in_loop == n_branch + 2
    assert total - in_loop == n_enc  # the encoder runs once, outside the loop


def test_fast_prox_model_survives_a_model_file(tmp_path):
    config = _model()
    params = _scramble(config.init(jax.random.key(0)))
    model_io.save(tmp_path / "m", config, params)
    config2, params2, _ = model_io.load(tmp_path / "m")
    assert config2 == config
    rgb, sparse = _frame(np.random.default_rng(3))
    z0 = config.host_inputs(sparse)["z0"]
    a = config.apply(params, rgb, sparse, z0=z0)[0]
    b = config2.apply(params2, rgb, sparse, z0=z0)[0]
    np.testing.assert_array_equal(a, b)


def test_a_model_file_naming_the_fast_prox_guided_as_before_loads_as_the_fast_prox():
    """Files written before the fast prox's type was "fast" name it "guided" (model_io.RENAMED_PRIOR_TYPES)."""
    config = _model()
    old = model_io.config_to_dict(config) | {"prior_type": "guided"}
    assert model_io.config_to_dict(config)["prior_type"] == "fast"
    assert model_io.config_from_dict(old) == config


def test_bad_widths_are_clear_errors():
    with pytest.raises(ValueError, match="3 widths"):
        FastPrior(encoder_widths=(8, 8))
    with pytest.raises(ValueError, match="must agree"):
        dataclasses.replace(TINY, branch_widths=(4, 16, 8))
