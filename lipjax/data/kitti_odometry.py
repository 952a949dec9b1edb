"""KITTI odometry (raw Velodyne scans) for the paper's Table III: the scan projected into the left colour camera.

Following Ma et al. (sparse-to-dense), the "ground truth" of a frame is its whole Velodyne scan projected into
image_2 (z-buffered: the nearest point per pixel), and the input is exactly N of those points, drawn by
`UniformSampler(N)` keyed by the frame id: so "200 points" means 200 real LiDAR returns.

Layout (the odometry development kit's):

    <root>/sequences/<SS>/image_2/<NNNNNN>.png
    <root>/sequences/<SS>/velodyne/<NNNNNN>.bin     float32 (x, y, z, reflectance) per point, metres
    <root>/sequences/<SS>/calib.txt                 "P2: 12 numbers" (3x4), "Tr: 12 numbers" (velodyne -> cam0)
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from lipjax.data.calib import read_odometry_calib
from lipjax.data.errors import dataset_error
from lipjax.data.folder import natural_key, read_rgb
from lipjax.data.frame import Frame, Intrinsics
from lipjax.pointcloud import project_lidar_to_depth, read_point_cloud

KITTI_ODOMETRY_LAYOUT = """\
<root>/sequences/<SS>/image_2/<NNNNNN>.png
<root>/sequences/<SS>/velodyne/<NNNNNN>.bin
<root>/sequences/<SS>/calib.txt   (P2: ..., Tr: ...)"""
KITTI_ODOMETRY_SOURCE = "KITTI odometry benchmark (colour images, Velodyne laser data, calibration files)"


def read_velodyne_bin(path: str | os.PathLike) -> np.ndarray:
    """(N, 3) float32 points in metres from a KITTI .bin scan (float32 x, y, z, reflectance per point)."""
    try:
        return read_point_cloud(path)
    except ValueError as exc:
        raise dataset_error(f"Corrupt Velodyne scan ({exc})", path, KITTI_ODOMETRY_LAYOUT,
                            KITTI_ODOMETRY_SOURCE) from None


class KittiOdometry:
    """KITTI odometry sequences as Frames whose depth is the projected scan (see module docstring).

    Args:
      root: the folder holding `sequences/`.
      sequences: sequence names, e.g. ("00", "01"); default: every sequence with images and scans.
    Frame.id = "kitti_odometry/<SS>/<NNNNNN>".
    """

    def __init__(self, root: str | os.PathLike, sequences: tuple[str, ...] | None = None):
        seq_root = Path(root) / "sequences"
        if not seq_root.is_dir():
            raise dataset_error("KITTI odometry root not found", seq_root, KITTI_ODOMETRY_LAYOUT,
                                KITTI_ODOMETRY_SOURCE)
        names = sequences or sorted((p.name for p in seq_root.iterdir() if (p / "velodyne").is_dir()), key=natural_key)
        self.frames: list[tuple[str, Path, Path]] = []
        self.calib: dict[str, tuple[Intrinsics, np.ndarray]] = {}
        for seq in names:
            d = seq_root / seq
            if not (d / "image_2").is_dir() or not (d / "velodyne").is_dir():
                raise dataset_error(f"Sequence {seq!r} lacks image_2/ or velodyne/", d, KITTI_ODOMETRY_LAYOUT,
                                    KITTI_ODOMETRY_SOURCE)
            self.calib[seq] = read_odometry_calib(d / "calib.txt")
            for scan in sorted((d / "velodyne").glob("*.bin"), key=lambda p: natural_key(p.stem)):
                image = d / "image_2" / f"{scan.stem}.png"
                if image.exists():
                    self.frames.append((seq, image, scan))
        if not self.frames:
            raise dataset_error("No frames with both image_2/*.png and velodyne/*.bin under", seq_root,
                                KITTI_ODOMETRY_LAYOUT, KITTI_ODOMETRY_SOURCE)

    def __len__(self) -> int:
        return len(self.frames)

    def __getitem__(self, index: int) -> Frame:
        seq, image_path, scan_path = self.frames[index]
        rgb = read_rgb(image_path)
        intrinsics, cam_from_velo = self.calib[seq]
        depth = project_lidar_to_depth(read_velodyne_bin(scan_path), intrinsics, cam_from_velo, rgb.shape[:2])
        return Frame.from_depth(rgb, depth, intrinsics, f"kitti_odometry/{seq}/{image_path.stem}")
