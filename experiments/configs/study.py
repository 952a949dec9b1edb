"""The equal-budget study's methods (experiments/equal_budget.py): every learned method of Tables I and II as one
trunk config on one scene's data, and the cool-down that finishes its model at each budget, supervised or (LIP+AD)
adversarial.

A trunk trains from random weights with a constant learning rate after its warm-up (TrainConfig.schedule
"constant"), so that its checkpoint at n images is the same model whatever the run's length: one run per seed serves
every budget of the data-efficiency curve. The model at budget N is the trunk's at N - C (C = COOLDOWN_FRACTION of
N) cooled down over C more images: the rate warms up again and decays linearly to 0 (schedule "linear";
warmup-stable-decay), as the methods' own papers end their runs with a decaying rate. Every run of a scene reads the
same frames, crops and samples: the scene base's data (experiments/configs/base.py) with the study's seed.

LIP+AD (paper Sec. III-B) is its trunk's cool-down made adversarial: from the same LIP model at N - C, D is
pretrained with G frozen (FINISH_D_STEPS steps), then G and D train together for the rest, on the frames of the
trunk's cool-down. LIP+AD and its LIP+CNN then differ only in the adversarial term, and both have read N images.
"""
from __future__ import annotations

import dataclasses
import os
import pathlib

from experiments.configs.base import (END_TO_END_DEPTH_SCALE, END_TO_END_PRESET, END_TO_END_TYPES, INDOOR, OUTDOOR,
                                      Expected, end_to_end_model, fast_model)
from lipjax.data.synthetic.dataset import SyntheticDataset
from lipjax.interfaces import SCENE_MAX_DEPTH_M
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset
from lipjax.train.config import DataConfig, TrainConfig
from lipjax.train.discriminator import Discriminator

SCENES = ("indoor", "outdoor")
BASES = {"indoor": INDOOR, "outdoor": OUTDOOR}
END_TO_END = tuple(END_TO_END_TYPES)  # the end-to-end networks (lipjax.networks)
TRUNKS = END_TO_END + ("lip-cnn", "lip-fast")  # trained from random weights
# branch -> (its trunk, what D sees): the paper's D on depth for the paper's prox; on log-depth gradients for the
# fast prox (its LIP+AD runs of 2026-11: on depth / max_depth D stayed at chance).
BRANCHES = {"lip-ad": ("lip-cnn", "depth"), "lip-ad-fast": ("lip-fast", "log_gradients")}
METHODS = TRUNKS + tuple(BRANCHES)
# The cool-down: its share of a budget, its warm-up steps, and D's pretraining steps in LIP+AD's (at most a fifth of
# them; the paper's LIP+AD configs use 50 D steps and 200 joint steps). It reads fresh frames: its data stream is
# seed + COOLDOWN_SEED_OFFSET (the trunk's own seed would read the trunk's first batches again: a batch is a
# function of the seed and the step), the same stream for LIP+CNN's and LIP+AD's.
COOLDOWN_FRACTION = 0.2
COOLDOWN_WARMUP_STEPS = 20
FINISH_D_STEPS = 50
COOLDOWN_SEED_OFFSET = 1000
WARMUP_STEPS = 100
# The study's runs, checkpoints and models (python -m experiments.equal_budget --root), and the seed whose models are
# shipped (python -m experiments.ship_study)
STUDY_ROOT = "runs/study"
SHIPPED_SEED = 0
# The tiny variant (tests; a check of the GPU script): tiny networks on 48x64 renders, 32x48 crops.
TINY_SIZE, TINY_CROP = (48, 64), (32, 48)


def trunk_of(method: str) -> str:
    """The trunk whose runs `method` comes from: a branch's trunk, else the method itself."""
    return BRANCHES[method][0] if method in BRANCHES else method


def branches_of(trunk: str, methods: tuple[str, ...] = METHODS) -> list[str]:
    """`trunk` and the branches of it among `methods`: the models one trunk run finishes."""
    return [trunk] + [m for m, (t, _) in BRANCHES.items() if t == trunk and m in methods]


def trunk_model(method: str, scene: str, tiny: bool = False):
    """The model of trunk `method` on `scene` (tiny: the tests' tiny networks)."""
    base, max_depth = BASES[scene], SCENE_MAX_DEPTH_M[scene]
    if method in END_TO_END:
        return end_to_end_model(method, max_depth, "tiny" if tiny else END_TO_END_PRESET, END_TO_END_DEPTH_SCALE)
    if method == "lip-cnn":
        return base.model if not tiny else dataclasses.replace(base.model, prior=dataclasses.replace(
            network_preset("tiny", max_depth_m=max_depth), depth_domain=base.model.prior.depth_domain))
    if tiny:
        return LIPConfig(prior=network_preset("tiny", max_depth_m=max_depth), num_iterations=2,
                         initial_estimate=base.model.initial_estimate)
    return fast_model(max_depth, base.model.initial_estimate)


def _run(method: str, scene: str, tiny: bool, **fields) -> TrainConfig:
    """One `dataclasses.replace` of the scene base: trunk `method`'s model, the study's run, and `fields`."""
    if method not in TRUNKS:
        raise ValueError(f"unknown trunk {method!r}; choose one of {TRUNKS}")
    base = BASES[scene]
    data = base.data if not tiny else dataclasses.replace(base.data, height=TINY_SIZE[0], width=TINY_SIZE[1],
                                                          crop=TINY_CROP, val_images=4)
    run = dict(model=trunk_model(method, scene, tiny), data=data, schedule="constant", init_from=None,
               keep_checkpoints=2, log_every=50)
    if method in END_TO_END:
        run["inverse_depth_weight"] = 0.0  # from random initialisation it diverged (experiments/configs/paper.py)
    return dataclasses.replace(base, **{**run, **fields})


def trunk_config(method: str, scene: str, *, learning_rate: float, seed: int, steps: int,
                 tiny: bool = False, name: str | None = None) -> TrainConfig:
    """The run of trunk `method` for `steps` steps (batch 8), named `name` (default study-<method>-<scene>): the
    scene base with that model, the constant schedule, checkpoints every 250 steps (2,000 images), validation every
    1,250 (10,000 images)."""
    return _run(method, scene, tiny, name=name or f"study-{method}-{scene}", seed=seed, learning_rate=learning_rate,
                g_steps=steps, d_steps=0, adv_steps=0, warmup_steps=WARMUP_STEPS, checkpoint_every=250,
                eval_every=1250)


def cooldown_config(method: str, scene: str, *, learning_rate: float, seed: int, init_from: str, images: int,
                    tiny: bool = False, name: str | None = None) -> TrainConfig:
    """The cool-down of `method` (a trunk, or a LIP+AD of BRANCHES) of seed `seed` on `scene` from its trunk's model
    at `init_from`, over `images` images (batch 8), named `name` (default study-<method>-<scene>): the trunk's
    `learning_rate`, warmed up again and decayed linearly to 0; for LIP+AD, FINISH_D_STEPS steps of D first (G
    frozen), then G and D together."""
    trunk, inputs = BRANCHES.get(method, (method, None))
    steps = images // BASES[scene].batch_size
    if steps < 2:
        raise ValueError(f"a cool-down of {images} images is {steps} step(s); it needs at least 2")
    run = dict(name=name or f"study-{method}-{scene}", init_from=init_from, seed=seed + COOLDOWN_SEED_OFFSET,
               learning_rate=learning_rate, schedule="linear", warmup_steps=COOLDOWN_WARMUP_STEPS, eval_every=steps,
               checkpoint_every=50)
    if inputs is None:
        return _run(trunk, scene, tiny, g_steps=steps, d_steps=0, adv_steps=0, **run)
    d_steps = max(1, min(FINISH_D_STEPS, steps // 5))
    return _run(trunk, scene, tiny, g_steps=0, d_steps=d_steps, adv_steps=steps - d_steps, adv_weight=1e-3,
                discriminator=Discriminator(max_depth_m=SCENE_MAX_DEPTH_M[scene], inputs=inputs), **run)


def cooldown_images(budget: int, fraction: float = COOLDOWN_FRACTION, batch: int = 8) -> int:
    """The cool-down's share of `budget` images, in whole batches."""
    return int(round(fraction * budget / batch)) * batch


def run_dir(root: str | os.PathLike, scene: str, method: str, learning_rate: float, seed: int) -> pathlib.Path:
    """The folder of `method`'s runs of `seed` at `learning_rate` on `scene` in the study's `root` (one per rate): a
    trunk's workdir, whose models/<images> are its exports; a cool-down's <budget>/ (its workdir) and
    <budget>/model."""
    return pathlib.Path(root) / scene / method / f"lr{learning_rate:g}" / f"seed{seed}"


def trunk_export(root: str | os.PathLike, scene: str, trunk: str, learning_rate: float, seed: int,
                 images: int) -> pathlib.Path:
    """Trunk `trunk`'s model at `images` images (the start of the cool-down of the budget it is 80 % of)."""
    return run_dir(root, scene, trunk, learning_rate, seed) / "models" / str(images)


def shipped_config(method: str, scene: str, *, learning_rate: float, budget: int,
                   cooldown_fraction: float = COOLDOWN_FRACTION, tiny: bool = False) -> TrainConfig:
    """The named config of the shipped model <method>-<scene> (python -m experiments.ship_study), the study's
    seed-SHIPPED_SEED model at `budget` images, its trunk trained at the tuned `learning_rate`. A trunk's: its run
    from random weights to the cool-down's start (budget - C images). A LIP+AD's: its adversarial cool-down over C
    images from the shipped trunk model <trunk>-<scene> (the study's starts from that trunk's model at budget - C,
    which is not shipped). The study makes the shipped model exactly, trunk and cool-down (python -m
    experiments.equal_budget with --seeds 0 --images BUDGET --curve BUDGET, a fresh --root and --scores)."""
    trunk, cooldown = trunk_of(method), cooldown_images(budget, cooldown_fraction)
    name = f"{method}-{scene}"
    if method in BRANCHES:
        return cooldown_config(method, scene, learning_rate=learning_rate, seed=SHIPPED_SEED,
                               init_from=f"{trunk}-{scene}", images=cooldown, tiny=tiny, name=name)
    return trunk_config(method, scene, learning_rate=learning_rate, seed=SHIPPED_SEED,
                        steps=(budget - cooldown) // BASES[scene].batch_size, tiny=tiny, name=name)


def test_split(scene: str, tiny: bool = False) -> SyntheticDataset:
    """The synthetic test split of Table I (rooms, 256x320) or Table II (streets, 128x416)."""
    data: DataConfig = BASES[scene].data
    h, w = TINY_SIZE if tiny else (data.height, data.width)
    return SyntheticDataset(scene, "test", height=h, width=w)


def shipped_expected(val_rmse_m: float, images: int, cooldown: int, trunk: str | None = None) -> Expected:
    """The EXPECTED entry (experiments/configs) of a study model that experiments.ship_study shipped: validation RMSE
    `val_rmse_m`, `images` training images of which the last `cooldown` a cool-down; `trunk`: a LIP+AD's trunk
    method, whose model its cool-down (with D) started from. Its config alone does not give that budget (a trunk's
    config is the trunk's run; a LIP+AD's starts from the shipped trunk model, the study's from the trunk's model
    before its cool-down), hence the note."""
    start = f"{trunk}'s trunk" if trunk else "this config"
    note = (f"the study's seed-{SHIPPED_SEED} run: {start} at a constant rate to {images - cooldown:,} images, then a "
            f"{cooldown:,}-image cool-down{' with D (this config, from that model)' if trunk else ''}")
    return Expected(val_rmse_m=val_rmse_m, images_seen=images, budget_from_config=False, note=note)
