"""The one data type every loader yields, and batching of frames into arrays.

Units: depth in metres everywhere (0 = invalid / no measurement); intrinsics in pixels.
"""
from __future__ import annotations

import dataclasses

import numpy as np


@dataclasses.dataclass(frozen=True)
class Intrinsics:
    """Pinhole camera intrinsics in pixels (origin at the top-left pixel's corner convention of OpenCV)."""

    fx: float
    fy: float
    cx: float
    cy: float

    def cropped(self, top: int, left: int) -> "Intrinsics":
        """Intrinsics after cropping `top` rows and `left` columns away."""
        return Intrinsics(self.fx, self.fy, self.cx - left, self.cy - top)

    def resized(self, scale_y: float, scale_x: float) -> "Intrinsics":
        """Intrinsics after resizing by (scale_y, scale_x) = (new_h / old_h, new_w / old_w).

        Uses the pixel-centre convention: a point at continuous coordinate c maps to (c + 0.5) * s - 0.5.
        """
        return Intrinsics(
            self.fx * scale_x,
            self.fy * scale_y,
            (self.cx + 0.5) * scale_x - 0.5,
            (self.cy + 0.5) * scale_y - 0.5,
        )


@dataclasses.dataclass(frozen=True)
class Frame:
    """One RGB-D frame.

    Attributes:
      rgb: (H, W, 3) uint8.
      depth: (H, W) float32 ground-truth depth in metres; 0 where invalid.
      valid: (H, W) bool, True where `depth` is a trusted measurement (depth > 0 and finite).
      intrinsics: camera intrinsics of this (possibly cropped / resized) frame.
      id: a stable identifier, e.g. "nyu/val/bedroom_0001/00042"; sparse samplers derive their key from it.
    """

    rgb: np.ndarray
    depth: np.ndarray
    valid: np.ndarray
    intrinsics: Intrinsics
    id: str

    def __post_init__(self):
        if self.rgb.dtype != np.uint8 or self.rgb.ndim != 3 or self.rgb.shape[2] != 3:
            raise ValueError(f"Frame {self.id!r}: rgb must be uint8 (H, W, 3), got {self.rgb.dtype} {self.rgb.shape}")
        if self.depth.dtype != np.float32 or self.depth.shape != self.rgb.shape[:2]:
            raise ValueError(
                f"Frame {self.id!r}: depth must be float32 (H, W) = {self.rgb.shape[:2]} in metres, "
                f"got {self.depth.dtype} {self.depth.shape}"
            )
        if self.valid.dtype != np.bool_ or self.valid.shape != self.depth.shape:
            raise ValueError(f"Frame {self.id!r}: valid must be bool {self.depth.shape}, "
                             f"got {self.valid.dtype} {self.valid.shape}")

    @classmethod
    def from_depth(cls, rgb: np.ndarray, depth: np.ndarray, intrinsics: Intrinsics, id: str) -> "Frame":
        """Builds a Frame, deriving `valid` from depth (> 0 and finite) and zeroing invalid depth."""
        depth = np.asarray(depth, dtype=np.float32)
        valid = np.isfinite(depth) & (depth > 0)
        return cls(np.ascontiguousarray(rgb, dtype=np.uint8), np.where(valid, depth, 0).astype(np.float32), valid,
                   intrinsics, id)

    @property
    def shape(self) -> tuple[int, int]:
        return self.depth.shape  # type: ignore[return-value]


@dataclasses.dataclass(frozen=True)
class Batch:
    """A batch of model inputs and targets, as numpy arrays (moved to devices by the pipeline).

    Attributes:
      rgb: (B, H, W, 3) uint8.
      sparse: (B, H, W) float32 sparse input depth in metres, 0 = no sample.
      gt: (B, H, W) float32 ground-truth depth in metres, 0 = invalid.
      gt_valid: (B, H, W) bool.
      z0: (B, H, W) float32 metres or None: a host-computed initial estimate, for models that need one
        (LIPConfig.host_inputs); added by the training loop after cropping.
    """

    rgb: np.ndarray
    sparse: np.ndarray
    gt: np.ndarray
    gt_valid: np.ndarray
    z0: np.ndarray | None = None

    def as_dict(self) -> dict[str, np.ndarray]:
        """The arrays of the batch (z0 only when present)."""
        return {k: v for k, v in dataclasses.asdict(self).items() if v is not None}
