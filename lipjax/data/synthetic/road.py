"""The ground of a street (asphalt with lane markings, tyre tracks, patches and a crosswalk; grass or paving
beyond) and its raised sidewalks. Units: metres."""
from __future__ import annotations

import numpy as np

from lipjax.data.synthetic.arrays import _cols, _set_cols
from lipjax.data.synthetic.colour import _c_grey, _hsv
from lipjax.data.synthetic.constants import _F32, _ROAD, _SIDEWALK
from lipjax.data.synthetic.materials import _Mat
from lipjax.data.synthetic.noise import _frac, _square, _vnoise
from lipjax.data.synthetic.patterns import Pattern, _p_noise, _p_solid, _p_tiles, _with_mean
from lipjax.data.synthetic.primitives import _Ground
from lipjax.data.synthetic.scene import _Builder
from lipjax.data.synthetic.street import Street

# Sidewalks start this far behind the camera (z, metres).
SIDEWALK_START_M = -30.0


def _lane_marks(rng, street: Street, paint_w, paint_y) -> list[tuple]:
    """(x centre, width, dash period (0 = solid), dash duty, colour) of each line painted on the road."""
    marks = []
    centre_solid = rng.random() < 0.3
    marks.append((0.0, rng.uniform(0.1, 0.2), 0.0 if centre_solid else rng.uniform(6, 12), rng.uniform(0.3, 0.5),
                  paint_y if rng.random() < 0.2 else paint_w))
    for s in (-1, 1):
        for k in range(1, street.lanes):
            marks.append((s * k * street.lane_width, 0.12, rng.uniform(6, 12), rng.uniform(0.25, 0.5), paint_w))
        if street.parking > 0 or rng.random() < 0.6:
            marks.append((s * street.lanes * street.lane_width, 0.15, 0.0, 1.0, paint_w))
    if rng.random() < 0.3 * (street.style != "residential"):
        marks = marks[:1] if rng.random() < 0.5 else []
    return marks


def _terrain(rng, style: str) -> Pattern:
    """Beyond the road: grass, or (on most urban streets) paving."""
    terrain_kind = rng.random()
    grass = _p_noise(rng, _hsv(rng.uniform(0.13, 0.28), rng.uniform(0.3, 0.7), rng.uniform(0.15, 0.35)),
                     _hsv(rng.uniform(0.1, 0.25), rng.uniform(0.2, 0.6), rng.uniform(0.3, 0.55)),
                     rng.uniform(0.5, 3), 2,
                     1.2)
    pave = _p_tiles(rng, _c_grey(rng, 0.35, 0.7), _c_grey(rng, 0.2, 0.5), rng.uniform(0.3, 1.0),
                    rng.uniform(0.3, 1.0), 0.01, 0.1)
    return grass if (style != "urban" or terrain_kind < 0.3) else pave


def road(b: _Builder, rng, street: Street) -> None:
    """The ground plane: its pattern gets world (x, z) and paints the road within |x| <= half width, terrain
    beyond (the renderer labels that part terrain: Scene.terrain_x)."""
    asphalt = _hsv(rng.uniform(0.0, 0.7), rng.uniform(0.0, 0.06), rng.uniform(0.18, 0.42))
    paint_w = _c_grey(rng, 0.75, 0.95)
    paint_y = _hsv(0.12, 0.7, 0.85)
    marks = _lane_marks(rng, street, paint_w, paint_y)
    crosswalk = rng.uniform(8, 40) if rng.random() < 0.25 else None
    terrain = _terrain(rng, street.style)
    ox, oz = rng.uniform(0, 256, 2)
    patchy = rng.uniform(0.0, 0.5)
    half, lane_w = street.half_width, street.lane_width

    def ground(x, z, fp):
        col = np.empty((3, x.shape[0]), _F32)
        ax = np.abs(x)
        out = np.flatnonzero(ax > half)
        if out.size:
            _set_cols(col, out, terrain(x.take(out), z.take(out), fp.take(out)))
        road = np.flatnonzero(ax <= half)
        if road.size == 0:
            return col
        x, z, fp, ax = x.take(road), z.take(road), fp.take(road), ax.take(road)
        n = _vnoise(x * 4.0 + ox, z * 4.0 + oz)
        n = 0.5 + (n - 0.5) * np.minimum(np.maximum(1.5 - 8.0 * fp, 0.0), 1.0)
        n2 = _vnoise(x * 0.25 + oz, z * 0.1 + ox)
        shade = (0.8 + 0.4 * n) * np.where(n2 > 0.6, 1.0 - 0.4 * patchy, 1.0).astype(_F32)
        lanepos = _frac(ax * (1.0 / lane_w))  # tyre tracks: slightly darker bands along the lanes
        shade[(np.abs(lanepos - 0.25) < 0.08) | (np.abs(lanepos - 0.75) < 0.08)] *= 0.94
        rc = asphalt * shade
        for xc, w, period, duty, c in marks:  # only the pixels near each line
            near = np.flatnonzero(np.abs(x - xc) < w / 2 + fp)
            if near.size == 0:
                continue
            fpn = fp[near]
            m = np.minimum(np.maximum(0.5 + (w / 2 - np.abs(x[near] - xc)) / (fpn + 1e-4), 0.0), 1.0)
            if period:
                m *= _square(z[near] + xc, period, duty, fpn)
            m *= 0.6 + 0.4 * n[near]  # worn paint
            old = _cols(rc, near)
            _set_cols(rc, near, old + (c - old) * m)
        if crosswalk is not None:
            near = np.flatnonzero((z > crosswalk) & (z < crosswalk + 3.0))
            if near.size:
                m = _square(x[near], 1.0, 0.5, fp[near]) * (0.6 + 0.4 * n[near])
                old = _cols(rc, near)
                _set_cols(rc, near, old + (paint_w - old) * m)
        _set_cols(col, road, rc)
        return col

    _with_mean(ground, asphalt)
    b.prims.append(_Ground(np.array([_ROAD, _ROAD, _ROAD, _ROAD, _ROAD, _ROAD], np.int8), _Mat(ground)))


def sidewalks(b: _Builder, rng, street: Street) -> None:
    """Paved sidewalks raised by the curb on both sides, from behind the camera to the end of the street."""
    if street.sidewalk <= 0:
        return
    half, sw, curb, z0 = street.half_width, street.sidewalk, street.curb, SIDEWALK_START_M
    side = _p_tiles(rng, _c_grey(rng, 0.35, 0.75), _c_grey(rng, 0.2, 0.55), rng.uniform(0.3, 1.5),
                    rng.uniform(0.3, 1.5), 0.008, 0.08)
    curb_m = _Mat(_p_solid(rng, _c_grey(rng, 0.4, 0.8), 0.05))
    for s in (-1, 1):
        mat = _Mat(side, faces={0 if s > 0 else 1: curb_m})
        L = street.length + 30.0
        b.box((s * (half + sw / 2), curb / 2, z0 + L / 2), (sw / 2, curb / 2, L / 2), _SIDEWALK, mat, cast=False)
