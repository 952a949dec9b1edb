"""Image / depth file readers, and a data set over a user's own folder of RGB-D frames.

Folder layout (frames matched by file stem):

    <root>/rgb/<stem>.png|.jpg|.jpeg          colour image (any bit depth; read as 8-bit RGB)
    <root>/depth/<stem>.png                   16-bit depth, metres = value / depth_scale, 0 = invalid
    <root>/depth/<stem>.npy                   float depth in metres (0 = invalid)
    <root>/sparse/<stem>.png|.npy             optional: your own sparse input, as depth/ (the "input" sampler,
                                          lipjax.data.sources.FolderInput; SPARSE_DIR)
    <root>/intrinsics.txt                     optional: "fx fy cx cy", the 9 numbers of K (row-major), the 12 of
                                          a 3x4 P, or a calibration file (lipjax.data.calib: KITTI, any rig);
                                          read only by samplers that simulate a LiDAR
    <root>/intrinsics/<stem>.txt              optional, per frame, same format
or <root>/train/ and <root>/val/, each laid out as <root> above: `lipjax train` trains on train/ and validates on
val/ (without them, on all but the last 5 % of the frames and on that 5 %).
A folder of rgb/ and sparse/ alone, without depth/ (your sensor without ground truth), adapts a model by
self-supervision (lipjax.train.adapt: the loss at samples hidden from the input, lipjax.data.hidden).

Depth scales of common sensors (raw PNG value per metre): KITTI 256, NYU / Kinect / RealSense 1000,
TUM RGB-D 5000. A PNG depth has no unit in it, so the scale must be given: there is no default.

Single frames, as the command line reads and writes them: `read_frame` (an RGB image and its aligned sparse
depth, checked), `write_depth` (.npy metres, 16-bit .png at a scale, or a .color.png picture).
"""
from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

import cv2
import numpy as np

from lipjax.data.errors import dataset_error
from lipjax.data.frame import Frame, Intrinsics
from lipjax.pointcloud import IntrinsicsLike, as_intrinsics
from lipjax.utils import written_whole

RGB_SUFFIXES = (".png", ".jpg", ".jpeg")
DEPTH_SUFFIXES = (".png", ".npy")
KNOWN_DEPTH_SCALES = {"kitti": 256.0, "nyu": 1000.0, "tum": 5000.0}
OUT_FORMATS = ("npy", "png", "color.png")

SPARSE_DIR = "sparse"  # <root>/sparse/<stem>.png|.npy: a folder's own sparse input (optional)
FOLDER_LAYOUT = f"""\
<root>/rgb/<stem>.png|.jpg
<root>/depth/<stem>.png (16-bit, needs depth_scale) or <stem>.npy (float metres)
<root>/{SPARSE_DIR}/<stem>.png|.npy (optional: your own sparse input, as depth/)
<root>/intrinsics.txt ("fx fy cx cy" or 9 numbers of K) or <root>/intrinsics/<stem>.txt (optional: read only by a
    sampler that simulates a LiDAR)
or <root>/train/ and <root>/val/, each laid out as above"""
FOLDER_SOURCE = "your own frames (lipjax.data.folder.FolderDataset)"

_DIGITS = re.compile(r"(\d+)")
# Stands in for the intrinsics of a folder without any, where nothing reads them (FolderDataset).
UNUSED_INTRINSICS = Intrinsics(1.0, 1.0, 0.0, 0.0)


def parse_depth_scale(text: str) -> float:
    """A PNG depth value per metre (> 0) from a number or a sensor's name in KNOWN_DEPTH_SCALES (kitti, nyu,
    tum); ValueError otherwise."""
    if text.lower() in KNOWN_DEPTH_SCALES:
        return KNOWN_DEPTH_SCALES[text.lower()]
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"expected a number or one of {sorted(KNOWN_DEPTH_SCALES)}, got {text!r}") from None
    if not value > 0:
        raise ValueError(f"must be > 0, got {text}")
    return value


def natural_key(text: str) -> tuple:
    """Sort key ordering embedded integers numerically ("2" < "10"), so listings are stable and human-ordered."""
    return tuple(int(tok) if tok.isdigit() else tok for tok in _DIGITS.split(text))


def _is_depth_png(path: str | os.PathLike) -> bool:
    """Whether a file is a 16-bit single-channel PNG (a depth map), from its header alone (PNG IHDR: bit depth at
    byte 24, colour type 0 = grey at byte 25)."""
    try:
        with open(path, "rb") as f:
            head = f.read(26)
    except OSError:
        return False
    is_png = head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR"
    return is_png and head[24:26] == b"\x10\x00"


def read_rgb(path: str | os.PathLike) -> np.ndarray:
    """Reads a colour image as (H, W, 3) uint8 RGB (cv2 decodes BGR; converted here). Grey images get 3 channels;
    a 16-bit grey PNG is a depth map given in place of the colour image, and raises DatasetError."""
    if _is_depth_png(path):
        raise dataset_error("A 16-bit single-channel PNG is a depth map, not a colour image: give it as the depth "
                            "and the camera's colour image as the RGB", path)
    image = cv2.imread(os.fspath(path), cv2.IMREAD_COLOR)
    if image is None:
        raise dataset_error("Cannot read RGB image (missing, corrupt or unsupported format)", path)
    return np.ascontiguousarray(cv2.cvtColor(image, cv2.COLOR_BGR2RGB))


def read_depth(path: str | os.PathLike, scale: float | None = None) -> np.ndarray:
    """Reads a depth map as (H, W) float32 metres, 0 = invalid.

    Formats:
      .png: 16-bit unsigned; metres = value / scale. `scale` is required (KITTI 256, NYU 1000, TUM 5000).
        8-bit PNGs are rejected: they cannot hold metric depth and usually mean a visualisation was saved.
      .npy: float or integer array (H, W) or (H, W, 1); metres = value / scale, scale defaults to 1 (metres).

    Raises DatasetError on an unreadable file, a wrong dtype / shape, or NaN / infinite / negative values
    (0 is the only invalid marker inside the library, so other markers are refused rather than guessed).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if scale is not None and not scale > 0:
        raise dataset_error(f"Depth scale must be > 0, got {scale}", path)
    if suffix == ".npy":
        try:
            raw = np.load(path, allow_pickle=False)
        except Exception as exc:  # noqa: BLE001 - any failure to decode is the same user-facing problem
            raise dataset_error(f"Cannot read depth .npy ({type(exc).__name__}: {exc})", path) from exc
        if raw.ndim == 3 and raw.shape[2] == 1:
            raw = raw[..., 0]
        if raw.ndim != 2 or not (np.issubdtype(raw.dtype, np.floating) or np.issubdtype(raw.dtype, np.integer)):
            raise dataset_error(f"Depth .npy must be a numeric (H, W) array, got {raw.dtype} {raw.shape}", path)
        depth = raw.astype(np.float32) / np.float32(1.0 if scale is None else scale)
    elif suffix == ".png":
        if scale is None:
            raise dataset_error(
                "A PNG depth map needs a depth scale (metres = value / scale; e.g. KITTI 256, NYU 1000, TUM 5000), "
                "none was given for",
                path,
            )
        raw = cv2.imread(os.fspath(path), cv2.IMREAD_UNCHANGED)
        if raw is None:
            raise dataset_error("Cannot read depth PNG (missing, corrupt or not an image)", path)
        if raw.dtype != np.uint16 or raw.ndim != 2:
            raise dataset_error(
                f"Depth PNG must be single-channel 16-bit, got {raw.dtype} with shape {raw.shape}", path)
        depth = raw.astype(np.float32) / np.float32(scale)
    else:
        raise dataset_error(f"Unsupported depth format {suffix!r} (use .png with a scale, or .npy in metres)", path)
    if not np.all(np.isfinite(depth)):
        raise dataset_error("Depth contains NaN or infinite values (use 0 to mark invalid pixels)", path)
    if np.any(depth < 0):
        raise dataset_error("Depth contains negative values (use 0 to mark invalid pixels)", path)
    return depth


def read_intrinsics_txt(path: str | os.PathLike, camera: int = 2) -> Intrinsics:
    """Reads "fx fy cx cy" (4 numbers), a row-major 3x3 K (9 numbers) or a rectified camera's 3x4 P = K [I | t]
    (12 numbers), any whitespace, in pixels; or the intrinsics of KITTI camera `camera` (a rig's one camera) in a
    calibration file of any lipjax.data.calib format."""
    try:
        tokens = Path(path).read_text().split()
    except (OSError, UnicodeDecodeError) as exc:
        raise dataset_error(f"Cannot read intrinsics ({exc})", path) from exc
    try:
        values = [float(tok) for tok in tokens]
    except ValueError:
        from lipjax.data.calib import read_calibration

        return read_calibration(path, camera)[0]
    if len(values) not in (4, 9, 12):
        raise dataset_error(f"Intrinsics file must hold 4 numbers (fx fy cx cy), 9 (K) or 12 (a 3x4 P), or be a "
                            f"calibration file (P2: ..., lipjax.data.calib); found {len(values)} numbers", path)
    try:
        if len(values) == 12:
            from lipjax.data.calib import camera_from_projection

            return camera_from_projection(np.asarray(values))[0]
        return as_intrinsics(np.asarray(values).reshape(3, 3) if len(values) == 9 else values)
    except ValueError as exc:
        raise dataset_error(str(exc), path) from exc


def read_intrinsics(intrinsics: IntrinsicsLike | str | os.PathLike | None, camera: int = 2) -> Intrinsics | None:
    """Checked Intrinsics (pixels) from an Intrinsics, (fx, fy, cx, cy) or a 3x3 K (lipjax.pointcloud.as_intrinsics),
    or from a file `read_intrinsics_txt` reads (KITTI camera `camera` of a calibration file); None stays None."""
    if intrinsics is None:
        return None
    if isinstance(intrinsics, (str, os.PathLike)):
        return read_intrinsics_txt(intrinsics, camera)
    return as_intrinsics(intrinsics)


def read_frame(rgb_path: str | os.PathLike, depth_path: str | os.PathLike,
               scale: float | None) -> tuple[np.ndarray, np.ndarray]:
    """(rgb (H, W, 3) uint8, sparse (H, W) float32 metres) of one frame, checked: the depth is a .npy (metres)
    or a 16-bit .png with its `scale` (value per metre), aligned with the RGB image and not empty."""
    rgb_path, depth_path = Path(rgb_path), Path(depth_path)
    rgb = read_rgb(rgb_path)
    suffix = depth_path.suffix.lower()
    if suffix == ".png" and scale is None:
        raise ValueError(f"{depth_path}: a PNG depth map has no unit; give its scale, --depth-scale S (metres = "
                         "value / S): KITTI 256, NYU 1000, TUM 5000")
    if suffix not in DEPTH_SUFFIXES:
        raise ValueError(f"{depth_path}: unsupported depth format {suffix!r} (use a 16-bit .png with --depth-scale, "
                         "or .npy in metres)")
    sparse = read_depth(depth_path, scale if suffix == ".png" else None)
    if sparse.shape != rgb.shape[:2]:
        raise ValueError(f"{depth_path}: sparse depth is {sparse.shape[0]}x{sparse.shape[1]} but the RGB image "
                         f"{rgb_path} is {rgb.shape[0]}x{rgb.shape[1]}; the depth must be aligned with the RGB image "
                         "pixel for pixel (project your LiDAR into the camera: "
                         "lipjax.pointcloud.project_lidar_to_depth)")
    if not (sparse > 0).any():
        raise ValueError(f"{depth_path}: the sparse depth map is empty (no pixel > 0); nothing to complete from")
    return rgb, sparse


def output_format(path: str | os.PathLike) -> str:
    """The format an output file name asks for: "npy", "png" or "color.png" (ValueError otherwise)."""
    name = Path(path).name.lower()
    for fmt in ("color.png", "npy", "png"):
        if name.endswith("." + fmt):
            return fmt
    raise ValueError(f"{path}: unknown output extension; use .npy (metres), .png (16-bit, scale S) or .color.png "
                     "(picture)")


def write_depth(path: str | os.PathLike, dense_m: np.ndarray, fmt: str, png_scale: float,
                color_range_m: tuple[float, float]) -> None:
    """Writes (H, W) metres as fmt: "npy" (float32 metres), "png" (16-bit, value = round(metres * png_scale);
    depths that do not fit are clipped, with a warning) or "color.png" (turbo picture over color_range_m). The
    file appears whole or not at all (lipjax.utils.written_whole)."""
    if fmt not in OUT_FORMATS:
        raise ValueError(f"unknown depth output format {fmt!r}; one of {OUT_FORMATS}")
    with written_whole(path) as temporary:
        if fmt == "npy":
            np.save(temporary, np.asarray(dense_m, np.float32))
        elif fmt == "color.png":
            from lipjax import viz

            viz.write_png(temporary, viz.colorize_depth(dense_m, *color_range_m))
        else:
            raw = np.round(np.asarray(dense_m, np.float64) * png_scale)
            if raw.max() > 65535:
                warnings.warn(f"{path}: depth above {65535 / png_scale:.1f} m does not fit a 16-bit PNG at scale "
                              f"{png_scale:g}; clipped (use a smaller --depth-scale or .npy)", stacklevel=3)
            if not cv2.imwrite(os.fspath(temporary), np.clip(raw, 0, 65535).astype(np.uint16)):
                raise OSError(f"cannot write {path}")


def check_one_depth_format(depth_paths: list[Path]) -> None:
    """Raises DatasetError naming the odd files when a folder mixes .png and .npy depth (their units differ)."""
    by_suffix: dict[str, list[Path]] = {}
    for path in depth_paths:
        by_suffix.setdefault(path.suffix.lower(), []).append(path)
    if len(by_suffix) > 1:
        odd = min(by_suffix.values(), key=len)
        names = ", ".join(p.name for p in odd[:3]) + (f" and {len(odd) - 3} more" if len(odd) > 3 else "")
        raise dataset_error(f"Depth folder mixes .png and .npy files (units differ: scaled integers vs metres); "
                            f"convert or move away the odd one(s): {names}, in", odd[0].parent)


def _list(directory: Path, suffixes: tuple[str, ...]) -> dict[str, Path]:
    found: dict[str, Path] = {}
    for path in sorted(directory.iterdir()):
        if path.is_file() and path.suffix.lower() in suffixes:
            if path.stem in found:
                raise dataset_error(f"Two files share the stem {path.stem!r} ({found[path.stem].name})", path,
                                    FOLDER_LAYOUT)
            found[path.stem] = path
    return found


def _trailing_number(stem: str) -> str | None:
    match = re.search(r"(\d+)$", stem)
    return match.group(1) if match else None


def files_by_number(directory: Path, suffixes: tuple[str, ...] = DEPTH_SUFFIXES) -> dict[str, Path]:
    """The files of `directory` with one of `suffixes`, keyed by the number their stems end with, as frames pair
    by number (rgb_00050.jpg, sync_depth_00050.png: "00050"); stems that end in none are left out."""
    return {n: p for stem, p in _list(Path(directory), suffixes).items() if (n := _trailing_number(stem)) is not None}


def pair_frames(rgb_dir: Path, depth_dir: Path) -> list[tuple[str, Path, Path]]:
    """(key, rgb path, depth path) of every frame, in natural order. Frames pair by file stem; when no stem
    matches, by the number the stem ends with. An RGB image without depth (or the reverse) is an error."""
    rgbs, depths = _list(rgb_dir, RGB_SUFFIXES), _list(depth_dir, DEPTH_SUFFIXES)
    if not rgbs:
        raise dataset_error("No RGB images (.png/.jpg) found", rgb_dir, FOLDER_LAYOUT, FOLDER_SOURCE)
    if not depths:
        raise dataset_error("No depth maps (.png/.npy) found", depth_dir, FOLDER_LAYOUT, FOLDER_SOURCE)
    if not set(rgbs) & set(depths):
        rgbs = _rekey_by_number(rgbs)
        depths = _rekey_by_number(depths)
    missing = sorted(set(rgbs) ^ set(depths), key=natural_key)
    if missing:
        side = [str(rgbs.get(k) or depths.get(k)) for k in missing[:5]]
        raise dataset_error(f"{len(missing)} frame(s) have no RGB/depth partner, e.g. {side}", rgb_dir.parent,
                            FOLDER_LAYOUT)
    return [(k, rgbs[k], depths[k]) for k in sorted(rgbs, key=natural_key)]


def _rekey_by_number(files: dict[str, Path]) -> dict[str, Path]:
    out: dict[str, Path] = {}
    for stem, path in files.items():
        number = _trailing_number(stem)
        if number is None or number in out:
            raise dataset_error("Cannot match frames: stems differ between rgb/ and depth/ and do not end in "
                                "unique numbers, e.g.", path, FOLDER_LAYOUT)
        out[number] = path
    return out


class FolderDataset:
    """A user's folder of RGB-D frames (layout in the module docstring), as Frames sorted by stem.

    Frames are matched by file stem. When no stem matches exactly, frames are matched by the trailing number
    of the stem instead (so BTS-style "rgb_00050.jpg" pairs with "sync_depth_00050.png"). Every RGB image
    must have a depth map and vice versa; anything else is an error rather than a silent skip.

    Args:
      root: the folder holding rgb/ and depth/.
      depth_scale: raw PNG value per metre (required when any depth file is a PNG).
      intrinsics: overrides intrinsics files; otherwise root/intrinsics.txt, else root/intrinsics/<stem>.txt.
      id_prefix: Frame.id = f"{id_prefix}/{stem}"; defaults to "folder/<root name>".
      intrinsics_needed: False when nothing reads the intrinsics (only the LiDAR simulation of
        lipjax.data.sampling does): a folder without them is then no error, and its Frames carry
        UNUSED_INTRINSICS.
      depth_dir: the folder of the Frames' depth: "depth", or SPARSE_DIR for a folder of RGB and sparse depth
        alone (no depth/ needed), whose Frames' depth is their own sparse map: the self-supervised runs of
        lipjax.data.hidden learn from samples hidden from the input.
    """

    def __init__(self, root: str | os.PathLike, depth_scale: float | None = None,
                 intrinsics: Intrinsics | None = None, id_prefix: str | None = None, intrinsics_needed: bool = True,
                 depth_dir: str = "depth"):
        self.root = Path(root)
        rgb_dir, depth_dir = self.root / "rgb", self.root / depth_dir
        for directory in (rgb_dir, depth_dir):
            if not directory.is_dir():
                raise dataset_error("Folder data set directory not found", directory, FOLDER_LAYOUT, FOLDER_SOURCE)
        frames = pair_frames(rgb_dir, depth_dir)
        self.keys = [k for k, _, _ in frames]
        self.rgb_paths = [r for _, r, _ in frames]
        self.depth_paths = [d for _, _, d in frames]
        pngs = [p for p in self.depth_paths if p.suffix.lower() == ".png"]
        if pngs and depth_scale is None:
            raise dataset_error(
                "PNG depth maps need depth_scale (metres = value / scale; KITTI 256, NYU 1000, TUM 5000), e.g.",
                pngs[0], FOLDER_LAYOUT,
            )
        self.depth_scale = depth_scale
        self.intrinsics = intrinsics
        if self.intrinsics is None and (self.root / "intrinsics.txt").is_file():
            self.intrinsics = read_intrinsics_txt(self.root / "intrinsics.txt")
        if self.intrinsics is None and not (self.root / "intrinsics").is_dir():
            if intrinsics_needed:
                raise dataset_error("No intrinsics: pass intrinsics=..., or write intrinsics.txt (fx fy cx cy) or "
                                    "intrinsics/<stem>.txt in", self.root, FOLDER_LAYOUT)
            self.intrinsics = UNUSED_INTRINSICS
        self.id_prefix = id_prefix if id_prefix is not None else f"folder/{self.root.resolve().name}"

    def __len__(self) -> int:
        return len(self.keys)

    def __getitem__(self, index: int) -> Frame:
        key = self.keys[index]
        rgb = read_rgb(self.rgb_paths[index])
        scale = self.depth_scale if self.depth_paths[index].suffix.lower() == ".png" else None
        depth = read_depth(self.depth_paths[index], scale)
        if depth.shape != rgb.shape[:2]:
            raise dataset_error(
                f"RGB {rgb.shape[:2]} and depth {depth.shape} sizes differ for frame {key!r}", self.depth_paths[index]
            )
        intrinsics = self.intrinsics
        if intrinsics is None:
            per_frame = self.root / "intrinsics" / f"{self.rgb_paths[index].stem}.txt"
            if not per_frame.is_file():
                raise dataset_error("Per-frame intrinsics file not found", per_frame, FOLDER_LAYOUT)
            intrinsics = read_intrinsics_txt(per_frame)
        return Frame.from_depth(rgb, depth, intrinsics, f"{self.id_prefix}/{key}")
