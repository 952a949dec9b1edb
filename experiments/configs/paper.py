"""The paper's methods on the embedded synthetic scenes: LIP+CNN, LIP+AD (the paper's prox and the fast prox) and
the end-to-end baselines.

The shipped models of both scenes (Table I, rooms; Table II, streets) are the equal-budget study's seed-0 models at
STUDY_BUDGET[scene] training images each (issue 52; experiments/equal_budget.py, experiments/configs/study.py), so
that each table compares equal budgets, each model at the learning rate the study's tuning chose on the scene's
validation split. A trunk's config (lip_cnn_<scene>, lip_fast_<scene>, the end-to-end networks) is its run from
random weights to the cool-down's start; LIP+AD's (lip_ad_<scene>, lip_ad_fast_<scene>) is its adversarial cool-down,
here from the shipped trunk model. The study made the shipped models, trunk and cool-down, and makes them again
exactly (it tunes again, in a fresh --scores):

    python -m experiments.equal_budget --scene indoor --seeds 0 --images 30000 --curve 30000 \\
        --methods lip-cnn,lip-ad --root runs/remake --scores runs/remake/scores
    python -m experiments.train --config lip_cnn_indoor          # the trunk alone: 24,000 images, ~1.5 h on 2 cores
"""
from __future__ import annotations

from experiments.configs.base import END_TO_END_TYPES, Expected
from experiments.configs.study import METHODS, SCENES, shipped_config, shipped_expected, trunk_of
from lipjax.train.config import TrainConfig

# Per scene: the study's budget of the shipped models (the largest it reached for all seven methods of the scene),
# and each trunk's learning rate, the lowest validation RMSE after 3,000 images
# (experiments/study_scores/<scene>/tuning.json; tests/test_configs.py reads it).
STUDY_BUDGET = {"indoor": 30_000, "outdoor": 30_000}
STUDY_RATES = {
    "indoor": {"ma2018": 3.125e-3, "unet": 7.8125e-3, "cspn": 3.125e-3, "lip-cnn": 5e-4, "lip-fast": 8e-5},
    "outdoor": {"ma2018": 3.125e-3, "unet": 1.25e-3, "cspn": 3.125e-3, "lip-cnn": 1.25e-3, "lip-fast": 5e-4},
}
STUDY = {scene: {method: shipped_config(method, scene, budget=STUDY_BUDGET[scene],
                                        learning_rate=STUDY_RATES[scene][trunk_of(method)])
                 for method in METHODS}
         for scene in SCENES}

LIP_CNN_INDOOR, LIP_CNN_OUTDOOR = STUDY["indoor"]["lip-cnn"], STUDY["outdoor"]["lip-cnn"]

BASELINE_CONFIGS: dict[str, TrainConfig] = {
    f"{key}_{scene}": STUDY[scene][key] for scene in SCENES for key in END_TO_END_TYPES}

CONFIGS: dict[str, TrainConfig] = {
    f"{method.replace('-', '_')}_{scene}": STUDY[scene][method]
    for scene in SCENES for method in METHODS if method not in END_TO_END_TYPES}

# What the shipped weights of these configs reached (lipjax/weights/<name>.json, "val_metrics" and "images_seen");
# as `python -m experiments.ship_study --images 30000 --scene <scene>` printed them.
EXPECTED: dict[str, Expected] = {
    "ma2018_indoor": shipped_expected(val_rmse_m=0.2469129, images=30_000, cooldown=6_000),
    "unet_indoor": shipped_expected(val_rmse_m=0.2026831, images=30_000, cooldown=6_000),
    "cspn_indoor": shipped_expected(val_rmse_m=0.1937541, images=30_000, cooldown=6_000),
    "lip_cnn_indoor": shipped_expected(val_rmse_m=0.1875187, images=30_000, cooldown=6_000),
    "lip_fast_indoor": shipped_expected(val_rmse_m=0.1940343, images=30_000, cooldown=6_000),
    "lip_ad_indoor": shipped_expected(val_rmse_m=0.1874051, images=30_000, cooldown=6_000, trunk="lip-cnn"),
    "lip_ad_fast_indoor": shipped_expected(val_rmse_m=0.1938957, images=30_000, cooldown=6_000, trunk="lip-fast"),
    "ma2018_outdoor": shipped_expected(val_rmse_m=4.818515, images=30_000, cooldown=6_000),
    "unet_outdoor": shipped_expected(val_rmse_m=3.792536, images=30_000, cooldown=6_000),
    "cspn_outdoor": shipped_expected(val_rmse_m=3.346198, images=30_000, cooldown=6_000),
    "lip_cnn_outdoor": shipped_expected(val_rmse_m=2.670375, images=30_000, cooldown=6_000),
    "lip_fast_outdoor": shipped_expected(val_rmse_m=2.808302, images=30_000, cooldown=6_000),
    "lip_ad_outdoor": shipped_expected(val_rmse_m=2.66819, images=30_000, cooldown=6_000, trunk="lip-cnn"),
    "lip_ad_fast_outdoor": shipped_expected(val_rmse_m=2.885722, images=30_000, cooldown=6_000, trunk="lip-fast"),
}
