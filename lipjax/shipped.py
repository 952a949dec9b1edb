"""The models shipped with the package: where their files are, which exist, and which are the defaults.

A leaf: it imports nothing from lipjax, so the input checks (lipjax.inputs) and the model files (lipjax.model_io)
can both name shipped models without importing each other.
"""
from __future__ import annotations

import pathlib

# A shipped model is `<name>.json` + `<name>.msgpack` in this folder (lipjax.model_io reads them).
WEIGHTS_DIR = pathlib.Path(__file__).parent / "weights"

# The default shipped model per scene, chosen on synthetic sensor-size frames through the default path by a rule
# fixed before the real frames were scored (benchmarks/default_choice.py: lowest geometric-mean RMSE ratio to linear
# over rooms at 480x640 and streets at 352x1216): this pair 0.705, lip-any (one model for both) 0.732, the pair before
# (lip-fast-indoor + lip-ad-outdoor) 0.748.
DEFAULT_MODELS = {"indoor": "lip-fast-indoor", "outdoor": "lip-ad-fast-outdoor"}
DEFAULT_MODEL = DEFAULT_MODELS["indoor"]


def available() -> list[str]:
    """Names of the models shipped with the package (those with both files), sorted."""
    return sorted(p.stem for p in WEIGHTS_DIR.glob("*.msgpack") if p.with_suffix(".json").exists())
