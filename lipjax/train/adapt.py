"""Your own sensor without ground truth: self-supervised adaptation of a model from sparse depth alone.

    adapt_folder("my_frames", "models/mine")             # rgb/ and sparse/ (no depth/): from the default model
    adapt_folder("my_frames", "models/mine", hide=0.25, steps=300, keep="last")
    completer = adapt_frame(rgb, sparse, steps=50)       # one frame adapting on itself (test-time adaptation)

Each training example hides a share (`hide`) of its frame's own samples from the input, whole scan-line segments
where the samples lie in LiDAR scan lines, and the loss is computed at the hidden samples alone, never at an input
sample (lipjax.data.hidden; the spec "hide:F" of lipjax.data.sources). Validation scores the validation frames (the
folder's val/, else its last 5 %) on their samples hidden with a fixed draw, before and after training;
`keep="best"` exports the adapted model only when it beats its start there (lipjax.train.run.run, whose last line
gives both numbers). The run is `lipjax train`'s (lipjax.train.run.fine_tune_folder): resumable, Ctrl-C safe,
with a progress bar.
"""
from __future__ import annotations

import contextlib
import dataclasses
import io
import os
import pathlib
import tempfile
from collections.abc import Callable
from typing import Any

import cv2
import numpy as np

from lipjax import model_io
from lipjax.data.augment import DEFAULT_TRAINING
from lipjax.data.hidden import HIDE, HIDE_SHARE
from lipjax.train.folder import fitted_to_folder, folder_config
from lipjax.train.run import check_keep, run

ADAPT_STEPS, ADAPT_BATCH_SIZE = 500, 8  # an adaptation's length and frames per step
ADAPT_WARMUP_SHARE = 0.1  # of the steps, at most folder_config's warm-up
# Random 128x160 crops at the working size (lipjax.data.hidden.AtWorkingSize) with the shipped fast models' training
# augmentation (zoom, flip, photometric, blur), folder_config's learning rate (2e-4) and lip-any's loss (the per-image
# log RMSE in units of each frame's sample scale, docs/decisions/0009-log-rmse-loss.md). Chosen in three runs of
# 150 steps of 4 on the 15 shared real frames (python -m benchmarks.adapt, (a)), geometric-mean RMSE ratio to linear
# from 0.844 unadapted: flips only at 1e-4 0.838, this augmentation at 1e-4 0.822, at 2e-4 0.815.
ADAPT_DATA = {"crop": (128, 160), "augment": DEFAULT_TRAINING}
ADAPT_LOSS = {"loss": "log_rmse", "loss_scale": "samples"}


def adapt_config(model, init_from: str, *, name: str, hide: float = HIDE_SHARE, steps: int = ADAPT_STEPS,
                 batch_size: int = ADAPT_BATCH_SIZE, **data: Any):
    """The TrainConfig of an adaptation of `model` (started from model `init_from`) on a folder of RGB and sparse
    depth: lipjax.train.folder.folder_config with the spec "hide:`hide`" for training and validation, ADAPT_DATA,
    ADAPT_LOSS and a warm-up of ADAPT_WARMUP_SHARE of the steps. data: DataConfig fields (root, depth_scale, crop,
    num_workers, augment, ...) over those."""
    if not 0 < hide < 1:
        raise ValueError(f"hide={hide}: the share of each frame's samples hidden from its input must be in (0, 1)")
    spec = f"{HIDE}:{hide:g}"
    config = folder_config(model, init_from, name=name,
                           **{**ADAPT_DATA, "train_sampler": spec, "val_sampler": spec, **data})
    warmup = max(1, min(config.warmup_steps, round(ADAPT_WARMUP_SHARE * steps)))
    return dataclasses.replace(config, g_steps=steps, batch_size=batch_size, warmup_steps=warmup, **ADAPT_LOSS)


def adapt_folder(root: str | os.PathLike, out: str | os.PathLike, *, init: str | None = None,
                 steps: int | None = None, hide: float | None = None, keep: str = "best",
                 batch_size: int | None = None, workdir: str | os.PathLike | None = None, progress: bool = True,
                 log: Callable[[str], None] | None = None, **data: Any) -> dict:
    """Adapts a model to a folder of RGB + sparse depth frames without dense depth (rgb/ and sparse/, optionally
    train/ and val/ holding them; lipjax.data.folder) by self-supervision, and exports it to `out` (a model path
    stem, also the run's name).

    Args:
      init: the model to start from (name or path); None: the default model (lipjax.shipped.DEFAULT_MODEL).
      steps, batch_size: training steps and frames per step (None: ADAPT_STEPS, ADAPT_BATCH_SIZE); a folder of
        fewer training frames trains on all of them per step, said in one line to `log`.
      hide: the share of each frame's samples hidden from its input, its ground truth (lipjax.data.hidden; None:
        HIDE_SHARE).
      keep: "best" exports the starting model when the adapted one scores worse on the validation frames'
        hidden samples, "last" the adapted one regardless; either way the last line says so (lipjax.train.run.run).
      workdir: checkpoints and logs (default runs/adapt-<out name>); started again, the run resumes.
      log: a callable taking a line (the start, the batch size), or None.
      data: DataConfig fields over ADAPT_DATA (depth_scale for PNG sparse maps, crop, num_workers, val_images);
        None keeps ADAPT_DATA's. No sampler: the input is the folder's own sparse maps less the hidden share.

    Returns the validation metrics (metres, on the hidden samples) of the exported model.
    """
    from lipjax.shipped import DEFAULT_MODEL

    check_keep(keep)
    init, hide = DEFAULT_MODEL if init is None else init, HIDE_SHARE if hide is None else hide
    data = {"root": os.fspath(root), **{k: v for k, v in data.items() if v is not None}}
    given = [k for k in ("train_sampler", "val_sampler") if k in data]
    if given:
        raise ValueError(f"{'/'.join(given)}={data[given[0]]!r}: a self-supervised run's input is the folder's own "
                         "sparse/ maps less the share hidden (hide=F, --self-supervised F); drop the sampler "
                         "(--sampler)")
    name = pathlib.Path(out).name
    config = adapt_config(model_io.load(init)[0], init, name=name, hide=hide, steps=steps or ADAPT_STEPS,
                          batch_size=batch_size or ADAPT_BATCH_SIZE, **data)
    if log is not None:
        log(f"self-supervised from {init}: {hide:g} of each frame's samples hidden from its input (whole scan-line "
            "segments on LiDAR input), the loss at them alone")
    return run(fitted_to_folder(config, log), workdir or f"runs/adapt-{name}", export=out, progress=progress,
               validate_start=True, keep=keep)


ADAPT_FRAME_STEPS = 50  # steps of one frame's adaptation on itself (`adapt_frame`)


def adapt_frame(rgb: np.ndarray, sparse: np.ndarray, *, model: str | None = None, steps: int = ADAPT_FRAME_STEPS,
                hide: float = HIDE_SHARE, keep: str = "last"):
    """A Completer of `model` (name or path; None: the default model) adapted on one frame by `steps` steps of
    `adapt_folder`'s self-supervision on the frame itself: rgb (H, W, 3) uint8 and its sparse depth (H, W) float32
    metres, written to a temporary folder as its train/ and val/ (deleted on return). Test-time adaptation: the
    frame's hidden samples are its only check, and training hides each of them in some step, so keep="best" compares
    in-sample scores; hence "last" by default. Cost on the 2-core development CPU, beside a training run: 5-6 s for
    10-50 steps on a KITTI frame with the HDL-64 pattern (RMSE ratio to linear 0.997 -> 0.954 at 10, 0.912 at 50),
    17 s on a lingbot frame with 200 points (1.482 -> 1.522 at 10, 1.471 at 50), compilation included."""
    from lipjax.inference import load_model

    with tempfile.TemporaryDirectory(prefix="lipjax-adapt-frame-") as tmp:
        root = pathlib.Path(tmp)
        for split in ("train", "val"):
            for d in ("rgb", "sparse"):
                (root / split / d).mkdir(parents=True)
            if not cv2.imwrite(str(root / split / "rgb" / "frame.png"), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)):
                raise OSError(f"cannot write the frame into {tmp}")
            np.save(root / split / "sparse" / "frame.npy", np.asarray(sparse, np.float32))
        with contextlib.redirect_stdout(io.StringIO()):
            adapt_folder(root, root / "model" / "frame", init=model, steps=steps, batch_size=1, hide=hide, keep=keep,
                         workdir=root / "run", progress=False, num_workers=0)
        return load_model(root / "model" / "frame")
