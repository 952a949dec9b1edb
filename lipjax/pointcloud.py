"""Depth maps <-> 3-D points: back-projection, PLY files, and LiDAR point clouds projected to sparse depth images.

Camera frame (OpenCV): x right, y down, z forward (the optical axis), metres. Pixel (row v, column u) has its
centre at image coordinates (u, v) and sees the ray through ((u - cx) / fx, (v - cy) / fy, 1); cx, cy are in
the same pixel-index coordinates (lipjax.data.frame.Intrinsics). Depth is z, the distance along the optical
axis (not the range along the ray), as in KITTI, NYU and TUM depth images.

    points = backproject(depth_m, intrinsics)                         # (N, 3) for the valid pixels
    write_ply("cloud.ply", *backproject_rgbd(depth_m, rgb, intrinsics))
    sparse = project_lidar_to_depth(scan_xyz, intrinsics, T_cam_from_lidar, (H, W))   # the model's input
    scan_xyz = read_point_cloud("000000.bin")                         # KITTI .bin, .npy or .pcd, metres
"""
from __future__ import annotations

import dataclasses
import os
import pathlib

import numpy as np

from lipjax.data.frame import Intrinsics
from lipjax.utils import written_whole
from lipjax.zbuffer import splat_nearest

IntrinsicsLike = Intrinsics | np.ndarray


def as_intrinsics(intrinsics: IntrinsicsLike) -> Intrinsics:
    """An Intrinsics from an Intrinsics, (fx, fy, cx, cy) or a 3x3 K (pixels), checked: fx, fy > 0, all finite.

    Raises ValueError naming the numbers otherwise (e.g. all zeros would put every point at NaN).
    """
    if isinstance(intrinsics, Intrinsics):
        k = intrinsics
    else:
        a = np.asarray(intrinsics, dtype=np.float64)
        if a.shape == (4,):
            k = Intrinsics(*map(float, a))
        elif a.shape == (3, 3):
            k = Intrinsics(float(a[0, 0]), float(a[1, 1]), float(a[0, 2]), float(a[1, 2]))
        else:
            raise ValueError(f"intrinsics must be an Intrinsics, (fx, fy, cx, cy) or a 3x3 K, got shape {a.shape}")
    values = (k.fx, k.fy, k.cx, k.cy)
    if not (np.isfinite(values).all() and k.fx > 0 and k.fy > 0):
        raise ValueError(f"intrinsics fx={k.fx:g} fy={k.fy:g} cx={k.cx:g} cy={k.cy:g}: the focal lengths fx, fy must "
                         "be > 0 and all four finite (pixels); give the camera's fx fy cx cy (or its K)")
    return k


def _valid(depth: np.ndarray) -> np.ndarray:
    return np.isfinite(depth) & (depth > 0)


def backproject(depth_m: np.ndarray, intrinsics: IntrinsicsLike) -> np.ndarray:
    """(N, 3) float32 camera-frame points (x right, y down, z forward, metres) of the valid pixels (depth > 0).

    Points are in row-major pixel order. `intrinsics`: Intrinsics, (fx, fy, cx, cy) or a 3x3 K, in pixels.
    """
    depth = np.asarray(depth_m)
    if depth.ndim != 2:
        raise ValueError(f"depth must be (H, W) metres, got shape {depth.shape}")
    k = as_intrinsics(intrinsics)
    v, u = np.nonzero(_valid(depth))
    z = depth[v, u].astype(np.float64)
    x = (u - k.cx) / k.fx * z
    y = (v - k.cy) / k.fy * z
    return np.stack([x, y, z], axis=1).astype(np.float32)


def backproject_rgbd(depth_m: np.ndarray, rgb: np.ndarray,
                     intrinsics: IntrinsicsLike) -> tuple[np.ndarray, np.ndarray]:
    """(points (N, 3) float32 metres, colours (N, 3) uint8) of the valid pixels; see `backproject`."""
    rgb = np.asarray(rgb)
    depth = np.asarray(depth_m)
    if rgb.shape != (*depth.shape, 3) or rgb.dtype != np.uint8:
        raise ValueError(f"rgb must be uint8 {(*depth.shape, 3)} to match the depth, got {rgb.dtype} {rgb.shape}")
    return backproject(depth, intrinsics), rgb[_valid(depth)]


def write_ply(path: str | os.PathLike, points: np.ndarray, colors: np.ndarray | None = None,
              binary: bool = True) -> None:
    """Writes a PLY point cloud: float32 x y z (metres) and optional uchar red green blue per vertex.

    Binary little-endian by default (compact; MeshLab, CloudCompare, Open3D, Blender read it), or ASCII. The
    file appears whole or not at all (lipjax.utils.written_whole).
    """
    points = np.asarray(points, dtype=np.float32)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points must be (N, 3), got shape {points.shape}")
    if colors is not None:
        colors = np.asarray(colors)
        if colors.shape != points.shape:
            raise ValueError(f"colors must be (N, 3) like the points {points.shape}, got {colors.shape}")
        if colors.dtype != np.uint8:
            raise ValueError(f"colors must be uint8 (0-255), got {colors.dtype}")
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    if colors is not None:
        fields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
    header = ["ply", f"format {'binary_little_endian' if binary else 'ascii'} 1.0",
              "comment lipjax point cloud, metres",
              f"element vertex {len(points)}"]
    header += [f"property {'float' if t == '<f4' else 'uchar'} {name}" for name, t in fields]
    header += ["end_header"]
    vertices = np.empty(len(points), dtype=fields)
    vertices["x"], vertices["y"], vertices["z"] = points.T
    if colors is not None:
        vertices["red"], vertices["green"], vertices["blue"] = colors.T
    with written_whole(path) as temporary, open(temporary, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        if binary:
            f.write(vertices.tobytes())
        else:
            fmt = ["%.6g"] * 3 + (["%d"] * 3 if colors is not None else [])
            np.savetxt(f, np.column_stack([points] + ([colors] if colors is not None else [])), fmt=fmt)


@dataclasses.dataclass(frozen=True)
class ProjectionCounts:
    """Where every point of a sweep went when projected into a camera (`project_lidar_to_depth(...,
    return_counts=True)`): points = not_finite + behind + outside + hidden + kept.

    behind: camera z below min_depth_m (behind the camera or on it); outside: in front but off the image; hidden:
    landed on a pixel where a nearer point landed too (the z-buffer kept that one); kept: one per pixel with depth.
    """

    points: int
    not_finite: int
    behind: int
    outside: int
    hidden: int
    kept: int

    def summary(self) -> str:
        """One line: e.g. '19456 of 120340 points kept: 3100 hidden behind a nearer point on the same pixel, 80000
        outside the image, 17784 behind the camera'."""
        parts = [f"{self.hidden} hidden behind a nearer point on the same pixel", f"{self.outside} outside the image",
                 f"{self.behind} behind the camera"] + ([f"{self.not_finite} not finite"] if self.not_finite else [])
        return f"{self.kept} of {self.points} points kept: {', '.join(parts)}"


def project_lidar_to_depth(points_lidar: np.ndarray, intrinsics: IntrinsicsLike, T_cam_from_lidar: np.ndarray,
                           image_size: tuple[int, int], min_depth_m: float = 1e-3, *, return_counts: bool = False
                           ) -> np.ndarray | tuple[np.ndarray, ProjectionCounts]:
    """Projects a LiDAR point cloud into a camera: the sparse depth image the model takes as input.

    Args:
      points_lidar: (N, 3) (or (N, >=3), extra columns such as intensity ignored) points in the LiDAR frame, metres.
      intrinsics: the camera's Intrinsics, (fx, fy, cx, cy) or 3x3 K, pixels.
      T_cam_from_lidar: (4, 4) rigid transform, p_cam = R p_lidar + t, metres. (3, 4) is accepted too. For a
        KITTI camera, lipjax.data.calib.read_calibration gives it with the camera's offset from the reference
        camera: [I | K^-1 P2[:, 3]] @ R0_rect @ Tr_velo_to_cam, not R0_rect @ Tr_velo_to_cam.
      image_size: (H, W) pixels.
      min_depth_m: points with camera z below this (behind the camera or on it) are dropped.

    Returns:
      (H, W) float32 depth in metres (z in the camera frame), 0 where no point lands. A point lands in the pixel
      whose centre is nearest its projection; when several land in one pixel the nearest (smallest z) is kept,
      as a z-buffer would (a far point seen "through" a near surface is an occluded return). Points outside the
      image are dropped. With `return_counts`, also the ProjectionCounts of where every point went.
    """
    points = np.asarray(points_lidar, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] < 3:
        raise ValueError(f"points must be (N, 3) metres, got shape {points.shape}")
    t = np.asarray(T_cam_from_lidar, dtype=np.float64)
    if t.shape == (3, 4):
        t = np.vstack([t, [0.0, 0.0, 0.0, 1.0]])
    if t.shape != (4, 4) or not np.allclose(t[3], [0, 0, 0, 1]):
        raise ValueError(f"T_cam_from_lidar must be a 4x4 rigid transform with last row [0 0 0 1], got {t.shape}")
    h, w = (int(s) for s in image_size)
    k = as_intrinsics(intrinsics)
    cam = points[:, :3] @ t[:3, :3].T + t[:3, 3]
    finite = np.isfinite(cam).all(axis=1)
    z = cam[:, 2]
    keep = finite & (z >= min_depth_m)
    cam, z = cam[keep], z[keep]
    col = np.floor(k.fx * cam[:, 0] / z + k.cx + 0.5)
    row = np.floor(k.fy * cam[:, 1] / z + k.cy + 0.5)
    inside = (col >= 0) & (col < w) & (row >= 0) & (row < h)
    pixel = row[inside].astype(np.int64) * w + col[inside].astype(np.int64)
    z = z[inside]
    sparse = splat_nearest(pixel, z, (h, w))
    if not return_counts:
        return sparse
    kept = int(np.unique(pixel).size)
    counts = ProjectionCounts(points=len(points), not_finite=int((~finite).sum()), behind=int((finite & ~keep).sum()),
                              outside=int((~inside).sum()), hidden=int(inside.sum()) - kept, kept=kept)
    return sparse, counts


POINT_CLOUD_FORMATS = ".bin (KITTI: float32 x y z reflectance), .npy ((N, >=3) x y z ...) or .pcd (ascii / binary)"
_PCD_TYPES = {("F", 4): "<f4", ("F", 8): "<f8", ("I", 1): "i1", ("I", 2): "<i2", ("I", 4): "<i4", ("I", 8): "<i8",
              ("U", 1): "u1", ("U", 2): "<u2", ("U", 4): "<u4", ("U", 8): "<u8"}


def read_point_cloud(path: str | os.PathLike) -> np.ndarray:
    """(N, 3) float32 x, y, z (metres, in the sensor's frame) of a point cloud file: a KITTI .bin (float32 x, y,
    z, reflectance per point), a .npy (N, >=3) array whose first three columns are x, y, z, or a PCD file
    (DATA ascii or binary, fields x y z). Other columns are dropped; non-finite points are kept (the projection
    drops them). Raises ValueError naming the file and the problem; for a .bin in another layout (float64, 3 or 5
    columns, millimetres: `_read_bin`), naming that layout and how to save the file as a .npy."""
    path = pathlib.Path(path)
    suffix = path.suffix.lower()
    if suffix == ".bin":
        return _read_bin(path)
    if suffix == ".npy":
        try:
            points = np.load(path, allow_pickle=False)
        except (OSError, ValueError) as exc:
            raise ValueError(f"{path}: cannot read the .npy point cloud ({exc})") from None
        if points.ndim != 2 or points.shape[1] < 3 or not np.issubdtype(points.dtype, np.number):
            raise ValueError(f"{path}: a .npy point cloud must be a numeric (N, 3) or (N, >=3) array of x y z "
                             f"metres, got {points.dtype} {points.shape}")
        return np.ascontiguousarray(points[:, :3], dtype=np.float32)
    if suffix == ".pcd":
        return _read_pcd(path)
    raise ValueError(f"{path}: unknown point cloud format {suffix!r}; use {POINT_CLOUD_FORMATS}")


# No LiDAR measures a kilometre: coordinates beyond it are the bytes of another layout read as KITTI's.
MAX_POINT_RANGE_M = 1000.0
# A layout fits a .bin when at least this share of its points is plausible (a sweep may hold a few odd returns).
PLAUSIBLE_SHARE = 0.99
# Layouts a .bin is checked against when KITTI's (float32 x y z reflectance) does not fit it: (dtype, columns, what),
# more columns first (a file read with fewer columns than it has still looks like points; with more, it does not).
OTHER_BIN_LAYOUTS = (("float64", 4, "x y z reflectance"), ("float64", 3, "x y z"),
                     ("float32", 5, "x y z intensity ring, as nuScenes"), ("float32", 3, "x y z"))


def _plausible_share(table: np.ndarray) -> float:
    """The share of the rows of an (N, >=3) table read from a .bin that are points: x y z within
    MAX_POINT_RANGE_M, any further columns (reflectance, intensity, ring) finite and >= 0. Rows whose x y z are
    not all finite (no return) are left out; 0 when no row is left."""
    xyz = table[:, :3].astype(np.float64)
    finite = np.isfinite(xyz).all(axis=1)
    if not finite.any():
        return 0.0
    ok = (np.abs(xyz[finite]) <= MAX_POINT_RANGE_M).all(axis=1)
    if table.shape[1] > 3:
        extra = table[finite, 3:].astype(np.float64)
        with np.errstate(invalid="ignore"):
            ok &= (np.isfinite(extra) & (extra >= 0)).all(axis=1)
    return float(ok.mean())


def _bin_table(blob: bytes, dtype: str, columns: int) -> np.ndarray | None:
    """The (N, columns) table of a .bin's bytes read as `dtype`, or None when its size does not divide."""
    size = np.dtype(dtype).itemsize * columns
    if not blob or len(blob) % size:
        return None
    return np.frombuffer(blob, dtype="<" + np.dtype(dtype).str[1:]).reshape(-1, columns)


def _read_bin(path: pathlib.Path) -> np.ndarray:
    """x, y, z of a KITTI .bin (float32 x y z reflectance per point, 16 bytes). A file that is not in that layout
    but in another one (float64, 3 or 5 columns: OTHER_BIN_LAYOUTS, each judged by `_plausible_share`) is a
    one-line error naming that layout and how to save it as a .npy, which records its layout itself."""
    blob = path.read_bytes()
    kitti = _bin_table(blob, "float32", 4)
    if kitti is not None and _plausible_share(kitti) >= PLAUSIBLE_SHARE:
        return np.array(kitti[:, :3])
    for dtype, columns, what in OTHER_BIN_LAYOUTS:
        table = _bin_table(blob, dtype, columns)
        if table is None or _plausible_share(table) < PLAUSIBLE_SHARE:
            continue
        if kitti is None:
            why = f"its {len(blob)} bytes are no multiple of 16"
        else:
            far = np.abs(kitti[:, :3].astype(np.float64))
            top = far[np.isfinite(far)].max(initial=0.0)
            why = (f"read so, its points lie up to {top:.2g} m away" if top > MAX_POINT_RANGE_M
                   else "read so, its reflectances are negative: its points are scrambled")
        npy = path.with_suffix(".npy")
        raise ValueError(f"{path}: a .bin of {columns} {dtype} per point ({what}), not KITTI's 4 float32 (x y z "
                         f"reflectance; {why}); save it as a .npy, which records its layout: "
                         f"np.save('{npy}', np.fromfile('{path}', np.{dtype}).reshape(-1, {columns}))")
    if kitti is None:
        raise ValueError(f"{path}: a KITTI .bin sweep holds 4 float32 per point (x y z reflectance); its size "
                         f"({len(blob)} bytes) is not a multiple of 16: corrupt, or another format")
    xyz_ok = _plausible_share(kitti[:, :3])
    if xyz_ok < PLAUSIBLE_SHARE:
        cause = ("millimetres? save x y z / 1000 (metres)" if _plausible_share(kitti[:, :3] / 1000) >= PLAUSIBLE_SHARE
                 else "not a sweep in metres in any layout lipjax knows; save x y z metres")
        raise ValueError(f"{path}: read as KITTI's float32 x y z reflectance, {100 * (1 - xyz_ok):.0f} % of its "
                         f"points lie beyond {MAX_POINT_RANGE_M:g} m: {cause} as an (N, 3) .npy")
    return np.array(kitti[:, :3])  # x y z in metres, only the 4th column odd (negative): not used


def _read_pcd(path: pathlib.Path) -> np.ndarray:
    """x, y, z of a PCD file (https://pointclouds.org/documentation/tutorials/pcd_file_format.html)."""
    blob = path.read_bytes()
    header, offset = {}, 0
    while "DATA" not in header:
        end = blob.find(b"\n", offset)
        if end < 0:
            raise ValueError(f"{path}: not a PCD file (no DATA line in its header)")
        line = blob[offset:end].decode("ascii", "replace").strip()
        offset = end + 1
        if line and not line.startswith("#"):
            key, _, value = line.partition(" ")
            header[key.upper()] = value.split()
    try:
        fields = header["FIELDS"]
        sizes = [int(v) for v in header["SIZE"]]
        types = header["TYPE"]
        counts = [int(v) for v in header.get("COUNT", ["1"] * len(fields))]
        points = int(header["POINTS"][0]) if "POINTS" in header else int(header["WIDTH"][0]) * int(
            header["HEIGHT"][0])
        dtype = np.dtype([(f"{name}_{i}", _PCD_TYPES[(t.upper(), s)], (c,))
                          for i, (name, s, t, c) in enumerate(zip(fields, sizes, types, counts))])
    except (KeyError, ValueError, IndexError) as exc:
        raise ValueError(f"{path}: PCD header lacks or garbles {exc} (needs FIELDS, SIZE, TYPE, POINTS)") from None
    if not {"x", "y", "z"} <= set(fields):
        raise ValueError(f"{path}: PCD fields {fields} lack x, y, z")
    mode = header["DATA"][0].lower()
    if mode == "binary":
        if len(blob) - offset < points * dtype.itemsize:
            raise ValueError(f"{path}: PCD file truncated ({points} points announced)")
        data = np.frombuffer(blob, dtype, count=points, offset=offset)
        columns = {name: data[f"{name}_{i}"][:, 0] for i, name in enumerate(fields)}
    elif mode == "ascii":
        table = np.loadtxt(blob[offset:].decode("ascii").splitlines(), dtype=np.float64, ndmin=2)
        starts = np.cumsum([0] + counts)
        if table.shape != (points, starts[-1]):
            raise ValueError(f"{path}: PCD announces {points} points of {starts[-1]} values, found {table.shape}")
        columns = {name: table[:, starts[i]] for i, name in enumerate(fields)}
    else:
        raise ValueError(f"{path}: PCD DATA {mode}: not supported; save it as ascii or binary "
                         "(pcl_convert_pcd_ascii_binary IN OUT 1)")
    return np.stack([columns["x"], columns["y"], columns["z"]], axis=1).astype(np.float32)
