"""A LiDAR sweep file and its calibration -> the sparse depth image of one camera, the model's input.

    sparse, intrinsics = project_sweep("velodyne/000000.bin", "calib/000000.txt", (375, 1242))  # metres
    rgb, sparse, intrinsics = read_lidar_frame("image_2/000000.png", "velodyne/000000.bin", "calib/000000.txt")

`lipjax project` and `lipjax complete --lidar` call these. Sweeps: lipjax.pointcloud.read_point_cloud (.bin,
.npy, .pcd); calibration: lipjax.data.calib.read_calibration (KITTI object / raw / odometry, any rig).
"""
from __future__ import annotations

import os

import numpy as np

from lipjax.data.calib import read_calibration
from lipjax.data.folder import read_rgb
from lipjax.data.sample import Intrinsics
from lipjax.pointcloud import ProjectionCounts, project_lidar_to_depth, read_point_cloud


def project_sweep(lidar_path: str | os.PathLike, calib_path: str | os.PathLike, image_size: tuple[int, int],
                  camera: int = 2, *, return_counts: bool = False
                  ) -> tuple[np.ndarray, Intrinsics] | tuple[np.ndarray, Intrinsics, ProjectionCounts]:
    """((H, W) float32 sparse depth in metres, 0 = no point; the camera's intrinsics, pixels): the sweep projected
    into KITTI camera `camera` (a rig file's one camera), keeping the nearest point per pixel; with `return_counts`
    also where every point went (lipjax.pointcloud.ProjectionCounts). ValueError when no point lands in the image
    (the wrong calibration or camera, most likely), with those counts."""
    intrinsics, cam_from_lidar = read_calibration(calib_path, camera)
    points = read_point_cloud(lidar_path)
    sparse, counts = project_lidar_to_depth(points, intrinsics, cam_from_lidar, image_size, return_counts=True)
    if not counts.kept:
        raise ValueError(f"{lidar_path}: none of its {len(points)} points lands in the {image_size[1]}x"
                         f"{image_size[0]} image with the calibration {calib_path} ({counts.summary()}); is it this "
                         "sweep's calibration (and camera)?")
    return (sparse, intrinsics, counts) if return_counts else (sparse, intrinsics)


def read_lidar_frame(rgb_path: str | os.PathLike, lidar_path: str | os.PathLike, calib_path: str | os.PathLike,
                     camera: int = 2) -> tuple[np.ndarray, np.ndarray, Intrinsics]:
    """(rgb (H, W, 3) uint8, sparse (H, W) float32 metres, intrinsics) of one frame given as a colour image, its
    LiDAR sweep and their calibration (`project_sweep`)."""
    rgb = read_rgb(rgb_path)
    sparse, intrinsics = project_sweep(lidar_path, calib_path, rgb.shape[:2], camera)
    return rgb, sparse, intrinsics
