"""The public inference entry point: clear input errors, batching, compile-once, save/load round trip."""

import hashlib
import json

import jax
import numpy as np
import pytest

import lipjax
from lipjax import inference, methods, model_io
from lipjax.classical.interpolate import linear_fill
from lipjax.classical.nearest import nearest_fill
from lipjax.fill import box_fill
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset

from helpers import perturbed

CONFIG = LIPConfig(prior=network_preset("tiny"), num_iterations=2)


@pytest.fixture(scope="module")
def completer():
    return lipjax.Completer.random(CONFIG)


@pytest.fixture(scope="module")
def scrambled(completer):
    """Non-zero weights: the prox is not the identity, so each parameter and each batch element shows in the output."""
    return perturbed(completer)


def _inputs(h=16, w=20, seed=0, batch=None):
    rng = np.random.default_rng(seed)
    shape = (h, w) if batch is None else (batch, h, w)
    rgb = rng.integers(0, 256, (*shape, 3), dtype=np.uint8)
    sparse = np.where(rng.random(shape) < 0.1, rng.uniform(1, 5, shape), 0).astype(np.float32)
    sparse.reshape(-1, h, w)[:, 0, 0] = 2.0
    return rgb, sparse


def test_single_and_batched_calls_agree_and_keep_measurements(completer, scrambled):
    rgb, sparse = _inputs(batch=2)
    batched = completer(rgb, sparse)
    assert batched.shape == (2, 16, 20) and batched.dtype == np.float32
    np.testing.assert_allclose(completer(rgb[1], sparse[1]), batched[1], rtol=1e-5)
    m = sparse > 0
    # An identity prox: z = x + u, so u stays 0 and every iterate is the initial estimate z_0 = box_fill(y, m), which
    # keeps the measured pixels; the x-updates (m y + rho z_0) / (m + rho) then leave it unchanged, at every pixel.
    np.testing.assert_allclose(batched, np.asarray(box_fill(sparse, m.astype(np.float32))), rtol=1e-5)
    np.testing.assert_allclose(batched[m], sparse[m], rtol=1e-6)
    # A real prox mixes pixels: each element of a batch still sees only its own frame. (Random weights amplify the
    # float32 rounding of XLA's batch-size-dependent convolution tiling to ~0.4 % at a few pixels; a frame mixed
    # with another would be off by metres.)
    mixed = scrambled(rgb, sparse)
    assert not np.allclose(mixed, batched, atol=1e-3)
    for i in range(2):
        np.testing.assert_allclose(scrambled(rgb[i], sparse[i]), mixed[i], rtol=1e-2, atol=1e-3)


def test_compiled_once_per_shape(completer):
    fn = inference.compiled_apply(CONFIG, False)
    for seed in range(3):
        completer(*_inputs(seed=seed))
    n = fn._cache_size()
    completer(*_inputs(seed=9))
    assert fn._cache_size() == n
    completer(*_inputs(h=24, w=20))
    assert fn._cache_size() == n + 1


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda r, s: (r[:, :-1], s), "differ in size"),
        (lambda r, s: (r[..., :2], s), "rgb must be"),
        (lambda r, s: (r.astype(np.int32), s), "uint8"),
        (lambda r, s: (r, np.where(s > 0, np.nan, 0).astype(np.float32)), "NaN"),
        (lambda r, s: (r, -s), "negative"),
        (lambda r, s: (r, np.zeros_like(s)), "no samples"),
        (lambda r, s: (r, (s * 1000).astype(np.uint16)), "float metres"),
        (lambda r, s: (r, s * 1000), "not metres"),
    ],
)
def test_bad_input_gives_a_clear_error(completer, mutate, message):
    rgb, sparse = _inputs()
    with pytest.raises(lipjax.InputError, match=message):
        completer(*mutate(rgb, sparse))


def test_save_and_load_round_trip(tmp_path, scrambled):
    model_io.save(tmp_path / "m", CONFIG, scrambled.params, {"note": "test"})
    loaded = lipjax.load_model(tmp_path / "m.json")
    assert loaded.config == CONFIG and loaded.metadata == {"note": "test"}
    saved, tree = jax.tree_util.tree_flatten(scrambled.params)
    back, back_tree = jax.tree_util.tree_flatten(loaded.params)
    assert back_tree == tree
    for a, b in zip(saved, back, strict=True):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))
    rgb, sparse = _inputs()
    np.testing.assert_array_equal(loaded(rgb, sparse), scrambled(rgb, sparse))
    # the JSON names the parameter file's bytes (hashlib, independently of model_io), which load checks
    doc = json.loads((tmp_path / "m.json").read_text())
    assert doc["params_sha256"] == hashlib.sha256((tmp_path / "m.msgpack").read_bytes()).hexdigest()


def test_unknown_model_name_lists_available():
    with pytest.raises(ValueError, match="unknown model 'no-such-model'"):
        lipjax.load_model("no-such-model")
    for empty in ("", ".json"):  # no file name at all: the same one-line error, not pathlib's
        with pytest.raises(ValueError, match=f"unknown model '{empty}'"):
            lipjax.load_model(empty)


def test_fewer_iterations_uses_the_first_operators(scrambled):
    short = scrambled.with_iterations(1)
    assert short.config.num_iterations == 1
    np.testing.assert_array_equal(short.params["log_rho"], scrambled.params["log_rho"][:1])
    rgb, sparse = _inputs()
    _, full = scrambled.trajectory(rgb, sparse)
    _, first = short.trajectory(rgb, sparse)
    assert full.x.shape == (2, 1, 16, 20) and first.x.shape == (1, 1, 16, 20)
    # The first iteration of the full model, operator for operator.
    np.testing.assert_allclose(first.x[0], full.x[0], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(first.z[0], full.z[0], rtol=1e-6, atol=1e-6)
    assert not np.allclose(full.z[0], full.z[1], atol=1e-3)  # the second operator does change z
    with pytest.raises(ValueError):
        scrambled.with_iterations(5)


@pytest.mark.parametrize("kind", ["linear", "nearest"])
def test_host_initial_estimate_untrained_model_returns_that_fill(kind):
    """With z_0 = a classical fill and the identity (untrained) prox, the model returns exactly that fill."""
    from lipjax.classical.interpolate import linear_fill
    from lipjax.classical.nearest import nearest_fill

    config = LIPConfig(prior=network_preset("tiny"), num_iterations=1, initial_estimate=kind)
    model = inference.Completer.random(config)
    rng = np.random.default_rng(3)
    gt = (1.0 + 3.0 * rng.random((2, 20, 28))).astype(np.float32)
    sparse = np.where(rng.random(gt.shape) < 0.08, gt, 0.0).astype(np.float32)
    rgb = rng.integers(0, 256, (2, 20, 28, 3), dtype=np.uint8)
    expected = np.stack([{"linear": linear_fill, "nearest": nearest_fill}[kind](s) for s in sparse])
    np.testing.assert_allclose(model(rgb, sparse), expected, atol=1e-5)
    with pytest.raises(ValueError, match="computed on the host"):
        config.apply(model.params, rgb, sparse)


def test_save_keeps_a_dotted_stem_exactly(tmp_path, completer):
    model_io.save(tmp_path / "smoke.v2", CONFIG, completer.params)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["smoke.v2.json", "smoke.v2.msgpack"]
    assert lipjax.load_model(tmp_path / "smoke.v2").config == CONFIG
    assert lipjax.load_model(tmp_path / "smoke.v2.msgpack").config == CONFIG


def test_complete_takes_any_method_name():
    """A classical fill by name runs at full size and returns exactly that fill."""
    rgb, sparse = _inputs()
    np.testing.assert_allclose(lipjax.complete(rgb, sparse, model="linear"), linear_fill(sparse), rtol=1e-6)
    np.testing.assert_array_equal(lipjax.complete(rgb, sparse, model="nearest"), nearest_fill(sparse))


def test_reproject_sparse_and_complete_frame_keep_measured_values(completer):
    sparse = np.zeros((8, 8), np.float32)
    sparse[0, 0], sparse[0, 1] = 5.0, 3.0   # same 2x2 block: one output pixel, the nearer wins
    sparse[7, 7] = 1.25
    small = inference.reproject_sparse(sparse, (4, 4))
    assert small[0, 0] == 3.0 and small[3, 3] == 1.25 and np.count_nonzero(small) == 2
    rgb, sparse = _inputs(h=24, w=32)
    dense = inference.complete_frame(methods.get_completer("linear"), rgb, sparse, max_side=16)
    assert dense.shape == (24, 32) and dense.dtype == np.float32
    np.testing.assert_array_equal(dense[sparse > 0], sparse[sparse > 0])


def test_auto_initial_estimate_is_nearest_on_scan_lines_and_linear_on_scattered_points():
    from lipjax.classical.interpolate import linear_fill
    from lipjax.classical.nearest import nearest_fill
    from lipjax.model import host_initial_estimate

    rng = np.random.default_rng(0)
    lines = np.zeros((40, 60), np.float32)
    lines[5::6, ::2] = rng.uniform(1.0, 9.0, lines[5::6, ::2].shape)  # rows 6 px apart, samples 2 px apart
    scattered = np.zeros((40, 60), np.float32)
    scattered.reshape(-1)[rng.choice(40 * 60, 30, replace=False)] = rng.uniform(1.0, 9.0, 30)
    out = host_initial_estimate("auto", np.stack([lines, scattered]))
    np.testing.assert_array_equal(out[0], nearest_fill(lines))
    np.testing.assert_array_equal(out[1], linear_fill(scattered))
    assert not np.array_equal(nearest_fill(lines), linear_fill(lines))  # the two fills differ on this input


def test_flip_averaging_is_flip_equivariant_keeps_measurements_and_changes_the_estimate(monkeypatch):
    """flip_averaged(I, y) = (z(I, y) + flip(z(flip I, flip y))) / 2 is exactly flip-equivariant, which one call
    of a network is not; the default path (complete_at, lipjax.complete) uses it on request (flip=True; by
    default on scan lines only) at full and at working size."""
    from lipjax.inference import complete_at, flip_averaged

    completer = perturbed(lipjax.Completer(CONFIG, CONFIG.init(jax.random.key(0)), "tiny"), seed=2)
    rng = np.random.default_rng(5)
    rgb = rng.integers(0, 256, (40, 56, 3), dtype=np.uint8)
    sparse = np.where(rng.random((40, 56)) < 0.05, rng.uniform(1, 8, (40, 56)), 0).astype(np.float32)
    averaged = flip_averaged(completer, rgb, sparse)
    flipped = flip_averaged(completer, rgb[:, ::-1].copy(), sparse[:, ::-1].copy())
    np.testing.assert_array_equal(flipped[:, ::-1], averaged)  # on the CPU: the same two calls, in two threads
    once = completer(rgb, sparse)
    once_flipped = completer(rgb[:, ::-1].copy(), sparse[:, ::-1].copy())
    assert np.abs(once_flipped[:, ::-1] - once).max() > 1e-3  # the network alone is not flip-equivariant
    np.testing.assert_array_equal(averaged, 0.5 * (once + once_flipped[:, ::-1]))
    with monkeypatch.context() as patch:  # elsewhere one batch of two: XLA's batched convolutions round differently
        patch.setattr(inference.jax, "default_backend", lambda: "gpu")
        batched = flip_averaged(completer, rgb, sparse)
    np.testing.assert_allclose(batched, averaged, rtol=0, atol=1e-3)  # measured 2e-4 m
    for size in ((40, 56), (20, 28)):
        got = complete_at(completer, rgb, sparse, size, flip=True)
        assert np.abs(got - complete_at(completer, rgb, sparse, size)).max() > 1e-3  # off on scattered
    for size in ((40, 56), (20, 28)):  # at any size the measured pixels are set back (the model's x keeps them ~)
        for flip in (False, True):
            got = complete_at(completer, rgb, sparse, size, flip=flip)
            np.testing.assert_array_equal(got[sparse > 0], sparse[sparse > 0])
    assert np.abs(completer(rgb, sparse)[sparse > 0] - sparse[sparse > 0]).max() > 1e-3
    unmeasured = sparse == 0  # the check against the linear fill would blend this random model with the fill
    got = complete_at(completer, rgb, sparse, (40, 56), flip=True, cross_check=False)
    np.testing.assert_allclose(got[unmeasured], averaged[unmeasured], rtol=0, atol=1e-6)
    np.testing.assert_allclose(lipjax.complete(rgb, sparse, model=completer, flip=True),
                               inference.complete_frame(completer, rgb, sparse, flip=True), rtol=0, atol=1e-6)
    with pytest.raises(lipjax.InputError, match="flip averaging is for learned models; drop --flip"):
        lipjax.complete(rgb, sparse, model="linear", flip=True)


@pytest.mark.filterwarnings("ignore:samples in LiDAR scan lines")  # a tiny model trained on neither
def test_by_default_the_flip_image_is_averaged_in_on_scan_lines_only():
    """flip=None (the default of complete_at, lipjax.complete): averaged with the flipped frame on LiDAR scan lines,
    where the check does not run (docs/decisions/0020), and not on scattered samples; True and False force it either
    way; a classical fill is never flipped by default."""
    from lipjax.inference import complete_at, is_lidar_pattern, flips

    completer = perturbed(lipjax.Completer(CONFIG, CONFIG.init(jax.random.key(0)), "tiny"), seed=2)
    rng = np.random.default_rng(8)
    rgb = rng.integers(0, 256, (40, 56, 3), dtype=np.uint8)
    lines = np.zeros((40, 56), np.float32)
    lines[1::4] = np.where(rng.random((10, 56)) < 0.8, rng.uniform(1, 8, (10, 56)), 0)
    scattered = np.where(rng.random((40, 56)) < 0.05, rng.uniform(1, 8, (40, 56)), 0).astype(np.float32)
    assert is_lidar_pattern(lines) and not is_lidar_pattern(scattered)
    for size in ((40, 56), (20, 28)):
        def run(sparse, flip=None):
            return complete_at(completer, rgb, sparse, size, flip=flip, cross_check=False)

        np.testing.assert_array_equal(run(lines), run(lines, True))
        assert np.abs(run(lines) - run(lines, False)).max() > 1e-3
        np.testing.assert_array_equal(run(scattered), run(scattered, False))
        assert np.abs(run(scattered) - run(scattered, True)).max() > 1e-3
    # a caller that already asked the pattern (complete_frame) is believed: at full size (nothing spread) scan_lines
    # only decides the flipped frame
    np.testing.assert_array_equal(complete_at(completer, rgb, scattered, (40, 56), cross_check=False, scan_lines=True),
                                  complete_at(completer, rgb, scattered, (40, 56), cross_check=False, flip=True))
    np.testing.assert_array_equal(complete_at(completer, rgb, lines, (40, 56), cross_check=False, scan_lines=False),
                                  complete_at(completer, rgb, lines, (40, 56), cross_check=False, flip=False))
    np.testing.assert_array_equal(lipjax.complete(rgb, lines, model=completer),
                                  lipjax.complete(rgb, lines, model=completer, flip=True))
    assert not flips(methods.get_completer("linear"), True, None) and flips(completer, True, None)
    np.testing.assert_array_equal(lipjax.complete(rgb, lines, model="linear"), linear_fill(lines))


@pytest.mark.filterwarnings("ignore:samples in LiDAR scan lines")  # a tiny model trained on neither
def test_below_full_size_the_samples_residuals_are_spread_over_the_resized_estimate():
    """complete_at(spread=True) at a working size: z resized back (bilinear), then lipjax.spread.spread_residuals with
    half a working pixel (scattered samples; scan lines with their own sigmas), then the measured pixels set back; at
    full size nothing is spread."""
    import cv2

    from lipjax.inference import complete_at, is_lidar_pattern, reproject_sparse
    from lipjax.spread import spread_on_host, spread_residuals

    completer = perturbed(lipjax.Completer(CONFIG, CONFIG.init(jax.random.key(0)), "tiny"), seed=2)
    rng = np.random.default_rng(6)
    rgb = rng.integers(0, 256, (40, 56, 3), dtype=np.uint8)
    sparse = np.where(rng.random((40, 56)) < 0.05, rng.uniform(1, 8, (40, 56)), 0).astype(np.float32)
    small = completer(cv2.resize(rgb, (28, 20), interpolation=cv2.INTER_AREA), reproject_sparse(sparse, (20, 28)))
    z = cv2.resize(np.asarray(small, np.float32), (56, 40), interpolation=cv2.INTER_LINEAR)
    expected = np.array(spread_residuals(z, sparse, (1.0, 1.0)))
    expected[sparse > 0] = sparse[sparse > 0]
    got = complete_at(completer, rgb, sparse, (20, 28), cross_check=False, spread=True)
    np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-5)
    plain = complete_at(completer, rgb, sparse, (20, 28), cross_check=False, spread=False)
    assert np.abs(got - plain).max() > 1e-3
    np.testing.assert_array_equal(got[sparse > 0], sparse[sparse > 0])
    full = [complete_at(completer, rgb, sparse, (40, 56), cross_check=False, spread=s) for s in (True, False)]
    np.testing.assert_array_equal(*full)
    # LiDAR scan lines: residual spreading's sigmas are those of scan lines (docs/decisions/0019)
    lines = np.zeros_like(sparse)
    lines[1::4] = np.where(rng.random((10, 56)) < 0.8, rng.uniform(1, 8, (10, 56)), 0)
    assert is_lidar_pattern(lines)
    small = completer(cv2.resize(rgb, (28, 20), interpolation=cv2.INTER_AREA), reproject_sparse(lines, (20, 28)))
    z = cv2.resize(np.asarray(small, np.float32), (56, 40), interpolation=cv2.INTER_LINEAR)
    expected = spread_on_host(z, lines, (20, 28), scan_lines=True)
    expected[lines > 0] = lines[lines > 0]
    got = complete_at(completer, rgb, lines, (20, 28), flip=False)  # one run: the spread alone
    np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-5)
    assert np.abs(spread_on_host(z, lines, (20, 28)) - expected)[lines == 0].max() > 1e-3


@pytest.fixture(scope="module")
def street_and_room():
    """(rgb, sparse m) of a synthetic 352x1216 street seen by a 64-beam LiDAR, and of a 480x640 room with 200 uniform
    points: the two inputs the default path was tuned for."""
    from lipjax.data.sampling import LidarSampler, UniformSampler
    from lipjax.data.synthetic.dataset import render

    street, room = render("outdoor", "test", 0, height=352, width=1216), render("indoor", "test", 0, 480, 640)
    return (street.rgb, LidarSampler.hdl64()(street)), (room.rgb, UniformSampler(200)(room))


def test_the_plan_of_a_scan_and_of_scattered_points(street_and_room):
    """plan_frame decides what the default path does to a frame before anything runs: a 64-beam scan is scan lines,
    flip-averaged, not cross-checked, at the capped working size, from the nearest fill; 200 points on a room are
    scattered, cross-checked, not flip-averaged, from the linear fill; its lines say so (lipjax complete --explain)."""
    model = lipjax.Completer.random(LIPConfig(prior=network_preset("tiny"), initial_estimate="auto"))
    (_, scan), (_, points) = street_and_room
    plan = inference.plan_frame(model, scan)
    assert (plan.pattern, plan.scan_lines, plan.flip, plan.cross_check, plan.initial_estimate) == (
        "scan lines", True, True, False, "nearest")
    assert plan.size == (132, 455) and plan.spread and plan.set_back and plan.samples == np.count_nonzero(scan)
    lines = plan.describe()
    assert lines[1].startswith("pattern: scan lines (a spinning LiDAR's): ") and "flip averaging: on" in lines
    assert "cross-check against the linear fill: off (not on scan lines)" in lines
    assert lines[2] == ("working size: 132x455 (0.38x of 352x1216; the rule: samples about 16 px apart, at most "
                        "60,000 pixels for scan lines)")
    plan = inference.plan_frame(model, points)
    assert (plan.pattern, plan.scan_lines, plan.flip, plan.cross_check, plan.initial_estimate, plan.size) == (
        "scattered", False, False, True, "linear", (196, 261))
    lines = plan.describe()
    assert lines[1] == "pattern: scattered (100 or more, not in scan lines): 200 samples on 480x640, 39.2 px apart"
    assert "cross-check against the linear fill: on" in lines and "flip averaging: off" in lines
    # the switches and the caller's size; a hand-crafted method: at full size, as it returns, never checked
    plan = inference.plan_frame(model, points, 160, flip=True, cross_check=False)
    assert (plan.size, plan.flip, plan.cross_check) == ((120, 160), True, False)
    assert "cross-check against the linear fill: off (turned off)" in plan.describe()
    plan = inference.plan_frame(methods.get_completer("linear"), scan)
    assert (plan.learned, plan.size, plan.initial_estimate, plan.flip, plan.cross_check, plan.set_back) == (
        False, (352, 1216), None, False, False, False)
    with pytest.raises(lipjax.InputError, match="flip averaging is for learned models"):
        inference.plan_frame(methods.get_completer("linear"), scan, flip=True)


@pytest.mark.filterwarnings("ignore:sparse depth beyond", "ignore:samples in LiDAR")  # an indoor model on a street
def test_the_default_path_asks_the_samples_pattern_once_per_frame(street_and_room, monkeypatch):
    """Issue 53: the pattern is asked of the full-size frame once (plan_frame) and passed down: the model's input
    checks and its "auto" fill on the working-size map, the flipped frame and the held-out folds take it."""
    import cv2

    from lipjax import crosscheck, inputs, model as model_module

    asked, ask = [], inputs.is_lidar_pattern
    for module in (inputs, inference, model_module, crosscheck):
        monkeypatch.setattr(module, "is_lidar_pattern", lambda s: asked.append(np.shape(s)) or ask(s))
    model = lipjax.Completer.random(LIPConfig(prior=network_preset("tiny"), initial_estimate="auto"))
    for rgb, sparse in street_and_room:  # a quarter of the size, for speed
        asked.clear()
        small = tuple(s // 4 for s in sparse.shape)
        frame_rgb, frame_sparse = cv2.resize(rgb, small[::-1]), inference.reproject_sparse(sparse, small)
        inference.complete_frame(model, frame_rgb, frame_sparse)
        assert asked == [small]
    # told the pattern, the model's own "auto" fill gives what it finds by itself
    rgb, scan = (a[-64:, :256] for a in street_and_room[0])
    assert inputs.is_lidar_pattern(scan)
    np.testing.assert_array_equal(model(rgb, scan, scan_lines=True), model(rgb, scan))
