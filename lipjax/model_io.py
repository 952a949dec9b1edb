"""Saving and loading a trained model (LIP or an end-to-end network): a config (JSON) and parameters (flax
msgpack). No pickle.

A model on disk is two files side by side: `<stem>.json` (the model config, with its type and its prior's type named)
and `<stem>.msgpack` (the parameter pytree, `flax.serialization.msgpack_serialize`). Models shipped with the package
live in `lipjax/weights/` and load by name, e.g. `load("lip-cnn-indoor")`.

The stem is used as given: `save("out/smoke.v2", ...)` writes `out/smoke.v2.json` and `out/smoke.v2.msgpack`.
`load` checks both files and raises ModelFileError (one line, naming the file and the fix) when either is
unreadable, truncated, holds a bad config field, when the parameters do not fit the config, or when the JSON's
`params_sha256` (the SHA-256 of the .msgpack that `save` wrote beside it) is not the .msgpack's: the parameters of
another save of the same architecture, or bytes changed since.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import pathlib
import tempfile

import flax.serialization
import jax
import numpy as np

from lipjax.inputs import OUTDOOR_MEDIAN_M
from lipjax.interfaces import MODEL_TYPES, PRIOR_TYPES, model_type_name
from lipjax.model import LIPConfig
import lipjax.priors.fast  # noqa: F401  (registers the prior types model files name)
import lipjax.priors.network  # noqa: F401
import lipjax.priors.wavelet  # noqa: F401
from lipjax.shipped import DEFAULT_MODELS, WEIGHTS_DIR, available


class ModelFileError(ValueError):
    """A model file that cannot be used; the message names the file and the fix."""


def _with_suffix(stem: pathlib.Path, suffix: str) -> pathlib.Path:
    """stem + suffix, keeping any dots of the stem (Path.with_suffix would turn "smoke.v2" into "smoke.json")."""
    return stem.with_name(stem.name + suffix)


def _model_types() -> dict[str, type]:
    """Model config types by the name written in model files (lipjax.interfaces.MODEL_TYPES: the LIP model and
    the end-to-end networks, flat frozen dataclasses saved field by field)."""
    import lipjax.networks  # noqa: F401  (registers the end-to-end network types)

    return MODEL_TYPES


def _tuples(d: dict) -> dict:
    return {k: tuple(v) if isinstance(v, list) else v for k, v in d.items()}


def config_to_dict(config) -> dict:
    """A JSON-able dict of a model config, with its type named (inverse: config_from_dict)."""
    _model_types()
    model_type = model_type_name(config)
    if not isinstance(config, LIPConfig):
        return {"model_type": model_type, **dataclasses.asdict(config)}
    prior_type = {cls: name for name, cls in PRIOR_TYPES.items()}[type(config.prior)]
    fields = {f.name: getattr(config, f.name) for f in dataclasses.fields(config) if f.name != "prior"}
    return {"model_type": "lip", "prior_type": prior_type, "prior": dataclasses.asdict(config.prior), **fields}


# Prior types under the names that files written by earlier versions give them: the fast prox (lipjax.priors.fast)
# was "guided" until 2026-12-06.
RENAMED_PRIOR_TYPES = {"guided": "fast"}


def config_from_dict(d: dict):
    d = dict(d)
    model_type = d.pop("model_type", "lip")
    types = _model_types()
    if model_type not in types:
        raise ValueError(f"unknown model type {model_type!r} in model file; known: {sorted(types)}")
    if model_type != "lip":
        return types[model_type](**_tuples(d))
    kind = d.pop("prior_type")
    kind = RENAMED_PRIOR_TYPES.get(kind, kind)
    if kind not in PRIOR_TYPES:
        raise ValueError(f"unknown prior type {kind!r} in model file; known: {sorted(PRIOR_TYPES)}")
    return LIPConfig(prior=PRIOR_TYPES[kind](**_tuples(d.pop("prior"))), **d)


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
    packed = flax.serialization.msgpack_serialize(params)
    _atomic_write(_with_suffix(stem, ".msgpack"), packed)
    doc = {"config": config_to_dict(config), "params_sha256": hashlib.sha256(packed).hexdigest(),
           "metadata": metadata or {}}
    _atomic_write(_with_suffix(stem, ".json"), json.dumps(doc, indent=2).encode())


def resolve(name_or_path: str | os.PathLike) -> pathlib.Path:
    """The stem of a shipped model name or of a path to `<stem>.json` / `<stem>.msgpack` / `<stem>`."""
    s = os.fspath(name_or_path)
    candidates = [WEIGHTS_DIR / s] if os.sep not in s and not s.endswith((".json", ".msgpack")) else []
    candidates.append(pathlib.Path(s.rsplit(".", 1)[0] if s.endswith((".json", ".msgpack")) else s))
    for stem in candidates:
        if stem.name and _with_suffix(stem, ".json").exists() and _with_suffix(stem, ".msgpack").exists():
            return stem
    raise ValueError(
        f"unknown model {s!r}: not a shipped model (available: {', '.join(available()) or 'none'}) "
        f"and no <stem>.json + <stem>.msgpack pair at that path"
    )


def _read_doc(stem: pathlib.Path) -> dict:
    return json.loads(_with_suffix(stem, ".json").read_bytes())


def metadata(name_or_path: str | os.PathLike) -> dict:
    """The metadata a model was saved with (training data, validation metrics, ...), without loading its weights."""
    return _read_doc(resolve(name_or_path)).get("metadata", {})


TABLE_COLUMNS = ("MODEL", "DEFAULT", "TYPE", "ITERS", "Z0", "RANGE", "VAL RMSE", "VALIDATED ON", "IMAGES SEEN")


def default_mark(defaults: dict[str, str], name: str) -> str:
    """The DEFAULT cell of model `name`: the scenes whose default it is (`defaults`: scene -> model name), "all"
    when it is the default of every scene, blank for none."""
    scenes = [s for s, m in defaults.items() if m == name]
    return "all" if len(scenes) == len(defaults) > 1 else ", ".join(scenes)


def table(defaults: dict[str, str]) -> str:
    """The shipped models as a text table in aligned columns (TABLE_COLUMNS), one row per model, from each model's
    config and metadata: DEFAULT names the scene(s) whose default it is (`default_mark`; `defaults`: scene ->
    name, e.g. lipjax.shipped.DEFAULT_MODELS), blank for the others; TYPE is "LIP, <prox>" or the end-to-end network's
    type; ITERS and Z0 (the initial estimate) are LIP's; RANGE the max depth; VAL RMSE, metres, on VALIDATED ON
    (its sampler); IMAGES SEEN the training budget (metadata images_seen); "-" where unknown or not applicable."""
    rows = [TABLE_COLUMNS]
    for name in available():
        config = config_from_dict(_read_doc(resolve(name))["config"])
        meta = metadata(name)
        rmse = meta.get("val_metrics", {}).get("rmse_m")
        if isinstance(config, LIPConfig):
            prior = {cls: p for p, cls in PRIOR_TYPES.items()}[type(config.prior)]
            kind, iters, z0 = f"LIP, {prior}", str(config.num_iterations), config.initial_estimate
        else:
            kind, iters, z0 = model_type_name(config), "-", "-"
        rows.append((name, default_mark(defaults, name), kind, iters, z0,
                     f"{config.max_depth_m:g} m", "-" if rmse is None else f"{rmse:.4f} m",
                     meta.get("val_sampler", "-"),
                     f"{meta['images_seen']:,}" if "images_seen" in meta else "-"))
    widths = [max(len(r[i]) for r in rows) for i in range(len(TABLE_COLUMNS))]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows)


def listing() -> str:
    """What `lipjax models` prints: the `table` of the shipped models (their defaults marked) and its legend, or
    where to get a model when none is shipped."""
    if not available():
        return (f"no shipped models in {WEIGHTS_DIR}; `lipjax complete` then uses an untrained model. Train one "
                "with `python -m experiments.train --config lip_cnn_indoor`, or pass --model PATH.")
    return (table(DEFAULT_MODELS) + "\n\nDEFAULT: the inputs lipjax complete gives the model: indoor (scattered "
            f"samples), outdoor (LiDAR scan lines or a\nmedian sample depth over {OUTDOOR_MEDIAN_M:g} m) or all "
            "(every input); --model NAME overrides it. TYPE: LIP and its prox, or an\nend-to-end network. VAL RMSE: "
            "on the model's own validation frames (VALIDATED ON); for a model of rooms and streets\n(both samplers "
            "named) rooms and streets together, so it is not comparable with the RMSE of a model of one scene.")


def load(name_or_path: str | os.PathLike) -> tuple[object, dict, dict]:
    """(config, params, metadata) of a shipped model name or a saved model path; ModelFileError if unusable."""
    stem = resolve(name_or_path)
    json_path, msgpack_path = _with_suffix(stem, ".json"), _with_suffix(stem, ".msgpack")
    fix = ("reinstall lipjax" if stem.parent == WEIGHTS_DIR
           else "save the model again (lipjax.model_io.save writes both files together)")
    try:
        doc = _read_doc(stem)
        config = config_from_dict(doc["config"])
    except (ValueError, TypeError, KeyError, AttributeError) as exc:  # JSONDecodeError is a ValueError
        raise ModelFileError(f"{json_path}: not a valid lipjax model config ({_describe(exc)}); {fix}") from exc
    packed = msgpack_path.read_bytes()
    try:
        params = flax.serialization.msgpack_restore(packed)
    except Exception as exc:  # noqa: BLE001 - msgpack raises several types for damaged data
        raise ModelFileError(f"{msgpack_path}: cannot read the parameters, the file is damaged or truncated "
                             f"({_describe(exc)}); {fix}") from exc
    params = jax.tree_util.tree_map(lambda a: np.asarray(a), params)
    mismatch = _mismatch(config, params)
    if mismatch:
        raise ModelFileError(f"{msgpack_path} does not match {json_path.name} ({mismatch}): the two files come "
                             f"from different models; {fix}")
    digest = hashlib.sha256(packed).hexdigest()
    if doc.get("params_sha256", digest) != digest:  # a model saved before 2026-12-08 has none
        raise ModelFileError(f"{msgpack_path} is not the parameter file saved with {json_path.name} (its SHA-256 "
                             f"is not params_sha256): changed since, or from another save; {fix}")
    return config, params, doc.get("metadata", {})


def _describe(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or "empty"
    text = f"{type(exc).__name__}: {text}"
    return text if len(text) <= 160 else text[:157] + "..."


def _mismatch(config, params) -> str:
    """What differs between the parameters a config makes and `params` ("" when they fit)."""
    expected = jax.eval_shape(config.init, jax.random.key(0))
    if not isinstance(params, dict) or set(params) != set(expected):
        have = sorted(params) if isinstance(params, dict) else type(params).__name__
        return f"the config makes parameters {sorted(expected)}, the file holds {have}"

    def flat(tree):
        return {".".join(str(getattr(k, "key", k)) for k in path): tuple(np.shape(leaf))
                for path, leaf in jax.tree_util.tree_leaves_with_path(tree)}

    want, have = flat(expected), flat(params)
    for name in sorted(set(want) | set(have)):
        if want.get(name) != have.get(name):
            return (f"{name}: the config makes {want.get(name, 'nothing')}, the file holds "
                    f"{have.get(name, 'nothing')}")
    return ""
