"""Named evaluation protocols: the exact crops, resizes and depth ranges each benchmark uses, in one place.

A protocol maps a raw loader Frame to the benchmark's input size and says which ground-truth depths count
in evaluation. Geometry rules shared by every step:

- RGB is resampled with area interpolation when shrinking and bilinear when enlarging (cv2).
- Depth and the valid mask are resampled with NEAREST neighbour using the *same* source pixel for both, so
  an output pixel is either one real measurement or invalid: never a blend of valid and invalid depth.
- Intrinsics follow every crop (Intrinsics.cropped) and resize (Intrinsics.resized, pixel-centre convention;
  the nearest-neighbour index below uses the same convention: output pixel i samples input
  floor((i + 0.5) * in / out)).

Protocols (registry PROTOCOLS):

  nyu_paper          NYU Depth v2, 480x640 -> centre crop 464x580 (rows 8..471, cols 30..609) -> 256x320.
                     The paper: "center-crop and reduce the resolution ... to 256 * 320". 464x580 is the
                     largest centre crop that (a) has the output aspect 0.8 exactly, so the resize is isotropic
                     (one scale 256/464 for x and y, square pixels kept, fx/fy scale alike) and (b) removes the
                     white border the Kinect RGB registration leaves on NYU frames (measured 6-8 px on each side
                     of real NYU frames; a 480x600 crop would keep 6 white rows at top and bottom). Depth 0..10 m.
  nyu_ma             Ma & Karaman / CSPN / NLSPN: resize 480x640 -> 240x320, centre crop 228x304. Depth 0..10 m.
  kitti_paper        KITTI depth completion, bottom crop 256x1216 (the paper drops the LiDAR-free top rows),
                     columns centred. Depth 0..80 m.
  kitti_selection    KITTI depth_selection crop: bottom crop 352x1216, columns centred (the crop of
                     val_selection_cropped). Depth: every GT pixel > 0, no upper cap, as the official devkit.
  tartanair          TartanAir 480x640 -> centre crop 480x600 -> 256x320 (the paper: "down-sample ... to the
                     same size as NYUdepthv2"; cropping the width first keeps the resize isotropic, like
                     nyu_paper). Depth 0..80 m (the paper states no range; the loader already drops sky > 1000 m).
                     Split 90/5/5 by trajectory: `tartanair_split`.
  synthetic_indoor   the embedded procedural data, already 256x320: identity (a no-op resize). Depth 0..10 m.
  synthetic_outdoor  as above, outdoor scenes. Depth 0..80 m.
"""
from __future__ import annotations

import dataclasses
import hashlib
import math
from typing import Any, Protocol as _TypingProtocol, Sequence

import cv2
import numpy as np

from lipjax.data.frame import Frame


class Step(_TypingProtocol):
    """One geometric step of a protocol."""

    def apply(self, frame: Frame) -> Frame: ...

    def apply_to_depth(self, depth: np.ndarray) -> np.ndarray: ...


@dataclasses.dataclass(frozen=True)
class _Crop:
    """Base of the crops: a window of (height, width) whose placement `offsets` defines."""

    height: int
    width: int

    def offsets(self, in_h: int, in_w: int) -> tuple[int, int]:
        raise NotImplementedError

    def _window(self, in_h: int, in_w: int) -> tuple[int, int]:
        if in_h < self.height or in_w < self.width:
            raise ValueError(f"{self} needs an input of at least {self.height}x{self.width}, got {in_h}x{in_w}")
        return self.offsets(in_h, in_w)

    def apply(self, frame: Frame) -> Frame:
        top, left = self._window(*frame.shape)
        rows, cols = slice(top, top + self.height), slice(left, left + self.width)
        return Frame(
            np.ascontiguousarray(frame.rgb[rows, cols]),
            np.ascontiguousarray(frame.depth[rows, cols]),
            np.ascontiguousarray(frame.valid[rows, cols]),
            frame.intrinsics.cropped(top, left),
            frame.id,
        )

    def apply_to_depth(self, depth: np.ndarray) -> np.ndarray:
        top, left = self._window(*depth.shape[:2])
        return np.ascontiguousarray(depth[top : top + self.height, left : left + self.width])


@dataclasses.dataclass(frozen=True)
class CenterCrop(_Crop):
    """Keeps the central (height, width) window; odd margins put the extra pixel at the bottom / right."""

    def offsets(self, in_h: int, in_w: int) -> tuple[int, int]:
        return (in_h - self.height) // 2, (in_w - self.width) // 2


@dataclasses.dataclass(frozen=True)
class BottomCrop(_Crop):
    """Keeps the bottom `height` rows and the central `width` columns (KITTI: the LiDAR sees no sky)."""

    def offsets(self, in_h: int, in_w: int) -> tuple[int, int]:
        return in_h - self.height, (in_w - self.width) // 2


def nearest_indices(in_size: int, out_size: int) -> np.ndarray:
    """Source index of each output pixel for a nearest resize, pixel-centre convention, exact integer maths.

    Output pixel i samples floor((i + 0.5) * in / out); integer arithmetic avoids float ties going either way.
    """
    i = np.arange(out_size, dtype=np.int64)
    return np.minimum(((2 * i + 1) * in_size) // (2 * out_size), in_size - 1)


@dataclasses.dataclass(frozen=True)
class Resize:
    """Resizes to (height, width): RGB area/bilinear, depth and valid mask nearest (same source pixels)."""

    height: int
    width: int

    def apply(self, frame: Frame) -> Frame:
        in_h, in_w = frame.shape
        if (in_h, in_w) == (self.height, self.width):
            return frame
        shrinking = self.height <= in_h and self.width <= in_w
        rgb = cv2.resize(frame.rgb, (self.width, self.height),
                         interpolation=cv2.INTER_AREA if shrinking else cv2.INTER_LINEAR)
        rows, cols = nearest_indices(in_h, self.height), nearest_indices(in_w, self.width)
        return Frame(
            np.ascontiguousarray(rgb),
            np.ascontiguousarray(frame.depth[np.ix_(rows, cols)]),
            np.ascontiguousarray(frame.valid[np.ix_(rows, cols)]),
            frame.intrinsics.resized(self.height / in_h, self.width / in_w),
            frame.id,
        )

    def apply_to_depth(self, depth: np.ndarray) -> np.ndarray:
        in_h, in_w = depth.shape[:2]
        if (in_h, in_w) == (self.height, self.width):
            return depth
        rows, cols = nearest_indices(in_h, self.height), nearest_indices(in_w, self.width)
        return np.ascontiguousarray(depth[np.ix_(rows, cols)])


@dataclasses.dataclass(frozen=True)
class EvalProtocol:
    """A named benchmark protocol.

    Attributes:
      name: registry key.
      steps: geometric steps applied in order to the raw Frame.
      output_size: (H, W) every output has; checked after the steps.
      min_depth_m, max_depth_m: ground truth counts in evaluation where min_depth_m < gt <= max_depth_m
        (and gt is valid). max_depth_m may be math.inf (no cap).
      description: where the numbers come from.
    """

    name: str
    steps: tuple[Step, ...]
    output_size: tuple[int, int]
    min_depth_m: float
    max_depth_m: float
    description: str = ""

    def __call__(self, frame: Frame) -> Frame:
        """Applies the steps; returns a Frame of size output_size, same id, intrinsics transformed."""
        for step in self.steps:
            frame = step.apply(frame)
        if frame.shape != self.output_size:
            raise ValueError(f"protocol {self.name!r} produced {frame.shape} for {frame.id!r}, "
                             f"expected {self.output_size}")
        return frame

    def apply_to_depth(self, depth: np.ndarray) -> np.ndarray:
        """Applies the same geometry (nearest) to another (H, W) depth map of the raw frame, e.g. real LiDAR.

        Crop offsets depend only on the input size, so a map of the frame's size gets exactly the pixels
        the frame's ground truth got.
        """
        for step in self.steps:
            depth = step.apply_to_depth(depth)
        if depth.shape[:2] != self.output_size:
            raise ValueError(f"protocol {self.name!r} produced {depth.shape[:2]}, expected {self.output_size}")
        return depth


# The NYU paper crop: see the module docstring for why 464x580 (aspect 0.8, drops the white border).
NYU_PAPER_CROP = (464, 580)
PAPER_SIZE = (256, 320)
EVAL_MAX_DEPTH_INDOOR_M = 10.0
EVAL_MAX_DEPTH_OUTDOOR_M = 80.0

NYU_PAPER = EvalProtocol(
    "nyu_paper", (CenterCrop(*NYU_PAPER_CROP), Resize(*PAPER_SIZE)), PAPER_SIZE, 0.0, EVAL_MAX_DEPTH_INDOOR_M,
    "NYU v2 480x640 -> centre crop 464x580 (drops the white border, aspect 0.8) -> resize 256x320 (scale 0.5517).",
)
NYU_MA = EvalProtocol(
    "nyu_ma", (Resize(240, 320), CenterCrop(228, 304)), (228, 304), 0.0, EVAL_MAX_DEPTH_INDOOR_M,
    "Ma & Karaman 2018 / CSPN / NLSPN: resize 480x640 -> 240x320, centre crop 228x304.",
)
KITTI_PAPER = EvalProtocol(
    "kitti_paper", (BottomCrop(256, 1216),), (256, 1216), 0.0, EVAL_MAX_DEPTH_OUTDOOR_M,
    "KITTI DC, bottom crop 256x1216 (the paper removes the top rows without LiDAR), columns centred.",
)
KITTI_SELECTION = EvalProtocol(
    "kitti_selection", (BottomCrop(352, 1216),), (352, 1216), 0.0, math.inf,
    "KITTI depth_selection crop 352x1216 (bottom, columns centred); all GT > 0 counts, as the official devkit.",
)
TARTANAIR = EvalProtocol(
    "tartanair", (CenterCrop(480, 600), Resize(*PAPER_SIZE)), PAPER_SIZE, 0.0, EVAL_MAX_DEPTH_OUTDOOR_M,
    "TartanAir 480x640 -> centre crop 480x600 -> resize 256x320 (isotropic 0.5333), the NYU paper size.",
)
SYNTHETIC_INDOOR = EvalProtocol(
    "synthetic_indoor", (Resize(*PAPER_SIZE),), PAPER_SIZE, 0.0, EVAL_MAX_DEPTH_INDOOR_M,
    "Embedded procedural indoor scenes, rendered at 256x320 (identity).",
)
SYNTHETIC_OUTDOOR = EvalProtocol(
    "synthetic_outdoor", (Resize(*PAPER_SIZE),), PAPER_SIZE, 0.0, EVAL_MAX_DEPTH_OUTDOOR_M,
    "Embedded procedural outdoor scenes, rendered at 256x320 (identity).",
)

PROTOCOLS: dict[str, EvalProtocol] = {
    p.name: p
    for p in (NYU_PAPER, NYU_MA, KITTI_PAPER, KITTI_SELECTION, TARTANAIR, SYNTHETIC_INDOOR, SYNTHETIC_OUTDOOR)
}


def get_protocol(name: str) -> EvalProtocol:
    """Looks a protocol up by name, with the list of names in the error."""
    try:
        return PROTOCOLS[name]
    except KeyError:
        raise KeyError(f"unknown protocol {name!r}; known: {sorted(PROTOCOLS)}") from None


# TartanAir split: 90 / 5 / 5 of the frames, whole trajectories only.
TARTANAIR_SPLIT_FRACTIONS = {"train": 0.90, "val": 0.05, "test": 0.05}
TARTANAIR_SPLIT_SALT = "lipjax/tartanair/v1"


def _hash_unit(text: str) -> int:
    return int.from_bytes(hashlib.sha256(text.encode("utf-8")).digest()[:8], "big")


def tartanair_split(trajectories: Sequence[str], frame_counts: Sequence[int] | None = None,
                    fractions: dict[str, float] = TARTANAIR_SPLIT_FRACTIONS,
                    salt: str = TARTANAIR_SPLIT_SALT) -> dict[str, str]:
    """Assigns whole trajectories to splits so that each split gets its fraction of the frames.

    The names are sorted, then ordered by sha256(f"{salt}/{name}") (a fixed pseudo-random order that does
    not depend on the listing order, the process or the platform). Walking that order, a trajectory goes to
    the split whose cumulative-fraction interval contains the midpoint of its frame interval; so the shares
    are as close to `fractions` as whole trajectories allow, and a trajectory is never in two splits.

    Args:
      trajectories: names such as "abandonedfactory/Easy/P000" (unique).
      frame_counts: frames per trajectory (same order); None weighs every trajectory equally.
      fractions: split name -> share, in assignment order; must sum to 1.
    Returns:
      {trajectory name: split name}. Note: adding trajectories can move others; the split is defined for
      the full list of a TartanAir release.
    """
    if len(set(trajectories)) != len(trajectories):
        raise ValueError("trajectory names must be unique")
    if not math.isclose(sum(fractions.values()), 1.0, abs_tol=1e-9):
        raise ValueError(f"split fractions must sum to 1, got {fractions}")
    counts = dict(zip(trajectories, frame_counts)) if frame_counts is not None else {t: 1 for t in trajectories}
    if len(counts) != len(trajectories):
        raise ValueError("frame_counts must have one entry per trajectory")
    order = sorted(sorted(trajectories), key=lambda name: _hash_unit(f"{salt}/{name}"))
    total = float(sum(counts.values()))
    bounds, acc = [], 0.0
    for split, share in fractions.items():
        acc += share
        bounds.append((acc, split))
    assignment, done = {}, 0
    for name in order:
        midpoint = (done + counts[name] / 2.0) / total if total else 0.0
        assignment[name] = next((split for bound, split in bounds if midpoint < bound), bounds[-1][1])
        done += counts[name]
    return assignment


class ProtocolView:
    """An indexable data set seen through a protocol: view[i] = protocol(dataset[i]) (lazy, nothing cached)."""

    def __init__(self, dataset: Any, protocol: "EvalProtocol | str"):
        self.dataset = dataset
        self.protocol = get_protocol(protocol) if isinstance(protocol, str) else protocol

    def __len__(self) -> int:
        return len(self.dataset)

    def __getitem__(self, index: int) -> Frame:
        return self.protocol(self.dataset[index])
