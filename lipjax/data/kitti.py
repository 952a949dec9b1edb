"""KITTI depth completion loaders: the official train/val tree, the depth_selection crops, and real LiDAR input.

KITTI has a real sparse input (the projected Velodyne scan, `velodyne_raw`) besides the semi-dense ground
truth (`groundtruth`, 11 accumulated scans cleaned with stereo). Loaders yield the ground truth as the
Frame; the scan is available as `dataset.lidar(i)` / `dataset.frame(i).lidar`, and `KittiLidarInput` turns
it into a sampler for the batch pipeline (optionally sub-sampled to exactly N points: the paper's Table III).

Depth PNGs are 16-bit, metres = value / 256, 0 = no measurement.
"""
from __future__ import annotations

import dataclasses
import os
import re
from pathlib import Path

import numpy as np

from lipjax.data.errors import dataset_error
from lipjax.data.folder import KNOWN_DEPTH_SCALES, natural_key, read_depth, read_intrinsics_txt, read_rgb
from lipjax.data.frame import Frame, Intrinsics
from lipjax.data.sampling import example_rng, subsample_exact

KITTI_CAMERAS = ("image_02", "image_03")  # left / right colour cameras

KITTI_DC_LAYOUT = """\
<depth_root>/data_depth_annotated/{train,val}/<drive>/proj_depth/groundtruth/image_0{2,3}/<frame>.png
<depth_root>/data_depth_velodyne/{train,val}/<drive>/proj_depth/velodyne_raw/image_0{2,3}/<frame>.png
<raw_root>/<date>/<drive>/image_0{2,3}/data/<frame>.png          (<date> = first 10 chars of <drive>)
<raw_root>/<date>/calib_cam_to_cam.txt                              (P_rect_02 / P_rect_03)"""
KITTI_DC_SOURCE = (
    "KITTI depth completion https://www.cvlibs.net/datasets/kitti/eval_depth.php?benchmark=depth_completion "
    "(data_depth_annotated.zip, data_depth_velodyne.zip) + "
    "KITTI raw https://www.cvlibs.net/datasets/kitti/raw_data.php "
    "(synced+rectified drives and calibration)"
)
KITTI_SELECTION_LAYOUT = """\
<root>/depth_selection/val_selection_cropped/image/<drive>_image_<frame>_image_0{2,3}.png
<root>/depth_selection/val_selection_cropped/velodyne_raw/<drive>_velodyne_raw_<frame>_image_0{2,3}.png
<root>/depth_selection/val_selection_cropped/groundtruth_depth/<drive>_groundtruth_depth_<frame>_image_0{2,3}.png
<root>/depth_selection/val_selection_cropped/intrinsics/<drive>_image_<frame>_image_0{2,3}.txt  (9 numbers: K)"""
KITTI_SELECTION_SOURCE = (
    "KITTI depth completion https://www.cvlibs.net/datasets/kitti/eval_depth.php?benchmark=depth_completion "
    "(data_depth_selection.zip)"
)


def read_kitti_depth(path: str | os.PathLike) -> np.ndarray:
    """Reads a KITTI 16-bit depth PNG -> (H, W) float32 metres (value / 256), 0 = no measurement."""
    return read_depth(path, KNOWN_DEPTH_SCALES["kitti"])


def read_calib_cam_to_cam(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Parses a KITTI raw calib_cam_to_cam.txt into {key: float64 array} (non-numeric lines are skipped)."""
    try:
        text = Path(path).read_text()
    except OSError as exc:
        raise dataset_error("KITTI calibration file not readable", path, KITTI_DC_LAYOUT, KITTI_DC_SOURCE) from exc
    calib = {}
    for line in text.splitlines():
        key, sep, value = line.partition(":")
        if not sep:
            continue
        try:
            calib[key.strip()] = np.array([float(tok) for tok in value.split()])
        except ValueError:
            continue  # e.g. "calib_time: 09-Jan-2012 13:57:47"
    return calib


def intrinsics_from_calib(path: str | os.PathLike, camera: str = "image_02") -> Intrinsics:
    """Intrinsics of a rectified colour camera from P_rect_0X (3x4) in calib_cam_to_cam.txt."""
    key = f"P_rect_{camera[-2:]}"
    p = read_calib_cam_to_cam(path).get(key)
    if p is None or p.size != 12:
        raise dataset_error(f"KITTI calibration lacks a 12-number {key}", path, KITTI_DC_LAYOUT, KITTI_DC_SOURCE)
    p = p.reshape(3, 4)
    return Intrinsics(float(p[0, 0]), float(p[1, 1]), float(p[0, 2]), float(p[1, 2]))


@dataclasses.dataclass(frozen=True)
class KittiFrame:
    """A KITTI frame: the ground-truth Frame and the real LiDAR scan.

    Attributes:
      frame: RGB + ground-truth depth (metres) + intrinsics.
      lidar: (H, W) float32 projected Velodyne scan in metres, 0 = no return (the real sparse input).
    """

    frame: Frame
    lidar: np.ndarray

    def __post_init__(self):
        if self.lidar.shape != self.frame.shape or self.lidar.dtype != np.float32:
            raise ValueError(f"{self.frame.id}: lidar must be float32 {self.frame.shape}, "
                             f"got {self.lidar.dtype} {self.lidar.shape}")


class _KittiBase:
    """Shared indexing: subclasses fill self.ids (and self.target) and implement rgb, ground_truth, lidar,
    intrinsics and _where (the path named in size-mismatch errors)."""

    ids: list[str]
    target: str = "groundtruth"  # or "velodyne_raw": the scan is the ground truth (set by subclasses)

    def __len__(self) -> int:
        return len(self.ids)

    def index_of(self, frame_id: str) -> int:
        """Index of the frame with this Frame.id (KeyError if none)."""
        if not hasattr(self, "_index"):
            self._index = {sid: i for i, sid in enumerate(self.ids)}
        return self._index[frame_id]

    def rgb(self, index: int) -> np.ndarray:
        raise NotImplementedError

    def ground_truth(self, index: int) -> np.ndarray:
        raise NotImplementedError

    def lidar(self, index: int) -> np.ndarray:
        """(H, W) float32 metres: the real projected Velodyne scan of frame `index` (full frame, no crop)."""
        raise NotImplementedError

    def intrinsics(self, index: int) -> Intrinsics:
        raise NotImplementedError

    def _target(self, index: int) -> np.ndarray:
        return self.lidar(index) if self.target == "velodyne_raw" else self.ground_truth(index)

    def __getitem__(self, index: int) -> Frame:
        rgb, depth = self.rgb(index), self._target(index)
        if depth.shape != rgb.shape[:2]:
            raise dataset_error(f"RGB {rgb.shape[:2]} and depth {depth.shape} sizes differ for {self.ids[index]}",
                                self._where(index))
        return Frame.from_depth(rgb, depth, self.intrinsics(index), self.ids[index])

    def frame(self, index: int) -> KittiFrame:
        """The ground-truth Frame with its real LiDAR scan."""
        return KittiFrame(self[index], self.lidar(index))

    def _where(self, index: int) -> Path:
        raise NotImplementedError


class KittiDepthCompletion(_KittiBase):
    """KITTI depth completion train / val (official tree, KITTI_DC_LAYOUT), as full-size Frames.

    Frame.id = "kitti/<split>/<drive>/<camera>/<frame>"; sorted by drive, camera, frame.

    Args:
      depth_root: holds data_depth_annotated/ and data_depth_velodyne/.
      raw_root: the KITTI raw root holding <date>/<drive>/ and <date>/calib_cam_to_cam.txt.
      split: "train" or "val".
      cameras: which colour cameras to include.
      target: "groundtruth" (the annotated semi-dense depth; default) or "velodyne_raw" (the scan itself is the
        ground truth and the input is sub-sampled from it, as Ma & Karaman's KITTI odometry protocol, the
        paper's Table III: pair with UniformSampler(N)).
    """

    def __init__(self, depth_root: str | os.PathLike, raw_root: str | os.PathLike, split: str = "val",
                 cameras: tuple[str, ...] = KITTI_CAMERAS, target: str = "groundtruth"):
        if split not in ("train", "val"):
            raise ValueError(f"KITTI split must be 'train' or 'val', got {split!r}")
        if target not in ("groundtruth", "velodyne_raw"):
            raise ValueError(f"target must be 'groundtruth' or 'velodyne_raw', got {target!r}")
        self.depth_root, self.raw_root, self.split, self.target = Path(depth_root), Path(raw_root), split, target
        gt_dir = self.depth_root / "data_depth_annotated" / split
        velo_dir = self.depth_root / "data_depth_velodyne" / split
        for directory in (gt_dir, velo_dir, self.raw_root):
            if not directory.is_dir():
                raise dataset_error("KITTI directory not found", directory, KITTI_DC_LAYOUT, KITTI_DC_SOURCE)
        listed = velo_dir if target == "velodyne_raw" else gt_dir
        kind = "velodyne_raw" if target == "velodyne_raw" else "groundtruth"
        entries = []
        for camera in cameras:
            for path in listed.glob(f"*/proj_depth/{kind}/{camera}/*.png"):
                entries.append((natural_key(path.parents[3].name), camera, natural_key(path.stem),
                                path.parents[3].name, path.stem))
        if not entries:
            raise dataset_error(f"No {kind} PNGs found under", listed, KITTI_DC_LAYOUT, KITTI_DC_SOURCE)
        entries.sort()
        self.frames = [(drive, camera, stem) for _, camera, _, drive, stem in entries]
        self.ids = [f"kitti/{split}/{d}/{c}/{s}" for d, c, s in self.frames]
        self._intrinsics: dict[tuple[str, str], Intrinsics] = {}
        for drive, camera, _ in self.frames:
            date = drive[:10]
            if (date, camera) not in self._intrinsics:
                calib = self.raw_root / date / "calib_cam_to_cam.txt"
                if not calib.is_file():
                    raise dataset_error("KITTI calibration file not found", calib, KITTI_DC_LAYOUT, KITTI_DC_SOURCE)
                self._intrinsics[(date, camera)] = intrinsics_from_calib(calib, camera)

    def _paths(self, index: int) -> tuple[Path, Path, Path]:
        drive, camera, stem = self.frames[index]
        gt = (self.depth_root / "data_depth_annotated" / self.split / drive / "proj_depth" / "groundtruth" / camera
              / f"{stem}.png")
        velo = (self.depth_root / "data_depth_velodyne" / self.split / drive / "proj_depth" / "velodyne_raw" / camera
                / f"{stem}.png")
        rgb = self.raw_root / drive[:10] / drive / camera / "data" / f"{stem}.png"
        return rgb, gt, velo

    def _read(self, path: Path, reader):
        if not path.is_file():
            raise dataset_error("KITTI file not found", path, KITTI_DC_LAYOUT, KITTI_DC_SOURCE)
        return reader(path)

    def rgb(self, index: int) -> np.ndarray:
        return self._read(self._paths(index)[0], read_rgb)

    def ground_truth(self, index: int) -> np.ndarray:
        return self._read(self._paths(index)[1], read_kitti_depth)

    def lidar(self, index: int) -> np.ndarray:
        return self._read(self._paths(index)[2], read_kitti_depth)

    def intrinsics(self, index: int) -> Intrinsics:
        drive, camera, _ = self.frames[index]
        return self._intrinsics[(drive[:10], camera)]

    def _where(self, index: int) -> Path:
        return self._paths(index)[1]


_SELECTION_NAME = re.compile(r"^(?P<drive>.+)_image_(?P<frame>\d+)_(?P<camera>image_0[23])$")


class KittiSelection(_KittiBase):
    """KITTI depth_selection/val_selection_cropped (1000 frames, already 352x1216, KITTI_SELECTION_LAYOUT).

    The intrinsics files already account for the crop. Frame.id = "kitti/selection/<drive>/<camera>/<frame>".

    Args:
      root: the directory holding depth_selection/, or depth_selection/ itself, or val_selection_cropped/ itself.
    """

    def __init__(self, root: str | os.PathLike, target: str = "groundtruth"):
        root = Path(root)
        for candidate in (root / "depth_selection" / "val_selection_cropped", root / "val_selection_cropped", root):
            if (candidate / "image").is_dir():
                root = candidate
                break
        else:
            raise dataset_error("KITTI val_selection_cropped/image not found under", root, KITTI_SELECTION_LAYOUT,
                                KITTI_SELECTION_SOURCE)
        if target not in ("groundtruth", "velodyne_raw"):
            raise ValueError(f"target must be 'groundtruth' or 'velodyne_raw', got {target!r}")
        self.root, self.target = root, target
        entries = []
        for path in (root / "image").glob("*.png"):
            match = _SELECTION_NAME.match(path.stem)
            if match is None:
                raise dataset_error("Unexpected file name in val_selection_cropped/image", path,
                                    KITTI_SELECTION_LAYOUT)
            d, f, c = match["drive"], match["frame"], match["camera"]
            entries.append((natural_key(d), c, natural_key(f), d, f))
        if not entries:
            raise dataset_error("No images in", root / "image", KITTI_SELECTION_LAYOUT, KITTI_SELECTION_SOURCE)
        entries.sort()
        self.frames = [(d, c, f) for _, c, _, d, f in entries]
        self.ids = [f"kitti/selection/{d}/{c}/{f}" for d, c, f in self.frames]

    def _path(self, index: int, kind: str) -> Path:
        drive, camera, frame = self.frames[index]
        if kind == "intrinsics":
            return self.root / "intrinsics" / f"{drive}_image_{frame}_{camera}.txt"
        folder = {"image": "image", "velodyne_raw": "velodyne_raw", "groundtruth_depth": "groundtruth_depth"}[kind]
        path = self.root / folder / f"{drive}_{kind}_{frame}_{camera}.png"
        if not path.is_file():
            raise dataset_error("KITTI selection file not found", path, KITTI_SELECTION_LAYOUT, KITTI_SELECTION_SOURCE)
        return path

    def rgb(self, index: int) -> np.ndarray:
        return read_rgb(self._path(index, "image"))

    def ground_truth(self, index: int) -> np.ndarray:
        return read_kitti_depth(self._path(index, "groundtruth_depth"))

    def lidar(self, index: int) -> np.ndarray:
        return read_kitti_depth(self._path(index, "velodyne_raw"))

    def intrinsics(self, index: int) -> Intrinsics:
        path = self._path(index, "intrinsics")
        if not path.is_file():
            raise dataset_error("KITTI selection intrinsics not found", path, KITTI_SELECTION_LAYOUT,
                                KITTI_SELECTION_SOURCE)
        return read_intrinsics_txt(path)

    def _where(self, index: int) -> Path:
        return self._path(index, "groundtruth_depth")


@dataclasses.dataclass(frozen=True)
class KittiLidarInput:
    """A sampler (same call signature) whose sparse input is the frame's REAL Velodyne scan.

    The scan is looked up by Frame.id in `dataset`, cropped with the same protocol as the Frame, and
    optionally sub-sampled to exactly num_points measured pixels (example_rng(seed, id); all of them when the
    scan has fewer) to simulate a sparser LiDAR.

    Attributes:
      dataset: a KittiDepthCompletion or KittiSelection (anything with index_of(id) and lidar(index)).
      protocol: the protocol the pipeline applies to the Frames (None: no crop).
      num_points: None keeps every return.
    """

    dataset: _KittiBase
    protocol: object | None = None
    num_points: int | None = None

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        lidar = self.dataset.lidar(self.dataset.index_of(frame.id))
        if self.protocol is not None:
            lidar = self.protocol.apply_to_depth(lidar)
        if lidar.shape != frame.shape:
            raise ValueError(f"{frame.id}: LiDAR {lidar.shape} does not match the frame {frame.shape}; "
                             "pass the pipeline's protocol to KittiLidarInput")
        if self.num_points is not None:
            lidar = subsample_exact(lidar, self.num_points, example_rng(seed, frame.id))
        return lidar.astype(np.float32, copy=False)
