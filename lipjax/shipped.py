"""The models shipped with the package: where their files are, which exist, and which are the defaults.

A leaf: it imports nothing from lipjax but the default path's numbers (lipjax.defaults), so the input checks
(lipjax.inputs) and the model files (lipjax.model_io) can both name shipped models without importing each other.
"""
from __future__ import annotations

import pathlib

from lipjax.defaults import DEFAULT_MODEL

# A shipped model is `<name>.json` + `<name>.msgpack` in this folder (lipjax.model_io reads them).
WEIGHTS_DIR = pathlib.Path(__file__).parent / "weights"

# The default shipped model (DEFAULT_MODEL, lipjax.defaults): one model, lip-any, for rooms and streets and every
# sensor, which `lipjax complete` and lipjax.complete run on every input. The rule, fixed before the real frames were
# scored: lip-any is the default for every input if it is within 10 % of the per-scene models on the synthetic tables
# (Table I 0.1544 m against lip-ad-fast-indoor's 0.1762, bound 0.1938; Table II 3042 mm against lip-ad-fast-outdoor's
# 3661, bound 4027: `python -m experiments.nyu_200pts`, `python -m experiments.kitti_dc`, at 1,572,640 images;
# 0.1894 m and 4016 mm when it was first chosen, at 164,000). The per-scene models are the equal-budget study's since
# 2026-12-06 (rooms) and 2026-12-07 (streets), 30,000 images each; against the best of them lip-any still holds:
# Table I 0.1544 m against lip-cnn-indoor's 0.2017, Table II 3042 mm against lip-cnn-outdoor's 2934, bound 3228. The
# per-scene models stay, for the paper's tables and by name. Per scene, for what still names a scene's model: the
# model `lipjax train` starts from (lipjax.train.folder.default_init), the input checks' advice, `lipjax models`'
# DEFAULT column.
DEFAULT_MODELS = {"indoor": DEFAULT_MODEL, "outdoor": DEFAULT_MODEL}


def available() -> list[str]:
    """Names of the models shipped with the package (those with both files), sorted."""
    return sorted(p.stem for p in WEIGHTS_DIR.glob("*.msgpack") if p.with_suffix(".json").exists())
