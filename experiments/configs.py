"""Training configurations (configs are code). Each entry: what it trains, the command, the expected runtime.

    python -m experiments.train --config lip_cnn_indoor            # ~1 h on 2 idle CPU cores
    python -m experiments.train --config lip_ad_indoor             # needs lip_cnn_indoor's weights first
    python -m experiments.train --config smoke                     # seconds after compilation: a check, not a model

Shipped weights (lipjax/weights/<name>) come from these configs, trained on the embedded synthetic data:
random 128x160 crops of 256x320 indoor renders, or 128x208 crops of 128x416 outdoor (KITTI-aspect) renders,
with a mixture of sparse patterns so that one model serves several sensors (lipjax.data.sampling.Mixture).
"""
from __future__ import annotations

import dataclasses

from lipjax.baselines.networks import baseline_preset
from lipjax.data.augment import DEFAULT_TRAINING as DEFAULT_AUGMENT
from lipjax.discriminator import Discriminator
from lipjax.model import LIPConfig
from lipjax.priors.guided import PRESETS as GUIDED_PRESETS
from lipjax.priors.network import network_preset
from lipjax.train.config import DataConfig, TrainConfig

INDOOR_MAX_DEPTH_M = 10.0
OUTDOOR_MAX_DEPTH_M = 85.0

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
#   + inverse-depth term (lipjax.losses.inverse_depth_loss, 1/m, floor 1 m; also penalises depth below the floor
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

# End-to-end learned baselines (lipjax.baselines.networks; Ma et al. [2], U-Net [6], CSPN [7]): the same data,
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
    for scene, lip, depth in (("indoor", LIP_CNN_INDOOR, INDOOR_MAX_DEPTH_M), ("outdoor", LIP_CNN_OUTDOOR, OUTDOOR_MAX_DEPTH_M))
}

# The shared-encoder prox (lipjax.priors.guided): ~3x cheaper per frame than the paper-style G above, so it can
# train ~3x longer for the same CPU time. Started from the linear fill (identity-initialised), L1 loss, with the
# augmentation real sensors need (lipjax.data.augment.DEFAULT_TRAINING). Reads pre-rendered frames when given
# --set data.source=rendered --set data.root=DIR (`lipjax data render`), else renders on the fly.
LIP_FAST_INDOOR = dataclasses.replace(
    LIP_CNN_INDOOR, name="lip-fast-indoor", model=_fast_model(INDOOR_MAX_DEPTH_M, INDOOR_INITIAL_ESTIMATE),
    data=dataclasses.replace(INDOOR_DATA, augment=DEFAULT_AUGMENT),
    g_steps=8000, learning_rate=1e-3, warmup_steps=200, eval_every=500, checkpoint_every=100,
)

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
    "smoke": SMOKE,
    **BASELINE_CONFIGS,
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
        if kind in (tuple, "tuple"):  # e.g. a crop: "128,160"
            return tuple(int(v) for v in text.split(","))
        return {"int": int, "float": float, "str": str}.get(kind, kind)(text)
    except ValueError:
        want = "true or false" if kind in (bool, "bool") else getattr(kind, "__name__", kind)
        raise ValueError(f"config field {key!r} takes {want}, not {text!r}") from None
