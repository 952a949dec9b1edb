"""lipjax.inputs: unit and model-range checks, the LiDAR pattern test and the default-model choice."""
import dataclasses
import warnings

import numpy as np
import pytest

import lipjax
from lipjax import inference, methods
from lipjax.inputs import InputError, check_for_model, check_inputs, is_lidar_pattern, suggest_scene

INDOOR, OUTDOOR = (10.0, "lip-cnn-indoor"), (85.0, "lip-cnn-outdoor")


def _lidar(depth_m=20.0, shape=(96, 200), seed=0):
    """Scan lines: every 4th row from row 40 down, a sample every 2nd column, depths around depth_m."""
    rng = np.random.default_rng(seed)
    sparse = np.zeros(shape, np.float32)
    sparse[40::4, ::2] = depth_m * rng.uniform(0.5, 2.0, sparse[40::4, ::2].shape)
    return sparse


def _scattered(low_m, high_m, n=200, shape=(96, 128), seed=0):
    rng = np.random.default_rng(seed)
    sparse = np.zeros(shape, np.float32)
    idx = rng.choice(sparse.size, n, replace=False)
    sparse.flat[idx] = rng.uniform(low_m, high_m, n)
    return sparse


def _dense(low_m, high_m, shape=(96, 128), seed=0):
    return np.random.default_rng(seed).uniform(low_m, high_m, shape).astype(np.float32)


def _messages(sparse, model):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_for_model(sparse, *model)
    return [str(w.message) for w in caught]


def test_millimetres_are_an_error_for_every_method():
    rgb = np.zeros((96, 128, 3), np.uint8)
    with pytest.raises(InputError, match=r"median of 3\d\d\d: not metres \(millimetres\? divide by 1000\)"):
        check_inputs(rgb, _scattered(3.0, 4.0) * 1000)


def test_centimetres_on_the_indoor_model_are_an_error():
    with pytest.raises(InputError, match=r"over 10x the 10 m range of lip-cnn-indoor: not metres \(centimetres\? "
                                         "divide by 100"):
        check_for_model(_scattered(1.0, 8.07) * 100, *INDOOR)


def test_centimetres_on_the_outdoor_model_warn():
    assert _messages(_scattered(1.0, 8.07) * 100, OUTDOOR)[0] == (
        "sparse depth far beyond the 85 m range of lip-cnn-outdoor: centimetres given as metres? divide by 100")


def test_outdoor_lidar_on_the_indoor_model_warns_to_use_the_outdoor_model():
    assert _messages(_lidar(20.0), INDOOR) == [
        "sparse depth beyond the 10 m range of the indoor model lip-cnn-indoor: looks like outdoor data, "
        "use lip-cnn-outdoor"]


def test_kinect_png_read_with_scale_256_warns_with_both_models():
    sparse = _dense(1.0, 8.0) * 1000 / 256  # 3.9 - 31 m
    assert _messages(sparse, INDOOR)[0].endswith(
        "read with --depth-scale 256 (use 1000), or outdoor data (use lip-cnn-outdoor)?")
    assert _messages(sparse, OUTDOOR) == [
        "a dense depth map within 39 m: a millimetre PNG (Kinect, NYU) read with --depth-scale 256 (use 1000), "
        "or indoor data (use lip-cnn-indoor)?"]


def test_indoor_data_on_the_outdoor_model_warns():
    assert _messages(_dense(0.5, 8.0), OUTDOOR) == [
        "every sample within 10 m and no LiDAR scan lines: looks like indoor data, use lip-cnn-indoor"]


def test_scan_lines_within_range_on_the_indoor_model_warn_about_the_pattern():
    assert _messages(_lidar(3.0), INDOOR) == [
        "samples in LiDAR scan lines, but the indoor model lip-cnn-indoor was trained on scattered points: "
        "lip-cnn-outdoor was trained on scan lines"]


def test_scan_lines_are_no_warning_for_an_indoor_model_trained_on_them():
    assert _messages(_lidar(3.0), INDOOR + (True,)) == []
    scattered = inference.Completer.random()
    lidar = dataclasses.replace(scattered, metadata={"train_sampler": "uniform:200|lidar:hdl64,azimuth_step_deg=0.4"})
    assert lidar.scan_lines_trained and not scattered.scan_lines_trained
    noisy = dataclasses.replace(scattered, metadata={"train_sampler": "uniform:200|lidar:vlp16+noise:std=0.02"})
    points = dataclasses.replace(scattered, metadata={"train_sampler": "uniform:200|bernoulli:100"})
    assert noisy.scan_lines_trained and not points.scan_lines_trained


def test_far_too_few_samples_warn():
    message = _messages(_scattered(1.0, 5.0, n=5, shape=(480, 640)), INDOOR)[0]
    assert message.endswith("(0.12 % of the pixels): expect larger errors")


def test_matching_data_gives_no_warning():
    assert _messages(_scattered(0.5, 8.0), INDOOR) == []
    assert _messages(_lidar(20.0), OUTDOOR) == []


def test_lidar_pattern_and_scene():
    assert is_lidar_pattern(_lidar()) and not is_lidar_pattern(_scattered(1, 5)) and not is_lidar_pattern(_dense(1, 5))
    assert suggest_scene(_lidar(3.0)) == "outdoor"  # scan lines, even near
    assert suggest_scene(_scattered(10.0, 30.0)) == "outdoor"  # median 20 m: no room is that deep
    assert suggest_scene(_scattered(0.5, 8.0)) == "indoor"
    assert suggest_scene(np.zeros((4, 4), np.float32)) == "indoor"


def test_one_default_model_for_rooms_and_streets():
    """Issue 22: the same model for a room with 200 points and a street with 64 scan lines (DEFAULT_MODELS)."""
    assert methods.get_completer(sparse=_lidar(20.0)).name == "lip-any"
    assert methods.get_completer(sparse=_scattered(0.5, 8.0)).name == "lip-any"
    assert methods.get_completer().name == "lip-any"


def test_the_completer_checks_against_its_range():
    rgb = np.zeros((96, 200, 3), np.uint8)
    with pytest.warns(UserWarning, match="looks like outdoor data, use lip-any"):
        lipjax.Completer.random()(rgb, _lidar(20.0))
    with pytest.raises(InputError, match="over 10x the 10 m range of random"):
        lipjax.Completer.random()(rgb, _lidar(300.0))


def test_the_unit_hint_names_the_unit_the_values_fit():
    """Issue 55: centimetres (values ~100x metres) were hinted as "millimetres? divide by 1000". The hint now names
    the unit that puts the median sample in a real scene's range: scan lines are a street (cm: 19 m; mm: 19 m),
    scattered samples a room first (mm: 3.5 m), and where two units fit, both, the likelier first."""
    rgb = np.zeros((96, 200, 3), np.uint8)
    for sparse, hint in ((_lidar(15.0) * 100, "centimetres? divide by 100"),
                         (_lidar(15.0) * 1000, "millimetres? divide by 1000"),
                         (_lidar(4.0) * 1000, "millimetres? divide by 1000; centimetres? by 100"),
                         (_scattered(3.0, 4.0, shape=(96, 200)) * 1e6,
                          "divide by its units per metre: 100 for centimetres, 1000 for millimetres")):
        with pytest.raises(InputError) as info:
            check_inputs(rgb, sparse)
        median = np.median(sparse[sparse > 0])
        assert str(info.value) == f"sparse depth has a median of {median:.0f}: not metres ({hint})"
    centimetres = _lidar(7.0) * 100  # a median of 9 m in centimetres: over 10x 85 m
    with pytest.raises(InputError) as info:
        check_for_model(centimetres, *OUTDOOR)
    median = np.median(centimetres[centimetres > 0])
    assert median > 850 and str(info.value) == (f"sparse depth has a median of {median:.0f} m, over 10x the 85 m "
                                                "range of lip-cnn-outdoor: not metres (centimetres? divide by 100)")
    with pytest.raises(InputError) as info:
        check_for_model(_scattered(0.55, 0.65) * 1000, *INDOOR)  # 0.6 m in millimetres or 6 m in centimetres
    assert str(info.value).endswith("over 10x the 10 m range of lip-cnn-indoor: not metres (centimetres? divide by "
                                    "100; millimetres? by 1000)")


def test_a_png_scale_that_puts_the_samples_beyond_every_models_range_warns_with_the_scale_that_fits():
    """Issue 55: a millimetre PNG of a street read with --depth-scale 256 put 23 % of its samples beyond 85 m
    without a word; over 5 % beyond it now warns, naming the known scale that fits."""
    from lipjax.inputs import check_depth_scale

    def warned(depth_m, scale):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            check_depth_scale(depth_m, scale)
        return [str(w.message) for w in caught]

    street_mm = np.round(_lidar(20.0) * 1000)  # 10-40 m, as a millimetre PNG holds it
    assert warned(street_mm / 256, 256) == [
        "depth PNG read with --depth-scale 256 puts over 5 % of its samples beyond 85 m, the deepest range of any "
        "model: millimetres? --depth-scale 1000 fits it"]
    assert warned(street_mm / 1000, 1000) == []
    assert warned(np.round(_lidar(20.0) * 5000) / 1000, 1000)[0].endswith(
        "TUM's 5000 per metre? --depth-scale 5000 fits it")
    assert warned(_lidar(500.0), 5000)[0].endswith(
        "beyond 85 m, the deepest range of any model: give the PNG's value per metre as --depth-scale")
