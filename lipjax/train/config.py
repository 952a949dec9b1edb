"""Training configuration as typed, frozen dataclasses (configs are code: see experiments/configs.py).

A run has up to three phases, by global step:
    [0, g_steps)                      G supervised pretraining (L2 through the whole unrolled solver)
    [g_steps, g_steps + d_steps)      D pretraining (cross-entropy, G frozen)
    [.., .. + adv_steps)              joint G + D adversarial training (LIP+AD)
LIP+CNN is g_steps only; LIP+AD adds the other two (usually starting from a LIP+CNN model via `init_from`).
"""
from __future__ import annotations

import dataclasses

from lipjax.data.augment import Augment
from lipjax.train.discriminator import Discriminator
from lipjax.model import LIPConfig


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
    """

    kind: str = "indoor"
    height: int = 256
    width: int = 320
    crop: tuple[int, int] | None = (128, 160)
    train_sampler: str = "uniform:200"
    val_sampler: str = "uniform:200"
    val_images: int | None = 32
    num_workers: int = 1
    source: str = "synthetic"
    root: str | None = None
    raw_root: str | None = None
    protocol: str | None = None
    depth_scale: float | None = None
    augment: Augment = Augment()  # lipjax.data.augment; the default only crops


LOSS_SCALES = ("max_depth", "samples")


@dataclasses.dataclass(frozen=True)
class TrainConfig:
    """Everything that defines a training run. Step counts are global optimisation steps."""

    name: str
    model: LIPConfig
    data: DataConfig = DataConfig()
    discriminator: Discriminator = Discriminator()
    batch_size: int = 8
    g_steps: int = 1000
    d_steps: int = 0
    adv_steps: int = 0
    learning_rate: float = 1e-3
    d_learning_rate: float = 2e-4
    warmup_steps: int = 100
    weight_decay: float = 1e-4
    grad_clip_norm: float = 1.0
    loss: str = "l2"
    loss_scale: str = "max_depth"  # depth errors in units of: the model's max depth, or "samples" (see __post_init__)
    inverse_depth_weight: float = 0.0  # weight of lipjax.train.losses.inverse_depth_loss (1/m) added to the depth loss
    inverse_depth_floor_m: float = 1.0
    iteration_weights: tuple[float, ...] = ()
    adv_weight: float = 1e-3
    log_every: int = 10
    eval_every: int = 500
    checkpoint_every: int = 100
    keep_checkpoints: int = 3
    seed: int = 0
    init_from: str | None = None

    def __post_init__(self):
        # "max_depth": errors / the prior's max depth (one constant per model); "samples": errors / each frame's
        # own sample scale s (geometric mean of its sparse depths, lipjax.priors.guided.sample_scale), so rooms
        # at 3 m and streets at 20 m weigh alike when one model trains on both.
        if self.loss_scale not in LOSS_SCALES:
            raise ValueError(f"loss_scale must be one of {LOSS_SCALES}, got {self.loss_scale!r}")

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
