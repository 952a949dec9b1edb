"""Fine-tuning a model on your own folder of RGB-D frames: the config behind `lipjax train --data DIR`.

    config = folder_config(model_config, "lip-cnn-indoor", root="my_frames", depth_scale=1000)
    lipjax.train.run.run(config, "runs/my_frames", export="models/my_model")

The named config lip_cnn_folder (experiments/configs.py) is folder_config(LIP_CNN_INDOOR's model, "lip-cnn-indoor").
"""
from __future__ import annotations

import dataclasses

from lipjax.train.config import DataConfig, TrainConfig

# Random 128x160 crops of the frames as they are (no protocol), a mixture of sparse densities; validation on the
# folder's val/ (or the last 5 % of its frames) with 200 uniform points.
FOLDER_DATA = DataConfig(
    source="folder", crop=(128, 160), train_sampler="uniform:200|uniform:500|bernoulli:200",
    val_sampler="uniform:200", val_images=32, num_workers=2,
)


def folder_config(model, init_from: str | None, *, name: str = "lip-cnn-folder", **data) -> TrainConfig:
    """A 2000-step, batch-8 L1 fine-tuning run of `model` (started from model `init_from`) on a folder source.

    data: DataConfig fields (root, depth_scale, crop, train_sampler, num_workers, ...) over FOLDER_DATA.
    """
    return TrainConfig(
        name=name, model=model, data=dataclasses.replace(FOLDER_DATA, **data), init_from=init_from,
        batch_size=8, g_steps=2000, learning_rate=2e-4, warmup_steps=100, loss="l1", eval_every=500,
        checkpoint_every=250,
    )
