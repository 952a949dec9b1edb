"""Saving and loading a trained LIP model: a config (JSON) and parameters (flax msgpack). No pickle.

A model on disk is two files side by side: `<stem>.json` (the LIPConfig, with the prior's type named) and
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
    types = {"network": NetworkPrior}
    try:  # the wavelet prior is optional at import time
        from lipjax.priors.wavelet import WaveletPrior

        types["wavelet"] = WaveletPrior
    except ImportError:
        pass
    return types


def config_to_dict(config: LIPConfig) -> dict:
    kind = {cls: name for name, cls in _prior_types().items()}[type(config.prior)]
    fields = {f.name: getattr(config, f.name) for f in dataclasses.fields(config) if f.name != "prior"}
    return {"prior_type": kind, "prior": dataclasses.asdict(config.prior), **fields}


def config_from_dict(d: dict) -> LIPConfig:
    d = dict(d)
    types = _prior_types()
    kind = d.pop("prior_type")
    if kind not in types:
        raise ValueError(f"unknown prior type {kind!r} in model config; known: {sorted(types)}")
    prior_fields = {k: tuple(v) if isinstance(v, list) else v for k, v in d.pop("prior").items()}
    return LIPConfig(prior=types[kind](**prior_fields), **d)


def _atomic_write(path: pathlib.Path, data: bytes) -> None:
    """Write to a temporary file in the same folder, then rename: a crash never leaves a half-written file."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def save(stem: str | os.PathLike, config: LIPConfig, params, metadata: dict | None = None) -> None:
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


def load(name_or_path: str | os.PathLike) -> tuple[LIPConfig, dict, dict]:
    """(config, params, metadata) of a shipped model name or a saved model path."""
    stem = resolve(name_or_path)
    doc = json.loads(stem.with_suffix(".json").read_text())
    config = config_from_dict(doc["config"])
    params = flax.serialization.msgpack_restore(stem.with_suffix(".msgpack").read_bytes())
    params = jax.tree_util.tree_map(lambda a: np.asarray(a), params)
    return config, params, doc.get("metadata", {})
