"""TartanAir loader (left camera): RGB + rendered depth, split 90/5/5 by trajectory.

Layout (as unzipped from the TartanAir release):

    <root>/<env>/<Easy|Hard>/<Pxxx>/image_left/<frame>_left.png
    <root>/<env>/<Easy|Hard>/<Pxxx>/depth_left/<frame>_left_depth.npy     float32 metres

The loader yields the raw 480x640 frames; apply protocols.TARTANAIR for the paper's 256x320.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from lipjax.data.errors import dataset_error
from lipjax.data.folder import natural_key, read_rgb
from lipjax.data.frame import Frame, Intrinsics
from lipjax.data.protocols import TARTANAIR_SPLIT_FRACTIONS, tartanair_split

# TartanAir's pinhole camera at 480x640 (same for every environment), pixels.
TARTANAIR_INTRINSICS = Intrinsics(fx=320.0, fy=320.0, cx=320.0, cy=240.0)
# The renderer writes the sky / background as very large depths (thousands of metres) rather than 0:
# anything beyond this is not a surface a depth sensor could measure and is marked invalid.
TARTANAIR_MAX_VALID_DEPTH_M = 1000.0
TARTANAIR_DIFFICULTIES = ("Easy", "Hard")

TARTANAIR_LAYOUT = """\
<root>/<env>/<Easy|Hard>/<Pxxx>/image_left/<frame>_left.png
<root>/<env>/<Easy|Hard>/<Pxxx>/depth_left/<frame>_left_depth.npy   (float32 metres)"""
TARTANAIR_SOURCE = "TartanAir (Wang et al., IROS 2020) https://theairlab.org/tartanair-dataset/"


def read_tartanair_depth(path: str | os.PathLike) -> np.ndarray:
    """(H, W) float32 metres; sky / beyond TARTANAIR_MAX_VALID_DEPTH_M / non-finite -> 0 (invalid)."""
    try:
        depth = np.load(path, allow_pickle=False)
    except Exception as exc:  # noqa: BLE001 - any decode failure is one user-facing problem
        raise dataset_error(f"Cannot read TartanAir depth ({type(exc).__name__}: {exc})", path, TARTANAIR_LAYOUT,
                            TARTANAIR_SOURCE) from exc
    if depth.ndim == 3 and depth.shape[2] == 1:
        depth = depth[..., 0]
    if depth.ndim != 2 or not np.issubdtype(depth.dtype, np.floating):
        raise dataset_error(f"TartanAir depth must be float (H, W), got {depth.dtype} {depth.shape}", path,
                            TARTANAIR_LAYOUT)
    depth = depth.astype(np.float32)
    if np.any(depth < 0):
        raise dataset_error("TartanAir depth has negative values", path, TARTANAIR_LAYOUT)
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(depth) & (depth <= TARTANAIR_MAX_VALID_DEPTH_M)
    return np.where(valid, depth, 0).astype(np.float32)


class TartanAirDataset:
    """TartanAir left-camera frames of one split (trajectory-level 90/5/5, protocols.tartanair_split).

    The split is computed over the trajectories found under root (weighted by their frame counts), so use
    the same full download for every split. Frame.id = "tartanair/<env>/<difficulty>/<Pxxx>/<frame>".

    Args:
      root: directory holding the environment folders.
      split: "train", "val", "test" or "all".
      difficulties: subset of ("Easy", "Hard").
    """

    def __init__(self, root: str | os.PathLike, split: str = "train",
                 difficulties: tuple[str, ...] = TARTANAIR_DIFFICULTIES,
                 intrinsics: Intrinsics = TARTANAIR_INTRINSICS):
        root = Path(root)
        if split != "all" and split not in TARTANAIR_SPLIT_FRACTIONS:
            raise ValueError(f"TartanAir split must be one of {sorted(TARTANAIR_SPLIT_FRACTIONS)} or 'all', "
                             f"got {split!r}")
        if not root.is_dir():
            raise dataset_error("TartanAir root not found", root, TARTANAIR_LAYOUT, TARTANAIR_SOURCE)
        trajectories: dict[str, list[str]] = {}
        for difficulty in difficulties:
            # Some release zips unpack to <env>/<env>/<difficulty>/...: accept one extra level.
            for pattern in (f"*/{difficulty}/P*", f"*/*/{difficulty}/P*"):
                for traj_dir in root.glob(pattern):
                    frames = [p.name[: -len("_left.png")] for p in (traj_dir / "image_left").glob("*_left.png")]
                    if frames:
                        trajectories[traj_dir.relative_to(root).as_posix()] = sorted(frames, key=natural_key)
        if not trajectories:
            raise dataset_error("No TartanAir trajectories (<env>/<Easy|Hard>/P*/image_left/*_left.png) under",
                                root, TARTANAIR_LAYOUT, TARTANAIR_SOURCE)
        names = sorted(trajectories, key=natural_key)
        self.assignment = tartanair_split(names, [len(trajectories[n]) for n in names])
        self.root, self.split, self.intrinsics = root, split, intrinsics
        self.frames = [(name, frame) for name in names if split in ("all", self.assignment[name])
                       for frame in trajectories[name]]

    def __len__(self) -> int:
        return len(self.frames)

    def __getitem__(self, index: int) -> Frame:
        trajectory, frame = self.frames[index]
        base = self.root / trajectory
        rgb_path, depth_path = (base / "image_left" / f"{frame}_left.png",
                                base / "depth_left" / f"{frame}_left_depth.npy")
        if not depth_path.is_file():
            raise dataset_error("TartanAir depth file not found", depth_path, TARTANAIR_LAYOUT, TARTANAIR_SOURCE)
        rgb, depth = read_rgb(rgb_path), read_tartanair_depth(depth_path)
        if depth.shape != rgb.shape[:2]:
            raise dataset_error(f"RGB {rgb.shape[:2]} and depth {depth.shape} sizes differ", depth_path,
                                TARTANAIR_LAYOUT)
        return Frame.from_depth(rgb, depth, self.intrinsics, f"tartanair/{trajectory}/{frame}")
