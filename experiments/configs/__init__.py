"""Training configurations (configs are code): each named config is one `dataclasses.replace` of a scene base
(base.py: INDOOR, OUTDOOR, MIXED) and states the result its shipped weights reached (EXPECTED).

    python -m experiments.train --config lip_cnn_indoor            # ~1.5 h on 2 idle CPU cores
    python -m experiments.train --config lip_ad_indoor             # needs lip_cnn_indoor's weights first
    python -m experiments.train --config smoke                     # seconds after compilation: a check, not a model
    python -m experiments.train --config lip_cnn_nyu --set data.root=DIR --export runs/lip_cnn_nyu/model   # real data

Families: paper.py (LIP+CNN, LIP+AD with the paper's prox and the fast prox, and the end-to-end baselines on the
synthetic scenes: the equal-budget study's), lip_any.py (the default model), real.py (NYU v2, KITTI DC, TartanAir,
your folder). Nothing is exported unless --export PATH is given. How the shipped weights were trained:
docs/training.md.
"""
from __future__ import annotations

from experiments.configs import lip_any, paper, real
from experiments.configs.base import OUTDOOR_DATA, Expected
from experiments.configs.paper import BASELINE_CONFIGS, LIP_CNN_INDOOR, LIP_CNN_OUTDOOR
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset
from lipjax.train.config import DataConfig, TrainConfig, apply_overrides

__all__ = ["BASELINE_CONFIGS", "CONFIGS", "EXPECTED", "LIP_CNN_INDOOR", "LIP_CNN_OUTDOOR", "OUTDOOR_DATA", "SMOKE",
           "Expected", "get_config"]

# A check of the training loop, not a model: a tiny prox on 48x64 rooms, every phase for a few steps.
SMOKE = TrainConfig(
    name="smoke", model=LIPConfig(prior=network_preset("tiny"), num_iterations=2),
    data=DataConfig(kind="indoor", height=48, width=64, crop=(32, 48), val_images=4),
    batch_size=2, g_steps=4, d_steps=2, adv_steps=2, log_every=2, eval_every=8, checkpoint_every=4,
)

CONFIGS: dict[str, TrainConfig] = {
    **paper.CONFIGS, **lip_any.CONFIGS, "smoke": SMOKE, **BASELINE_CONFIGS, **real.CONFIGS, **real.REAL_DATA_BASELINES,
}
# Keyed as CONFIGS: the configs whose weights are shipped (lipjax/weights/<config name>), and what they reached.
EXPECTED: dict[str, Expected] = {**paper.EXPECTED, **lip_any.EXPECTED}


def get_config(name: str, overrides: dict[str, str] | None = None) -> TrainConfig:
    """A named config with `field=value` overrides (lipjax.train.config.apply_overrides), nested fields dotted.

    E.g. {'g_steps': '200'} or {'data.num_workers': '8'} (more loader processes on a machine with many cores).
    """
    if name not in CONFIGS:
        raise ValueError(f"unknown config {name!r}; choose one of {sorted(CONFIGS)}")
    return apply_overrides(CONFIGS[name], overrides)
