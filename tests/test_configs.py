"""The named training configs (experiments/configs/): each shipped model reached what its config states, each
config is at most one `dataclasses.replace` from a scene base, and `--set` overrides live in the library."""
import dataclasses
import hashlib
import importlib
import json
import pathlib
import re
import sys

import numpy as np
import pytest

from experiments.configs import CONFIGS, EXPECTED
from lipjax import model_io
from lipjax.shipped import DEFAULT_MODEL, WEIGHTS_DIR, available
from lipjax.train.config import TrainConfig, apply_overrides, parse_overrides
from lipjax.train.folder import folder_config


def _shipped_docs() -> dict[str, dict]:
    """Config key -> the model file's document (and its "name", the shipped name), for every shipped model whose
    metadata names its train_config."""
    docs = [{**json.loads((WEIGHTS_DIR / f"{name}.json").read_text()), "name": name} for name in available()]
    return {doc["metadata"]["train_config"].replace("-", "_"): doc for doc in docs
            if "train_config" in doc.get("metadata", {})}


def test_every_shipped_model_has_an_expected_result_and_every_expected_result_a_shipped_model():
    shipped = _shipped_docs()
    assert len(shipped) == len(available()) > 0  # every shipped model names the config that trained it
    assert set(EXPECTED) == set(shipped)


@pytest.mark.parametrize("key", sorted(_shipped_docs()))
def test_shipped_model_reached_its_configs_expected_result(key):
    """The model file records the validation RMSE its weights scored when shipped (ship_study, or the run's
    export), and that is the config's EXPECTED result; the weights are still those (the JSON's params_sha256, which
    lipjax.model_io.load checks too, is the SHA-256 of the .msgpack beside it)."""
    doc, config, expected = _shipped_docs()[key], CONFIGS[key], EXPECTED[key]
    meta = doc["metadata"]
    assert meta["train_config"] == config.name
    assert meta["val_metrics"]["rmse_m"] == pytest.approx(expected.val_rmse_m, rel=1e-6)
    assert doc["params_sha256"] == hashlib.sha256((WEIGHTS_DIR / f"{doc['name']}.msgpack").read_bytes()).hexdigest()
    assert meta["images_seen"] == expected.images_seen
    # validated as the config validates, so the RMSE is the config's to state
    assert (meta["val_sampler"], meta["val_images"]) == (config.data.val_sampler, config.data.val_images)
    assert model_io.config_from_dict(doc["config"]) == config.model  # the config's model, field for field
    if expected.budget_from_config:
        started = model_io.metadata(config.init_from)["images_seen"] if config.init_from else 0
        assert meta["steps"] == config.total_steps
        assert meta["images_seen"] == started + config.total_steps * config.batch_size
    else:
        assert expected.note  # a budget the config alone does not give is explained


@pytest.mark.parametrize("scene", ["indoor", "outdoor"])
def test_the_shipped_study_models_are_the_studys_at_its_tuned_rates(scene):
    """Tables I and II's learned rows are the equal-budget study's seed-0 models (experiments/configs/paper.py): each
    config states the rate the study's tuning chose on the scene's validation split (its committed tuning.json), and
    each shipped model records that rate and the scene's one budget (STUDY_BUDGET[scene]), and its EXPECTED note the
    cool-down its last run was."""
    from experiments.configs import paper
    from experiments.configs.study import BASES, BRANCHES, METHODS, shipped_expected
    from experiments.equal_budget import SCORES
    from experiments.study_report import best_rate

    tuning = json.loads((pathlib.Path(SCORES) / scene / "tuning.json").read_text())
    assert paper.STUDY_RATES[scene] == {trunk: best_rate({float(lr): r["val_rmse_m"] for lr, r in rates.items()})
                                        for trunk, rates in tuning.items()}
    for method in METHODS:
        trunk, key = BRANCHES.get(method, (method,))[0], f"{method.replace('-', '_')}_{scene}"
        meta = model_io.metadata(f"{method}-{scene}")
        assert meta["study"]["learning_rate"] == CONFIGS[key].learning_rate == paper.STUDY_RATES[scene][trunk]
        assert meta["images_seen"] == meta["study"]["budget_images"] == paper.STUDY_BUDGET[scene] and meta["seed"] == 0
        cooldown = meta["steps"] * BASES[scene].batch_size
        expected = shipped_expected(meta["val_metrics"]["rmse_m"], meta["images_seen"], cooldown,
                                    trunk if method in BRANCHES else None)
        assert EXPECTED[key].note == expected.note


def _replace_depths(monkeypatch) -> tuple[object, dict[int, tuple[TrainConfig, int, TrainConfig]]]:
    """Imports experiments.configs afresh with `dataclasses.replace` traced. Returns the module and, per TrainConfig
    made by a replace: id -> (config, replaces since the last TrainConfig built without one, that config)."""
    made: dict[int, tuple[TrainConfig, int, TrainConfig]] = {}
    replace = dataclasses.replace

    def traced(obj, /, **changes):
        new = replace(obj, **changes)
        if isinstance(new, TrainConfig):
            _, depth, root = made.get(id(obj), (obj, 0, obj))
            made[id(new)] = (new, depth + 1, root)
        return new

    monkeypatch.setattr(dataclasses, "replace", traced)
    for name in [m for m in sys.modules if m == "experiments.configs" or m.startswith("experiments.configs.")]:
        monkeypatch.delitem(sys.modules, name)
    module = importlib.import_module("experiments.configs")
    monkeypatch.setattr(dataclasses, "replace", replace)
    return module, made


def test_every_config_is_at_most_one_replace_from_a_scene_base(monkeypatch):
    configs, made = _replace_depths(monkeypatch)
    bases = configs.base.SCENES
    assert all(id(base) not in made for base in bases.values())  # the bases are built directly
    derived = {key: made[id(config)] for key, config in configs.CONFIGS.items() if id(config) in made}
    assert {key: depth for key, (_, depth, _) in derived.items() if depth > 1} == {}
    from_base = {key: next(scene for scene, base in bases.items() if root is base)
                 for key, (_, _, root) in derived.items() if any(root is base for base in bases.values())}
    assert set(from_base) == set(derived)  # every replace starts from a scene base
    assert set(configs.CONFIGS) - set(derived) == {"smoke", "lip_cnn_folder"}  # built directly (folder_config)
    assert from_base["lip_any"] == "mixed" and from_base["lip_cnn_kitti"] == "outdoor"
    assert from_base["cspn_nyu"] == "indoor"


def test_overrides_are_the_librarys_and_apply_to_any_train_config():
    config = folder_config(CONFIGS["lip_cnn_indoor"].model, "lip-cnn-indoor")  # as `lipjax train` builds it
    changed = apply_overrides(config, parse_overrides(["g_steps=7", "data.crop=64,80", "init_from=None"]))
    assert (changed.g_steps, changed.data.crop, changed.init_from) == (7, (64, 80), None)
    assert dataclasses.replace(changed, g_steps=config.g_steps, data=config.data, init_from=config.init_from) == config
    assert apply_overrides(config, None) is config
    with pytest.raises(ValueError, match="expected FIELD=VALUE"):
        parse_overrides(["=3"])
    with pytest.raises(ValueError, match="takes int, not 'x'"):
        apply_overrides(config, {"batch_size": "x"})


def test_trained_min_density_is_the_sparsest_scattered_input_of_the_shipped_configs():
    """lipjax.inputs cannot read experiments/ (nor do 12 of the 14 shipped models record their samplers): this test
    keeps its copy of the configs' facts true."""
    from lipjax.inputs import TRAINED_MIN_DENSITY

    scattered = re.compile(r"(uniform|bernoulli):(\d+)")  # N points, whatever noise follows
    for scene, density in TRAINED_MIN_DENSITY.items():
        data = [CONFIGS[key].data for key in EXPECTED if CONFIGS[key].data.kind == scene]
        per_pixel = [int(match[2]) / (d.height * d.width) for d in data
                     for match in map(scattered.match, d.train_sampler.split("|")) if match]
        assert len(data) >= 6 and min(per_pixel) == density


def test_the_shipped_default_model_beats_the_linear_fill_on_rendered_rooms_and_streets():
    """The weights themselves, not their metadata: corrupted or untrained lip-any weights return about the linear
    fill (the untrained prox is the identity) or worse. 3 test rooms (128x160, 100 points) and 2 test streets
    (128x416, HDL-64), through the default path."""
    import lipjax
    from lipjax.classical import linear_fill
    from lipjax.data.sampling import sampler_from_spec
    from lipjax.data.synthetic import SyntheticDataset

    model = lipjax.load_model(DEFAULT_MODEL)
    ratios = []
    for kind, h, w, spec, n in (("indoor", 128, 160, "uniform:100", 3), ("outdoor", 128, 416, "lidar:hdl64", 2)):
        for frame in SyntheticDataset(kind, "test", size=n, height=h, width=w):
            sparse = sampler_from_spec(spec)(frame, 0)
            keep = frame.valid & (sparse <= 0)
            rmse = [np.sqrt(np.mean((pred[keep] - frame.depth[keep]) ** 2))
                    for pred in (lipjax.complete(frame.rgb, sparse, model=model), linear_fill(sparse))]
            ratios.append(rmse[0] / rmse[1])
    assert np.exp(np.mean(np.log(ratios))) < 0.95, ratios
