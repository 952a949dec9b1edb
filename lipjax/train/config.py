"""Training configuration as typed, frozen dataclasses (configs are code: see experiments/configs/), and the
`--set FIELD=VALUE` overrides of `python -m experiments.train` (parse_overrides, apply_overrides).

A run has up to three phases, by global step:
    [0, g_steps)                      G supervised pretraining (the depth loss `loss`, L2 by default, L1 in the
                                      configs of the shipped models; through the whole unrolled solver)
    [g_steps, g_steps + d_steps)      D pretraining (cross-entropy, G frozen)
    [.., .. + adv_steps)              joint G + D adversarial training (LIP+AD)
LIP+CNN is g_steps only; LIP+AD adds the other two (usually starting from a LIP+CNN model via `init_from`).
"""
from __future__ import annotations

import dataclasses

from lipjax.data.augment import Augment
from lipjax.data.sampling import DEFAULT_SAMPLER
from lipjax.interfaces import LearnedModel
from lipjax.train.discriminator import Discriminator
from lipjax.train.losses import LOSS_KINDS


@dataclasses.dataclass(frozen=True)
class DataConfig:
    """Where the frames come from (lipjax.data.sources), the training crop and the sparse samplers.

    source, root: one of lipjax.data.sources.SOURCES and its folder ("synthetic" needs none; "rendered" also
    takes several folders of one frame size, "A,B", e.g. rooms and streets for one model of both).
    raw_root: KITTI raw drives for source kitti_dc (default: root). protocol: a lipjax.data.protocols name
    (None: the source's default). depth_scale: PNG value per metre of a folder's depth (None: .npy metres).
    kind, height, width: the synthetic scenes (sources synthetic and rendered; rendered validates on the
    synthetic val split at this size). Training batches are random crops, so that at test time (full size)
    the network sees objects at the same pixel scale and the samples at the same density as in training.
    Samplers: lipjax.data.sampling specs, or "input[:N]" for the data set's own sparse input.
    val_images: the validation set is the first val_images val frames (None: all of them).
    num_workers: loader worker processes (0: load in the training process).
    augment: training augmentation applied with the crop (zoom, flip, photometric, blur, sample noise).
    focal_range: source synthetic, training frames only: (lo, hi) factors on the reference camera's focal
    length, one drawn per frame (lipjax.data.synthetic.focal_factor): fields of view wider and narrower than
    NYU v2's and KITTI's. Validation keeps the reference camera, so that runs stay comparable.
    far_view_prob: source synthetic, kind mixed, training frames only: the probability that a room shows a street
    through a window (lipjax.data.synthetic.far_view): far samples inside rooms. Validation keeps closed rooms.
    clutter_prob: source synthetic, rooms (kind indoor or mixed), training frames only: the probability that a room
    has things of many sizes on its floor where the camera looks (lipjax.data.synthetic.clutter). Validation keeps
    the rooms as built.
    foliage_prob: source synthetic, streets (kind outdoor or mixed), training frames only: the probability that a
    street's trees and bushes are porous, clumps of leaves (lipjax.data.synthetic.foliage). Validation keeps them
    solid.
    """

    kind: str = "indoor"
    height: int = 256
    width: int = 320
    crop: tuple[int, int] | None = (128, 160)
    train_sampler: str = DEFAULT_SAMPLER
    val_sampler: str = DEFAULT_SAMPLER
    val_images: int | None = 32
    num_workers: int = 1
    source: str = "synthetic"
    root: str | None = None
    raw_root: str | None = None
    protocol: str | None = None
    depth_scale: float | None = None
    augment: Augment = Augment()  # lipjax.data.augment; the default only crops
    focal_range: tuple[float, float] = (1.0, 1.0)
    far_view_prob: float = 0.0
    clutter_prob: float = 0.0
    foliage_prob: float = 0.0


LOSS_SCALES = ("max_depth", "samples")
# The learning rate of G over a run (lipjax.train.state.g_learning_rate): "cosine" warms up, then decays to 5 % of
# learning_rate at the run's last step; "constant" warms up, then holds learning_rate, so that the model at step s
# does not depend on how long the run is (the equal-budget study: one run gives every budget of its curve);
# "linear" warms up, then decays linearly to 0 over G's updates: the cool-down that finishes a model from a constant
# run's (warmup-stable-decay, Hagele et al. 2024, arXiv:2405.18392).
LR_SCHEDULES = ("cosine", "constant", "linear")


@dataclasses.dataclass(frozen=True)
class TrainConfig:
    """Everything that defines a training run. Step counts are global optimisation steps."""

    name: str
    model: LearnedModel  # LIP (lipjax.model.LIPConfig) or an end-to-end network
    data: DataConfig = DataConfig()
    discriminator: Discriminator = Discriminator()
    batch_size: int = 8
    g_steps: int = 1000
    d_steps: int = 0
    adv_steps: int = 0
    learning_rate: float = 1e-3
    d_learning_rate: float = 2e-4
    warmup_steps: int = 100
    schedule: str = "cosine"  # LR_SCHEDULES
    weight_decay: float = 1e-4
    grad_clip_norm: float = 1.0
    loss: str = "l2"  # lipjax.train.losses.LOSS_KINDS; experiments/configs/ set "l1", lip_any "log_rmse"
    loss_scale: str = "max_depth"  # depth errors in units of: the model's max depth, or "samples" (see __post_init__)
    inverse_depth_weight: float = 0.0  # weight of lipjax.train.losses.inverse_depth_loss (1/m) added to the depth loss
    inverse_depth_floor_m: float = 1.0
    iteration_weights: tuple[float, ...] = ()
    adv_weight: float = 1e-3
    log_every: int = 10
    eval_every: int = 500
    checkpoint_every: int = 100
    keep_checkpoints: int = 3
    seed: int = 0  # the data stream (frames' order, samples, crops) and fresh weights; a warm start needs its own
    init_from: str | None = None

    def __post_init__(self):
        # "max_depth": errors / the prior's max depth (one constant per model); "samples": errors / each frame's
        # own sample scale s (geometric mean of its sparse depths, lipjax.priors.fast.sample_scale), so rooms
        # at 3 m and streets at 20 m weigh alike when one model trains on both.
        if self.loss_scale not in LOSS_SCALES:
            raise ValueError(f"loss_scale must be one of {LOSS_SCALES}, got {self.loss_scale!r}")
        if self.loss not in LOSS_KINDS:
            raise ValueError(f"loss must be one of {LOSS_KINDS}, got {self.loss!r}")
        if self.schedule not in LR_SCHEDULES:
            raise ValueError(f"schedule must be one of {LR_SCHEDULES}, got {self.schedule!r}")

    @property
    def total_steps(self) -> int:
        return self.g_steps + self.d_steps + self.adv_steps

    def phase(self, step: int) -> str:
        """'supervised', 'discriminator' or 'adversarial' for a global step."""
        if step < self.g_steps:
            return "supervised"
        if step < self.g_steps + self.d_steps:
            return "discriminator"
        return "adversarial"

    @property
    def adversarial(self) -> bool:
        return self.d_steps + self.adv_steps > 0


# DataConfig fields that do not change which frames, samples and crops a run reads (where, and how fast).
NOT_RECIPE = ("root", "raw_root", "num_workers", "val_sampler", "val_images")


def data_recipe(data: DataConfig) -> dict:
    """The fields of `data` that differ from DataConfig()'s (an Augment's from Augment()'s, nested), as JSON
    values, leaving out NOT_RECIPE: with a run's config name and seed they fix the frames, samples and crops it
    reads, --set overrides included (lipjax.train.loop.data_streams)."""
    def diff(obj, default, skip=()) -> dict:
        out = {}
        for f in dataclasses.fields(obj):
            value, base = getattr(obj, f.name), getattr(default, f.name)
            if f.name in skip or value == base:
                continue
            out[f.name] = diff(value, base) if dataclasses.is_dataclass(value) else (
                list(value) if isinstance(value, tuple) else value)
        return out

    return diff(data, DataConfig(), NOT_RECIPE)


def parse_overrides(items: list[str]) -> dict[str, str]:
    """["a.b=1", ...] (the --set arguments) -> {"a.b": "1"}; one-line ValueError for an item without '=' or a field."""
    overrides = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ValueError(f"--set {item!r}: expected FIELD=VALUE, e.g. --set g_steps=200")
        overrides[key.strip()] = value
    return overrides


def apply_overrides(config: TrainConfig, overrides: dict[str, str] | None) -> TrainConfig:
    """`config` with `field=value` overrides of scalar fields, nested ones dotted; one-line ValueError for an
    unknown field, a group, or a value the field's type cannot take.

    E.g. {'g_steps': '200'} or {'data.num_workers': '8'} (more loader processes on a machine with many cores).
    """
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
