"""Training configurations (configs are code). Each entry: what it trains, the command, the expected runtime.

    python -m experiments.train --config lip_cnn_indoor            # ~1 h on 2 idle CPU cores
    python -m experiments.train --config lip_ad_indoor             # needs lip_cnn_indoor's weights first
    python -m experiments.train --config smoke                     # seconds after compilation: a check, not a model
    python -m experiments.train --config lip_cnn_nyu --set data.root=DIR --export runs/lip_cnn_nyu/model   # real data

Real data sets and your own folders: lip_cnn_nyu, lip_ad_nyu, lip_cnn_kitti, lip_ad_kitti, lip_cnn_tartanair,
lip_cnn_folder and the baselines on them (below, each with its protocol, sampler, budget and estimated runtime).
Nothing is exported unless --export PATH is given.

Shipped weights (lipjax/weights/<name>) come from these configs, trained on the embedded synthetic data:
random 128x160 crops of 256x320 indoor renders, or 128x208 crops of 128x416 outdoor (KITTI-aspect) renders,
with a mixture of sparse patterns so that one model serves several sensors (lipjax.data.sampling.Mixture).
"""
from __future__ import annotations

import dataclasses

from lipjax.networks import baseline_preset
from lipjax.data.augment import DEFAULT_TRAINING as DEFAULT_AUGMENT
from lipjax.train.discriminator import Discriminator
from lipjax.interfaces import SCENE_MAX_DEPTH_M
from lipjax.model import LIPConfig
from lipjax.priors.guided import PRESETS as GUIDED_PRESETS
from lipjax.priors.network import network_preset
from lipjax.train.config import DataConfig, TrainConfig
from lipjax.train.folder import folder_config

INDOOR_MAX_DEPTH_M = SCENE_MAX_DEPTH_M["indoor"]  # the models' depth range (lipjax.interfaces)
OUTDOOR_MAX_DEPTH_M = SCENE_MAX_DEPTH_M["outdoor"]

INDOOR_DATA = DataConfig(
    kind="indoor", height=256, width=320, crop=(128, 160),
    train_sampler="uniform:200|uniform:100|uniform:500|uniform:1000|bernoulli:200",
    val_sampler="uniform:200", val_images=32,
)
OUTDOOR_DATA = DataConfig(
    kind="outdoor", height=128, width=416, crop=(128, 208),
    train_sampler="lidar:hdl64|lidar:vlp32|lidar:vlp16|uniform:500|uniform:200",
    val_sampler="lidar:hdl64", val_images=32,
)


# z_0, the initial estimate the learned prox starts from: the classical fill with the lowest MAE on the scene's
# validation split (Delaunay linear indoors; nearest outdoors, where linear interpolation across the large
# depth jumps between LiDAR rows is worse and 100x slower). An untrained model returns exactly this fill (the
# residual prox starts as the identity), so training starts from the best classical baseline and refines it.
INDOOR_INITIAL_ESTIMATE = "linear"
OUTDOOR_INITIAL_ESTIMATE = "nearest"


def _model(max_depth_m: float, initial_estimate: str, preset: str = "small", iterations: int = 3,
           output: str = "x", depth_domain: str = "linear") -> LIPConfig:
    prior = dataclasses.replace(network_preset(preset, max_depth_m=max_depth_m), depth_domain=depth_domain)
    return LIPConfig(prior=prior, num_iterations=iterations, initial_estimate=initial_estimate, output=output)


def _fast_model(max_depth_m: float, initial_estimate: str) -> LIPConfig:
    """The shared-encoder prox (lipjax.priors.guided "fast"), read out from the last prox (always positive)."""
    prior = dataclasses.replace(GUIDED_PRESETS["fast"], max_depth_m=max_depth_m)
    return LIPConfig(prior=prior, num_iterations=3, initial_estimate=initial_estimate, output="z")


# The loss is L1, not the paper's L2: starting from the linear fill, L2 training raised the validation MAE
# (0.095 m -> 0.104 m at step 200 -> 0.113 m at step 400, RMSE 0.215 -> 0.212 m; runs/lip-cnn-indoor-v2-l2):
# L2 hedges between the two sides of a depth edge, which costs MAE; L1 does not.
LIP_CNN_INDOOR = TrainConfig(
    name="lip-cnn-indoor", model=_model(INDOOR_MAX_DEPTH_M, INDOOR_INITIAL_ESTIMATE), data=INDOOR_DATA,
    batch_size=8, g_steps=1200, learning_rate=5e-4, loss="l1", eval_every=200, checkpoint_every=50,
)
# Outdoors the L1 depth loss alone left 123 validation pixels (in 10 of 32 frames) below 1 m, mostly negative (down
# to -15 m against ~15 m truth): thin poles above the top LiDAR beam, in a region that is mostly sky and so
# unsupervised. A handful of such pixels costs the depth loss nothing but ruins the inverse-depth metrics (val
# iRMSE 4135 1/km against 13 for the nearest fill). What was tried, on the 32 val frames (RMSE m / iRMSE 1/km):
#   + inverse-depth term (lipjax.train.losses.inverse_depth_loss, 1/m, floor 1 m; also penalises depth below the floor
#     where there is no ground truth): 2 such pixels left, made by the final dual step's extrapolation
#     z_K - u_K = 2 z_K - x_K - u_{K-1}: 4.344 / 177 (runs/lip-cnn-outdoor-v4, shipped in session 3);
#   + output read from the last prox (LIPConfig.output="z"): the prox itself then made 6: 4.346 / 397 (v5);
#   + inverse-depth weight 10, 30 or 100 (stopped at steps 400-600): no better on iRMSE (12.7-12.8, against 12.5
#     for weight 1 at step 600, before its bad pixels appeared) and worse on RMSE (5.10-5.11 against 4.50);
#   + the prox in log depth (NetworkPrior.depth_domain="log": z = v * exp(residual), relative corrections) with the
#     output read from the last prox: no depth <= 0 is possible any more, and it was better on every metric:
#     4.115 / 11.9, MAE 1.148 m against 1.273 (runs/lip-cnn-outdoor-log). That is the shipped model.
LIP_CNN_OUTDOOR = dataclasses.replace(
    LIP_CNN_INDOOR, name="lip-cnn-outdoor",
    model=_model(OUTDOOR_MAX_DEPTH_M, OUTDOOR_INITIAL_ESTIMATE, output="z", depth_domain="log"),
    data=OUTDOOR_DATA, g_steps=900, inverse_depth_weight=1.0, inverse_depth_floor_m=1.0,
)
# LIP+AD: start from the LIP+CNN model, pretrain D with G frozen, then train both (paper Sec. III-B).
LIP_AD_INDOOR = dataclasses.replace(
    LIP_CNN_INDOOR, name="lip-ad-indoor", init_from="lip-cnn-indoor", g_steps=0, d_steps=50, adv_steps=200,
    learning_rate=2e-4, warmup_steps=20, adv_weight=1e-3, discriminator=Discriminator(max_depth_m=INDOOR_MAX_DEPTH_M),
)
LIP_AD_OUTDOOR = dataclasses.replace(
    LIP_AD_INDOOR, name="lip-ad-outdoor", model=LIP_CNN_OUTDOOR.model, data=OUTDOOR_DATA,
    init_from="lip-cnn-outdoor", discriminator=Discriminator(max_depth_m=OUTDOOR_MAX_DEPTH_M),
    inverse_depth_weight=LIP_CNN_OUTDOOR.inverse_depth_weight,
    inverse_depth_floor_m=LIP_CNN_OUTDOOR.inverse_depth_floor_m,
)

# End-to-end learned baselines (lipjax.networks; Ma et al. [2], U-Net [6], CSPN [7]): the same data,
# samplers, batch size, loss, schedule and step budget as the LIP+CNN run of their scene, with a "small" preset of
# about LIP small's parameter count over its 3 iterations (1.48 M):
#     ma2018_*  SparseToDense, ResNet-34 basic blocks at 1/4 width, random init   1,553,369 parameters
#     unet_*    UNet, base width 14, 4 levels                                      1,488,439 parameters
#     cspn_*    CSPN, U-Net backbone of base width 14, 12 propagation steps        1,489,567 parameters
# The shipped cspn_* weights were trained on one H100 (JAX 0.11.2, --set data.num_workers=5, 10-12 min each beside
# other runs, bound by the CPU rendering the synthetic scenes); every other shipped model on the 2-core CPU.
BASELINE_PRESET = "small"


# One exception to "the same loss": the outdoor inverse-depth term. Ma et al.'s network trained with it from random
# initialisation diverged to val RMSE 65 m / iRMSE 191,814 1/km in 900 steps (runs/ma2018-outdoor-v4; with L1
# alone: 7.43 m), so the end-to-end networks train with the depth loss alone, their better setting.
def _baseline(lip: TrainConfig, name: str, model_type: str, max_depth_m: float) -> TrainConfig:
    """The LIP+CNN run `lip` (data, batch size, depth loss, steps, schedule) with another model."""
    model = baseline_preset(model_type, BASELINE_PRESET, max_depth_m=max_depth_m)
    return dataclasses.replace(lip, name=name, model=model, inverse_depth_weight=0.0)


BASELINE_CONFIGS: dict[str, TrainConfig] = {
    f"{key}_{scene}": _baseline(lip, f"{key}-{scene}", model_type, depth)
    for key, model_type in (("ma2018", "sparse_to_dense"), ("unet", "unet"), ("cspn", "cspn"))
    for scene, lip, depth in (("indoor", LIP_CNN_INDOOR, INDOOR_MAX_DEPTH_M),
                              ("outdoor", LIP_CNN_OUTDOOR, OUTDOOR_MAX_DEPTH_M))
}

# Scattered points plus LiDAR scan lines on the rooms (a 64-beam and a 16-beam pattern at 0.4 deg azimuth steps,
# about 7,800 and 2,200 points on a 256x320 room): real sensors give either, and a prox trained on scan lines as
# well beats linear interpolation on more real frames (docs/design-notes.md, "Scan lines on rooms").
FAST_INDOOR_SAMPLER = INDOOR_DATA.train_sampler + "|lidar:hdl64,azimuth_step_deg=0.4|lidar:vlp16,azimuth_step_deg=0.4"
# The shared-encoder prox (lipjax.priors.guided): a third of the paper-style G's FLOPs per frame and ~2.7x its
# train-step rate here, so it trains longer for the same CPU time. Started from the linear fill (identity-
# initialised), L1 loss, zoom / flip / photometric / blur augmentation (lipjax.data.augment.DEFAULT_TRAINING).
# The shipped lip-fast-indoor (100,000 images) is this config, trained in three runs on the 2-core CPU:
#     lipjax data render --kind indoor --split train --count 12000 --out runs/data/indoor-train-256x320
#     python -m experiments.train --config lip_fast_indoor --set data.source=rendered \
#         --set data.root=runs/data/indoor-train-256x320 --export lipjax/weights/lip-fast-indoor
# (3,500 steps, 28,000 images, ~75 min; its first 1,000 steps at learning rate 1e-3, cosine over 8,000 steps, with
# sample noise and outliers on, then resumed at step 1,000 with these settings), then continued from those weights
# for 4,500 steps (36,000 images, ~80 min; scattered samples only, 64,000 images in all), validation RMSE
# 0.198 -> 0.174 m (docs/training/lip-fast-indoor-to-64k.png):
#     ... --set init_from=lip-fast-indoor --set g_steps=4500 --set learning_rate=3e-4 --set warmup_steps=200
# (both runs with INDOOR_DATA's scattered samplers: add --set "data.train_sampler=..." to repeat them exactly),
# then with LiDAR scan lines added to the rooms' samplers (FAST_INDOOR_SAMPLER, now this config's) for 4,500 more
# steps (100,000 images in all, ~100 min), exported as the mean of its last 4 checkpoints, validation RMSE
# 0.1742 -> 0.1694 m (docs/training/lip-fast-indoor.png):
#     ... --set init_from=lip-fast-indoor --set g_steps=4500 --set learning_rate=1e-4 --set warmup_steps=100 \
#         --set checkpoint_every=250 --set keep_checkpoints=40 --set data.num_workers=1 --set eval_every=500
#     python -m experiments.train ...the same... --export-only --average 4 --export lipjax/weights/lip-fast-indoor
LIP_FAST_INDOOR = dataclasses.replace(
    LIP_CNN_INDOOR, name="lip-fast-indoor", model=_fast_model(INDOOR_MAX_DEPTH_M, INDOOR_INITIAL_ESTIMATE),
    data=dataclasses.replace(INDOOR_DATA, augment=DEFAULT_AUGMENT, train_sampler=FAST_INDOOR_SAMPLER),
    g_steps=3500, learning_rate=5e-4, warmup_steps=200, eval_every=500, checkpoint_every=100,
)
# The outdoor counterpart: nearest fill (as lip-cnn-outdoor), the inverse-depth term, 128x208 crops of 128x416
# renders (zoom >= 1 only: the renders are no taller than the crop, see lipjax.data.augment). The shipped
# lip-fast-outdoor (74,400 images, of which 10,400 outdoor) is the shipped lip-fast-indoor's parameters trained
# 1,300 steps on 10,000 pre-rendered streets (~50 min here, shared with other jobs):
#     lipjax data render --kind outdoor --split train --count 10000 --out runs/data/outdoor-train-128x416
#     python -m experiments.train --config lip_fast_outdoor --set data.source=rendered \
#         --set data.root=runs/data/outdoor-train-128x416 --export lipjax/weights/lip-fast-outdoor
# (validation RMSE 3.81, 3.44, 3.56 m at steps 500, 1,000, 1,300).
LIP_FAST_OUTDOOR = dataclasses.replace(
    LIP_FAST_INDOOR, name="lip-fast-outdoor", model=_fast_model(OUTDOOR_MAX_DEPTH_M, OUTDOOR_INITIAL_ESTIMATE),
    data=dataclasses.replace(OUTDOOR_DATA, augment=DEFAULT_AUGMENT),
    inverse_depth_weight=LIP_CNN_OUTDOOR.inverse_depth_weight,
    inverse_depth_floor_m=LIP_CNN_OUTDOOR.inverse_depth_floor_m,
    init_from="lip-fast-indoor", g_steps=1300, learning_rate=3e-4, warmup_steps=100,
)
# LIP+AD on the fast prox: D sees differences of log depth (Discriminator(inputs="log_gradients")): with depth /
# max_depth, the paper's D stayed at chance (held-out accuracy 0.49-0.50 after 100 steps at lr 2e-4 or 1e-3, and
# 4x wider); with log-depth differences it reached 0.76-0.89 (benchmarks/discriminator_probe.py --steps 100
# --train 16 --val 8, G = lip-ad-indoor; 0.87-0.93 at 400 steps with --train 64 --val 32). The previous
# lip-ad-fast-indoor was this config from the 64,000-image lip-fast-indoor, on the rendered frames (--set
# data.source=rendered --set data.root=runs/data/indoor-train-256x320): D accuracy 0.67 after its 100 steps, 0.79 on
# average over the 300 joint steps (0.90 at the end); validation RMSE 0.1729 / MAE 0.0652 m against 0.1742 / 0.0663
# for lip-fast-indoor. At learning rate 2e-4 (the earlier setting) the same run ended worse than its start (0.1760 /
# 0.0678): after a run whose cosine schedule has decayed to zero, the joint steps need a small learning rate.
# The shipped lip-ad-fast-indoor (103,200 images) is this config from the 100,000-image lip-fast-indoor, exported as
# the mean of its last 3 checkpoints (steps 200-400: `--set init_from=PATH` of that model, then `--export-only
# --average 3`): validation RMSE 0.1691 m against 0.1694 (its last checkpoint alone: 0.1699, behind its start);
# D accuracy 0.60 after its 100 steps, 0.77 on average over the joint steps.
LIP_AD_FAST_INDOOR = dataclasses.replace(
    LIP_FAST_INDOOR, name="lip-ad-fast-indoor", init_from="lip-fast-indoor", g_steps=0, d_steps=100, adv_steps=300,
    learning_rate=5e-5, warmup_steps=20, adv_weight=1e-3,
    discriminator=Discriminator(max_depth_m=INDOOR_MAX_DEPTH_M, inputs="log_gradients"),
)
# lip-ad-fast-outdoor is LIP_AD_FAST_OUTDOOR from the shipped lip-fast-outdoor on the rendered streets (--set
# data.source=rendered --set data.root=runs/data/outdoor-train-128x416; 77,600 images): D accuracy 0.86 after its
# 100 steps, 0.83 on average over the 300 joint steps; validation RMSE 3.454 / MAE 0.974 m against 3.558 / 1.038.
LIP_AD_FAST_OUTDOOR = dataclasses.replace(
    LIP_AD_FAST_INDOOR, name="lip-ad-fast-outdoor", model=LIP_FAST_OUTDOOR.model, data=LIP_FAST_OUTDOOR.data,
    init_from="lip-fast-outdoor", inverse_depth_weight=LIP_FAST_OUTDOOR.inverse_depth_weight,
    inverse_depth_floor_m=LIP_FAST_OUTDOOR.inverse_depth_floor_m,
    discriminator=Discriminator(max_depth_m=OUTDOOR_MAX_DEPTH_M, inputs="log_gradients"),
)

# lip-any: one model for rooms and streets, any sensor (issue 22). The shared-encoder prox (its network never sees a
# metric depth: log depth relative to the frame's own samples) from the shipped lip-fast-indoor, trained on rooms and
# streets interleaved (data.kind="mixed", both rendered at 256x320), each frame's error in units of its own sample
# scale (loss_scale="samples"), from 50 to 5,000 scattered points, 16- to 64-beam scans at random mount pitch, noise
# and bleed-through outliers on some, and colour texture without depth edges (augment.texture_prob). Its initial
# estimate is the linear fill, the reference it has to beat everywhere.
ANY_SAMPLER = "|".join((
    "uniform:50", "uniform:200", "uniform:200", "uniform:500", "uniform:1000", "uniform:5000", "bernoulli:2000",
    "uniform:300+noise:rel=0.01,outliers=0.03",
    "lidar:hdl64,azimuth_step_deg=0.4", "lidar:vlp32,azimuth_step_deg=0.3,mount_pitch_deg=-3",
    "lidar:vlp16,azimuth_step_deg=0.4,mount_pitch_deg=2", "lidar:hdl64+noise:rel=0.005,outliers=0.02",
))
ANY_AUGMENT = dataclasses.replace(DEFAULT_AUGMENT, zoom=(0.6, 1.6), texture_prob=0.3)
LIP_ANY = dataclasses.replace(
    LIP_FAST_INDOOR, name="lip-any", model=_fast_model(OUTDOOR_MAX_DEPTH_M, INDOOR_INITIAL_ESTIMATE),
    data=dataclasses.replace(INDOOR_DATA, kind="mixed", augment=ANY_AUGMENT, train_sampler=ANY_SAMPLER,
                             val_sampler="uniform:200|lidar:hdl64", val_images=32),
    loss_scale="samples", init_from="lip-fast-indoor", g_steps=4000, learning_rate=2e-4, warmup_steps=100,
    eval_every=500, checkpoint_every=250, keep_checkpoints=40,
)

# ---- The paper's data sets and your own (lipjax.data.sources). Each run reads its frames from --set data.root=DIR:
#     python -m experiments.train --config lip_cnn_nyu --set data.root=/data/nyudepthv2 --export runs/lip_cnn_nyu/model
# Runtimes on one GPU are ESTIMATES, not measurements: no GPU was lent to the session that wrote these configs.
# They assume GPU_IMAGES_PER_S training images/s at 256x320 (scaled by pixel count for other sizes), which needs the
# grain loader with ~16 workers (benchmarks/train_throughput.py gives the per-worker rate of each source); the one
# GPU measurement so far was input-bound at 14-25 images/s with the old thread loader (issue 14).
GPU_IMAGES_PER_S = 400
NYU_PAPER_DATA = DataConfig(
    source="nyu_h5", protocol="nyu_paper", crop=None, train_sampler="uniform:200", val_sampler="uniform:200",
    val_images=64, num_workers=8,
)
KITTI_PAPER_DATA = DataConfig(
    source="kitti_dc", protocol="kitti_paper", crop=None, train_sampler="input", val_sampler="input",
    val_images=32, num_workers=8,
)
TARTANAIR_DATA = dataclasses.replace(NYU_PAPER_DATA, source="tartanair", protocol="tartanair")

# lip_cnn_nyu. Protocol nyu_paper: NYU v2 h5 frames (Ma et al. layout), centre crop 464x580, resize 256x320; depth
# 0-10 m. Sampler: 200 uniform ground-truth pixels (the paper's setting), keyed by frame id. Budget: 20000 steps x
# batch 16 = 320k images (~6.7 epochs of the 47584 training frames), L1 loss from the linear fill. Expected
# runtime on one GPU: ~13 min at GPU_IMAGES_PER_S (estimate). Source nyu_tfds reads a prepared TFDS instead:
# --set data.source=nyu_tfds --set data.root=TFDS_DATA_DIR.
LIP_CNN_NYU = dataclasses.replace(
    LIP_CNN_INDOOR, name="lip-cnn-nyu", data=NYU_PAPER_DATA, batch_size=16, g_steps=20000, warmup_steps=500,
    eval_every=1000, checkpoint_every=500,
)
# lip_ad_nyu. LIP+AD from the exported lip_cnn_nyu model: D pretrained 500 steps with G frozen, then 2000 joint
# steps (protocol and sampler as lip_cnn_nyu). Budget 40k images, ~2 min at GPU_IMAGES_PER_S (estimate, plus the
# discriminator's cost). Needs `--export runs/lip_cnn_nyu/model` on the lip_cnn_nyu run first (or --set init_from=).
LIP_AD_NYU = dataclasses.replace(
    LIP_AD_INDOOR, name="lip-ad-nyu", data=NYU_PAPER_DATA, batch_size=16, init_from="runs/lip_cnn_nyu/model",
    d_steps=500, adv_steps=2000, eval_every=500, checkpoint_every=250,
)
# lip_cnn_kitti. Protocol kitti_paper: KITTI depth completion train/val, bottom crop 256x1216; depth 0-80 m. Sampler:
# the real projected Velodyne scan (velodyne_raw, sampler "input"), not points drawn from the ground truth, which is
# the semi-dense annotated depth. Model: the outdoor LIP (log-depth prox, nearest fill). Budget: 30000 steps x
# batch 8 = 240k images (~2.8 epochs of 86k frames). Expected runtime on one GPU: ~38 min at GPU_IMAGES_PER_S
# scaled by pixels (256x1216 is 3.8x 256x320; estimate).
LIP_CNN_KITTI = dataclasses.replace(
    LIP_CNN_OUTDOOR, name="lip-cnn-kitti", data=KITTI_PAPER_DATA, batch_size=8, g_steps=30000, warmup_steps=500,
    eval_every=1000, checkpoint_every=500,
)
# lip_ad_kitti. LIP+AD from the exported lip_cnn_kitti model (500 D + 2000 joint steps, batch 8, as lip_cnn_kitti's
# data). Budget 20k images, ~3 min at GPU_IMAGES_PER_S scaled by pixels (estimate). Needs lip_cnn_kitti exported to
# runs/lip_cnn_kitti/model (or --set init_from=).
LIP_AD_KITTI = dataclasses.replace(
    LIP_AD_OUTDOOR, name="lip-ad-kitti", data=KITTI_PAPER_DATA, batch_size=8, init_from="runs/lip_cnn_kitti/model",
    d_steps=500, adv_steps=2000, eval_every=500, checkpoint_every=250,
)
# lip_cnn_tartanair. Protocol tartanair: left-camera frames, centre crop 480x600, resize 256x320, depth 0-80 m;
# split 90/5/5 by trajectory. Sampler: 200 uniform points. Model: the outdoor LIP (log-depth prox: TartanAir spans
# indoor and outdoor depths). Budget: 20000 steps x batch 16 = 320k images. Expected runtime on one GPU: ~13 min at
# GPU_IMAGES_PER_S (estimate).
LIP_CNN_TARTANAIR = dataclasses.replace(
    LIP_CNN_OUTDOOR, name="lip-cnn-tartanair", data=TARTANAIR_DATA, batch_size=16, g_steps=20000, warmup_steps=500,
    eval_every=1000, checkpoint_every=500,
)
# lip_cnn_folder. Your own RGB-D frames (lipjax.data.folder layout: rgb/, depth/, intrinsics; train/ and val/
# subfolders, else the last 5 % of the frames validate), fine-tuned from the shipped lip-cnn-indoor. Protocol: none
# (frames as they are, random 128x160 crops; --set data.crop=H,W). Sampler: a mixture of 200 / 500 uniform and
# 200 Bernoulli points; "input" uses your own sparse/<stem> maps. PNG depth needs --set data.depth_scale=1000 (or
# 256, 5000). Budget: 2000 steps x batch 8 = 16k images: ~15 min on a 2-core CPU at this repository's measured
# ~20 images/s, well under a minute on one GPU (estimate). The same run: `lipjax train --data DIR --out MODEL`.
LIP_CNN_FOLDER = folder_config(LIP_CNN_INDOOR.model, "lip-cnn-indoor")  # = `lipjax train --data DIR`
# The end-to-end baselines on the same data (Ma et al., U-Net, CSPN; the preset of the synthetic baselines above):
# each takes its LIP+CNN run's data, protocol, sampler, batch size, loss and step budget, so its runtime is about
# that run's (the networks have about LIP small's parameter count).
REAL_DATA_BASELINES: dict[str, TrainConfig] = {
    f"{key}_{scene}": _baseline(lip, f"{key}-{scene}", model_type, depth)
    for key, model_type in (("ma2018", "sparse_to_dense"), ("unet", "unet"), ("cspn", "cspn"))
    for scene, lip, depth in (("nyu", LIP_CNN_NYU, INDOOR_MAX_DEPTH_M), ("kitti", LIP_CNN_KITTI, OUTDOOR_MAX_DEPTH_M),
                              ("tartanair", LIP_CNN_TARTANAIR, OUTDOOR_MAX_DEPTH_M))
}

SMOKE = TrainConfig(
    name="smoke", model=LIPConfig(prior=network_preset("tiny"), num_iterations=2),
    data=DataConfig(kind="indoor", height=48, width=64, crop=(32, 48), val_images=4),
    batch_size=2, g_steps=4, d_steps=2, adv_steps=2, log_every=2, eval_every=8, checkpoint_every=4,
)

CONFIGS: dict[str, TrainConfig] = {
    "lip_cnn_indoor": LIP_CNN_INDOOR,
    "lip_cnn_outdoor": LIP_CNN_OUTDOOR,
    "lip_ad_indoor": LIP_AD_INDOOR,
    "lip_ad_outdoor": LIP_AD_OUTDOOR,
    "lip_fast_indoor": LIP_FAST_INDOOR,
    "lip_fast_outdoor": LIP_FAST_OUTDOOR,
    "lip_ad_fast_indoor": LIP_AD_FAST_INDOOR,
    "lip_ad_fast_outdoor": LIP_AD_FAST_OUTDOOR,
    "lip_any": LIP_ANY,
    "smoke": SMOKE,
    **BASELINE_CONFIGS,
    "lip_cnn_nyu": LIP_CNN_NYU,
    "lip_ad_nyu": LIP_AD_NYU,
    "lip_cnn_kitti": LIP_CNN_KITTI,
    "lip_ad_kitti": LIP_AD_KITTI,
    "lip_cnn_tartanair": LIP_CNN_TARTANAIR,
    "lip_cnn_folder": LIP_CNN_FOLDER,
    **REAL_DATA_BASELINES,
}


def get_config(name: str, overrides: dict[str, str] | None = None) -> TrainConfig:
    """A named config with `field=value` overrides of scalar fields, nested ones dotted.

    E.g. {'g_steps': '200'} or {'data.num_workers': '8'} (more loader threads on a machine with many cores).
    """
    if name not in CONFIGS:
        raise ValueError(f"unknown config {name!r}; choose one of {sorted(CONFIGS)}")
    config = CONFIGS[name]
    for key, text in (overrides or {}).items():
        config = _override(config, key.split("."), text, key)
    return config


def _override(obj, path: list[str], text: str, key: str):
    """`obj` (a frozen dataclass) with the field at `path` set to `text` converted to the field's current type."""
    fields = {f.name: f for f in dataclasses.fields(obj)}
    if path[0] not in fields:
        raise ValueError(f"unknown config field {key!r}; fields of {type(obj).__name__}: {sorted(fields)}")
    current = getattr(obj, path[0])
    if len(path) > 1:
        if not dataclasses.is_dataclass(current):
            raise ValueError(f"config field {key!r}: {path[0]!r} has no sub-fields")
        value = _override(current, path[1:], text, key)
    elif dataclasses.is_dataclass(current):
        raise ValueError(f"config field {key!r} is a group; set one of its fields, e.g. {key}.<field>=...")
    else:
        value = _parse_value(text, str(fields[path[0]].type), current, key)
    return dataclasses.replace(obj, **{path[0]: value})


def _parse_value(text: str, annotation: str, current, key: str):
    """`text` as the type of a field: its current value's type, else the first type of its annotation."""
    if text == "None":
        return None
    kind = type(current) if current is not None else annotation.split("|")[0].split("[")[0].strip()
    try:
        if kind in (bool, "bool"):  # bool("False") would be True
            if text.lower() not in ("true", "false"):
                raise ValueError
            return text.lower() == "true"
        if kind in (tuple, "tuple"):  # e.g. a crop "128,160", or a zoom range "0.75,1.33" (float like the field)
            element = float if any(isinstance(v, float) for v in current or ()) else int
            return tuple(element(v) for v in text.split(","))
        return {"int": int, "float": float, "str": str}.get(kind, kind)(text)
    except ValueError:
        want = "true or false" if kind in (bool, "bool") else getattr(kind, "__name__", kind)
        raise ValueError(f"config field {key!r} takes {want}, not {text!r}") from None
