"""Self-supervised adaptation from sparse depth alone (lipjax.train.adapt, lipjax.data.hidden): a folder of RGB and
sparse maps without depth/, the loss only at samples hidden from the input, whole scan-line segments hidden on LiDAR
input, and a model written only when it beats its start on the validation frames' hidden samples.

Tiny frames, a tiny random model with one iteration and a few steps."""
from __future__ import annotations

import cv2
import jax
import numpy as np
import pytest

import lipjax
from lipjax import model_io
from lipjax.data.augment import Augment
from lipjax.data.frame import Frame, Intrinsics
from lipjax.data.hidden import AtWorkingSize, hidden_samples, hide_share, scan_line_segments, working_shape
from lipjax.data.pipeline import BatchIterator, StepBatches, validation_batches
from lipjax.data.sampling import example_rng
from lipjax.data.sources import open_source
from lipjax.inputs import is_lidar_pattern
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset
from lipjax.train import run as run_module
from lipjax.train.adapt import adapt_folder, adapt_frame
from lipjax.train.config import DataConfig

SIZE, CROP = (30, 40), (24, 32)
TINY = LIPConfig(prior=network_preset("tiny"), num_iterations=1)


def _scattered(seed: int, size=SIZE, n: int = 60) -> np.ndarray:
    rng = np.random.default_rng(seed)
    sparse = np.zeros(size, np.float32)
    sparse.reshape(-1)[rng.choice(sparse.size, n, replace=False)] = rng.uniform(0.5, 9.0, n)
    return sparse


def _scan_lines(size=(60, 120), lines: int = 10) -> tuple[np.ndarray, np.ndarray]:
    """(sparse m, line index per pixel, -1 where none): `lines` gently curved scan lines 5 rows apart, a return every
    2 px, each line broken by no gap."""
    sparse, line = np.zeros(size, np.float32), np.full(size, -1)
    cols = np.arange(0, size[1], 2)
    for k in range(lines):
        rows = 5 + 5 * k + np.rint(1.2 * np.sin(cols / 25.0)).astype(int)
        sparse[rows, cols], line[rows, cols] = 2.0 + 0.5 * k + 0.01 * cols, k
    return sparse, line


def _write_folder(folder, seeds, size=SIZE, n: int = 60) -> None:
    """rgb/ and sparse/ (16-bit PNG, millimetres) alone: no depth/."""
    for d in ("rgb", "sparse"):
        (folder / d).mkdir(parents=True, exist_ok=True)
    for i, seed in enumerate(seeds):
        rgb = np.random.default_rng(seed).integers(0, 256, (*size, 3), dtype=np.uint8)
        assert cv2.imwrite(str(folder / "rgb" / f"{i:04d}.png"), rgb)
        sparse = _scattered(seed, size, n)
        assert cv2.imwrite(str(folder / "sparse" / f"{i:04d}.png"), np.rint(sparse * 1000).astype(np.uint16))


def test_hide_specs():
    assert hide_share("hide") == 0.2 and hide_share("hide:0.25") == 0.25 and hide_share("uniform:200") is None
    assert hide_share("input") is None
    for bad in ("hide:1", "hide:0", "hide:x"):
        with pytest.raises(ValueError, match="share of the samples hidden"):
            hide_share(bad)


def test_scattered_samples_hide_a_share_and_scan_lines_hide_whole_lines():
    sparse = _scattered(0, (60, 80), 200)
    hidden = hidden_samples(sparse, 0.2, example_rng(0, "a"))
    assert hidden.sum() == 40 and not np.any(hidden & (sparse <= 0))
    lines, line = _scan_lines()
    assert is_lidar_pattern(lines)
    labels = scan_line_segments(lines)
    assert all(len(np.unique(labels[line == k])) == 1 for k in range(10))  # one segment a line ...
    assert len(np.unique(labels[labels >= 0])) == 10  # ... and no two lines in one
    for seed in range(5):
        hidden = hidden_samples(lines, 0.2, example_rng(seed, "lines"))
        share = [hidden[line == k].mean() for k in range(10)]
        assert set(share) == {0.0, 1.0}  # every line hidden whole or kept whole
        assert 0.2 * (lines > 0).sum() <= hidden.sum() <= 0.3 * (lines > 0).sum()


def _first_examples(tmp_path):
    root = tmp_path / "frames"
    _write_folder(root, range(6))
    data = DataConfig(source="folder", root=str(root), depth_scale=1000.0, train_sampler="hide:0.2",
                      val_sampler="hide:0.2", crop=None)
    return root, open_source(data, "train")


def test_the_loss_sees_the_hidden_samples_alone_and_training_redraws_them(tmp_path):
    """On a training batch, the ground truth is exactly the frame's samples removed from its input: none at an input
    sample; each epoch hides other samples, validation always the same."""
    root, source = _first_examples(tmp_path)
    iterator = BatchIterator(source.dataset, 2, source.sampler, seed=3, shuffle=False)
    batch = StepBatches(iterator, 4, Augment(), None, seed=3, model_config=None)[0]
    assert not np.any(batch["gt_valid"] & (batch["sparse"] > 0))
    for i in range(2):
        full = cv2.imread(str(root / "sparse" / f"{i:04d}.png"), cv2.IMREAD_UNCHANGED) / np.float32(1000)
        removed = (full > 0) & (batch["sparse"][i] <= 0)
        assert np.array_equal(batch["gt_valid"][i], removed) and removed.sum() == round(0.2 * (full > 0).sum())
        assert np.allclose(batch["gt"][i][removed], full[removed]) and not batch["gt"][i][~removed].any()
        assert np.allclose(batch["sparse"][i][batch["sparse"][i] > 0], full[batch["sparse"][i] > 0])
    steps = StepBatches(iterator, 6, Augment(hflip=True), CROP, seed=3, model_config=None)
    cropped = steps[1]
    assert cropped["gt_valid"].any() and not np.any(cropped["gt_valid"] & (cropped["sparse"] > 0))
    again = iterator.steps_per_epoch * 1  # the same frames one epoch later: other samples hidden
    assert not np.array_equal(iterator.batch(again).gt_valid, iterator.batch(0).gt_valid)
    assert np.array_equal(iterator.example(0)[1], iterator.example(0)[1])
    val = validation_batches(source, None)
    assert np.array_equal(val[0].gt_valid, validation_batches(source, None)[0].gt_valid)


def test_frames_adapt_at_the_default_paths_working_size(tmp_path):
    """A frame above the working size trains at it, as the default path runs the model; no ground truth at an input
    sample once the samples meet on the smaller grid."""
    sparse = _scattered(1, (96, 128), 20)
    assert working_shape(sparse) == (64, 85)
    frame = AtWorkingSize()(Frame.from_depth(np.zeros((96, 128, 3), np.uint8), sparse, Intrinsics(1, 1, 0, 0), "x"))
    assert frame.shape == (64, 85) and frame.valid.sum() == 20
    root = tmp_path / "big"
    _write_folder(root, range(3), size=(96, 128), n=20)
    source = open_source(DataConfig(source="folder", root=str(root), depth_scale=1000.0, train_sampler="hide:0.3",
                                    val_sampler="hide:0.3"), "train")
    frame, inputs = BatchIterator(source.dataset, 1, source.sampler).example(0, epoch=0)
    assert frame.shape == inputs.shape == (64, 85)
    assert frame.valid.any() and not np.any(frame.valid & (inputs > 0))


def test_adapting_a_folder_without_depth_writes_the_model_only_when_it_beats_its_start(tmp_path, capsys,
                                                                                         monkeypatch):
    """rgb/ and sparse/ alone: two steps from a tiny model. With a start that scores worse on the held-out samples
    the adapted model is written; with a start that scores better (keep="best"), the start."""
    root = tmp_path / "frames"
    _write_folder(root, range(8))
    init = tmp_path / "tiny"
    model_io.save(init, TINY, TINY.init(jax.random.key(1)))
    lines: list[str] = []
    common = dict(init=str(init), steps=2, batch_size=4, workdir=tmp_path / "run", progress=False, log=lines.append,
                  depth_scale=1000.0, crop=CROP, num_workers=0)
    logged = run_module.logged_validation

    def start_scored(rmse_m):
        def logged_at(path, step):
            found = logged(path, step)
            return found and ({**found, "rmse_m": rmse_m} if step == 0 else found)
        return logged_at

    monkeypatch.setattr(run_module, "logged_validation", start_scored(1e9))  # the start: worse than any end
    out = tmp_path / "adapted" / "mine"
    val = adapt_folder(root, out, **common)
    assert lines[0].startswith(f"self-supervised from {init}: 0.2 of each frame's samples hidden")
    line = capsys.readouterr().out.splitlines()[-1]
    assert line == (f"[lipjax] exported mine (step 2) to {out}: val rmse_m={val['rmse_m']:.4f} "
                    "(1000000000.0000 at step 0)")
    meta = model_io.metadata(out)
    assert meta["train_sampler"] == meta["val_sampler"] == "hide:0.2" and meta["steps"] == 2 and "kept" not in meta
    rgb = np.zeros((*SIZE, 3), np.uint8)
    assert lipjax.complete(rgb, _scattered(9), model=str(out)).shape == SIZE

    monkeypatch.setattr(run_module, "logged_validation", start_scored(0.0))  # the start: better than any end
    kept = tmp_path / "kept" / "mine"  # the same run, resumed at its end
    assert adapt_folder(root, kept, **common)["rmse_m"] == 0.0
    assert "(its start: step 2 validated worse" in capsys.readouterr().out.splitlines()[-1]
    _, params, meta = model_io.load(kept)
    assert meta["kept"] == "start" and meta["steps"] == 0
    assert all(np.array_equal(a, b) for a, b in zip(jax.tree_util.tree_leaves(params),
                                                    jax.tree_util.tree_leaves(model_io.load(init)[1]), strict=True))
    with pytest.raises(ValueError, match="hide=1.5: the share"):
        adapt_folder(root, tmp_path / "x" / "mine", hide=1.5, **common)
    with pytest.raises(ValueError, match="train_sampler='input': a self-supervised run's input is the folder's own"):
        adapt_folder(root, tmp_path / "x" / "mine", train_sampler="input", **common)


def test_one_frame_adapts_on_itself(tmp_path):
    init = tmp_path / "tiny"
    model_io.save(init, TINY, TINY.init(jax.random.key(2)))
    rgb, sparse = np.random.default_rng(0).integers(0, 256, (*SIZE, 3), dtype=np.uint8), _scattered(4)
    completer = adapt_frame(rgb, sparse, model=str(init), steps=2)
    assert completer.metadata["steps"] == 2 and completer.metadata["train_sampler"] == "hide:0.2"
    assert completer(rgb, sparse).shape == SIZE
    start = jax.tree_util.tree_leaves(model_io.load(init)[1])  # it trained: weights moved from the start's
    assert not all(np.array_equal(a, b) for a, b in zip(jax.tree_util.tree_leaves(completer.params), start,
                                                        strict=True))


@pytest.mark.parametrize("argv, message", [
    (["--self-supervised", "--sampler", "uniform:200"], "lipjax: error: train_sampler='uniform:200': a self-"),
    (["--self-supervised", "1.5"], "lipjax: error: hide=1.5: the share of each frame's samples hidden"),
])
def test_lipjax_train_self_supervised_refuses_a_sampler_and_a_share_outside_0_1(tmp_path, capsys, argv, message):
    from lipjax import cli

    _write_folder(tmp_path / "mine", seeds=range(3))
    assert cli.main(["train", "--data", str(tmp_path / "mine"), "--out", str(tmp_path / "m"), "--workdir",
                     str(tmp_path / "run"), "-q", *argv]) == 1
    lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith(message), lines
    assert not (tmp_path / "run").exists() and not (tmp_path / "m.json").exists()
