"""Clutter for rooms, on request: things of many sizes on the floor where the camera looks.

The rendered rooms are tidy (furniture along the walls, a few things on its tops, open floor); photographed rooms
are not (boxes, bags, bins, chairs and toys on the floor, close to the camera), and real rooms have about 1.7x the
renders' depth-edge pixels (research/README.md, edge_statistics; docs/decisions/0010-clutter-in-training-rooms.md).
`add_clutter(scene, rng)` adds `ClutterRanges.objects` things to a built room, each on the floor at a distance and
bearing drawn inside the camera's horizontal view: boxes (some stacked), cylinders (bins, buckets, stools), balls, and
the tabletop things of `furniture._small_object` scaled up. Its draws come from `rng` alone, after the room is built,
so a room with clutter is the same room with more in it. Units: metres and radians.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from lipjax.data.synthetic.colour import _c_any, _c_grey
from lipjax.data.synthetic.constants import _OBJECT
from lipjax.data.synthetic.furniture import _small_object
from lipjax.data.synthetic.materials import _Mat
from lipjax.data.synthetic.patterns import _p_noise, _p_solid, _p_stripes
from lipjax.data.synthetic.primitives import _Box
from lipjax.data.synthetic.scene import Scene, _Builder


@dataclasses.dataclass(frozen=True)
class ClutterRanges:
    """How many things ([low, high)), where (metres from the camera along the floor; bearing within +-half_view
    radians of the view direction; at least wall_gap_m from the walls) and how big (half-size, metres, at most
    near_fraction of the distance, so that nothing fills the view)."""

    objects: tuple[int, int] = (6, 31)
    distance_m: tuple[float, float] = (0.7, 5.0)
    half_view: float = 0.55
    wall_gap_m: float = 0.15
    half_size_m: tuple[float, float] = (0.04, 0.45)
    near_fraction: float = 0.35


CLUTTER = ClutterRanges()


def _material(rng) -> _Mat:
    """Plain, speckled or striped, matte or glossy."""
    r = rng.random()
    if r < 0.6:
        pattern = _p_solid(rng, _c_any(rng), 0.05)
    elif r < 0.8:
        pattern = _p_noise(rng, _c_any(rng), _c_grey(rng), rng.uniform(2.0, 20.0))
    else:
        pattern = _p_stripes(rng, _c_any(rng), _c_any(rng), rng.uniform(0.03, 0.3), angle=rng.uniform(0, math.pi))
    return _Mat(pattern, spec=rng.choice([0.0, 0.0, 0.1, 0.3]), shin=rng.uniform(10, 80))


def _thing(b: _Builder, rng, x: float, z: float, half: float) -> None:
    """One thing standing on the floor at (x, z), about `half` metres in half-size."""
    r = rng.random()
    yaw = rng.uniform(-math.pi, math.pi)
    if r < 0.45:  # a box, or a stack of two or three
        y = 0.0
        for _ in range(int(rng.choice([1, 1, 2, 3]))):
            hx, hy, hz = half * rng.uniform(0.5, 1.0, 3)
            b.box((x, y + hy, z), (hx, hy, hz), _OBJECT, _material(rng), yaw + rng.uniform(-0.3, 0.3))
            y += 2 * hy
            half *= rng.uniform(0.6, 0.95)
    elif r < 0.7:  # a bin, bucket, stool or pot
        rad, hh = half * rng.uniform(0.4, 1.0), half * rng.uniform(0.5, 1.6)
        b.cyl((x, hh, z), rad, hh, _OBJECT, _material(rng))
    elif r < 0.85:  # a ball
        rad = half * rng.uniform(0.3, 0.8)
        b.spheres([(x, rad, z)], [rad], _OBJECT, _material(rng))
    else:  # the things of a tabletop, on the floor
        for _ in range(int(rng.integers(1, 4))):
            _small_object(b, rng, x + rng.uniform(-half, half), 0.0, z + rng.uniform(-half, half), None,
                          max(0.35, 2 * half))  # (its books need 0.12 m)


def add_clutter(scene: Scene, rng: np.random.Generator, ranges: ClutterRanges = CLUTTER) -> Scene:
    """`scene` (a room: its shell is an inside box) with things on its floor where the camera looks."""
    shell = next((p for p in scene.prims if isinstance(p, _Box) and p.inside), None)
    if shell is None:
        raise ValueError("add_clutter needs a room (a scene with an inside box, lipjax.data.synthetic.indoor)")
    (cx, _, cz), (hx, _, hz) = shell.c, shell.h
    b = _Builder(rng)
    b._next_asm = max((p.asm for p in scene.prims), default=0) + 1  # shadow-culling groups of their own
    forward = scene.cam_R[:, 2]
    bearing0 = math.atan2(forward[0], forward[2])
    for _ in range(int(rng.integers(*ranges.objects))):
        t = rng.uniform(*ranges.distance_m)
        bearing = bearing0 + rng.uniform(-ranges.half_view, ranges.half_view)
        half = min(rng.uniform(*ranges.half_size_m), ranges.near_fraction * t)
        margin = ranges.wall_gap_m + half
        x = float(np.clip(scene.cam_pos[0] + t * math.sin(bearing), cx - hx + margin, cx + hx - margin))
        z = float(np.clip(scene.cam_pos[2] + t * math.cos(bearing), cz - hz + margin, cz + hz - margin))
        _thing(b, rng, x, z, half)
    return dataclasses.replace(scene, prims=list(scene.prims) + b.prims)
