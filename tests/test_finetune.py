"""Fine-tuning on a user's folder end to end (`lipjax train`, lipjax.train.run.fine_tune_folder): frames of mixed
sizes, the folder's own sparse input, a folder too small for the batch, keeping the better of start and end, and
the model that comes out loading and completing everywhere.

Tiny frames, a tiny random model with one iteration and a few steps, so that the file runs in about a minute."""
from __future__ import annotations

import cv2
import jax
import numpy as np
import pytest

import lipjax
from lipjax import model_io
from lipjax.data.augment import Augment, augment_batch
from lipjax.data.frame import Frame, Intrinsics
from lipjax.data.pipeline import BatchIterator, StepBatches, stacked, validation_batches
from lipjax.data.sampling import UniformSampler, draws_scan_lines, sampler_from_spec
from lipjax.data.sources import Source
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset
from lipjax.train import run as run_module
from lipjax.train.folder import fitted_batch_size
from lipjax.train.run import fine_tune_folder

SIZES = ((30, 40), (32, 44))  # two frame sizes, as KITTI's drives give (370x1224, 375x1242, ...)
CROP = (24, 32)
TINY = LIPConfig(prior=network_preset("tiny"), num_iterations=1)


def _frame(seed: int, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rgb uint8, depth m, sparse m: every 17th pixel) of one size."""
    rng = np.random.default_rng(seed)
    rgb = rng.integers(0, 256, (*size, 3), dtype=np.uint8)
    depth = rng.uniform(0.5, 9.0, size).astype(np.float32)
    depth[rng.random(size) < 0.1] = 0
    return rgb, depth, np.where(np.arange(depth.size).reshape(size) % 17 == 0, depth, 0).astype(np.float32)


def _write_frames(folder, seeds) -> None:
    """rgb/ depth/ sparse/ (PNG, millimetres) of the folder format lipjax.data.folder reads, sizes alternating."""
    for d in ("rgb", "depth", "sparse"):
        (folder / d).mkdir(parents=True, exist_ok=True)
    for i, seed in enumerate(seeds):
        rgb, depth, sparse = _frame(seed, SIZES[i % 2])
        assert cv2.imwrite(str(folder / "rgb" / f"{i:04d}.png"), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
        for d, metres in (("depth", depth), ("sparse", sparse)):
            assert cv2.imwrite(str(folder / d / f"{i:04d}.png"), np.rint(metres * 1000).astype(np.uint16))


def _frames(n: int) -> list[Frame]:
    return [Frame.from_depth(*_frame(i, SIZES[i % 2])[:2], Intrinsics(30, 30, 20, 15), f"mixed/{i}")
            for i in range(n)]


def test_frames_of_mixed_sizes_are_cropped_one_by_one_and_validated_each_at_its_own_size():
    """A training step of frames of two sizes: each frame is cropped before batching, with the draws it has in a
    batch of one size; validation batches frames of one size together, each whole."""
    frames, aug = _frames(5), Augment(zoom=(0.8, 1.25), hflip=True)
    iterator = BatchIterator(frames, 4, UniformSampler(20), seed=3)
    steps = StepBatches(iterator, 2, aug, CROP, seed=3, model_config=None)
    got = steps[1]
    assert got["rgb"].shape == (4, *CROP, 3) and got["gt"].shape == got["sparse"].shape == (4, *CROP)
    for i, example in enumerate(iterator.examples(1)):
        alone = augment_batch(stacked([example]), aug, CROP, 3, 1, i)
        assert np.array_equal(got["gt"][i], alone.gt[0]) and np.array_equal(got["rgb"][i], alone.rgb[0])
    with pytest.raises(ValueError, match=r"different sizes .*; train with a crop \(data.crop"):
        StepBatches(iterator, 2, aug, None, seed=3, model_config=None)[1]
    batches = validation_batches(Source(frames, UniformSampler(20)), None, batch_size=2)
    assert [b.gt.shape for b in batches] == [(1, *SIZES[0]), (1, *SIZES[1])] * 2 + [(1, *SIZES[0])]
    same = validation_batches(Source(frames[::2], UniformSampler(20)), None, batch_size=2)
    assert [b.gt.shape[0] for b in same] == [2, 1]


def test_own_input_counts_as_scan_lines_trained_and_is_no_sampler():
    assert draws_scan_lines("input") and draws_scan_lines("input:500") and draws_scan_lines("lidar:hdl64")
    assert not draws_scan_lines("uniform:200|bernoulli:500")
    for spec in ("input|uniform:200", "uniform:200|input:5"):
        with pytest.raises(ValueError, match="'input' is a data set's own sparse input"):
            sampler_from_spec(spec)
    for metadata, trained in (({"train_sampler": "input"}, True), ({"train_sampler": "input:300"}, True),
                              ({"train_sampler": "uniform:200"}, False), ({}, False),
                              ({"train_sampler": "a-later-sampler:9"}, True)):
        assert lipjax.Completer(TINY, TINY.init(jax.random.key(0)), "m", metadata).scan_lines_trained == trained


def test_a_small_folder_trains_on_a_smaller_batch():
    assert fitted_batch_size(8, 7) == 7 and fitted_batch_size(8, 20) == 8 and fitted_batch_size(8, 7, 2) == 6
    with pytest.raises(ValueError, match="1 training frame.* add frames"):
        fitted_batch_size(8, 1, 2)


def test_fine_tuning_a_folder_of_mixed_sizes_on_its_own_input_gives_a_model_that_completes(tmp_path, capsys,
                                                                                             monkeypatch):
    """`lipjax train --data DIR --sampler input`: 7 training frames of two sizes (a batch of 7, said in a line),
    validation on 2 frames of two sizes with their own sparse maps; the model loads and completes through
    lipjax.load_model and lipjax.complete. Then the same run with a start that validates better: the start is
    exported by default (keep="best"), said in one line, and keep="last" exports the end, saying it is worse."""
    root = tmp_path / "frames"
    _write_frames(root / "train", range(7))
    _write_frames(root / "val", (100, 101))
    init = tmp_path / "tiny"
    model_io.save(init, TINY, TINY.init(jax.random.key(1)))
    lines: list[str] = []
    common = dict(init=str(init), steps=2, workdir=tmp_path / "run", progress=False, log=lines.append,
                  depth_scale=1000.0, crop=CROP, train_sampler="input", num_workers=0)
    out = tmp_path / "models" / "mine"
    val = fine_tune_folder(root, out, keep="last", **common)
    assert lines == ["batch size 7: the folder's 7 training frame(s) fill no batch of 8; add frames for larger "
                     "batches"]
    printed = capsys.readouterr().out.splitlines()
    assert printed[-1].startswith(f"[lipjax] exported mine (step 2) to {out}: val rmse_m={val['rmse_m']:.4f}")
    meta = model_io.metadata(out)
    assert meta["train_sampler"] == meta["val_sampler"] == "input" and meta["steps"] == 2
    assert meta["data_streams"][-1]["data"]["train_sampler"] == "input"

    model = lipjax.load_model(out)
    assert model.scan_lines_trained
    trained, start = (jax.tree_util.tree_leaves(model_io.load(path)[1]) for path in (out, init))
    assert not all(np.array_equal(a, b) for a, b in zip(trained, start, strict=True))  # it trained: weights moved
    rgb, _, sparse = _frame(7, SIZES[1])
    depth = model(rgb, sparse)
    assert depth.shape == SIZES[1] and np.all(np.isfinite(depth))
    completed = lipjax.complete(rgb, sparse, model=str(out))
    assert completed.shape == SIZES[1] and np.all(np.isfinite(completed)) and completed.max() > 0

    logged = run_module.logged_validation

    def better_start(path, step):  # the start validates better than any end: the run must not export the end
        found = logged(path, step)
        return found and ({**found, "rmse_m": 0.0} if step == 0 else found)

    monkeypatch.setattr(run_module, "logged_validation", better_start)
    kept = tmp_path / "kept" / "mine"  # the same name: the same run, resumed at its end
    assert fine_tune_folder(root, kept, **common)["rmse_m"] == 0.0  # the run is done: nothing trains again
    line = capsys.readouterr().out.splitlines()[-1]
    assert line == (f"[lipjax] exported mine (its start: step 2 validated worse, rmse_m={val['rmse_m']:.4f}; keep "
                    f"last exports it) to {kept}: val rmse_m=0.0000")
    _, params, meta = model_io.load(kept)
    assert all(np.array_equal(a, b) for a, b in zip(jax.tree_util.tree_leaves(params),
                                                    jax.tree_util.tree_leaves(model_io.load(init)[1]), strict=True))
    assert meta["kept"] == "start" and meta["steps"] == 0 and meta["kept_over"]["val_metrics"] == val
    assert lipjax.load_model(kept)(rgb, sparse).shape == SIZES[1]
    fine_tune_folder(root, tmp_path / "last" / "mine", keep="last", **common)
    assert "WORSE than 0.0000 at step 0 (the last, as asked" in capsys.readouterr().out.splitlines()[-1]
    with pytest.raises(ValueError, match="keep='newest': choose 'best'"):
        fine_tune_folder(root, tmp_path / "x" / "mine", keep="newest", **common)


def test_a_model_of_both_scenes_fine_tuned_on_a_folder_still_serves_both():
    """lip-any fine-tuned on one folder keeps metadata "data": "mixed" (no warning that its input looks like the
    other scene's); a per-scene model fine-tuned on a folder records the folder."""
    from lipjax.interfaces import MIXED_SCENES
    from lipjax.train.config import TrainConfig, DataConfig
    from lipjax.train.run import trained_on

    folder = DataConfig(source="folder", root="my_frames")
    lip_any = lipjax.load_model("lip-any")
    assert lip_any.both_scenes
    assert trained_on(TrainConfig(name="mine", model=lip_any.config, data=folder, init_from="lip-any")) == MIXED_SCENES
    indoor = lipjax.load_model("lip-fast-indoor")
    fine_tuned = TrainConfig(name="mine", model=indoor.config, data=folder, init_from="lip-fast-indoor")
    assert trained_on(fine_tuned) == "folder"
    assert trained_on(TrainConfig(name="x", model=indoor.config, data=DataConfig(kind="outdoor"))) == "outdoor"
