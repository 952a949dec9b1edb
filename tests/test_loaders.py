"""Loaders read tiny fixture files written here in each real on-disk format (never the shared data)."""
from __future__ import annotations

import sys

import cv2
import h5py
import numpy as np
import pytest

from lipjax.data.errors import DatasetError
from lipjax.data.folder import FolderDataset, read_depth, read_rgb
from lipjax.data.kitti import (
    KittiDepthCompletion,
    KittiFrame,
    KittiLidarInput,
    KittiSelection,
    intrinsics_from_calib,
)
from lipjax.data.frame import Intrinsics
from lipjax.data.nyu import NYU_INTRINSICS, NyuH5Dataset, NyuTfdsDataset
from lipjax.data.protocols import BottomCrop, EvalProtocol
from lipjax.data.tartanair import TARTANAIR_INTRINSICS, TARTANAIR_MAX_VALID_DEPTH_M, TartanAirDataset

H, W = 12, 16


def write_rgb(path, rgb):
    path.parent.mkdir(parents=True, exist_ok=True)
    assert cv2.imwrite(str(path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))


def write_png16(path, raw):
    path.parent.mkdir(parents=True, exist_ok=True)
    assert cv2.imwrite(str(path), raw.astype(np.uint16))


def pattern_rgb(seed: int) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 256, (H, W, 3), dtype=np.uint8)


# ---- image / depth readers --------------------------------------------------------------------------------------


def test_read_rgb_converts_bgr_to_rgb(tmp_path):
    rgb = np.zeros((4, 5, 3), np.uint8)
    rgb[..., 0] = 255  # pure red
    write_rgb(tmp_path / "red.png", rgb)
    out = read_rgb(tmp_path / "red.png")
    assert out.dtype == np.uint8 and out.shape == (4, 5, 3) and out[0, 0].tolist() == [255, 0, 0]
    (tmp_path / "bad.png").write_bytes(b"not an image")
    with pytest.raises(DatasetError, match="bad.png"):
        read_rgb(tmp_path / "bad.png")


def test_read_depth_png_and_npy(tmp_path):
    raw = np.array([[0, 1000, 2500]], np.uint16)
    write_png16(tmp_path / "d.png", raw)
    assert read_depth(tmp_path / "d.png", scale=1000).tolist() == [[0.0, 1.0, 2.5]]
    with pytest.raises(DatasetError, match=r"(?s)depth scale.*KITTI 256.*d\.png"):
        read_depth(tmp_path / "d.png")
    np.save(tmp_path / "m.npy", np.array([[0.0, 1.5]], np.float64))
    out = read_depth(tmp_path / "m.npy")
    assert out.dtype == np.float32 and out.tolist() == [[0.0, 1.5]]
    np.save(tmp_path / "nan.npy", np.array([[np.nan, 1.0]], np.float32))
    with pytest.raises(DatasetError, match="NaN"):
        read_depth(tmp_path / "nan.npy")
    np.save(tmp_path / "neg.npy", np.array([[-1.0, 1.0]], np.float32))
    with pytest.raises(DatasetError, match="negative"):
        read_depth(tmp_path / "neg.npy")
    assert cv2.imwrite(str(tmp_path / "8bit.png"), np.ones((2, 2), np.uint8))
    with pytest.raises(DatasetError, match="16-bit"):
        read_depth(tmp_path / "8bit.png", scale=256)
    (tmp_path / "pickled.npy").write_bytes(b"\x93NUMPY garbage")
    with pytest.raises(DatasetError, match="pickled.npy"):
        read_depth(tmp_path / "pickled.npy")


# ---- NYU h5 ---------------------------------------------------------------------------------------------------


def write_nyu_h5(path, seed):
    path.parent.mkdir(parents=True, exist_ok=True)
    rgb = pattern_rgb(seed)
    depth = np.random.default_rng(seed).uniform(0.5, 9.0, (H, W)).astype(np.float32)
    depth[0, 0] = 0
    with h5py.File(path, "w") as f:
        f["rgb"] = np.transpose(rgb, (2, 0, 1))  # stored (3, H, W) as in Ma et al.'s files
        f["depth"] = depth
    return rgb, depth


def test_nyu_h5_values_ids_order(tmp_path):
    root = tmp_path / "data" / "nyudepthv2"
    written = {n: write_nyu_h5(root / "val" / "official" / f"{n}.h5", n) for n in (10, 2, 1)}
    write_nyu_h5(root / "val" / "a_scene" / "7.h5", 7)
    ds = NyuH5Dataset(tmp_path / "data", "val")  # the parent of nyudepthv2 works too
    assert [ds[i].id for i in range(len(ds))] == ["nyu/val/a_scene/7", "nyu/val/official/1", "nyu/val/official/2",
                                                  "nyu/val/official/10"]
    s = ds[3]
    rgb, depth = written[10]
    assert np.array_equal(s.rgb, rgb) and s.depth.dtype == np.float32
    assert np.allclose(s.depth, depth) and not s.valid[0, 0] and s.valid[0, 1]
    assert s.intrinsics == NYU_INTRINSICS and NyuH5Dataset(root, "val")[0].id == "nyu/val/a_scene/7"


def test_nyu_h5_errors(tmp_path):
    with pytest.raises(DatasetError,
                       match=r"(?s)not found: .*missing/val.*Expected layout.*nyudepthv2.*sparse-to-dense"):
        NyuH5Dataset(tmp_path / "missing", "val")
    bad = tmp_path / "nyudepthv2" / "train" / "s" / "1.h5"
    bad.parent.mkdir(parents=True)
    bad.write_bytes(b"this is not hdf5")
    ds = NyuH5Dataset(tmp_path, "train")
    with pytest.raises(DatasetError, match=r"(?s)Corrupt.*1\.h5"):
        ds[0]
    with h5py.File(bad, "w") as f:
        f["rgb"] = np.zeros((3, H, W), np.uint8)  # no 'depth'
    with pytest.raises(DatasetError, match="depth"):
        ds[0]
    (tmp_path / "nyudepthv2" / "val").mkdir()
    with pytest.raises(DatasetError, match="No .h5"):
        NyuH5Dataset(tmp_path, "val")


def test_nyu_tfds_missing_package_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "tensorflow_datasets", None)  # installed or not: the import fails
    with pytest.raises(DatasetError, match=r"pip install lipjax\[tfds\]"):
        NyuTfdsDataset("val")


# ---- KITTI depth completion ------------------------------------------------------------------------------------

CALIB = ("calib_time: 09-Jan-2012 13:57:47\n"
         "corner_dist: 9.950000e-02\n"
         "P_rect_00: 7.215377e+02 0.000000e+00 6.095593e+02 0.000000e+00 0.000000e+00 7.215377e+02 1.728540e+02 "
         "0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00\n"
         "P_rect_02: 7.215377e+02 0.000000e+00 6.095593e+02 4.485728e+01 0.000000e+00 7.215377e+02 1.728540e+02 "
         "2.163791e-01 0.000000e+00 0.000000e+00 1.000000e+00 2.745884e-03\n"
         "P_rect_03: 7.205000e+02 0.000000e+00 6.090000e+02 -3.395242e+02 0.000000e+00 7.215377e+02 1.728540e+02 "
         "2.199936e+00 0.000000e+00 0.000000e+00 1.000000e+00 2.729905e-03\n")
DRIVE = "2011_09_26_drive_0002_sync"


def make_kitti_tree(tmp_path, frames=("0000000005", "0000000010", "0000000100"), cameras=("image_02", "image_03")):
    depth_root, raw_root = tmp_path / "kitti_depth", tmp_path / "kitti_raw"
    (raw_root / DRIVE[:10]).mkdir(parents=True)
    (raw_root / DRIVE[:10] / "calib_cam_to_cam.txt").write_text(CALIB)
    raws = {}
    for c, camera in enumerate(cameras):
        for f, frame in enumerate(frames):
            rng = np.random.default_rng(100 * c + f)
            gt = rng.integers(0, 80 * 256, (H, W)).astype(np.uint16)
            velo = np.where(rng.random((H, W)) < 0.3, gt, 0).astype(np.uint16)
            write_png16(depth_root / "data_depth_annotated" / "val" / DRIVE / "proj_depth" / "groundtruth" / camera
                        / f"{frame}.png", gt)
            write_png16(depth_root / "data_depth_velodyne" / "val" / DRIVE / "proj_depth" / "velodyne_raw" / camera
                        / f"{frame}.png", velo)
            write_rgb(raw_root / DRIVE[:10] / DRIVE / camera / "data" / f"{frame}.png", pattern_rgb(100 * c + f))
            raws[(camera, frame)] = (gt, velo)
    return depth_root, raw_root, raws


def test_kitti_depth_completion(tmp_path):
    depth_root, raw_root, raws = make_kitti_tree(tmp_path)
    ds = KittiDepthCompletion(depth_root, raw_root, "val")
    assert len(ds) == 6
    assert ds.ids[:3] == [f"kitti/val/{DRIVE}/image_02/{f}" for f in ("0000000005", "0000000010", "0000000100")]
    s = ds[4]  # image_03, second frame
    gt, velo = raws[("image_03", "0000000010")]
    assert s.id == f"kitti/val/{DRIVE}/image_03/0000000010"
    assert np.array_equal(s.depth, gt.astype(np.float32) / 256) and np.array_equal(s.valid, gt > 0)
    assert np.array_equal(s.rgb, pattern_rgb(101))
    assert s.intrinsics == Intrinsics(720.5, 721.5377, 609.0, 172.854)
    assert ds[0].intrinsics == Intrinsics(721.5377, 721.5377, 609.5593, 172.854)
    frame = ds.frame(4)
    assert isinstance(frame, KittiFrame) and np.array_equal(frame.lidar, velo.astype(np.float32) / 256)
    # The scan as ground truth (Ma & Karaman's odometry protocol), and as a sampler with exactly N points.
    assert np.array_equal(KittiDepthCompletion(depth_root, raw_root, "val", target="velodyne_raw")[4].depth,
                          frame.lidar)
    crop = EvalProtocol("tiny", (BottomCrop(8, 12),), (8, 12), 0.0, 80.0)
    cropped = crop(s)
    real = KittiLidarInput(ds, crop)(cropped)
    assert np.array_equal(real, frame.lidar[4:, 2:14]) and np.array_equal(crop.apply_to_depth(frame.lidar), real)
    sub = KittiLidarInput(ds, crop, num_points=5)(cropped, seed=1)
    assert np.count_nonzero(sub) == 5 and np.array_equal(sub[sub > 0], real[sub > 0])
    assert np.array_equal(sub, KittiLidarInput(ds, crop, num_points=5)(cropped, seed=1))
    assert len(KittiDepthCompletion(depth_root, raw_root, "val", cameras=("image_02",))) == 3


def test_kitti_errors(tmp_path):
    with pytest.raises(DatasetError, match=r"(?s)data_depth_annotated.*Expected layout.*calib_cam_to_cam.*cvlibs"):
        KittiDepthCompletion(tmp_path / "nope", tmp_path / "raw", "val")
    depth_root, raw_root, _ = make_kitti_tree(tmp_path, frames=("0000000005",), cameras=("image_02",))
    (raw_root / DRIVE[:10] / DRIVE / "image_02" / "data" / "0000000005.png").unlink()
    ds = KittiDepthCompletion(depth_root, raw_root, "val")
    with pytest.raises(DatasetError, match=r"not found.*0000000005\.png"):
        ds[0]
    (raw_root / DRIVE[:10] / "calib_cam_to_cam.txt").unlink()
    with pytest.raises(DatasetError, match="calib_cam_to_cam.txt"):
        KittiDepthCompletion(depth_root, raw_root, "val")
    (tmp_path / "calib.txt").write_text("P_rect_02: 1 2 3\n")
    with pytest.raises(DatasetError, match="P_rect_02"):
        intrinsics_from_calib(tmp_path / "calib.txt")


def test_kitti_selection(tmp_path):
    root = tmp_path / "depth_selection" / "val_selection_cropped"
    frames = [("2011_09_26_drive_0002_sync", "0000000005", "image_02"),
              ("2011_09_26_drive_0002_sync", "0000000005", "image_03"),
              ("2011_09_26_drive_0001_sync", "0000000011", "image_02")]
    for i, (d, f, c) in enumerate(frames):
        write_rgb(root / "image" / f"{d}_image_{f}_{c}.png", pattern_rgb(i))
        write_png16(root / "velodyne_raw" / f"{d}_velodyne_raw_{f}_{c}.png", np.full((H, W), 256 * (i + 1)))
        write_png16(root / "groundtruth_depth" / f"{d}_groundtruth_depth_{f}_{c}.png", np.full((H, W), 512 * (i + 1)))
        (root / "intrinsics").mkdir(exist_ok=True)
        (root / "intrinsics" / f"{d}_image_{f}_{c}.txt").write_text(
            f"{700 + i} 0.0 600.0 0.0 {700 + i} 170.0 0.0 0.0 1.0\n")
    ds = KittiSelection(tmp_path)
    assert ds.ids == ["kitti/selection/2011_09_26_drive_0001_sync/image_02/0000000011",
                      "kitti/selection/2011_09_26_drive_0002_sync/image_02/0000000005",
                      "kitti/selection/2011_09_26_drive_0002_sync/image_03/0000000005"]
    s = ds[2]
    assert np.all(s.depth == 4.0) and np.all(ds.lidar(2) == 2.0) and np.array_equal(s.rgb, pattern_rgb(1))
    assert s.intrinsics == Intrinsics(701.0, 701.0, 600.0, 170.0)
    assert np.all(KittiLidarInput(ds)(s) == 2.0)
    with pytest.raises(DatasetError, match=r"(?s)val_selection_cropped.*data_depth_selection"):
        KittiSelection(tmp_path / "nothing")


# ---- TartanAir ------------------------------------------------------------------------------------------------


def test_tartanair(tmp_path):
    trajectories = [f"env{e}/{d}/P00{p}" for e in range(3) for d in ("Easy", "Hard") for p in range(4)]  # 24
    for t, name in enumerate(trajectories):
        for frame in range(2 if t else 3):
            write_rgb(tmp_path / name / "image_left" / f"{frame:06d}_left.png", pattern_rgb(frame))
            depth = np.full((H, W), 1.0 + frame, np.float32)
            depth[0, :] = 5000.0  # sky
            (tmp_path / name / "depth_left").mkdir(exist_ok=True)
            np.save(tmp_path / name / "depth_left" / f"{frame:06d}_left_depth.npy", depth)
    splits = {s: TartanAirDataset(tmp_path, s) for s in ("train", "val", "test", "all")}
    assert len(splits["all"]) == 49
    trajs = {s: {f[0] for f in ds.frames} for s, ds in splits.items()}
    assert trajs["train"] | trajs["val"] | trajs["test"] == set(trajectories)
    assert (not (trajs["train"] & trajs["val"]) and not (trajs["train"] & trajs["test"])
            and not (trajs["val"] & trajs["test"]))
    assert len(trajs["val"]) >= 1 and len(trajs["test"]) >= 1 and len(trajs["train"]) >= 20
    s = splits["all"][1]
    assert s.id == "tartanair/env0/Easy/P000/000001" and s.intrinsics == TARTANAIR_INTRINSICS
    assert np.all(s.depth[1:] == 2.0) and not s.valid[0].any() and TARTANAIR_MAX_VALID_DEPTH_M == 1000.0
    assert np.array_equal(s.rgb, pattern_rgb(1))
    with pytest.raises(DatasetError, match=r"(?s)TartanAir.*image_left.*theairlab"):
        TartanAirDataset(tmp_path / "nope")


# ---- user folder ------------------------------------------------------------------------------------------------


def test_folder_png_with_scale_and_intrinsics(tmp_path):
    for i, stem in enumerate(["frame_2", "frame_10", "frame_1"]):
        write_rgb(tmp_path / "rgb" / f"{stem}.png", pattern_rgb(i))
        write_png16(tmp_path / "depth" / f"{stem}.png", np.full((H, W), 5000 * (i + 1)))
    (tmp_path / "intrinsics.txt").write_text("500 501 8 6\n")
    with pytest.raises(DatasetError, match=r"(?s)depth_scale.*TUM 5000.*frame_1\.png"):
        FolderDataset(tmp_path)
    ds = FolderDataset(tmp_path, depth_scale=5000, id_prefix="mine")
    assert [ds[i].id for i in range(3)] == ["mine/frame_1", "mine/frame_2", "mine/frame_10"]
    assert np.all(ds[0].depth == 3.0) and np.array_equal(ds[0].rgb, pattern_rgb(2))
    assert ds[0].intrinsics == Intrinsics(500, 501, 8, 6)


def test_folder_npy_per_frame_intrinsics_and_number_matching(tmp_path):
    write_rgb(tmp_path / "rgb" / "rgb_00050.jpg", pattern_rgb(0))
    (tmp_path / "depth").mkdir()
    np.save(tmp_path / "depth" / "sync_depth_00050.npy", np.full((H, W), 2.25, np.float32))
    with pytest.raises(DatasetError, match="intrinsics"):
        FolderDataset(tmp_path)
    (tmp_path / "intrinsics").mkdir()
    (tmp_path / "intrinsics" / "rgb_00050.txt").write_text("1 0 2\n0 3 4\n0 0 1\n")
    ds = FolderDataset(tmp_path)
    assert len(ds) == 1 and ds[0].id.endswith("/00050") and np.all(ds[0].depth == 2.25)
    assert ds[0].intrinsics == Intrinsics(1, 3, 2, 4)


def test_folder_errors(tmp_path):
    with pytest.raises(DatasetError, match=r"(?s)rgb.*Expected layout"):
        FolderDataset(tmp_path)
    write_rgb(tmp_path / "rgb" / "a.png", pattern_rgb(0))
    (tmp_path / "depth").mkdir()
    np.save(tmp_path / "depth" / "a.npy", np.ones((H + 1, W), np.float32))
    ds = FolderDataset(tmp_path, intrinsics=Intrinsics(1, 1, 0, 0))
    with pytest.raises(DatasetError, match=r"sizes differ.*a\.npy"):
        ds[0]
    write_rgb(tmp_path / "rgb" / "b.png", pattern_rgb(1))
    with pytest.raises(DatasetError, match="no RGB/depth partner"):
        FolderDataset(tmp_path, intrinsics=Intrinsics(1, 1, 0, 0))


def test_kitti_odometry_projects_the_scan_into_image_2(tmp_path):
    from lipjax.data.kitti_odometry import KittiOdometry

    seq = tmp_path / "sequences" / "00"
    (seq / "image_2").mkdir(parents=True)
    (seq / "velodyne").mkdir()
    cv2.imwrite(str(seq / "image_2" / "000000.png"), np.zeros((10, 12, 3), np.uint8))
    fx, cx, cy, baseline = 10.0, 6.0, 5.0, 0.5
    p2 = [fx, 0, cx, fx * baseline, 0, fx, cy, 0, 0, 0, 1, 0]
    # velodyne x forward, y left, z up -> camera x right, y down, z forward
    tr = [0, -1, 0, 0, 0, 0, -1, 0, 1, 0, 0, 0]
    (seq / "calib.txt").write_text("P0: " + " ".join(["0"] * 12) + "\nP2: " + " ".join(map(str, p2)) +
                                   "\nTr: " + " ".join(map(str, tr)) + "\n")
    # a point 4 m ahead, 0.5 m to the left of the LiDAR: camera-2 x = 0.5 baseline shift - 0.5 = 0 -> u = cx
    points = np.array([[4.0, 0.5, 0.0, 0.3], [8.0, 0.5, 0.0, 0.1], [-3.0, 0.0, 0.0, 0.2]], np.float32)
    points.tofile(seq / "velodyne" / "000000.bin")
    ds = KittiOdometry(tmp_path)
    frame = ds[0]
    assert len(ds) == 1 and frame.id == "kitti_odometry/00/000000"
    assert frame.depth[5, 6] == pytest.approx(4.0)  # the nearer of the two points on that ray wins; behind dropped
    assert frame.valid.sum() == 1
    with pytest.raises(ValueError, match="KITTI odometry root not found"):
        KittiOdometry(tmp_path / "nope")
