"""The scene description (`Scene`, `Light`), the camera rotation and the primitive `_Builder`."""
from __future__ import annotations

import dataclasses
import math
from typing import Callable

import numpy as np

from lipjax.data.synthetic.constants import _F32
from lipjax.data.synthetic.geometry import _rot_y
from lipjax.data.synthetic.primitives import _Box, _Cyl, _Prim, _Spheres


@dataclasses.dataclass
class Light:
    color: np.ndarray  # (3,) linear, intensity included
    direction: tuple | None = None  # unit vector towards a directional light
    position: tuple | None = None  # point light
    r0: float = 3.0  # point light falloff radius: 1 / (1 + d^2 / r0^2)
    shadow_blur: int = 1


@dataclasses.dataclass
class Scene:
    prims: list
    cam_pos: np.ndarray
    cam_R: np.ndarray  # camera-to-world rotation
    lights: list
    ambient: np.ndarray  # (3,) linear
    ambient_up: float  # hemispheric ambient: ambient * (1 + ambient_up * n_y)
    extent: float  # bound on scene size (metres), for shadow volumes
    sky: Callable | None = None  # (dx, dy, dz) unit world directions -> (3, n) radiance
    haze_dist: float = 0.0
    haze_color: np.ndarray | None = None
    max_depth: float = np.inf
    terrain_x: float | None = None  # outdoor: ground with |x| beyond this is labelled terrain, not road
    shadow_range: float = np.inf  # objects farther than this (Chebyshev distance, metres) cast no shadow
    # camera model
    exposure: float = 0.2  # target mean linear luminance
    wb: np.ndarray = dataclasses.field(default_factory=lambda: np.ones(3, _F32))
    blur: float = 0.1
    noise_read: float = 0.005
    noise_shot: float = 0.01
    vignette: float = 0.2
    gamma: float = 2.2


def _camera_rotation(yaw: float, pitch: float, roll: float) -> np.ndarray:
    """Camera-to-world rotation (world y up). yaw about world y (positive turns right, towards +x), pitch
    positive = looking up, roll about the optical axis."""
    f = np.array([math.cos(pitch) * math.sin(yaw), math.sin(pitch), math.cos(pitch) * math.cos(yaw)])
    up = np.array([0.0, 1.0, 0.0])
    right = np.cross(up, f)
    right /= np.linalg.norm(right)
    down = np.cross(right, f)
    cr, sr = math.cos(roll), math.sin(roll)
    r2 = cr * right + sr * down
    d2 = -sr * right + cr * down
    return np.stack([r2, d2, f], axis=1)


class _Builder:
    """Collects primitives; group transforms place parts given in a local frame (x right, y up, z back,
    front faces towards -z) at floor position (gx, gz) with yaw."""

    def __init__(self, rng):
        self.rng = rng
        self.prims: list[_Prim] = []
        self._asm = None
        self._next_asm = 0

    def assembly(self) -> "_Builder":
        """`with b.assembly():` groups the primitives made inside into one shadow caster (one cull)."""
        return self

    def __enter__(self):
        self._asm = self._fresh()

    def __exit__(self, *exc):
        self._asm = None

    def _fresh(self) -> int:
        self._next_asm += 1
        return self._next_asm

    def _add(self, p):
        p.asm = self._asm if self._asm is not None else self._fresh()
        self.prims.append(p)
        return p

    @staticmethod
    def place(group, lx, ly, lz):
        if group is None:
            return lx, ly, lz
        gx, gz, yaw = group
        c, s = math.cos(yaw), math.sin(yaw)
        return gx + c * lx + s * lz, ly, gz - s * lx + c * lz

    @staticmethod
    def _R(group, yaw, R):
        a = (group[2] if group else 0.0) + yaw
        if R is not None:
            return _rot_y(a) @ R if a else R
        return _rot_y(a) if a else None

    def box(self, center, half, label, mat, yaw=0.0, group=None, cast=True, R=None):
        return self._add(_Box(self.place(group, *center), half, label, mat, self._R(group, yaw, R), cast=cast))

    def cyl(self, center, r, h, label, mat, yaw=0.0, group=None, cast=True, R=None):
        return self._add(_Cyl(self.place(group, *center), r, h, label, mat, self._R(group, yaw, R), cast=cast))

    def spheres(self, centres, radii, label, mat, group=None, cast=True):
        cs = [self.place(group, *c) for c in centres]
        return self._add(_Spheres(cs, radii, label, mat, cast=cast))
