"""A LiDAR sweep file and its calibration -> the sparse depth image of one camera, the model's input.

    sparse, intrinsics = project_sweep("velodyne/000000.bin", "calib/000000.txt", (375, 1242))  # metres
    rgb, sparse, intrinsics = read_lidar_frame("image_2/000000.png", "velodyne/000000.bin", "calib/000000.txt")

`lipjax project` and `lipjax complete --lidar` call these. Sweeps: lipjax.pointcloud.read_point_cloud (.bin,
.npy, .pcd); calibration: lipjax.data.calib.read_calibration (KITTI object / raw / odometry, any rig).

What a projection checks (errors are one-line ValueErrors, warnings one line through lipjax.utils.warn_user):

    the image's folder names another KITTI camera than `camera`      error: use --camera N
    (image_2 / image_02 / image_3 ...; KITTI calibrations only)
    the principal point a quarter of the image from its centre      warning: resized or cropped image?
    under MIN_KEPT_SHARE of a sweep's points in the image            warning: resized image, wrong calibration?
    under MIN_SIDE_SHARE of the points in one half of the image      warning: inverted transform?
    (or under WEAK_SIDE_SHARE, the points in no scan lines across the image)
    median depth of the points in the image beyond 1 km              error: not metres (the unit inferred)

What cannot be checked from the files: an image of one KITTI camera with the calibration of the other when the
image's path names no camera (image_2 and image_3 share fx, fy, cx, cy; their projections differ only by the 54 cm
baseline, a shift of the points by fx * 0.54 / depth pixels that only the image's content could show).
"""
from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from lipjax.data.calib import calibration_format, read_calibration
from lipjax.data.folder import read_rgb
from lipjax.data.frame import Intrinsics
from lipjax.inputs import MAX_PLAUSIBLE_DEPTH_M, is_lidar_pattern, unit_hint
from lipjax.pointcloud import ProjectionCounts, project_lidar_to_depth, read_point_cloud
from lipjax.utils import warn_user

# A spinning LiDAR's sweep puts 7-13 % of its points on a KITTI camera's image (its 90 degrees of the 360; measured
# on KITTI-like streets): under 2 % means an image smaller than the calibration's, or the wrong calibration.
MIN_KEPT_SHARE = 0.02
# A calibrated camera sees a sweep across its whole width: each half of the image holds 43-57 % of the points on
# KITTI-like streets; an inverted Tr_velo_to_cam (camera to LiDAR) leaves 0-21 % in one half (the ground on one side),
# 27-31 % in a street between tall walls 2.5-3 m away.
MIN_SIDE_SHARE = 0.25
# Under this share in one half counts too where the points lie in no scan lines across the image
# (`_scan_lines_across`): a spinning LiDAR level with the camera draws its beams across the image, an inverted
# transform draws them down it. (A correct sweep with one open side, whose upward beams find nothing there, keeps
# about a third of its points in that half: VLP-16, 8 of its 16 beams upward.)
WEAK_SIDE_SHARE = 0.40
# Scan lines run across the image when pairs of points 1-3 px apart in a row outnumber those in a column by this
# (2.8-17x on KITTI-like streets; 0.3-1.1x with an inverted transform; about 1x for scattered points).
ACROSS_RATIO = 1.5
# The shares above say little of fewer points (a few test points, a cropped sweep): a sweep must hold this many to
# be judged by MIN_KEPT_SHARE, and its points in the image a tenth of it to be judged by MIN_SIDE_SHARE.
JUDGED_POINTS = 1000
# KITTI's principal points lie within 4 % of the size of their images from the centre: a quarter of the size away,
# the image was resized or cropped without its calibration.
PRINCIPAL_POINT_OFF_CENTRE = 0.25
# A folder image_2 (object, odometry) or image_02 (raw) holds the images of KITTI camera 2.
_CAMERA_FOLDER = re.compile(r"image_0?(\d)")


def camera_of_image(path: str | os.PathLike) -> int | None:
    """The KITTI camera that the folders of an image's path name (image_2/, image_02/data/: 2), the innermost
    such folder; None when none does."""
    for part in reversed(Path(path).parent.parts):
        match = _CAMERA_FOLDER.fullmatch(part)
        if match:
            return int(match.group(1))
    return None


def _check_camera(image_path: str | os.PathLike, calib_path: str | os.PathLike, camera: int) -> None:
    """ValueError when the image's folder names another KITTI camera than `camera` (a rig file has one camera)."""
    named = camera_of_image(image_path)
    if named is None or named == camera or calibration_format(calib_path) == "rig":
        return
    raise ValueError(f"{image_path}: its folder names KITTI camera {named} (image_{named}), but camera {camera}'s "
                     f"projection was taken from {calib_path}: give --camera {named}")


def _check_principal_point(intrinsics: Intrinsics, image_size: tuple[int, int], calib_path, camera: int) -> bool:
    """Warns when the principal point lies a quarter of the image's size or more from its centre; whether it did."""
    h, w = image_size
    off = max(abs(intrinsics.cx - (w - 1) / 2) / w, abs(intrinsics.cy - (h - 1) / 2) / h)
    if off >= PRINCIPAL_POINT_OFF_CENTRE:
        warn_user(f"{calib_path}: camera {camera}'s principal point ({intrinsics.cx:.1f}, {intrinsics.cy:.1f}) lies "
                  f"far from the centre ({(w - 1) / 2:.1f}, {(h - 1) / 2:.1f}) of the {w}x{h} image: was the image "
                  "resized or cropped? resize or shift fx, fy, cx, cy with it")
        return True
    return False


def _scan_lines_across(sparse: np.ndarray, reach: int = 3) -> bool:
    """Whether the points of a projected sweep lie in lines across the image: pairs of samples 1..reach pixels
    apart in a row outnumber those in a column ACROSS_RATIO times."""
    m = sparse > 0
    in_rows = sum(np.count_nonzero(m[:, d:] & m[:, :-d]) for d in range(1, reach + 1))
    in_cols = sum(np.count_nonzero(m[d:] & m[:-d]) for d in range(1, reach + 1))
    return in_rows >= ACROSS_RATIO * in_cols


def _check_projection(sparse: np.ndarray, counts: ProjectionCounts, intrinsics: Intrinsics, lidar_path,
                      calib_path, warn: bool = True) -> None:
    """The checks of where a sweep landed (module docstring): a median beyond 1 km is an error; too few points in
    the image, or else in one half of it, a warning (one at most; none without `warn`: another warning named the
    likelier cause)."""
    h, w = sparse.shape
    rows, cols = np.nonzero(sparse)
    depths = sparse[rows, cols]
    median = float(np.median(depths))
    if median > MAX_PLAUSIBLE_DEPTH_M:
        raise ValueError(f"{lidar_path}: its points in the image lie at a median depth of {median:.0f}: not metres "
                         f"({unit_hint(depths, is_lidar_pattern(sparse))})")
    if not warn:
        return
    if counts.points >= JUDGED_POINTS and counts.kept < MIN_KEPT_SHARE * counts.points:
        warn_user(f"{lidar_path}: only {counts.kept} of its {counts.points} points land in the {w}x{h} image "
                  f"(under {100 * MIN_KEPT_SHARE:g} %): was the image resized or cropped, or is {calib_path} another "
                  "sweep's calibration?")
    elif counts.kept >= JUDGED_POINTS // 10:
        left, right = float(np.mean(cols < intrinsics.cx)), float(np.mean(cols > intrinsics.cx))
        if min(left, right) < MIN_SIDE_SHARE or (min(left, right) < WEAK_SIDE_SHARE
                                                  and not _scan_lines_across(sparse)):
            side, share = ("left", left) if left < right else ("right", right)
            warn_user(f"{lidar_path}: only {100 * share:.0f} % of its {counts.kept} points in the image lie in its "
                      f"{side} half, where a calibrated camera sees about half: is the transform in {calib_path} "
                      "inverted (camera to LiDAR, not LiDAR to camera) or another rig's?")


def project_sweep(lidar_path: str | os.PathLike, calib_path: str | os.PathLike, image_size: tuple[int, int],
                  camera: int = 2, *, return_counts: bool = False, image_path: str | os.PathLike | None = None
                  ) -> tuple[np.ndarray, Intrinsics] | tuple[np.ndarray, Intrinsics, ProjectionCounts]:
    """((H, W) float32 sparse depth in metres, 0 = no point; the camera's intrinsics, pixels): the sweep projected
    into KITTI camera `camera` (a rig file's one camera), keeping the nearest point per pixel; with `return_counts`
    also where every point went (lipjax.pointcloud.ProjectionCounts). `image_path`: the image the sweep is
    projected into, whose folder may name its KITTI camera (checked against `camera`).

    ValueError when no point lands in the image (the wrong calibration or camera, most likely), with those counts,
    and for the other errors of the module docstring; its warnings name the likely cause."""
    if image_path is not None:
        _check_camera(image_path, calib_path, camera)
    intrinsics, cam_from_lidar = read_calibration(calib_path, camera)
    off_centre = _check_principal_point(intrinsics, image_size, calib_path, camera)
    points = read_point_cloud(lidar_path)
    sparse, counts = project_lidar_to_depth(points, intrinsics, cam_from_lidar, image_size, return_counts=True)
    if not counts.kept:
        raise ValueError(f"{lidar_path}: none of its {len(points)} points lands in the {image_size[1]}x"
                         f"{image_size[0]} image with the calibration {calib_path} ({counts.summary()}); is it this "
                         "sweep's calibration (and camera)?")
    _check_projection(sparse, counts, intrinsics, lidar_path, calib_path, warn=not off_centre)
    return (sparse, intrinsics, counts) if return_counts else (sparse, intrinsics)


def read_lidar_frame(rgb_path: str | os.PathLike, lidar_path: str | os.PathLike, calib_path: str | os.PathLike,
                     camera: int = 2) -> tuple[np.ndarray, np.ndarray, Intrinsics]:
    """(rgb (H, W, 3) uint8, sparse (H, W) float32 metres, intrinsics) of one frame given as a colour image, its
    LiDAR sweep and their calibration (`project_sweep`, which checks the camera that the image's folder names)."""
    rgb = read_rgb(rgb_path)
    sparse, intrinsics = project_sweep(lidar_path, calib_path, rgb.shape[:2], camera, image_path=rgb_path)
    return rgb, sparse, intrinsics
