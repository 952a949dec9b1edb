"""Saving and loading a trained LIP model: a config (JSON) and parameters (flax msgpack). No pickle.

A model on disk is two files side by side: `<stem>.json` (the model config, with its type and its prior's type named) and
`<stem>.msgpack` (the parameter pytree, `flax.serialization.msgpack_serialize`). Models shipped with the package
live in `lipjax/weights/` and load by name, e.g. `load("lip-cnn-indoor")`.
"""
from __future__ import annotations

import dataclasses
import json
import os
import pathlib
import tempfile

import flax.serialization
import jax
import numpy as np

from lipjax.model import LIPConfig
from lipjax.priors.network import NetworkPrior

WEIGHTS_DIR = pathlib.Path(__file__).parent / "weights"


def _prior_types() -> dict[str, type]:
    from lipjax.priors.guided import GuidedPrior
    from lipjax.priors.wavelet import WaveletPrior

    return {"network": NetworkPrior, "guided": GuidedPrior, "wavelet": WaveletPrior}


def _model_types() -> dict[str, type]:
    """Model config types by the name written in model files. End-to-end baselines register in
    lipjax.baselines.networks (MODEL_TYPES): flat frozen dataclasses saved field by field."""
    types: dict[str, type] = {"lip": LIPConfig}
    try:
        from lipjax.baselines.networks import MODEL_TYPES
    except ImportError:  # the learned baselines are optional
        MODEL_TYPES = {}
    types.update(MODEL_TYPES)
    return types


def _tuples(d: dict) -> dict:
    return {k: tuple(v) if isinstance(v, list) else v for k, v in d.items()}


def config_to_dict(config) -> dict:
    """A JSON-able dict of a model config, with its type named (inverse: config_from_dict)."""
    model_type = {cls: name for name, cls in _model_types().items()}.get(type(config))
    if model_type is None:
        raise ValueError(f"cannot save a model config of unregistered type {type(config).__name__}")
    if not isinstance(config, LIPConfig):
        return {"model_type": model_type, **dataclasses.asdict(config)}
    prior_type = {cls: name for name, cls in _prior_types().items()}[type(config.prior)]
    fields = {f.name: getattr(config, f.name) for f in dataclasses.fields(config) if f.name != "prior"}
    return {"model_type": "lip", "prior_type": prior_type, "prior": dataclasses.asdict(config.prior), **fields}


def config_from_dict(d: dict):
    d = dict(d)
    model_type = d.pop("model_type", "lip")
    types = _model_types()
    if model_type not in types:
        raise ValueError(f"unknown model type {model_type!r} in model file; known: {sorted(types)}")
    if model_type != "lip":
        return types[model_type](**_tuples(d))
    priors = _prior_types()
    kind = d.pop("prior_type")
    if kind not in priors:
        raise ValueError(f"unknown prior type {kind!r} in model file; known: {sorted(priors)}")
    return LIPConfig(prior=priors[kind](**_tuples(d.pop("prior"))), **d)


def _atomic_write(path: pathlib.Path, data: bytes) -> None:
    """Write to a temporary file in the same folder, then rename: a crash never leaves a half-written file."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.chmod(tmp, 0o644)  # mkstemp makes the file private; model files are meant to be shared
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def save(stem: str | os.PathLike, config, params, metadata: dict | None = None) -> None:
    """Writes `<stem>.json` and `<stem>.msgpack`. `metadata` (training data, metrics, ...) goes into the JSON."""
    stem = pathlib.Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    params = jax.tree_util.tree_map(np.asarray, params)
    _atomic_write(stem.with_suffix(".msgpack"), flax.serialization.msgpack_serialize(params))
    doc = {"config": config_to_dict(config), "metadata": metadata or {}}
    _atomic_write(stem.with_suffix(".json"), json.dumps(doc, indent=2).encode())


def available() -> list[str]:
    """Names of the models shipped with the package."""
    return sorted(p.stem for p in WEIGHTS_DIR.glob("*.msgpack") if p.with_suffix(".json").exists())


def resolve(name_or_path: str | os.PathLike) -> pathlib.Path:
    """The stem of a shipped model name or of a path to `<stem>.json` / `<stem>.msgpack` / `<stem>`."""
    s = str(name_or_path)
    candidates = [WEIGHTS_DIR / s] if os.sep not in s and not s.endswith((".json", ".msgpack")) else []
    candidates.append(pathlib.Path(s).with_suffix("") if s.endswith((".json", ".msgpack")) else pathlib.Path(s))
    for stem in candidates:
        if stem.with_suffix(".json").exists() and stem.with_suffix(".msgpack").exists():
            return stem
    raise ValueError(
        f"unknown model {s!r}: not a shipped model (available: {', '.join(available()) or 'none'}) "
        f"and no <stem>.json + <stem>.msgpack pair at that path"
    )


def load(name_or_path: str | os.PathLike) -> tuple[object, dict, dict]:
    """(config, params, metadata) of a shipped model name or a saved model path."""
    stem = resolve(name_or_path)
    doc = json.loads(stem.with_suffix(".json").read_text())
    config = config_from_dict(doc["config"])
    params = flax.serialization.msgpack_restore(stem.with_suffix(".msgpack").read_bytes())
    params = jax.tree_util.tree_map(lambda a: np.asarray(a), params)
    return config, params, doc.get("metadata", {})
