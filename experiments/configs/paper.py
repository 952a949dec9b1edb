"""The paper's methods on the embedded synthetic scenes: LIP+CNN, LIP+AD (the paper's prox and the fast prox) and
the end-to-end baselines.

Rooms (Table I): the shipped models are the equal-budget study's seed-0 models at INDOOR_BUDGET training images each
(issue 52; experiments/equal_budget.py, experiments/configs/study.py), so that Table I compares equal budgets, each
at the learning rate the study's tuning chose on the validation split. A trunk's config (lip_cnn_indoor,
lip_fast_indoor, the end-to-end networks) is its run from random weights to the cool-down's start; LIP+AD's
(lip_ad_indoor, lip_ad_fast_indoor) is its adversarial cool-down, here from the shipped trunk model. The study made
the shipped models, trunk and cool-down, and makes them again exactly (it tunes again, in a fresh --scores):

    python -m experiments.equal_budget --scene indoor --seeds 0 --images 30000 --curve 30000 \\
        --methods lip-cnn,lip-ad --root runs/remake --scores runs/remake/scores
    python -m experiments.train --config lip_cnn_indoor          # the trunk alone: 24,000 images, ~1.5 h on 2 cores

Streets (Table II): the earlier runs, each one `dataclasses.replace` of the scene base, until the study's streets
are shipped:

    python -m experiments.train --config lip_cnn_outdoor            # ~1 h on 2 idle CPU cores
    python -m experiments.train --config lip_ad_outdoor             # needs lip_cnn_outdoor's weights first
"""
from __future__ import annotations

import dataclasses

from experiments.configs.base import END_TO_END_TYPES, OUTDOOR, OUTDOOR_MAX_DEPTH_M, Expected, end_to_end_model
from experiments.configs.study import METHODS, shipped_config, shipped_expected, trunk_of
from lipjax.train.config import TrainConfig
from lipjax.train.discriminator import Discriminator

# The study's budget of the shipped rooms models, and each trunk's learning rate: the lowest validation RMSE after
# 3,000 images (experiments/study_scores/indoor/tuning.json; tests/test_configs.py reads it).
INDOOR_BUDGET = 30_000
INDOOR_RATES = {"ma2018": 3.125e-3, "unet": 7.8125e-3, "cspn": 3.125e-3, "lip-cnn": 5e-4, "lip-fast": 8e-5}
INDOOR_STUDY = {method: shipped_config(method, "indoor", budget=INDOOR_BUDGET,
                                       learning_rate=INDOOR_RATES[trunk_of(method)])
                for method in METHODS}

LIP_CNN_INDOOR = INDOOR_STUDY["lip-cnn"]
LIP_CNN_OUTDOOR = dataclasses.replace(OUTDOOR, name="lip-cnn-outdoor")
# LIP+AD: start from the LIP+CNN model, pretrain D with G frozen, then train both (paper Sec. III-B).
LIP_AD_OUTDOOR = dataclasses.replace(
    OUTDOOR, name="lip-ad-outdoor", init_from="lip-cnn-outdoor", g_steps=0, d_steps=50, adv_steps=200,
    learning_rate=2e-4, warmup_steps=20, adv_weight=1e-3, discriminator=Discriminator(max_depth_m=OUTDOOR_MAX_DEPTH_M),
)


def baseline(base: TrainConfig, name: str, method: str, depth_scale: str | None = None, **run) -> TrainConfig:
    """The LIP+CNN run of scene `base` (data, batch size, depth loss, steps, schedule; `run`: fields of a real-data
    run) with the end-to-end network `method` (base.END_TO_END_TYPES) seeing depth in units of `depth_scale`.
    Without the inverse-depth term: from random initialisation it diverged."""
    model = end_to_end_model(method, base.model.max_depth_m, depth_scale=depth_scale)
    return dataclasses.replace(base, name=name, model=model, inverse_depth_weight=0.0, **run)


BASELINE_CONFIGS: dict[str, TrainConfig] = {
    **{f"{key}_indoor": INDOOR_STUDY[key] for key in END_TO_END_TYPES},
    **{f"{key}_outdoor": baseline(OUTDOOR, f"{key}-outdoor", key) for key in END_TO_END_TYPES},
}

CONFIGS: dict[str, TrainConfig] = {
    **{f"{method.replace('-', '_')}_indoor": INDOOR_STUDY[method]
       for method in METHODS if method not in END_TO_END_TYPES},
    "lip_cnn_outdoor": LIP_CNN_OUTDOOR,
    "lip_ad_outdoor": LIP_AD_OUTDOOR,
}

# What the shipped weights of these configs reached (lipjax/weights/<name>.json, "val_metrics" and "images_seen");
# the rooms' entries as `python -m experiments.ship_study --images 30000 --scene indoor` printed them.
EXPECTED: dict[str, Expected] = {
    "ma2018_indoor": shipped_expected(val_rmse_m=0.2469129, images=30_000, cooldown=6_000),
    "unet_indoor": shipped_expected(val_rmse_m=0.2026831, images=30_000, cooldown=6_000),
    "cspn_indoor": shipped_expected(val_rmse_m=0.1937541, images=30_000, cooldown=6_000),
    "lip_cnn_indoor": shipped_expected(val_rmse_m=0.1875187, images=30_000, cooldown=6_000),
    "lip_fast_indoor": shipped_expected(val_rmse_m=0.1940343, images=30_000, cooldown=6_000),
    "lip_ad_indoor": shipped_expected(val_rmse_m=0.1874051, images=30_000, cooldown=6_000, trunk="lip-cnn"),
    "lip_ad_fast_indoor": shipped_expected(val_rmse_m=0.1938957, images=30_000, cooldown=6_000, trunk="lip-fast"),
    "lip_cnn_outdoor": Expected(val_rmse_m=4.115104, images_seen=7_200),
    "lip_ad_outdoor": Expected(val_rmse_m=4.078569, images_seen=9_200),
    "ma2018_outdoor": Expected(val_rmse_m=7.428356, images_seen=7_200),
    "unet_outdoor": Expected(val_rmse_m=5.535435, images_seen=7_200),
    "cspn_outdoor": Expected(val_rmse_m=4.304113, images_seen=7_200, note="trained on one H100 GPU"),
}
