"""End-to-end learned baselines (Ma et al., U-Net, CSPN): preset sizes, any input size, model files, CSPN's
propagation maths, one training step through the shared train loop, and the baseline training configs.

Compile-bound: every network test uses the "tiny" presets on one small odd-sized batch, through one module-level
jitted forward, so that each network compiles once for the whole file.
"""
import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import lipjax
from lipjax import model_io
from lipjax.interfaces import MODEL_TYPES
from lipjax.networks import (
    CSPN,
    PRESETS,
    SparseToDense,
    UNet,
    baseline_preset,
    normalize_affinity,
    propagate,
)
from lipjax.train.config import DataConfig, TrainConfig
from lipjax.train.state import init_state
from lipjax.train.steps import make_steps

from helpers import conv_params, up_projection_params

EXPECTED_PARAMETERS = {  # as counted_by_hand derives them from each architecture
    ("sparse_to_dense", "paper"): 14_644_257,
    ("sparse_to_dense", "small"): 1_553_369,
    ("sparse_to_dense", "tiny"): 133_305,
    ("unet", "paper"): 31_041_089,
    ("unet", "small"): 1_488_439,
    ("unet", "tiny"): 122_309,
    ("cspn", "paper"): 31_046_217,
    ("cspn", "small"): 1_489_567,
    ("cspn", "tiny"): 122_637,
}
SHAPE = (2, 21, 37)  # odd on purpose: not a multiple of any network's downsampling


_forward = jax.jit(lambda config, params, rgb, sparse: config.apply(params, rgb, sparse)[0], static_argnums=0)


def _inputs(shape=SHAPE, seed=0):
    rng = np.random.default_rng(seed)
    rgb = rng.integers(0, 256, (*shape, 3), dtype=np.uint8)
    sparse = np.where(rng.random(shape) < 0.1, rng.uniform(0.5, 9.0, shape), 0.0).astype(np.float32)
    return rgb, sparse


def _tiny(name):
    config = baseline_preset(name, "tiny")
    return config, config.init(jax.random.key(0))


def _double_conv(a, c):  # U-Net: two bias-free 3x3 convolutions, each GroupNorm-ed (2c)
    return conv_params(3, a, c, False) + 2 * c + conv_params(3, c, c, False) + 2 * c


def _unet_body(base, levels):  # RGB-D in (4 channels); down, bottom, then 1x1 up-convolutions to 4c + skip concat
    widths = [base * 2**level for level in range(levels + 1)]
    down = sum(_double_conv(a, c) for a, c in zip([4] + widths, widths))
    up = sum(conv_params(1, widths[level + 1], 4 * widths[level]) + _double_conv(2 * widths[level], widths[level])
             for level in range(levels))
    return down + up


def _sparse_to_dense(w, blocks):  # ResNet (basic blocks, bias-free, projection shortcuts) + up-projections
    count = conv_params(7, 4, w, False) + 2 * w
    for stage, n in enumerate(blocks):
        c = w * 2**stage
        for i in range(n):
            a = c // 2 if i == 0 and stage > 0 else c
            count += conv_params(3, a, c, False) + 2 * c + conv_params(3, c, c, False) + 2 * c
            count += conv_params(1, a, c, False) + 2 * c if a != c else 0
    count += conv_params(1, 8 * w, 4 * w, False) + 2 * 4 * w
    for a in (4 * w, 2 * w, w, w // 2):  # lipjax.priors.network.UpProjection to a // 2 channels
        count += up_projection_params(a, a // 2)
    return count + conv_params(3, w // 4, 1)


def counted_by_hand(model: str, config) -> int:
    """A baseline's parameters from its architecture (lipjax.networks), GroupNorm of c channels 2c."""
    if model == "sparse_to_dense":
        return _sparse_to_dense(config.width, config.blocks)
    head = conv_params(1, config.base_width, 1) if model == "unet" else (  # CSPN: depth + 8 affinities, 3x3 each
        conv_params(3, config.base_width, 1) + conv_params(3, config.base_width, 8))
    return _unet_body(config.base_width, config.levels) + head


@pytest.mark.parametrize("model,size", sorted(EXPECTED_PARAMETERS))
def test_preset_parameter_counts(model, size):
    config = PRESETS[model][size]
    shapes = jax.eval_shape(config.init, jax.random.key(0))  # shapes only: no compile, no compute
    assert config.parameter_count(shapes) == counted_by_hand(model, config) == EXPECTED_PARAMETERS[(model, size)]


def test_small_presets_are_about_the_size_of_lip_small_over_three_iterations():
    lip = lipjax.LIPConfig()  # small prior, K = 3
    lip_count = lip.parameter_count(jax.eval_shape(lip.init, jax.random.key(0)))
    for model in PRESETS:
        assert abs(EXPECTED_PARAMETERS[(model, "small")] / lip_count - 1) < 0.1, model


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_output_has_input_size_is_finite_and_survives_a_model_file(name, tmp_path):
    config, params = _tiny(name)
    rgb, sparse = _inputs()
    depth = np.asarray(_forward(config, params, rgb, sparse))
    assert depth.shape == SHAPE
    assert np.isfinite(depth).all()
    assert np.abs(depth[0] - depth[1]).max() > 1e-6  # the output follows the input (two frames, two depths)
    alone = np.asarray(_forward(config, params, rgb[1:], sparse[1:]))[0]  # no statistics shared across the batch
    np.testing.assert_allclose(alone, depth[1], rtol=1e-4, atol=1e-5 * float(np.abs(depth).max()))

    model_io.save(tmp_path / name, config, params, {"note": "test"})
    loaded = lipjax.load_model(tmp_path / name)
    assert type(loaded.config) is MODEL_TYPES[name] and loaded.config == config
    assert loaded.parameter_count() == config.parameter_count(params)
    np.testing.assert_array_equal(np.asarray(_forward(loaded.config, loaded.params, rgb, sparse)), depth)


def test_cspn_output_equals_the_sparse_input_exactly_on_measured_pixels():
    config, params = _tiny("cspn")
    rgb, sparse = _inputs()
    depth = np.asarray(_forward(config, params, rgb, sparse))  # same shapes as above: no new compile
    measured = sparse > 0
    np.testing.assert_array_equal(depth[measured], sparse[measured])
    assert not np.allclose(depth[~measured], 0.0)


def test_cspn_propagation_preserves_constants_for_any_affinities():
    rng = np.random.default_rng(1)
    raw = jnp.asarray(rng.normal(size=(2, 9, 11, 8)) * rng.uniform(0.01, 100.0, (2, 9, 11, 1)), jnp.float32)
    h0 = jnp.full((2, 9, 11), 3.7, jnp.float32)
    no_samples = jnp.zeros((2, 9, 11), bool)
    h = propagate(h0, raw, jnp.zeros_like(h0), no_samples, iterations=6)
    np.testing.assert_allclose(h, 3.7, rtol=1e-5)
    kappa, centre = normalize_affinity(raw)
    assert float(jnp.abs(kappa).sum(-1).max()) <= 1.0 + 1e-6  # the stability normalisation
    np.testing.assert_allclose(centre + kappa.sum(-1), 1.0, atol=1e-6)


def test_cspn_propagation_with_positive_affinities_is_a_local_convex_smoothing_that_keeps_samples():
    rng = np.random.default_rng(2)
    raw = jnp.asarray(rng.uniform(0.0, 1.0, (1, 11, 13, 8)), jnp.float32)  # kappa >= 0 and centre >= 0: convex
    mask = jnp.zeros((1, 11, 13), bool).at[0, 5, 6].set(True)
    sparse = jnp.zeros((1, 11, 13), jnp.float32).at[0, 5, 6].set(9.0)
    h0 = jnp.asarray(rng.uniform(1.0, 5.0, (1, 11, 13)), jnp.float32)
    h = np.asarray(propagate(h0, raw, sparse, mask, iterations=3))
    assert h[0, 5, 6] == 9.0
    assert h[~np.asarray(mask)].min() >= 1.0 - 1e-5 and h.max() <= 9.0  # within the range of h0 and the sample
    assert np.abs(h - np.asarray(h0)).max() > 1e-3  # it does propagate
    # From a flat map, the sample raises its neighbours, and reaches exactly T = 3 pixels (3x3 kernel) in 3 steps.
    h = np.asarray(propagate(jnp.full_like(h0, 2.0), raw, sparse, mask, iterations=3))[0]
    dist = np.maximum(*np.abs(np.mgrid[:11, :13] - np.array([5, 6])[:, None, None]))
    assert (h[(dist >= 1) & (dist <= 3)] > 2.0).all()
    np.testing.assert_allclose(h[dist > 3], 2.0, rtol=1e-6)


def test_one_supervised_train_step_through_the_shared_train_loop():
    model = baseline_preset("unet", "tiny")
    config = TrainConfig(name="baseline-step", model=model,
                         data=DataConfig(kind="indoor", height=32, width=40, crop=None, num_workers=0),
                         batch_size=2, g_steps=2, warmup_steps=1)
    rng = np.random.default_rng(3)
    rgb, sparse = _inputs((2, 32, 40))
    gt = rng.uniform(0.5, 9.0, (2, 32, 40)).astype(np.float32)
    batch = {"rgb": rgb, "sparse": sparse, "gt": gt, "gt_valid": gt > 1.0}
    state = init_state(config)
    before = jax.tree_util.tree_map(np.array, state.g_params)
    step = make_steps(config).supervised
    losses, params = [], []
    for _ in range(2):  # the warm-up schedule starts at learning rate 0: the first step moves nothing
        state, metrics = step(state, batch, jax.random.key(0))
        losses.append(float(metrics["loss"]))
        params.append(jax.tree_util.tree_leaves(jax.tree_util.tree_map(np.array, state.g_params)))
    assert np.isfinite(losses).all() and losses[0] > 0
    before = jax.tree_util.tree_leaves(before)
    assert all(np.array_equal(a, b) for a, b in zip(before, params[0], strict=True))
    assert any(not np.array_equal(a, b) for a, b in zip(before, params[1], strict=True))
    assert int(state.step) == 2


def test_presets_by_name_and_invalid_configs_are_clear_errors():
    assert baseline_preset("unet", "small", max_depth_m=85.0) == UNet(base_width=14, max_depth_m=85.0)
    assert baseline_preset("cspn", "tiny") == PRESETS["cspn"]["tiny"]
    with pytest.raises(ValueError, match="decoder widths"):
        SparseToDense(width_multiplier=0.375)
    with pytest.raises(ValueError, match="max_depth_m"):
        UNet(max_depth_m=0.0)
    with pytest.raises(ValueError, match="iterations"):
        CSPN(iterations=-1)
    with pytest.raises(ValueError, match="unknown preset 'huge'"):
        baseline_preset("unet", "huge")


def test_baseline_training_configs_copy_the_lip_runs():
    from experiments import configs
    from experiments.configs import BASELINE_CONFIGS

    assert sorted(BASELINE_CONFIGS) == sorted(f"{m}_{s}" for m in ("ma2018", "unet", "cspn")
                                              for s in ("indoor", "outdoor"))
    for key, config in BASELINE_CONFIGS.items():
        scene = key.split("_")[1]
        lip = configs.LIP_CNN_INDOOR if scene == "indoor" else configs.LIP_CNN_OUTDOOR
        assert config.name == key.replace("_", "-")
        # only name, model and the study's tuned learning rate differ, and the end-to-end networks train
        # without the inverse-depth term
        assert config.inverse_depth_weight == 0.0
        same = dataclasses.replace(config, name=lip.name, model=lip.model, learning_rate=lip.learning_rate,
                                   inverse_depth_weight=lip.inverse_depth_weight)
        assert same == lip
        assert config.model.max_depth_m == lip.model.max_depth_m
        assert model_io.config_from_dict(model_io.config_to_dict(config.model)) == config.model
        assert config.total_steps == config.g_steps and not config.iteration_weights  # supervised only, no trajectory
