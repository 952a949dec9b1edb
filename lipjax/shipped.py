"""The models shipped with the package: where their files are, which exist, and which are the defaults.

A leaf: it imports nothing from lipjax, so the input checks (lipjax.inputs) and the model files (lipjax.model_io)
can both name shipped models without importing each other.
"""
from __future__ import annotations

import pathlib

# A shipped model is `<name>.json` + `<name>.msgpack` in this folder (lipjax.model_io reads them).
WEIGHTS_DIR = pathlib.Path(__file__).parent / "weights"

# The default shipped model per scene. Indoor: the shared-encoder model, ahead of lip-ad-indoor on Table I and on
# the real NYU frames (README Results).
DEFAULT_MODELS = {"indoor": "lip-fast-indoor", "outdoor": "lip-ad-outdoor"}
DEFAULT_MODEL = DEFAULT_MODELS["indoor"]


def available() -> list[str]:
    """Names of the models shipped with the package (those with both files), sorted."""
    return sorted(p.stem for p in WEIGHTS_DIR.glob("*.msgpack") if p.with_suffix(".json").exists())
