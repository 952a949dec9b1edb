"""The scene bases every named config is built from, in one `dataclasses.replace`: INDOOR, OUTDOOR and MIXED.

A base holds what its scene needs (data, model, loss) and the synthetic LIP+CNN schedule; a named config
(experiments/configs/paper.py, lip_any.py, real.py) changes the run: its name, model variant, data source, budget.
Why each choice was made, and the runs behind it: docs/decisions/ and docs/training.md, "How the shipped models were
trained" (the run history: `git log -p -- docs/training.md`).
"""
from __future__ import annotations

import dataclasses

from lipjax.data.augment import DEFAULT_TRAINING as DEFAULT_AUGMENT
from lipjax.interfaces import SCENE_MAX_DEPTH_M
from lipjax.model import LIPConfig
from lipjax.networks import baseline_preset
from lipjax.priors.fast import PRESETS as FAST_PRESETS
from lipjax.priors.network import network_preset
from lipjax.train.config import DataConfig, TrainConfig

INDOOR_MAX_DEPTH_M = SCENE_MAX_DEPTH_M["indoor"]  # the models' depth range (lipjax.interfaces)
OUTDOOR_MAX_DEPTH_M = SCENE_MAX_DEPTH_M["outdoor"]


@dataclasses.dataclass(frozen=True)
class Expected:
    """What a config's shipped model (lipjax/weights/<config name>) reached, as its metadata records it.

    val_rmse_m: validation RMSE (metres) on the config's val_sampler and val_images, to 7 significant digits.
    images_seen: training images of all its steps, with those of the model it started from (init_from).
    budget_from_config: its steps and images follow from this config as written (steps = total_steps, from the
      shipped init_from model); False where it was trained in several runs or from an older init model (note).
    note: how it was trained, where that is more than this config.
    """

    val_rmse_m: float
    images_seen: int
    budget_from_config: bool = True
    note: str = ""


# Rooms: random 128x160 crops of 256x320 renders. Streets: 128x208 crops of 128x416 (KITTI-aspect) renders. A
# mixture of sparse patterns, so that one model serves several sensors (lipjax.data.sampling.Mixture).
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
# Rooms and streets interleaved, both rendered at 256x320: 50 to 5,000 scattered points, 16- to 64-beam scans at
# random mount pitch, noise and bleed-through outliers on some, returns seen through edges from a sensor beside the
# camera (lipjax.data.parallax), image keypoints, dense depth with holes; colour texture without depth edges, light
# without geometry, camera noise.
MIXED_SAMPLER = "|".join((
    "uniform:50", "uniform:200", "uniform:200", "uniform:500", "uniform:1000", "uniform:5000", "bernoulli:2000",
    "uniform:300+noise:rel=0.01,outliers=0.03",
    "lidar:hdl64,azimuth_step_deg=0.4", "lidar:vlp32,azimuth_step_deg=0.3,mount_pitch_deg=-3",
    "lidar:vlp16,azimuth_step_deg=0.4,mount_pitch_deg=2", "lidar:hdl64+noise:rel=0.005,outliers=0.02",
    "keypoint:500", "holes:0.3",  # a structure-from-motion map; a stereo / ToF camera's dense depth with holes
    # the sensor beside the camera: a LiDAR 5-30 cm off (KITTI's: 29 cm), an RGB-D camera's 2-8 cm
    "lidar:hdl64+parallax:min_m=0.05,max_m=0.3", "uniform:1000+parallax:min_m=0.02,max_m=0.08",
))
# Zoom 0.5 shows whole 256x320 frames at half scale (KITTI-size streets at their working size); texture on one
# rectangle and camera noise against the renders' clean, flat surfaces, and light that follows no geometry
# (research/README.md: edge_statistics, nuisances). The reference cameras only. Runs 7-12 trained with texture on up to
# 6 rectangles and focal lengths 0.7-1.4x the reference: from the shipped model, 44,000 images of that recipe came to
# 0.7814 on `python -m benchmarks.generalisation` (run 10), 44,320 of this one to 0.7723 (run 14, with the parallax
# patterns too; runs in git: `git log -p -- docs/training.md`).
# Rooms with a window onto a street (lipjax.data.synthetic.far_view): a closed room never shows a far sample, and the
# prox learned to reject them (research/README.md, far_views).
MIXED_FAR_VIEW_PROB = 0.3
MIXED_DATA = dataclasses.replace(
    INDOOR_DATA, kind="mixed", train_sampler=MIXED_SAMPLER, val_sampler="uniform:200|lidar:hdl64",
    augment=dataclasses.replace(DEFAULT_AUGMENT, zoom=(0.5, 1.6), texture_prob=0.8, texture_strength=0.7,
                                sensor_noise=0.02, jpeg_prob=0.3, illumination_prob=0.5, illumination_strength=0.7),
    far_view_prob=MIXED_FAR_VIEW_PROB,
)

# z_0, the fill the learned prox starts from (an untrained model returns it): the classical fill with the lowest
# validation MAE per scene. Linear interpolation across the depth jumps between LiDAR rows is worse outdoors.
INDOOR_INITIAL_ESTIMATE = "linear"
OUTDOOR_INITIAL_ESTIMATE = "nearest"


def lip_model(max_depth_m: float, initial_estimate: str, output: str = "x",
              depth_domain: str = "linear") -> LIPConfig:
    """The paper-style LIP: the "small" network prox (lipjax.priors.network), 3 iterations."""
    prior = dataclasses.replace(network_preset("small", max_depth_m=max_depth_m), depth_domain=depth_domain)
    return LIPConfig(prior=prior, num_iterations=3, initial_estimate=initial_estimate, output=output)


# The end-to-end networks (lipjax.networks): Ma et al. [2], U-Net [6], CSPN [7], at about LIP small's parameter count.
END_TO_END_TYPES = {"ma2018": "sparse_to_dense", "unet": "unet", "cspn": "cspn"}
END_TO_END_PRESET = "small"
# The study's and the real-data runs' networks see depth in units of each frame's own sample scale
# (lipjax.networks.common.DEPTH_SCALES; the shipped baselines, until the study's replace them, the depth range). In
# units of the 10 m depth range, Ma et al. at 3,000 images scored a validation RMSE of 1.22 m and ignored the samples'
# level (its per-frame medians barely followed the truth's; GroupNorm erases a frame's absolute level); in units of
# the samples, 0.53 m at the same budget and learning rate (docs/decisions/0027-end-to-end-depth-unit.md).
END_TO_END_DEPTH_SCALE = "samples"


def end_to_end_model(method: str, max_depth_m: float, preset: str = END_TO_END_PRESET,
                     depth_scale: str | None = None):
    """The end-to-end network `method` (a key of END_TO_END_TYPES) at lipjax.networks preset `preset`, seeing depth
    in units of `depth_scale` (lipjax.networks.common.DEPTH_SCALES; None: the network's default)."""
    model = baseline_preset(END_TO_END_TYPES[method], preset, max_depth_m=max_depth_m)
    return model if depth_scale is None else dataclasses.replace(model, depth_scale=depth_scale)


def fast_model(max_depth_m: float, initial_estimate: str) -> LIPConfig:
    """The fast prox (lipjax.priors.fast "fast"), read out from the last prox (always positive)."""
    prior = dataclasses.replace(FAST_PRESETS["fast"], max_depth_m=max_depth_m)
    return LIPConfig(prior=prior, num_iterations=3, initial_estimate=initial_estimate, output="z")


# L1, not the paper's L2: L2 hedges between the two sides of a depth edge, which costs MAE.
INDOOR = TrainConfig(
    name="indoor", model=lip_model(INDOOR_MAX_DEPTH_M, INDOOR_INITIAL_ESTIMATE), data=INDOOR_DATA,
    batch_size=8, g_steps=1200, learning_rate=5e-4, loss="l1", eval_every=200, checkpoint_every=50,
)
# Outdoors the prox works in log depth, read out from the last prox (no depth <= 0 is possible), and an
# inverse-depth term keeps thin poles above the top beam from ruining iRMSE.
OUTDOOR = TrainConfig(
    name="outdoor", data=OUTDOOR_DATA,
    model=lip_model(OUTDOOR_MAX_DEPTH_M, OUTDOOR_INITIAL_ESTIMATE, output="z", depth_domain="log"),
    batch_size=8, g_steps=900, learning_rate=5e-4, loss="l1", eval_every=200, checkpoint_every=50,
    inverse_depth_weight=1.0, inverse_depth_floor_m=1.0,
)
# Rooms and streets: the fast prox (it never sees a metric depth) from the "auto" fill (nearest on scan
# lines, linear elsewhere: benchmarks/initial_estimate.py), each frame's error in units of its own sample scale. No
# schedule: its config (lip_any.py) sets it.
MIXED = TrainConfig(
    name="mixed", model=fast_model(OUTDOOR_MAX_DEPTH_M, "auto"), data=MIXED_DATA,
    batch_size=8, loss="l1", loss_scale="samples",
)
SCENES: dict[str, TrainConfig] = {"indoor": INDOOR, "outdoor": OUTDOOR, "mixed": MIXED}
