"""Every training source from tiny fixture files in its real on-disk format: open, train a few steps, resume.

Formats written here: NYU h5 (Ma et al.), KITTI depth completion (annotated + velodyne_raw + raw drive + calib)
and its val_selection_cropped, a user folder (rgb/ depth/ sparse/ intrinsics.txt) and `lipjax data render`
shards; TFDS nyu_depth_v2 comes from tfds.testing.mock_data when tensorflow-datasets is installed. The network is
the tiny preset with one iteration and every test uses the same crop, so the train step compiles once for the file.
"""
from __future__ import annotations

import dataclasses
import importlib.util
import json
import os
import pathlib
import signal
import subprocess
import sys
import time

import cv2
import h5py
import jax
import numpy as np
import pytest

from lipjax.train.checkpoint import CheckpointManager
from lipjax.data.rendered import RenderedDataset, render_to_disk
from lipjax.data.sources import open_source
from lipjax.data.synthetic import render
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset
from lipjax.train import loop
from lipjax.train.config import DataConfig, TrainConfig
from lipjax.train.state import init_state

from helpers import alive, children

H, W = 30, 40  # fixture frames; training crops are CROP
CROP = (24, 32)
DRIVE = "2011_09_26_drive_0002_sync"
CALIB = ("P_rect_02: 7.2e+02 0 6.0e+02 4.4e+01 0 7.2e+02 1.7e+02 0.2 0 0 1 0.003\n"
         "P_rect_03: 7.2e+02 0 6.0e+02 -3.3e+02 0 7.2e+02 1.7e+02 2.2 0 0 1 0.003\n")


def frame(seed: int, max_depth_m: float = 9.0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    rgb = rng.integers(0, 256, (H, W, 3), dtype=np.uint8)
    depth = rng.uniform(0.5, max_depth_m, (H, W)).astype(np.float32)
    depth[rng.random((H, W)) < 0.1] = 0
    return rgb, depth


def write_rgb(path, rgb):
    path.parent.mkdir(parents=True, exist_ok=True)
    assert cv2.imwrite(str(path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))


def write_png16(path, metres, scale):
    path.parent.mkdir(parents=True, exist_ok=True)
    assert cv2.imwrite(str(path), np.rint(metres * scale).astype(np.uint16))


def make_nyu(root, n=4):
    for split in ("train", "val"):
        for i in range(n):
            rgb, depth = frame(i + (100 if split == "val" else 0))
            path = root / "nyudepthv2" / split / "office_0001" / f"{i + 1}.h5"
            path.parent.mkdir(parents=True, exist_ok=True)
            with h5py.File(path, "w") as f:
                f["rgb"] = np.transpose(rgb, (2, 0, 1))  # (3, H, W) as in Ma et al.'s files
                f["depth"] = depth
    return root


def make_kitti(root, n=4):
    (root / "raw" / DRIVE[:10]).mkdir(parents=True)
    (root / "raw" / DRIVE[:10] / "calib_cam_to_cam.txt").write_text(CALIB)
    for split in ("train", "val"):
        for i in range(n):
            rgb, gt = frame(i + (100 if split == "val" else 0), 80.0)
            velo = np.where(np.random.default_rng(i).random((H, W)) < 0.1, gt, 0)
            name = f"{i:010d}.png"
            gt_dir = root / "depth/data_depth_annotated" / split / DRIVE / "proj_depth/groundtruth/image_02"
            velo_dir = root / "depth/data_depth_velodyne" / split / DRIVE / "proj_depth/velodyne_raw/image_02"
            write_png16(gt_dir / name, gt, 256)
            write_png16(velo_dir / name, velo, 256)
            write_rgb(root / "raw" / DRIVE[:10] / DRIVE / "image_02/data" / name, rgb)
    return root


def make_kitti_selection(root, n=2):
    base = root / "depth_selection" / "val_selection_cropped"
    for i in range(n):
        rgb, gt = frame(300 + i, 80.0)
        stem = f"{DRIVE}_{{}}_{i:010d}_image_02"
        write_rgb(base / "image" / f"{stem.format('image')}.png", rgb)
        write_png16(base / "groundtruth_depth" / f"{stem.format('groundtruth_depth')}.png", gt, 256)
        write_png16(base / "velodyne_raw" / f"{stem.format('velodyne_raw')}.png", np.where(gt > 40, gt, 0), 256)
        (base / "intrinsics").mkdir(exist_ok=True)
        (base / "intrinsics" / f"{stem.format('image')}.txt").write_text("40 0 20 0 40 15 0 0 1\n")
    return root


def make_folder(root, n=6):
    for i in range(n):
        rgb, depth = frame(200 + i)
        write_rgb(root / "rgb" / f"{i:04d}.png", rgb)
        write_png16(root / "depth" / f"{i:04d}.png", depth, 1000)
        sparse = np.where(np.arange(H * W).reshape(H, W) % 17 == 0, depth, 0)
        write_png16(root / "sparse" / f"{i:04d}.png", sparse, 1000)
    (root / "intrinsics.txt").write_text("40 40 20 15\n")
    return root


CONFIG = TrainConfig(
    name="sources", model=LIPConfig(prior=network_preset("tiny"), num_iterations=1),
    data=DataConfig(crop=CROP, train_sampler="uniform:30", val_sampler="uniform:30", val_images=2, num_workers=0),
    batch_size=2, g_steps=3, log_every=1, eval_every=3, checkpoint_every=1,
)


def source_config(tmp_path, source: str) -> DataConfig:
    """The DataConfig of `source` over fixture files written under tmp_path."""
    d = CONFIG.data
    if source == "nyu_h5":
        return dataclasses.replace(d, source=source, root=str(make_nyu(tmp_path / "nyu")), protocol="none")
    if source == "kitti_dc":
        root = make_kitti(tmp_path / "kitti")
        return dataclasses.replace(d, source=source, root=str(root / "depth"), raw_root=str(root / "raw"),
                                   protocol="none", train_sampler="input", val_sampler="input:20")
    if source == "folder":
        return dataclasses.replace(d, source=source, root=str(make_folder(tmp_path / "folder")), depth_scale=1000.0,
                                   train_sampler="input")
    if source == "rendered":
        out = render_to_disk("indoor", "train", 6, tmp_path / "rendered", height=H, width=W, workers=1, progress=False)
        return dataclasses.replace(d, source=source, root=str(out), height=H, width=W)
    raise AssertionError(source)


def test_kitti_input_is_the_real_scan_and_folder_input_its_sparse_maps(tmp_path):
    kitti_config = source_config(tmp_path, "kitti_dc")
    kitti = open_source(kitti_config, "train")
    frame = kitti.dataset[1]
    scan = cv2.imread(str(tmp_path / f"kitti/depth/data_depth_velodyne/train/{DRIVE}/proj_depth/velodyne_raw/"
                                     "image_02/0000000001.png"), cv2.IMREAD_UNCHANGED) / np.float32(256)
    assert np.array_equal(kitti.sampler(frame), scan.astype(np.float32))
    val = open_source(kitti_config, "val")
    assert np.count_nonzero(val.sampler(val.dataset[0])) == 20
    selection = dataclasses.replace(kitti_config, source="kitti_selection", root=str(make_kitti_selection(
        tmp_path / "selection")), val_sampler="input")
    val = open_source(selection, "val")
    scan_dir = tmp_path / "selection/depth_selection/val_selection_cropped/velodyne_raw"
    scan = cv2.imread(str(scan_dir / f"{DRIVE}_velodyne_raw_0000000001_image_02.png"), cv2.IMREAD_UNCHANGED) / 256
    assert np.array_equal(val.sampler(val.dataset[1]), scan.astype(np.float32)) and scan.any()
    with pytest.raises(ValueError, match="val split only"):
        open_source(selection, "train")
    folder = source_config(tmp_path, "folder")
    train, val = open_source(folder, "train"), open_source(folder, "val")
    assert (len(train.dataset), len(val.dataset)) == (5, 1)  # no train/ val/: the last 5 % (>= 1 frame) validates
    own = cv2.imread(str(tmp_path / "folder/sparse/0000.png"), cv2.IMREAD_UNCHANGED) / np.float32(1000)
    assert np.array_equal(train.sampler(train.dataset[0]), own.astype(np.float32)) and own.any()
    with pytest.raises(ValueError, match="no sparse input of its own"):
        open_source(dataclasses.replace(CONFIG.data, train_sampler="input"), "train")
    with pytest.raises(ValueError, match="needs data.root"):
        open_source(dataclasses.replace(CONFIG.data, source="nyu_h5"), "train")


def test_tartanair_and_kitti_odometry_sources_split_without_overlap(tmp_path):
    for t in range(20):  # TartanAir: 20 trajectories of 2 frames, split 90/5/5 by trajectory
        for f in range(2):
            base = tmp_path / "tartanair" / f"env{t % 4}" / "Easy" / f"P{t:03d}"
            rgb, depth = frame(t * 2 + f)
            write_rgb(base / "image_left" / f"{f:06d}_left.png", rgb)
            (base / "depth_left").mkdir(exist_ok=True)
            np.save(base / "depth_left" / f"{f:06d}_left_depth.npy", depth)
    data = dataclasses.replace(CONFIG.data, source="tartanair", root=str(tmp_path / "tartanair"), val_images=40,
                               protocol="none")
    train, val = open_source(data, "train"), open_source(data, "val")
    ids = [{s.dataset[i].id.rsplit("/", 1)[0] for i in range(len(s.dataset))} for s in (train, val)]
    assert ids[0] and ids[1] and not ids[0] & ids[1]
    for seq in ("00", "01"):  # KITTI odometry: the last 5 % of each sequence (>= 1 frame) validates
        d = tmp_path / "odometry" / "sequences" / seq
        (d / "image_2").mkdir(parents=True)
        (d / "velodyne").mkdir()
        (d / "calib.txt").write_text("P2: 20 0 20 0 0 20 15 0 0 0 1 0\nTr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n")
        for f in range(4):
            cv2.imwrite(str(d / "image_2" / f"{f:06d}.png"), frame(f)[0])
            np.array([[4.0, 0.0, 0.0, 1.0], [6.0, 0.5, 0.2, 1.0]], np.float32).tofile(d / "velodyne" / f"{f:06d}.bin")
    data = dataclasses.replace(CONFIG.data, source="kitti_odometry", root=str(tmp_path / "odometry"), protocol="none")
    train, val = open_source(data, "train"), open_source(data, "val")
    val_ids = [val.dataset[i].id for i in range(len(val.dataset))]
    assert val_ids == ["kitti_odometry/00/000003", "kitti_odometry/01/000003"]
    assert len(train.dataset) == 6 and np.count_nonzero(train.sampler(train.dataset[0])) == 2


def test_rendered_shards_hold_the_on_the_fly_frames(tmp_path):
    out = render_to_disk("indoor", "train", 5, tmp_path / "r", height=H, width=W, workers=2, shard_size=2,
                         progress=False)
    index = json.loads((out / "index.json").read_text())
    assert index["count"] == 5 and index["shards"] == ["shard-00000", "shard-00001", "shard-00002"]
    assert index["depth_dtype"] == "uint16" and index["depth_scale"] == 1000.0
    data = RenderedDataset(out)
    for i in (0, 3, 4):
        want, got = render("indoor", "train", i, H, W), data[i]
        assert got.id == want.id and got.intrinsics == want.intrinsics and np.array_equal(got.rgb, want.rgb)
        assert np.abs(got.depth - want.depth).max() <= 0.5e-3 + 1e-6 and np.array_equal(got.valid, want.valid)
    with pytest.raises(ValueError, match="different render"):
        render_to_disk("indoor", "train", 6, out, height=H, width=W, workers=1, progress=False)
    window = RenderedDataset(render_to_disk("outdoor", "val", 2, tmp_path / "w", height=H, width=W, window=(16, 24),
                                            workers=1, progress=False))
    full = render("outdoor", "val", 1, H, W).intrinsics
    top, left = full.cy - window[1].intrinsics.cy, full.cx - window[1].intrinsics.cx
    assert window[1].shape == (16, 24) and 0 <= top <= H - 16 and 0 <= left <= W - 24


def test_several_rendered_folders_train_as_one_data_set(tmp_path):
    """data.root="A,B": rooms then streets (one frame size) in one data set, each frame with its own folder's id,
    intrinsics and depth; data.kind must be the first folder's (it names the val split); other sizes are refused."""
    rooms = render_to_disk("indoor", "train", 3, tmp_path / "rooms", height=H, width=W, workers=1, progress=False)
    streets = render_to_disk("outdoor", "train", 2, tmp_path / "streets", height=3 * H, width=4 * W, window=(H, W),
                             workers=1, progress=False)
    data = dataclasses.replace(CONFIG.data, source="rendered", root=f"{rooms},{streets}", height=H, width=W)
    mixed = open_source(data, "train").dataset
    assert len(mixed) == 5 and mixed.kinds == ("indoor", "outdoor")
    for i, (part, j) in enumerate([(rooms, 0), (rooms, 1), (rooms, 2), (streets, 0), (streets, 1)]):
        want, got = RenderedDataset(part)[j], mixed[i]
        assert got.id == want.id and got.intrinsics == want.intrinsics and np.array_equal(got.depth, want.depth)
    assert mixed[4].depth.max() > 10.0  # a street, not a room
    with pytest.raises(IndexError):
        mixed[5]
    with pytest.raises(ValueError, match="holds outdoor renders first but data.kind='indoor'"):
        open_source(dataclasses.replace(data, root=f"{streets},{rooms}"), "train")
    other = render_to_disk("indoor", "val", 1, tmp_path / "other", height=H + 2, width=W, workers=1, progress=False)
    with pytest.raises(ValueError, match="different frame sizes"):
        open_source(dataclasses.replace(data, root=f"{rooms},{other}"), "train")
    config = dataclasses.replace(CONFIG, name="mixed", data=data, loss_scale="samples")
    state = loop.train(config, tmp_path / "run", stop_at=2, progress=False)
    assert int(state.step) == 2


@pytest.mark.parametrize("source", ["nyu_h5", "kitti_dc", "folder", "rendered"])
def test_trains_a_few_steps_and_resumes(tmp_path, source):
    config = dataclasses.replace(CONFIG, name=source, data=source_config(tmp_path, source))
    loop.train(config, tmp_path / "run", stop_at=2, progress=False)  # the "killed" run
    state = loop.train(config, tmp_path / "run", progress=False)
    assert int(state.step) == 3
    rows = [json.loads(line) for line in (tmp_path / "run" / "metrics.jsonl").read_text().splitlines()]
    assert [r["step"] for r in rows if "phase" in r] == [1, 2, 3]
    assert all(np.isfinite(r["loss"]) for r in rows if "loss" in r)
    assert [r for r in rows if r.get("split") == "val"][0]["rmse_m"] > 0
    _, meta = CheckpointManager(tmp_path / "run" / "checkpoints").restore(init_state(config))
    assert meta["data_position"] == 3
    straight = loop.train(config, tmp_path / "straight", progress=False)  # the same 3 steps without the stop
    for a, b in zip(jax.tree_util.tree_leaves(straight.g_params), jax.tree_util.tree_leaves(state.g_params),
                    strict=True):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))


@pytest.mark.skipif(importlib.util.find_spec("tensorflow_datasets") is None, reason="pip install lipjax[tfds]")
def test_nyu_tfds_trains_through_mock_data(tmp_path):
    """TFDS nyu_depth_v2 read as a data source (no TensorFlow): random 480x640 frames from tfds.testing.mock_data,
    through the nyu_paper protocol (256x320) and the crop."""
    import tensorflow_datasets as tfds

    data = dataclasses.replace(CONFIG.data, source="nyu_tfds", root=str(tmp_path / "tfds"))
    with tfds.testing.mock_data(num_examples=4, policy=tfds.testing.MockPolicy.USE_CODE):
        assert open_source(data, "val").dataset[0].shape == (256, 320)
        state = loop.train(dataclasses.replace(CONFIG, name="tfds", data=data), tmp_path / "run", progress=False)
    assert int(state.step) == 3


def test_workers_resume_bit_identically(tmp_path):
    """A run with 2 loader processes, killed and resumed from the grain state, equals one straight run."""
    config = dataclasses.replace(CONFIG, data=dataclasses.replace(source_config(tmp_path, "rendered"), num_workers=2),
                                 eval_every=0)
    straight = loop.train(config, tmp_path / "straight", progress=False)
    loop.train(config, tmp_path / "killed", stop_at=1, progress=False)
    resumed = loop.train(config, tmp_path / "killed", progress=False)
    assert jax.tree_util.tree_structure(straight.g_params) == jax.tree_util.tree_structure(resumed.g_params)
    for a, b in zip(jax.tree_util.tree_leaves(straight.g_params), jax.tree_util.tree_leaves(resumed.g_params)):
        assert np.array_equal(np.asarray(a), np.asarray(b))


def complete(model, rgb, depth, out, *extra):
    return subprocess.run([sys.executable, "-m", "lipjax.cli", "complete", "--model", str(model), "--rgb", str(rgb),
                           "--depth", str(depth), "--out", str(out), "--quiet", *extra], capture_output=True,
                          text=True, timeout=600)


def test_lip_cnn_nyu_trains_exports_and_the_model_completes(tmp_path, capsys):
    """The issue's "done when": the named config on NYU h5 files, exported to a given path, then `lipjax complete`
    and `lipjax evaluate --source nyu_h5` (the fixture frames are 30x40, so the nyu_paper crop is replaced by
    protocol none)."""
    import lipjax
    from lipjax import cli
    from lipjax.data.folder import read_frame

    root = make_nyu(tmp_path / "nyu")
    model = tmp_path / "model"
    args = ["--config", "lip_cnn_nyu", "--workdir", str(tmp_path / "run"), "--no-progress", "--export", str(model),
            "--set", f"data.root={root}", "--set", "data.protocol=none", "--set", "data.crop=24,32",
            "--set", "data.num_workers=1", "--set", "data.val_images=2", "--set", "g_steps=2",
            "--set", "batch_size=2", "--set", "eval_every=0", "--set", "model.num_iterations=1"]  # K=1: compile time
    train = subprocess.run([sys.executable, "-m", "experiments.train", *args], capture_output=True, text=True,
                           timeout=600)
    assert train.returncode == 0, train.stderr[-3000:]
    rgb, depth = frame(0)
    cv2.imwrite(str(tmp_path / "rgb.png"), rgb)
    np.save(tmp_path / "sparse.npy", np.where(np.arange(H * W).reshape(H, W) % 13 == 0, depth, 0))
    done = complete(model, tmp_path / "rgb.png", tmp_path / "sparse.npy", tmp_path / "out.npy")
    assert done.returncode == 0, done.stderr[-3000:]
    rgb_read, sparse_read = read_frame(tmp_path / "rgb.png", tmp_path / "sparse.npy", None)
    expected = lipjax.complete(rgb_read, sparse_read, model=lipjax.load_model(model))  # the exported model's output
    np.testing.assert_allclose(np.load(tmp_path / "out.npy"), expected, rtol=1e-5, atol=1e-5)
    assert cli.main(["evaluate", "--source", "nyu_h5", "--root", str(root), "--protocol", "none",
                     "--model", str(model), "--limit", "2", "--quiet"]) == 0
    row = [line for line in capsys.readouterr().out.splitlines() if line.startswith(f"| {model} |")]
    assert len(row) == 1 and np.isfinite(float(row[0].split("|")[2]))


def test_lipjax_evaluate_reads_a_source_as_training_does(tmp_path, capsys):
    """`lipjax evaluate --source nyu_h5` scores the val frames open_source gives training, over the depth range of
    the source's protocol (nyu_paper: 10 m) even with protocol none; a missing or bad root is a one-line error."""
    from lipjax import cli
    from lipjax.data.protocols import get_protocol
    from lipjax.evaluate import evaluate
    from lipjax.methods import get_completer

    root = make_nyu(tmp_path / "nyu")
    assert cli.main(["evaluate", "--source", "nyu_h5", "--root", str(root), "--protocol", "none", "--model", "linear",
                     "--limit", "2", "--quiet", "--json", str(tmp_path / "results.json")]) == 0
    out = capsys.readouterr().out
    source = open_source(dataclasses.replace(CONFIG.data, source="nyu_h5", root=str(root), protocol="none",
                                             val_sampler="uniform:200"), "val")
    nyu = get_protocol("nyu_paper")
    want = evaluate(get_completer("linear", None), source.dataset, source.sampler, min_depth_m=nyu.min_depth_m,
                    max_depth_m=nyu.max_depth_m, limit=2, progress=False)
    got = json.loads((tmp_path / "results.json").read_text())["linear"]
    assert np.isfinite(want.metrics["rmse_m"]) and got["metrics"]["rmse_m"] == want.metrics["rmse_m"]
    assert [r["id"] for r in got["per_image"]] == ["nyu/val/office_0001/1", "nyu/val/office_0001/2"]
    assert f"| linear | {want.metrics['rmse_m']:.3f} |" in out and "depth range: (0, 10] m" in out
    for args, message in [(["--root", str(tmp_path / "nowhere")], "lipjax: error: NYU Depth v2 'val' split not found"),
                          ([], "lipjax: error: --source nyu_h5 needs --root DIR")]:
        assert cli.main(["evaluate", "--source", "nyu_h5", "--model", "linear", "--quiet", *args]) == 1
        lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith(message), lines


def test_lipjax_train_on_a_folder_exports_a_model_that_completes(tmp_path):
    """`lipjax train --data DIR --init lip-cnn-indoor` (= lip_cnn_folder), then `lipjax complete`."""
    root = make_folder(tmp_path / "folder")
    model = tmp_path / "model"
    train = subprocess.run([sys.executable, "-m", "lipjax.cli", "train", "--data", str(root), "--out", str(model),
                            "--depth-scale", "1000", "--steps", "2", "--batch-size", "2", "--crop", "24", "32",
                            "--workers", "0", "--init", "lip-cnn-indoor", "--keep", "last",
                            "--workdir", str(tmp_path / "run"), "--quiet"],
                           capture_output=True, text=True, timeout=600)
    assert train.returncode == 0, train.stderr[-3000:]
    done = complete(model, root / "rgb" / "0000.png", root / "sparse" / "0000.png", tmp_path / "out.npy",
                    "--depth-scale", "1000")
    assert done.returncode == 0, done.stderr[-3000:]
    import lipjax
    from lipjax.data.folder import read_depth, read_rgb

    trained, start = lipjax.load_model(model), lipjax.load_model("lip-cnn-indoor")
    assert trained.config == start.config
    assert any(not np.array_equal(np.asarray(a), np.asarray(b)) for a, b in  # two steps did move the weights
               zip(jax.tree_util.tree_leaves(trained.params), jax.tree_util.tree_leaves(start.params), strict=True))
    rgb, sparse = read_rgb(root / "rgb" / "0000.png"), read_depth(root / "sparse" / "0000.png", 1000)
    np.testing.assert_allclose(np.load(tmp_path / "out.npy"), lipjax.complete(rgb, sparse, model=trained),
                               rtol=1e-5, atol=1e-5)  # the command's output is the exported model's completion


def test_lipjax_train_starts_from_the_default_model_names_the_export_after_out_and_validates_at_0_and_the_end(
        tmp_path, capsys, monkeypatch):
    """Without --init, `lipjax train` fine-tunes the default model of the frames' scene (lipjax.shipped.DEFAULT_MODELS,
    here a tiny stand-in) and says so in one line; no intrinsics are needed for point samplers; the validation score
    of the starting model (step 0) and of the result are printed and logged; the model and the run are named after
    --out."""
    import lipjax.shipped
    from lipjax import cli, model_io
    from lipjax.train.folder import default_init, folder_config
    from lipjax.train.run import logged_validation

    stem = tmp_path / "tiny"
    model_io.save(stem, CONFIG.model, init_state(CONFIG).g_params)
    monkeypatch.setitem(lipjax.shipped.DEFAULT_MODELS, "indoor", str(stem))
    root = make_folder(tmp_path / "folder")
    (root / "intrinsics.txt").unlink()
    out = tmp_path / "models" / "mine"
    assert cli.main(["train", "--data", str(root), "--out", str(out), "--depth-scale", "1000", "--steps", "2",
                     "--batch-size", "2", "--crop", "24", "32", "--workers", "0", "--keep", "last",
                     "--workdir", str(tmp_path / "run")]) == 0
    captured = capsys.readouterr()
    init, scene, why = default_init(root=str(root), depth_scale=1000.0)
    assert (init, scene) == (str(stem), "indoor")
    assert captured.err.splitlines()[0] == (f"init: {stem}, the default for indoor input ({why}); "
                                            "choose another with --init")
    start, end = (logged_validation(tmp_path / "run" / "metrics.jsonl", step) for step in (0, 2))
    config = folder_config(CONFIG.model, str(stem), root=str(root), depth_scale=1000.0, crop=CROP, num_workers=0)
    want = loop.evaluate_params(CONFIG.model, model_io.load(stem)[1], loop.validation_batches(config), 10.0)
    assert start["rmse_m"] == pytest.approx(want["rmse_m"], rel=1e-6)
    lines = captured.out.splitlines()
    assert f"[lipjax] step 0 (start) val rmse_m={start['rmse_m']:.4f} mae_m={start['mae_m']:.4f}" in lines
    worse = end["rmse_m"] > start["rmse_m"]  # --keep last exports the end either way, and says which it was
    before = (f", WORSE than {start['rmse_m']:.4f} at step 0 (the last, as asked; keep best exports the start)"
              if worse else f" ({start['rmse_m']:.4f} at step 0)")
    assert lines[-1] == f"[lipjax] exported mine (step 2) to {out}: val rmse_m={end['rmse_m']:.4f}{before}"
    meta = model_io.metadata(out)
    assert meta["train_config"] == "mine" and meta["val_metrics"]["rmse_m"] == end["rmse_m"]


def test_lipjax_train_checks_its_output_folder_and_every_frame_before_training(tmp_path, capsys):
    """`lipjax train` fails before training, with one line and no workdir: when --out's folder cannot be written,
    and when frames are unreadable (naming every one: a corrupt RGB, a truncated depth PNG, and the sparse map
    of a run that trains on the folder's own input)."""
    from lipjax import cli
    from lipjax.train.folder import check_frames

    root = make_folder(tmp_path / "folder")
    (tmp_path / "blocker").write_text("a file where the model's folder should be")
    args = ["train", "--data", str(root), "--depth-scale", "1000", "--steps", "2", "--workers", "0", "--quiet",
            "--workdir", str(tmp_path / "run")]
    assert cli.main(args + ["--out", str(tmp_path / "blocker" / "model")]) == 1
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines == [f"lipjax: error: cannot write the model (--out / --export) into {tmp_path / 'blocker'} "
                     f"({tmp_path / 'blocker'}: a file, not a folder); choose a writable folder"]
    assert check_frames(dataclasses.replace(CONFIG.data, source="folder", root=str(root), depth_scale=1000)) == 6
    (root / "rgb" / "0001.png").write_bytes(b"not a png")
    (root / "depth" / "0004.png").write_bytes((root / "depth" / "0004.png").read_bytes()[:60])
    (root / "sparse" / "0002.png").write_bytes(b"")
    assert cli.main(args + ["--out", str(tmp_path / "model" / "mine"), "--sampler", "input"]) == 1
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines == [f"lipjax: error: 3 unreadable file(s) in {root}, checked before training: Cannot read RGB image "
                     "(missing, corrupt or unsupported format): rgb/0001.png; Cannot read depth PNG (missing, "
                     "corrupt or not an image): depth/0004.png; Cannot read depth PNG (missing, corrupt or not an "
                     "image): sparse/0002.png; fix or remove them (with their partner files)"]
    assert not (tmp_path / "run").exists() and not (tmp_path / "model").exists()


def test_lipjax_data_render_command(tmp_path, capsys):
    from lipjax import cli

    args = ["data", "render", "--kind", "outdoor", "--count", "2", "--height", "16", "--width", "24", "--workers", "1",
            "--out", str(tmp_path / "r"), "--quiet"]
    assert cli.main(args) == 0 and len(RenderedDataset(tmp_path / "r")) == 2
    assert cli.main(args[:5] + ["3"] + args[6:]) == 1  # another render into the same folder: a one-line error
    assert "already holds a different render" in capsys.readouterr().err


# `lipjax data render` with 4-frame shards, so that a short render has many shards to stop between.
RENDER_IN_SHARDS_OF_4 = ("import functools, sys; import lipjax.data.rendered as r; "
                         "r.render_to_disk = functools.partial(r.render_to_disk, shard_size=4); "
                         "from lipjax.cli import main; sys.exit(main(sys.argv[1:]))")


@pytest.mark.skipif(not pathlib.Path("/proc/self/stat").exists(), reason="needs Linux /proc")
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT, signal.SIGKILL])
def test_a_stopped_render_takes_its_workers_with_it_and_the_same_command_finishes_it(tmp_path, signum):
    """SIGTERM, Ctrl-C (SIGINT to the whole process group, as a terminal sends it) or SIGKILL in the middle of
    `lipjax data render --workers 2`: no worker outlives the command, which says in one line how to finish
    (exit 143 / 130); the finished shards stay as they were, and the same render finishes the set, bit for bit
    what an uninterrupted render writes."""
    from lipjax.data.rendered import RenderSpec, _render_shard

    out, count = tmp_path / "r", 40  # 10 shards: seconds of rendering left when the first one lands
    args = ["data", "render", "--kind", "indoor", "--count", str(count), "--height", "256", "--width", "320",
            "--workers", "2", "--out", str(out), "--quiet"]
    with open(tmp_path / "err.txt", "w") as err:
        proc = subprocess.Popen([sys.executable, "-c", RENDER_IN_SHARDS_OF_4, *args], stderr=err,
                                start_new_session=True)
    try:
        deadline = time.time() + 120
        while not list(out.glob("shard-*.depth.npy")) and time.time() < deadline:
            time.sleep(0.05)
        workers = children(proc.pid)
        assert len(workers) >= 2  # the two workers (and multiprocessing's resource tracker)
        if signum == signal.SIGINT:
            os.killpg(proc.pid, signum)
        else:
            proc.send_signal(signum)
        assert proc.wait(timeout=60) == {signal.SIGTERM: 143, signal.SIGINT: 130, signal.SIGKILL: -9}[signum]
    finally:
        proc.kill()
    deadline = time.time() + 20
    while [w for w in workers if alive(w)] and time.time() < deadline:
        time.sleep(0.1)
    assert not [w for w in workers if alive(w)], "render processes outlived the command"
    if signum != signal.SIGKILL:
        assert (tmp_path / "err.txt").read_text() == (f"lipjax: render stopped; its finished shards stay in {out}, "
                                                      "and the same command finishes it\n")
    finished = {p.name: p.read_bytes() for p in out.glob("shard-*.npy")}
    assert 0 < len(finished) < 2 * count // 4 and not (out / "index.json").exists()
    render_to_disk("indoor", "train", count, out, height=256, width=320, workers=1, shard_size=4, progress=False)
    assert len(RenderedDataset(out)) == count and not list(out.glob(".shard-*"))
    assert all((out / name).read_bytes() == data for name, data in finished.items())
    spec = RenderSpec("indoor", "train", count, 256, 320, None, 4)
    for shard in (0, spec.num_shards - 1):
        _render_shard(spec, shard, str(tmp_path))
        for part in ("rgb", "depth"):
            name = f"shard-{shard:05d}.{part}.npy"
            assert (out / name).read_bytes() == (tmp_path / name).read_bytes(), name


def test_lipjax_evaluate_source_rendered_scores_the_rendered_frames(tmp_path, capsys):
    """`lipjax evaluate --source rendered --root DIR` scores the frames in DIR (not the synthetic val split) over
    the depth range of the render's kind (outdoor: 80 m); --kind picks the synthetic scenes of --source synthetic;
    flags --source ignores, or a split it has not, are one-line errors; training reads a render of another kind
    as an error for either split."""
    from lipjax import cli
    from lipjax.data.protocols import get_protocol
    from lipjax.evaluate import evaluate, open_eval_source
    from lipjax.data.sampling import sampler_from_spec
    from lipjax.data.synthetic import frame_id
    from lipjax.methods import get_completer

    out = render_to_disk("outdoor", "val", 2, tmp_path / "r", height=H, width=W, workers=1, progress=False)
    assert cli.main(["evaluate", "--source", "rendered", "--root", str(out), "--model", "nearest", "--quiet",
                     "--json", str(tmp_path / "results.json")]) == 0
    assert "data: rendered outdoor/val" in capsys.readouterr().out
    more = render_to_disk("outdoor", "train", 1, tmp_path / "r2", height=H, width=W, workers=1, progress=False)
    assert cli.main(["evaluate", "--source", "rendered", "--root", f"{out},{more}", "--model", "nearest", "--quiet",
                     "--json", str(tmp_path / "both.json")]) == 0  # several folders of one kind: one set
    assert "data: rendered outdoor/val + outdoor/train" in capsys.readouterr().out
    both = json.loads((tmp_path / "both.json").read_text())["nearest"]
    assert [r["id"] for r in both["per_image"]] == [RenderedDataset(out)[0].id, RenderedDataset(out)[1].id,
                                                     RenderedDataset(more)[0].id]
    rooms = render_to_disk("indoor", "val", 1, tmp_path / "r3", height=H, width=W, workers=1, progress=False)
    with pytest.raises(ValueError, match="mixes indoor and outdoor renders"):
        open_eval_source("rendered", f"{out},{rooms}")
    outdoor = get_protocol("synthetic_outdoor")
    want = evaluate(get_completer("nearest", None), RenderedDataset(out), sampler_from_spec("uniform:200"),
                    min_depth_m=outdoor.min_depth_m, max_depth_m=outdoor.max_depth_m, progress=False)
    got = json.loads((tmp_path / "results.json").read_text())["nearest"]
    assert outdoor.max_depth_m == 80.0 and got["max_depth_m"] == 80.0 and got["num_images"] == 2
    assert np.isfinite(want.metrics["rmse_m"]) and got["metrics"]["rmse_m"] == want.metrics["rmse_m"]
    assert [r["id"] for r in got["per_image"]] == [RenderedDataset(out)[i].id for i in range(2)]
    synthetic, protocol = open_eval_source("synthetic", None, kind="outdoor")
    first = synthetic.dataset[0]  # the outdoor val split at the outdoor training size
    assert (first.id, first.shape) == (frame_id("outdoor", "val", 0), (128, 416))
    assert protocol.name == "synthetic_outdoor"
    with pytest.raises(ValueError, match="holds outdoor renders"):
        open_eval_source("rendered", out, kind="indoor")
    data = dataclasses.replace(CONFIG.data, source="rendered", root=str(out), height=H, width=W)
    for split in ("train", "val"):
        with pytest.raises(ValueError, match="add --set data.kind=outdoor"):
            open_source(data, split)
    outdoor_val = open_source(dataclasses.replace(data, kind="outdoor"), "val").dataset
    assert outdoor_val[0].id == render("outdoor", "val", 0, H, W).id and len(outdoor_val) == CONFIG.data.val_images
    base = ["evaluate", "--model", "nearest", "--quiet"]
    rendered = ["--source", "rendered", "--root", str(out)]
    for args, message in [(rendered + ["--size", "16", "24"], "--size is for --data synthetic-*"),
                          (rendered + ["--intrinsics", "1", "1", "0", "0"], "--intrinsics / --intrinsics-file"),
                          (["--source", "synthetic", "--intrinsics-file", "K.txt"],
                           "--intrinsics / --intrinsics-file"),
                          (["--source", "synthetic", "--split", "test"], "--split test: with --source"),
                          (rendered + ["--split", "val"], "--split: --source rendered evaluates the frames"),
                          (rendered + ["--kind", "outdoor"], "--kind goes with --source synthetic"),
                          (["--data", "synthetic-indoor", "--kind", "outdoor"],
                           "--kind goes with --source synthetic")]:
        assert cli.main(base + args) == 1, args
        lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith(f"lipjax: error: {message}"), lines


def test_synthetic_far_views_train_on_mixed_scenes_only_and_never_validate():
    mixed = DataConfig(kind="mixed", height=H, width=W, far_view_prob=1.0, val_images=2)
    assert open_source(mixed, "train").dataset.far_view_prob == 1.0
    assert open_source(mixed, "val").dataset.far_view_prob == 0.0  # validation: closed rooms
    with pytest.raises(ValueError, match="data.far_view_prob needs rooms and streets"):
        open_source(DataConfig(kind="indoor", far_view_prob=0.3), "train")
