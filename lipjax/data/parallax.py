"""A depth sensor beside the camera: what it sees from its own viewpoint, and where its returns land in the image.

A LiDAR or a depth camera is never at the camera's centre (KITTI's Velodyne sits 0.27 m behind and 0.08 m above
the colour camera; an RGB-D camera's depth sensor 2.5-5 cm beside its colour sensor). Projected into the image,
its returns carry the two artefacts of that baseline b (metres, camera frame: x right, y down, z forward):

- seen through an edge: beside a foreground object the sensor sees the background that the camera sees hidden,
  and those returns land on the object's pixels (a band about f |b| (1/z_near - 1/z_far) pixels wide);
- shadowed: surfaces the camera sees but the sensor does not (behind the object, from the sensor) get no return.

Both are made from the camera's own depth map with the camera's intrinsics K and axes (no second render):

    view = sensor_view(depth, valid, K, b)
                                        every valid pixel's point P = z K^-1 (u, v, 1) moved to P - b and projected
                                        with K, the nearest kept per pixel; the sensor's own view
    fill the disocclusions of view      pixels no point reached take the farther side's depth: the background is
                                        continued under the foreground (`fill_background`); pixels the camera saw
                                        as invalid (sky) count as infinitely far, and give no return
    sparse = to_camera(y_view, K, b)    a sampler's returns y_view in that view moved back by + b and projected
                                        into the camera, the nearest kept per pixel

The fill walks along epipolar lines (`epipolar_directions`), where a near and a far surface part as the viewpoint
moves. The hidden background is a guess (the depth of the visible background next to the gap, carried across it):
good for the narrow gaps of a baseline of centimetres to decimetres, not for a sensor metres away.

Pixel (u, v) has its centre at integer coordinates, as in `lipjax.data.sampling.LidarSampler`.
"""
from __future__ import annotations

import numpy as np

from lipjax.data.frame import Intrinsics
from lipjax.pointcloud import backproject, project_lidar_to_depth

MIN_VIEW_DEPTH_M = 0.05  # points closer than this to the sensor (or behind it) are not seen
MAX_FILL_PX = 64  # a hole takes the background from at most this many pixels away (along its epipolar line)


def _move(depth: np.ndarray, valid: np.ndarray, k: Intrinsics, shift_m: np.ndarray) -> np.ndarray:
    """(H, W) z-depth metres of the valid pixels, their points moved by `shift_m` and projected with K into an
    (H, W) image, the nearest per pixel (0 where none): `pointcloud.backproject`, then
    `pointcloud.project_lidar_to_depth` with the pure translation as the rigid transform."""
    moved = np.eye(4)
    moved[:3, 3] = shift_m
    points = backproject(np.where(valid, depth, 0.0), k)
    return project_lidar_to_depth(points, k, moved, depth.shape, min_depth_m=MIN_VIEW_DEPTH_M)


def epipolar_directions(rows: np.ndarray, cols: np.ndarray, k: Intrinsics, baseline_m) -> np.ndarray:
    """(N, 2) unit (row, column) directions along which the pixels' depths part when the viewpoint moves by
    `baseline_m`: a point at depth z moves by about (fy b_y - (v - cy) b_z, fx b_x - (u - cx) b_z) / z pixels
    (sign aside), so a near and a far point on one ray separate along that line (through the epipole)."""
    bx, by, bz = (float(c) for c in baseline_m)
    d = np.stack([k.fy * by - (rows - k.cy) * bz, k.fx * bx - (cols - k.cx) * bz], axis=1)
    norm = np.linalg.norm(d, axis=1, keepdims=True)
    return np.where(norm > 0, d / np.where(norm > 0, norm, 1.0), 0.0)


def fill_background(view: np.ndarray, k: Intrinsics, baseline_m) -> np.ndarray:
    """Fills the holes (0) of an (H, W) depth image seen from `baseline_m` with the background beside them; +inf
    (far: no return) is a value too and stays.

    A hole pixel walks both ways along its epipolar direction (`epipolar_directions`), up to MAX_FILL_PX pixels,
    to the first non-hole pixel on each side, and takes the farther of the two: a disocclusion lies between a near
    surface and the far one that continues under it (filling from both sides would meet in the middle and put the
    near surface's depth into half of the gap). A pixel with nothing on either side stays 0.
    """
    h, w = view.shape
    rows, cols = np.nonzero(view == 0)
    if rows.size == 0:
        return view
    direction = epipolar_directions(rows, cols, k, baseline_m)
    found = np.zeros(rows.size, np.float32)
    for side in (1.0, -1.0):
        todo = np.arange(rows.size)
        for step in range(1, MAX_FILL_PX + 1):
            r = np.rint(rows[todo] + side * step * direction[todo, 0]).astype(np.int64)
            c = np.rint(cols[todo] + side * step * direction[todo, 1]).astype(np.int64)
            inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
            value = np.zeros(todo.size, np.float32)
            value[inside] = view[r[inside], c[inside]]
            hit = value != 0
            found[todo[hit]] = np.maximum(found[todo[hit]], value[hit])
            todo = todo[~hit & inside]
            if todo.size == 0:
                break
    out = view.copy()
    out[rows, cols] = found
    return out


def sensor_view(depth: np.ndarray, valid: np.ndarray, k: Intrinsics, baseline_m) -> np.ndarray:
    """The (H, W) float32 z-depth (metres, 0 = no return) seen by a sensor at `baseline_m` (3,) from the camera
    centre, with the camera's intrinsics and axes; disocclusions continue the background (`fill_background`)."""
    b = np.asarray(baseline_m, np.float64)
    view = _move(depth, valid, k, -b)
    # The camera's invalid pixels (sky, out of range) are far: seen from the sensor at (nearly) the same pixel.
    view = np.where((view == 0) & ~valid, np.inf, view).astype(np.float32)
    view = fill_background(view, k, b)
    return np.where(np.isfinite(view), view, 0.0).astype(np.float32)


def to_camera(sparse_view: np.ndarray, k: Intrinsics, baseline_m) -> np.ndarray:
    """(H, W) sparse z-depth metres measured from the sensor at `baseline_m` -> the camera's (H, W) float32 sparse
    depth: each return moved back into the camera frame and projected, the nearest per pixel."""
    return _move(sparse_view, sparse_view > 0, k, np.asarray(baseline_m, np.float64))
