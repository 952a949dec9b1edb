"""The paper's models on the embedded synthetic scenes: LIP+CNN, LIP+AD and the end-to-end baselines, each one
`dataclasses.replace` of its scene base (experiments/configs/base.py).

    python -m experiments.train --config lip_cnn_indoor            # ~1 h on 2 idle CPU cores
    python -m experiments.train --config lip_ad_indoor             # needs lip_cnn_indoor's weights first
"""
from __future__ import annotations

import dataclasses

from experiments.configs.base import (END_TO_END_TYPES, INDOOR, INDOOR_MAX_DEPTH_M, OUTDOOR, OUTDOOR_MAX_DEPTH_M,
                                      Expected, end_to_end_model)
from lipjax.train.config import TrainConfig
from lipjax.train.discriminator import Discriminator

LIP_CNN_INDOOR = dataclasses.replace(INDOOR, name="lip-cnn-indoor")
LIP_CNN_OUTDOOR = dataclasses.replace(OUTDOOR, name="lip-cnn-outdoor")

# LIP+AD: start from the LIP+CNN model, pretrain D with G frozen, then train both (paper Sec. III-B).
LIP_AD_INDOOR = dataclasses.replace(
    INDOOR, name="lip-ad-indoor", init_from="lip-cnn-indoor", g_steps=0, d_steps=50, adv_steps=200,
    learning_rate=2e-4, warmup_steps=20, adv_weight=1e-3, discriminator=Discriminator(max_depth_m=INDOOR_MAX_DEPTH_M),
)
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
    f"{key}_{scene}": baseline(base, f"{key}-{scene}", key)
    for key in END_TO_END_TYPES for scene, base in (("indoor", INDOOR), ("outdoor", OUTDOOR))
}

CONFIGS: dict[str, TrainConfig] = {
    "lip_cnn_indoor": LIP_CNN_INDOOR,
    "lip_cnn_outdoor": LIP_CNN_OUTDOOR,
    "lip_ad_indoor": LIP_AD_INDOOR,
    "lip_ad_outdoor": LIP_AD_OUTDOOR,
}

# What the shipped weights of these configs reached (lipjax/weights/<name>.json, "val_metrics" and "images_seen").
EXPECTED: dict[str, Expected] = {
    "lip_cnn_indoor": Expected(val_rmse_m=0.2069898, images_seen=9_600),
    "lip_cnn_outdoor": Expected(val_rmse_m=4.115104, images_seen=7_200),
    "lip_ad_indoor": Expected(val_rmse_m=0.2075945, images_seen=11_600),
    "lip_ad_outdoor": Expected(val_rmse_m=4.078569, images_seen=9_200),
    "ma2018_indoor": Expected(val_rmse_m=1.172203, images_seen=9_600),
    "ma2018_outdoor": Expected(val_rmse_m=7.428356, images_seen=7_200),
    "unet_indoor": Expected(val_rmse_m=0.5477983, images_seen=9_600),
    "unet_outdoor": Expected(val_rmse_m=5.535435, images_seen=7_200),
    "cspn_indoor": Expected(val_rmse_m=0.4424063, images_seen=9_600, note="trained on one H100 GPU"),
    "cspn_outdoor": Expected(val_rmse_m=4.304113, images_seen=7_200, note="trained on one H100 GPU"),
}
