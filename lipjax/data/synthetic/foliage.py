"""Porous foliage, on request: tree crowns and bushes as clumps of leaves with sky and street between them.

The rendered crowns and bushes are a few smooth spheres each: solid blobs whose depth is one smooth surface. Real
foliage is porous: a LiDAR scan or an accumulated depth map of a tree holds returns from the near leaves, the far
side of the crown, the trunk and whatever stands behind, side by side (KITTI's streets are lined with trees).
`porous_foliage(scene, rng)` replaces each foliage sphere of radius R (label _VEGETATION, R >= `min_radius_m`) by
n clumps of radius at most a R, their centres uniform in the ball of radius (1 - a) R: every clump lies inside the
sphere, so the crown keeps its outline and nothing comes nearer than the solid crown was. A ray through the crown's
middle meets on average about (3/2) n (r / ((1 - a) R))^2 clumps of radius r (0.3 to 14 over the ranges) and, with
probability about exp of minus that, none: sky, trunk or street behind. Draws come from `rng` alone, after the
scene is built: the same street, its trees see-through. Units: metres.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from lipjax.data.synthetic.constants import _VEGETATION
from lipjax.data.synthetic.primitives import _Spheres
from lipjax.data.synthetic.scene import Scene


@dataclasses.dataclass(frozen=True)
class FoliageRanges:
    """Clumps per foliage sphere ([low, high)), their radius as a fraction of the sphere's, and the smallest
    sphere made porous (metres; smaller ones, a potted plant's leaves, stay as they are)."""

    clumps: tuple[int, int] = (20, 50)
    clump_fraction: tuple[float, float] = (0.15, 0.3)
    min_radius_m: float = 0.3


FOLIAGE = FoliageRanges()


def _clumps(rng, centre: np.ndarray, radius: float, r: FoliageRanges) -> tuple[np.ndarray, np.ndarray]:
    n = int(rng.integers(*r.clumps))
    a = rng.uniform(*r.clump_fraction)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    reach = (1.0 - a) * radius * rng.random(n) ** (1.0 / 3.0)  # uniform in the ball
    radii = a * radius * rng.uniform(0.6, 1.0, n)  # inside the sphere
    return centre + reach[:, None] * d, radii


def porous_foliage(scene: Scene, rng: np.random.Generator, ranges: FoliageRanges = FOLIAGE) -> Scene:
    """`scene` with every foliage sphere of radius >= ranges.min_radius_m replaced by clumps of leaves (same
    material, label, shadow group)."""
    prims = []
    for p in scene.prims:
        if not (isinstance(p, _Spheres) and np.all(p.label == _VEGETATION)) or not (p.rs >= ranges.min_radius_m).any():
            prims.append(p)
            continue
        pieces = [_clumps(rng, c, radius, ranges) if radius >= ranges.min_radius_m else (c[None], np.array([radius]))
                  for c, radius in zip(p.cs.astype(np.float64), p.rs.astype(np.float64))]
        q = _Spheres(np.concatenate([c for c, _ in pieces]), np.concatenate([r for _, r in pieces]), p.label, p.mat,
                     cast=p.cast)
        q.asm = p.asm
        prims.append(q)
    return dataclasses.replace(scene, prims=prims)
