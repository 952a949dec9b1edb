"""The one model interface and the one registry: every learned model type implements LearnedModel, by name."""
import dataclasses

import pytest

import lipjax.networks  # noqa: F401  (registers the end-to-end network types)
from lipjax import methods
from lipjax.interfaces import MODEL_TYPES, SCENE_MAX_DEPTH_M, LearnedModel, model_type_name, register_model_type
from lipjax.model import LIPConfig, presets
from lipjax.networks import PRESETS, baseline_preset


def test_every_model_type_is_a_learned_model_and_named_both_ways():
    assert set(MODEL_TYPES) == {"lip", *PRESETS}
    for name, cls in MODEL_TYPES.items():
        assert issubclass(cls, LearnedModel)
        assert model_type_name(cls) == name
    assert LIPConfig().host_input_names == ()  # box fill: computed inside the program
    for name in PRESETS:  # only the unrolled solver has an iteration count to choose
        with pytest.raises(ValueError, match="end-to-end network: it has no iterations"):
            baseline_preset(name, "tiny").with_iterations({}, 5)
    assert dataclasses.replace(LIPConfig(), initial_estimate="linear").host_input_names == ("z0",)


def test_a_type_name_cannot_be_taken_twice_and_unknown_types_are_named():
    with pytest.raises(ValueError, match="already registered"):
        register_model_type("lip")(type("Other", (), {}))
    with pytest.raises(ValueError, match="not a registered model type"):
        model_type_name(object())


def test_scene_depth_ranges_reach_the_models():
    assert presets("small-outdoor").max_depth_m == SCENE_MAX_DEPTH_M["outdoor"]
    assert baseline_preset("unet", "tiny", SCENE_MAX_DEPTH_M["indoor"]).max_depth_m == 10.0


def test_the_registry_names_every_hand_crafted_method():
    assert {"nearest", "linear", "ip_basic", "ip_basic_multiscale", "ip_basic_adaptive", "colorization",
            "lip-wavelet"} == set(methods.CLASSICAL)
    assert set(methods.CLASSICAL) <= set(methods.available_methods("indoor"))


def test_every_kind_of_completer_implements_the_one_protocol(tmp_path):
    from lipjax.export import export_completer, load_exported, save_exported
    from lipjax.inference import Completer
    from lipjax.interfaces import DepthCompleter
    from lipjax.methods import get_completer

    model = Completer.random()
    for completer in (get_completer("linear"), get_completer("lip-wavelet"), model):
        assert isinstance(completer, DepthCompleter), completer
    path = save_exported(export_completer(model, 1, 16, 24), tmp_path / "m.stablehlo")
    exported = load_exported(path)
    assert isinstance(exported, DepthCompleter) and exported.name == "m"
