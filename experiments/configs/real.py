"""The paper's data sets and your own folder (lipjax.data.sources): LIP+CNN, LIP+AD and the end-to-end baselines,
each one `dataclasses.replace` of its scene base (base.py) with the data set's run (data, batch, budget, schedule).
Each run reads its frames from --set data.root=DIR:

    python -m experiments.train --config lip_cnn_nyu --set data.root=/data/nyudepthv2 --export runs/lip_cnn_nyu/model

No weights of these configs are shipped. GPU runtimes are estimates at 400 training images/s at 256x320 (scaled by
pixel count), which needs the grain loader with ~16 workers; protocols and sources: docs/training.md,
"Data sources" (the estimates are in this module).
"""
from __future__ import annotations

import dataclasses
from typing import Any

from experiments.configs.base import (END_TO_END_DEPTH_SCALE, END_TO_END_TYPES, INDOOR, INDOOR_MAX_DEPTH_M, OUTDOOR,
                                      OUTDOOR_MAX_DEPTH_M, end_to_end_model)
from lipjax.train.config import DataConfig, TrainConfig
from lipjax.train.discriminator import Discriminator
from lipjax.train.folder import folder_config

NYU_PAPER_DATA = DataConfig(
    source="nyu_h5", protocol="nyu_paper", crop=None, train_sampler="uniform:200", val_sampler="uniform:200",
    val_images=64, num_workers=8,
)
# The real projected Velodyne scan (velodyne_raw) as input; the ground truth is the semi-dense annotated depth.
KITTI_PAPER_DATA = DataConfig(
    source="kitti_dc", protocol="kitti_paper", crop=None, train_sampler="input", val_sampler="input",
    val_images=32, num_workers=8,
)
TARTANAIR_DATA = DataConfig(
    source="tartanair", protocol="tartanair", crop=None, train_sampler="uniform:200", val_sampler="uniform:200",
    val_images=64, num_workers=8,
)

# The LIP+CNN run on each data set, shared by its baselines: 20,000 x 16 = 320k images on NYU v2 and TartanAir
# (~13 min on one GPU, estimate), 30,000 x 8 = 240k on KITTI DC (~38 min).
NYU_RUN: dict[str, Any] = dict(data=NYU_PAPER_DATA, batch_size=16, g_steps=20000, warmup_steps=500, eval_every=1000,
                               checkpoint_every=500)
KITTI_RUN: dict[str, Any] = dict(data=KITTI_PAPER_DATA, batch_size=8, g_steps=30000, warmup_steps=500,
                                 eval_every=1000, checkpoint_every=500)
TARTANAIR_RUN: dict[str, Any] = dict(NYU_RUN, data=TARTANAIR_DATA)

LIP_CNN_NYU = dataclasses.replace(INDOOR, name="lip-cnn-nyu", **NYU_RUN)
LIP_CNN_KITTI = dataclasses.replace(OUTDOOR, name="lip-cnn-kitti", **KITTI_RUN)
# TartanAir spans indoor and outdoor depths: the outdoor (log-depth) LIP.
LIP_CNN_TARTANAIR = dataclasses.replace(OUTDOOR, name="lip-cnn-tartanair", **TARTANAIR_RUN)
# LIP+AD from the exported LIP+CNN model: D pretrained 500 steps with G frozen, then 2,000 joint steps.
LIP_AD_NYU = dataclasses.replace(
    INDOOR, name="lip-ad-nyu", data=NYU_PAPER_DATA, batch_size=16, init_from="runs/lip_cnn_nyu/model",
    g_steps=0, d_steps=500, adv_steps=2000, learning_rate=2e-4, warmup_steps=20, adv_weight=1e-3,
    discriminator=Discriminator(max_depth_m=INDOOR_MAX_DEPTH_M), eval_every=500, checkpoint_every=250,
)
LIP_AD_KITTI = dataclasses.replace(
    OUTDOOR, name="lip-ad-kitti", data=KITTI_PAPER_DATA, batch_size=8, init_from="runs/lip_cnn_kitti/model",
    g_steps=0, d_steps=500, adv_steps=2000, learning_rate=2e-4, warmup_steps=20, adv_weight=1e-3,
    discriminator=Discriminator(max_depth_m=OUTDOOR_MAX_DEPTH_M), eval_every=500, checkpoint_every=250,
)
# Your own RGB-D frames, fine-tuned from the shipped lip-cnn-indoor: the run of `lipjax train --data DIR`.
LIP_CNN_FOLDER = folder_config(INDOOR.model, "lip-cnn-indoor")

CONFIGS: dict[str, TrainConfig] = {
    "lip_cnn_nyu": LIP_CNN_NYU,
    "lip_ad_nyu": LIP_AD_NYU,
    "lip_cnn_kitti": LIP_CNN_KITTI,
    "lip_ad_kitti": LIP_AD_KITTI,
    "lip_cnn_tartanair": LIP_CNN_TARTANAIR,
    "lip_cnn_folder": LIP_CNN_FOLDER,
}


def baseline(base: TrainConfig, name: str, method: str, **run) -> TrainConfig:
    """The LIP+CNN run `run` (data, batch, budget, schedule) of scene `base` with the end-to-end network `method`
    (base.END_TO_END_TYPES) in place of LIP, seeing depth in units of each frame's samples (END_TO_END_DEPTH_SCALE),
    without the inverse-depth term: from random initialisation it diverged."""
    model = end_to_end_model(method, base.model.max_depth_m, depth_scale=END_TO_END_DEPTH_SCALE)
    return dataclasses.replace(base, name=name, model=model, inverse_depth_weight=0.0, **run)


REAL_DATA_BASELINES: dict[str, TrainConfig] = {
    f"{key}_{data}": baseline(base, f"{key}-{data}", key, **run)
    for key in END_TO_END_TYPES
    for data, base, run in (("nyu", INDOOR, NYU_RUN), ("kitti", OUTDOOR, KITTI_RUN),
                            ("tartanair", OUTDOOR, TARTANAIR_RUN))
}
