"""The ONNX export (lipjax.onnx_export, lipjax.jaxpr_to_onnx): under onnxruntime it computes what JAX computes,
primitive by primitive and for a whole model, and equals `lipjax.complete` wherever the fill in its graph is the
model's own (and the default path's check against the linear fill does not run: scan lines, or under 100 samples)."""
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import lipjax
from lipjax import jaxpr_to_onnx
from lipjax.inputs import is_lidar_pattern
from lipjax.model import LIPConfig
from lipjax.onnx_export import (export_onnx, export_working_size, inference_graph, nearest_twin, samples_interval)
from lipjax.priors.fast import PRESETS
from lipjax.resolution import DENSE, MAX_WORKING_PIXELS, working_size

from helpers import perturbed

pytest.importorskip("onnx")
ort = pytest.importorskip("onnxruntime")


def _run_onnx(model_or_path, **inputs):
    data = model_or_path if isinstance(model_or_path, str) else model_or_path.SerializeToString()
    return ort.InferenceSession(data, providers=["CPUExecutionProvider"]).run(None, inputs)


def _kitchen_sink(x, u8, idx):
    """Most primitives lipjax.jaxpr_to_onnx translates, on (2, 12, 10, 3) float32, uint8 and int32 inputs."""
    y = jnp.tanh(x) * jax.nn.sigmoid(x) - jnp.abs(x) / (1.0 + x**2) + jnp.floor(3 * x) + jnp.round(4.5 * x)
    y = jnp.where(jnp.isfinite(1.0 / x) & (x > 0.1), jnp.sqrt(jnp.abs(x)), jax.lax.rsqrt(1.0 + x**4)) + y
    y = jnp.clip(y, -2.0, 2.0) + jnp.cumsum(x, axis=1) + jnp.square(x) - jnp.log1p(x**2)
    y = y + jnp.maximum(x, 0.3) + jnp.minimum(x, -0.2)
    kernel = jnp.asarray(np.random.default_rng(0).standard_normal((3, 3, 3, 4)), jnp.float32)
    conv = jax.lax.conv_general_dilated(y, kernel, (2, 1), "SAME", rhs_dilation=(1, 2),
                                        dimension_numbers=("NHWC", "HWIO", "NHWC"))
    win = jax.lax.reduce_window(u8, np.uint8(0), jax.lax.max, (1, 3, 1, 1), (1, 1, 1, 1),
                                ((0, 0), (2, 2), (0, 0), (0, 0)), window_dilation=(1, 2, 1, 1))
    taken = jnp.take(y, idx, axis=2)  # (2, 12, 5, 3)
    padded = jax.lax.pad(y, 0.5, ((0, 0, 0), (2, -3, 0), (-1, 1, 0), (0, 0, 0)))
    stacked = jnp.stack([y[:, ::3].sum(axis=(1, 2)), y.max(axis=(1, 2)), y.min(axis=(1, 2))], axis=-1)
    mat = jnp.einsum("bhwc,cd->bhwd", y, kernel[0, 0]) @ jnp.ones((4, 2))
    return (conv.transpose(0, 3, 1, 2).reshape(2, -1).sum(axis=1) + stacked.sum(axis=(1, 2)),
            win.astype(jnp.float32) + (u8 > 100), jnp.concatenate([taken, padded[:, :, :5]], axis=1),
            mat + jnp.flip(mat, axis=(1, 2)), jnp.argmax(y, axis=2).astype(jnp.float32))


def test_each_primitive_computes_what_jax_computes():
    rng = np.random.default_rng(0)
    x = rng.normal(size=(2, 12, 10, 3)).astype(np.float32)
    u8 = rng.integers(0, 256, x.shape, dtype=np.uint8)
    idx = np.array([9, 0, 3, 3, 5], np.int32)
    names = ["x", "u8", "idx"]
    specs = [jax.ShapeDtypeStruct(a.shape, a.dtype) for a in (x, u8, idx)]
    model = jaxpr_to_onnx.convert(_kitchen_sink, specs, names, [f"o{i}" for i in range(5)])
    for got, expected in zip(_run_onnx(model, x=x, u8=u8, idx=idx), jax.jit(_kitchen_sink)(x, u8, idx)):
        np.testing.assert_allclose(got, np.asarray(expected), rtol=1e-5, atol=1e-5)


def test_an_untranslated_primitive_is_a_one_line_error():
    with pytest.raises(NotImplementedError, match="jax primitive 'sort' has no ONNX translation"):
        jaxpr_to_onnx.convert(jnp.sort, [jax.ShapeDtypeStruct((4,), jnp.float32)], ["x"], ["y"])


def test_the_working_size_is_fixed_from_the_sample_count_for_an_interval_of_counts():
    size = export_working_size(352, 1216, 20000)  # a 64-beam scan: the scan lines' pixel cap decides
    assert size == working_size((352, 1216), math.sqrt(352 * 1216 / 20000), capped=True)
    assert size[0] * size[1] == pytest.approx(MAX_WORKING_PIXELS, rel=0.01)
    lo, hi = samples_interval(352, 1216, 20000)
    assert hi == 352 * 1216 and 1 < lo < 20000 and export_working_size(352, 1216, lo) == size
    assert export_working_size(352, 1216, lo - 1) != size
    # as many scattered points: no cap, the full size, for every count whose spacing is under about 22 px, up to
    # DENSE samples a pixel; a dense map beyond that is capped as scan lines are (docs/decisions/0017)
    assert export_working_size(352, 1216, 20000, scan_lines=False) == (352, 1216)
    lo, hi = samples_interval(352, 1216, 20000, scan_lines=False)
    assert hi == math.floor(DENSE * 352 * 1216)
    assert export_working_size(352, 1216, lo - 1, scan_lines=False) != (352, 1216)
    assert export_working_size(352, 1216, hi + 1, scan_lines=False) == size
    assert samples_interval(352, 1216, hi + 1, scan_lines=False) == (hi + 1, 352 * 1216)
    lo, hi = samples_interval(128, 160, 10)
    assert export_working_size(128, 160, 10) == (64, 80)
    assert all(export_working_size(128, 160, n) == (64, 80) for n in (lo, hi))
    assert export_working_size(128, 160, hi + 1) != (64, 80) and lo == 1
    with pytest.raises(ValueError, match="--samples 0"):
        export_working_size(8, 8, 0)


@pytest.fixture(scope="module")
def auto_model():
    """A tiny fast-prox LIP model (as the shipped ones) with random, non-zero weights and the "auto" fill."""
    config = LIPConfig(prior=PRESETS["tiny"], num_iterations=2, initial_estimate="auto", output="z")
    c = lipjax.Completer(config, lipjax.Completer.random(config, seed=1).params, "tiny-auto",
                         {"train_sampler": "uniform:10|lidar:hdl64"})  # no input warning for either pattern
    return perturbed(c)


@pytest.mark.parametrize("flip", [None, False, True])
def test_a_resized_frame_equals_the_jax_graph_and_complete_with_the_nearest_fill(auto_model, tmp_path, flip):
    """128x160 with 10 points runs at 64x80 (area resize, reprojection, bilinear back): scattered points, so
    lipjax.complete fills linearly and the graph equals the model's nearest twin, not the model itself; with and
    without flip averaging, and by default (None) without it, as complete on scattered points."""
    h, w = 128, 160
    written = export_onnx(auto_model, tmp_path / "m.onnx", height=h, width=w, samples=10, scan_lines=False,
                          flip=flip)
    assert written.working == (64, 80) and written.replaced_z0 == "auto" and written.flip == bool(flip)
    assert "instead of the model's 'auto'" in written.summary() and "64x80" in written.summary()
    rng = np.random.default_rng(3)
    rgb = rng.integers(0, 256, (1, h, w, 3), dtype=np.uint8)
    sparse = np.zeros((1, h, w), np.float32)
    sparse.reshape(-1)[rng.choice(h * w, 10, replace=False)] = rng.uniform(1, 8, 10)
    got, = _run_onnx(str(written.path), rgb=rgb, sparse=sparse)
    graph = inference_graph(auto_model, (h, w), (64, 80), flip=flip, scan_lines=False)
    in_jax = np.asarray(jax.jit(graph)(rgb, sparse))
    np.testing.assert_allclose(got, in_jax, rtol=1e-5, atol=1e-5)
    expected = lipjax.complete(rgb[0], sparse[0], model=nearest_twin(auto_model), flip=flip)
    np.testing.assert_allclose(got[0], expected, rtol=1e-5, atol=1e-4)
    linear = lipjax.complete(rgb[0], sparse[0], model=auto_model, flip=flip)
    assert np.abs(got[0] - linear).max() > 0.01  # the Delaunay fill differs: that is the documented gap
    measured = sparse[0] > 0
    np.testing.assert_array_equal(got[0][measured], sparse[0][measured])


def test_scan_lines_at_full_size_equal_complete_with_the_models_own_fill(auto_model, tmp_path):
    """A 48x64 frame runs at full size (no resize in the graph); on scan lines "auto" is the nearest fill, so the
    exported batch of two equals lipjax.complete frame by frame (both without the flipped frame: the fill alone)."""
    b, h, w = 2, 48, 64
    written = export_onnx(auto_model, tmp_path / "m.onnx", height=h, width=w, batch=b, flip=False)
    assert written.working == (h, w) and written.shape == (b, h, w)
    rng = np.random.default_rng(4)
    rgb = rng.integers(0, 256, (b, h, w, 3), dtype=np.uint8)
    sparse = np.zeros((b, h, w), np.float32)
    sparse[:, 1::3] = np.where(rng.random((b, 16, w)) < 0.7, rng.uniform(2, 9, (b, 16, w)), 0)
    assert all(is_lidar_pattern(s) for s in sparse)
    got, = _run_onnx(str(written.path), rgb=rgb, sparse=sparse)
    expected = np.stack([lipjax.complete(c, s, model=auto_model, flip=False) for c, s in zip(rgb, sparse)])
    np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-4)


def test_the_graph_spreads_scan_lines_with_their_own_sigmas_as_complete_does(auto_model):
    """A 48x64 scan at a 24x32 working size: the jax graph (scan_lines=True) equals complete_at, whose spread uses
    the scan-line sigmas (lipjax.spread.SCAN_LINE_SIGMAS_WORKING_PX) for this input; scattered sigmas differ (all
    three without the flipped frame, so that only the sigmas can tell them apart)."""
    from lipjax.inference import complete_at

    h, w = 48, 64
    rng = np.random.default_rng(7)
    rgb = rng.integers(0, 256, (1, h, w, 3), dtype=np.uint8)
    sparse = np.zeros((1, h, w), np.float32)
    sparse[:, 1::4] = np.where(rng.random((1, 12, w)) < 0.8, rng.uniform(2, 9, (1, 12, w)), 0)
    assert is_lidar_pattern(sparse[0])
    host = complete_at(auto_model, rgb[0], sparse[0], (24, 32), flip=False)
    lines, scattered = (np.asarray(jax.jit(inference_graph(auto_model, (h, w), (24, 32), flip=False,
                                                           scan_lines=s))(rgb, sparse)) for s in (True, False))
    np.testing.assert_allclose(lines[0], host, rtol=1e-5, atol=1e-4)
    assert np.abs(scattered[0] - host).max() > 1e-3


@pytest.mark.parametrize("option", [{"samples": 100}, {"scattered": True}, {"flip": True}])
def test_an_onnx_option_on_a_stablehlo_export_is_a_one_line_error(option, tmp_path):
    from lipjax.export import export

    name = "--" + next(iter(option))
    with pytest.raises(ValueError, match=f"^{name} applies to .onnx exports only; drop it"):
        export("linear", tmp_path / "m.stablehlo", height=8, width=8, **option)


def test_a_scan_line_export_averages_with_the_flip_image_as_complete_does(auto_model, tmp_path):
    """export_onnx on LiDAR scan lines holds the frame and its flipped frame in one batch (lax.rev as ONNX Slice with
    step -1), by default as with flip=True, and equals lipjax.complete's default path there, which averages with the
    flipped frame on scan lines (docs/decisions/0020); flip=False (--no-flip) leaves it out, as complete does."""
    b, h, w = 2, 48, 64
    written = export_onnx(auto_model, tmp_path / "m.onnx", height=h, width=w, batch=b)
    plain = export_onnx(auto_model, tmp_path / "plain.onnx", height=h, width=w, batch=b, flip=False)
    rng = np.random.default_rng(6)
    rgb = rng.integers(0, 256, (b, h, w, 3), dtype=np.uint8)
    sparse = np.zeros((b, h, w), np.float32)
    sparse[:, 1::3] = np.where(rng.random((b, 16, w)) < 0.7, rng.uniform(2, 9, (b, 16, w)), 0)
    assert all(is_lidar_pattern(s) for s in sparse)
    got, = _run_onnx(str(written.path), rgb=rgb, sparse=sparse)
    expected = np.stack([lipjax.complete(c, s, model=auto_model) for c, s in zip(rgb, sparse)])
    np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-4)
    np.testing.assert_array_equal(expected, [lipjax.complete(c, s, model=auto_model, flip=True)
                                             for c, s in zip(rgb, sparse)])
    without, = _run_onnx(str(plain.path), rgb=rgb, sparse=sparse)
    np.testing.assert_allclose(without, [lipjax.complete(c, s, model=auto_model, flip=False)
                                         for c, s in zip(rgb, sparse)], rtol=1e-5, atol=1e-4)
    assert np.abs(got - without).max() > 1e-3
    import onnx

    assert {p.key: p.value for p in onnx.load(str(written.path)).metadata_props}["flip_averaged"] == "true"
    assert {p.key: p.value for p in onnx.load(str(plain.path)).metadata_props}["flip_averaged"] == "false"
    assert "flip averaging in the graph" in written.summary() and "flip averaging" not in plain.summary()
