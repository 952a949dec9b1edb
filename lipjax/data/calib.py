"""Camera-LiDAR calibration files -> (intrinsics of one camera image, T_cam_from_lidar): what
lipjax.pointcloud.project_lidar_to_depth needs to turn a LiDAR sweep into the model's sparse depth input.

    intrinsics, T_cam_from_lidar = read_calibration("calib/000000.txt")          # any format below, image_2
    intrinsics, T_cam_from_lidar = read_calibration("2011_09_26/", camera=3)     # KITTI raw, image_03

Formats (`read_calibration` tells them apart by their keys; "key: numbers" lines, row-major):

    KITTI object / tracking   P0..P3 (3x4), R0_rect (3x3; tracking: R_rect), Tr_velo_to_cam (3x4; Tr_velo_cam)
    KITTI raw                 a date folder (or either file in it) with calib_velo_to_cam.txt (R: 9, T: 3) and
                              calib_cam_to_cam.txt (R_rect_00: 9, P_rect_0X: 12)
    KITTI odometry            calib.txt: P0..P3, Tr (3x4) (read_odometry_calib)
    any rig (text or .yaml)   K (9 numbers, or 3 rows of 3) or intrinsics (fx fy cx cy), and T_cam_from_lidar
                              (12 or 16 numbers: 3x4 or 4x4), pixels and metres:
                                  K: 721.5 0 609.6 0 721.5 172.9 0 0 1
                                  T_cam_from_lidar: 0 -1 0 0  0 0 -1 -0.08  1 0 0 -0.27

A KITTI camera X is rectified: its projection is P_X = K [I | t_X], t_X its offset from the reference camera
(image_2: about 6 cm along x), so t_X = K^-1 P_X[:, 3], and

    T_cam_from_lidar = [I | t_X] @ R0_rect @ Tr_velo_to_cam      (4x4, metres; R0_rect, Tr padded to 4x4)

which projects a point exactly as the devkit's P_X @ R0_rect @ Tr_velo_to_cam does.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from lipjax.data.errors import dataset_error
from lipjax.data.frame import Intrinsics
from lipjax.pointcloud import as_intrinsics

FORMATS = ("a KITTI object/tracking calib .txt (P2, R0_rect, Tr_velo_to_cam), a KITTI raw date folder "
           "(calib_velo_to_cam.txt + calib_cam_to_cam.txt), a KITTI odometry calib.txt (P2, Tr), or a rig .txt/.yaml "
           "with K (9 numbers) or intrinsics (fx fy cx cy) and T_cam_from_lidar (12 or 16 numbers)")
RAW_FILES = ("calib_velo_to_cam.txt", "calib_cam_to_cam.txt")


def read_key_values(path: str | os.PathLike, layout: str = "", source: str = "") -> dict[str, np.ndarray]:
    """{key: float64 numbers} of a "key: n n n ..." text file; the colon may be missing (KITTI tracking:
    "R_rect 1 0 0 ..."); a "#" starts a comment, to the end of its line; lines whose values are not all numbers
    (e.g. "calib_time: 09-Jan-2012") are skipped. An unreadable file raises DatasetError with `layout` and
    `source` (lipjax.data.errors)."""
    try:
        text = Path(path).read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise dataset_error(f"Cannot read calibration ({exc})", path, layout, source) from None
    rows = {}
    for line in text.splitlines():
        key, _, values = line.partition("#")[0].replace(":", " ", 1).strip().partition(" ")
        if not key:
            continue
        try:
            rows[key.strip()] = np.array([float(v) for v in values.split()])
        except ValueError:
            continue
    return rows


def camera_from_projection(p: np.ndarray) -> tuple[Intrinsics, np.ndarray]:
    """(intrinsics, t (3,) metres) of a rectified camera's 3x4 projection P = K [I | t]: t = K^-1 P[:, 3], the
    camera's offset from the reference camera. ValueError when P[:, :3] is not a pinhole K (no skew)."""
    p = np.asarray(p, np.float64).reshape(3, 4)
    k = p[:, :3]
    if k[0, 1] or k[1, 0] or k[2, 0] or k[2, 1] or k[2, 2] != 1 or not (k[0, 0] > 0 and k[1, 1] > 0):
        raise ValueError(f"projection matrix {p.ravel().tolist()}: its left 3x3 is not a camera matrix "
                         "[fx 0 cx; 0 fy cy; 0 0 1] (a rectified camera's P = K [I | t])")
    return Intrinsics(*(float(v) for v in (k[0, 0], k[1, 1], k[0, 2], k[1, 2]))), np.linalg.solve(k, p[:, 3])


def rigid(rotation: np.ndarray | None = None, translation: np.ndarray | None = None) -> np.ndarray:
    """(4, 4) float64 [R t; 0 0 0 1] from a 3x3 (or 9) R and a 3 t (identity / zero when None); a 3x4 or 4x4 matrix
    given as `rotation` is padded (3x4) or taken as is."""
    out = np.eye(4)
    if rotation is not None:
        r = np.asarray(rotation, np.float64)
        r = r.reshape((3, 3) if r.size == 9 else (3, 4) if r.size == 12 else (4, 4))
        out[: r.shape[0], : r.shape[1]] = r
    if translation is not None:
        out[:3, 3] += np.asarray(translation, np.float64).reshape(3)
    return out


def _need(rows: dict, path, *keys_and_sizes: tuple[tuple[str, ...], tuple[int, ...]]) -> list[np.ndarray]:
    """The first present key of each alternative group, checked for its number count."""
    found = []
    for keys, sizes in keys_and_sizes:
        key = next((k for k in keys if k in rows), None)
        if key is None or rows[key].size not in sizes:
            what = f"{rows[key].size} numbers in {key}" if key else f"no {' or '.join(keys)}"
            raise dataset_error(f"Calibration has {what} (expected {' or '.join(map(str, sizes))} numbers)", path)
        found.append(rows[key])
    return found


def _with_offset(p: np.ndarray, cam0_from_lidar: np.ndarray, path) -> tuple[Intrinsics, np.ndarray]:
    try:
        intrinsics, t = camera_from_projection(p)
    except ValueError as exc:
        raise dataset_error(str(exc), path) from None
    return intrinsics, rigid(translation=t) @ cam0_from_lidar


def read_kitti_object_calib(path: str | os.PathLike, camera: int = 2) -> tuple[Intrinsics, np.ndarray]:
    """(intrinsics of image_<camera>, (4, 4) T_cam_from_velodyne, metres) of a KITTI object (or tracking) calib
    file: [I | K^-1 P_X[:, 3]] @ R0_rect @ Tr_velo_to_cam (module docstring)."""
    rows = read_key_values(path)
    p, r0, tr = _need(rows, path, ((f"P{camera}",), (12,)), (("R0_rect", "R_rect"), (9,)),
                      (("Tr_velo_to_cam", "Tr_velo_cam"), (12,)))
    return _with_offset(p, rigid(r0) @ rigid(tr), path)


def read_kitti_raw_calib(folder: str | os.PathLike, camera: int = 2) -> tuple[Intrinsics, np.ndarray]:
    """(intrinsics of image_0<camera>, (4, 4) T_cam_from_velodyne, metres) of a KITTI raw date folder holding
    calib_velo_to_cam.txt (R, T) and calib_cam_to_cam.txt (R_rect_00, P_rect_0X): [I | K^-1 P_rect_0X[:, 3]] @
    R_rect_00 @ [R | T]."""
    velo_path, cam_path = (Path(folder) / name for name in RAW_FILES)
    r, t = _need(read_key_values(velo_path), velo_path, (("R",), (9,)), (("T",), (3,)))
    p, r_rect = _need(read_key_values(cam_path), cam_path, ((f"P_rect_0{camera}",), (12,)), (("R_rect_00",), (9,)))
    return _with_offset(p, rigid(r_rect) @ rigid(r, t), cam_path)


def _yaml_numbers(value) -> np.ndarray:
    """The float64 numbers of a YAML value: a list (nested or flat), or one string of whitespace-separated numbers
    ("721.5 0 609.6 ...", as in a text rig file); ValueError when any is not a number."""
    return np.asarray(value.split() if isinstance(value, str) else value, np.float64).ravel()


def read_rig_calib(path: str | os.PathLike) -> tuple[Intrinsics, np.ndarray]:
    """(intrinsics, (4, 4) T_cam_from_lidar, metres) of a plain rig file, "key: numbers" text or YAML (nested
    lists, flat lists or a string of numbers), with K (9 numbers) or intrinsics (fx fy cx cy), and
    T_cam_from_lidar (3x4 or 4x4); "#" starts a comment in either."""
    path = Path(path)
    if path.suffix.lower() in (".yaml", ".yml"):
        import yaml

        try:
            loaded = yaml.safe_load(path.read_text())
            rows = {str(k): _yaml_numbers(v) for k, v in dict(loaded).items()
                    if k in ("K", "intrinsics", "T_cam_from_lidar")}
        except (OSError, yaml.YAMLError, TypeError, ValueError) as exc:
            raise dataset_error(f"Cannot read YAML calibration ({type(exc).__name__}: {exc})".replace("\n", " "),
                                path) from None
    else:
        rows = read_key_values(path)
    k, t = _need(rows, path, (("K", "intrinsics"), (9, 4)), (("T_cam_from_lidar",), (12, 16)))
    try:
        intrinsics = as_intrinsics(k.reshape(3, 3) if k.size == 9 else k)
    except ValueError as exc:
        raise dataset_error(str(exc), path) from None
    transform = rigid(t)
    if not np.allclose(transform[3], [0, 0, 0, 1]):
        raise dataset_error("T_cam_from_lidar must end in the row 0 0 0 1 (a rigid transform)", path)
    return intrinsics, transform


def read_odometry_calib(path: str | os.PathLike, camera: int = 2) -> tuple[Intrinsics, np.ndarray]:
    """(intrinsics of image_<camera>, (4, 4) T_cam_from_velodyne, metres) from a sequence's calib.txt: P_X and Tr
    (velodyne -> cam0), T = [I | K^-1 P_X[:, 3]] @ Tr (lipjax.data.calib)."""
    rows = read_key_values(path)
    try:
        p, tr = rows[f"P{camera}"].reshape(3, 4), rows["Tr"].reshape(3, 4)
        intrinsics, t = camera_from_projection(p)
    except (KeyError, ValueError) as e:
        raise dataset_error(f"Cannot read KITTI odometry calibration ({e})", path) from None
    # P_X = K [I | t]: image_X's offset from the rectified cam0 (a baseline along x, in metres).
    return intrinsics, rigid(translation=t) @ rigid(tr)


def calibration_format(path: str | os.PathLike) -> str:
    """Which format of the module docstring a calibration is, told apart by its keys: "kitti-raw",
    "kitti-object" (object and tracking), "kitti-odometry" or "rig". Raises DatasetError for a missing file or one
    of no known format."""
    path = Path(path)
    if path.is_dir() or path.name in RAW_FILES:
        return "kitti-raw"
    if not path.is_file():
        raise dataset_error(f"Calibration file not found (give {FORMATS})", path)
    if path.suffix.lower() in (".yaml", ".yml"):
        return "rig"
    rows = read_key_values(path)
    if {"Tr_velo_to_cam", "Tr_velo_cam"} & rows.keys():
        return "kitti-object"
    if "Tr" in rows:
        return "kitti-odometry"
    if "T_cam_from_lidar" in rows:
        return "rig"
    raise dataset_error(f"Not a calibration file of a known format: no Tr_velo_to_cam, Tr or T_cam_from_lidar; give "
                        f"{FORMATS}", path)


def read_calibration(path: str | os.PathLike, camera: int = 2) -> tuple[Intrinsics, np.ndarray]:
    """(intrinsics of the camera's image, pixels; (4, 4) T_cam_from_lidar, metres) from any format of the module
    docstring, told apart by its keys (`calibration_format`). `camera`: the KITTI camera (2 = left colour, 3 = right
    colour); a rig file describes one camera and ignores it."""
    path = Path(path)
    fmt = calibration_format(path)
    if fmt == "kitti-raw":
        return read_kitti_raw_calib(path if path.is_dir() else path.parent, camera)
    if fmt == "kitti-object":
        return read_kitti_object_calib(path, camera)
    if fmt == "kitti-odometry":
        return read_odometry_calib(path, camera)
    return read_rig_calib(path)
