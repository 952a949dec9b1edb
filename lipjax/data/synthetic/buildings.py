"""Buildings along a street: blocks with facades (windows, shop fronts) and roofs, stepped roof slabs and front
yards (hedges, fences, trees) on residential streets, gaps with trees, and a building closing an urban street.
Units: metres."""
from __future__ import annotations

import dataclasses

import numpy as np

from lipjax.data.synthetic.arrays import _set_cols
from lipjax.data.synthetic.colour import _c_any, _c_grey, _c_wall, _c_wood, _hsv, _mix
from lipjax.data.synthetic.constants import _BUILDING, _F32, _FENCE, _VEGETATION
from lipjax.data.synthetic.materials import _Mat
from lipjax.data.synthetic.noise import _hash
from lipjax.data.synthetic.patterns import (
    Pattern,
    _mean_of,
    _p_foliage,
    _p_noise,
    _p_stripes,
    _p_tiles,
    _with_mean,
)
from lipjax.data.synthetic.scene import _Builder
from lipjax.data.synthetic.street import Street
from lipjax.data.synthetic.vegetation import tree


@dataclasses.dataclass(frozen=True)
class BuildingRanges:
    """The buildings of one street style (metres): setback from the sidewalk (one per side), each building's
    length along the street and height, the probability of a gap instead of a building, the lateral jitter of a
    facade (uniform in [0, jitter_m)) and the spacing to the next building."""

    setback_m: tuple[float, float]
    length_m: tuple[float, float]
    height_m: tuple[float, float]
    gap_p: float
    jitter_m: float
    spacing_m: tuple[float, float]


BUILDINGS = {
    "urban": BuildingRanges((0.0, 0.5), (8, 35), (6, 28), 0.15, 1.0, (0.0, 0.3)),
    "residential": BuildingRanges((2.5, 10.0), (7, 14), (4, 9), 0.35, 3.0, (2.0, 8.0)),
    "open": BuildingRanges((15.0, 60.0), (8, 30), (4, 12), 0.6, 3.0, (2.0, 8.0)),
}
# Rows of buildings start this far behind the camera (z, metres).
ROW_START_M = (-30.0, -5.0)


def _p_facade(rng, wall: Pattern, length_u0: float) -> Pattern:
    floor_h = rng.uniform(2.8, 3.6)
    bay = rng.uniform(1.8, 4.0)
    win_w = bay * rng.uniform(0.3, 0.7)
    win_h = floor_h * rng.uniform(0.35, 0.6)
    sill = rng.uniform(0.6, 1.0)
    off = length_u0 + rng.uniform(0, bay)
    ga = _hsv(rng.uniform(0.5, 0.65), rng.uniform(0.05, 0.4), rng.uniform(0.05, 0.25))
    gb = _hsv(rng.uniform(0.5, 0.65), rng.uniform(0.0, 0.25), rng.uniform(0.25, 0.7))
    fc = _c_grey(rng, 0.1, 0.95)
    fw = rng.uniform(0.04, 0.12)
    shop = rng.random() < 0.4
    shop_c = _c_any(rng)
    mullion = win_w > 1.1

    def fn(u, v, fp):
        out = np.array(wall(u, v, fp), dtype=_F32)
        fl = np.floor(v / floor_h)
        vv = v - fl * floor_h
        uo = u - off
        bi = np.floor(uo / bay)
        ub = uo - bi * bay
        uu = ub - (bay - win_w) / 2
        if shop:
            ground = fl == 0
            uu = np.where(ground, ub - 0.25, uu)
            ww = np.where(ground, bay - 0.5, win_w)
            lo = np.where(ground, 0.35, sill)
            hi = np.where(ground, floor_h - 0.6, sill + win_h)
        else:
            ww, lo, hi = win_w, sill, sill + win_h
        glass = (uu > 0) & (uu < ww) & (vv > lo) & (vv < hi)
        frame = (uu > -fw) & (uu < ww + fw) & (vv > lo - fw) & (vv < hi + fw) & ~glass
        if mullion:
            mm = glass & (np.abs(uu - ww * 0.5) < fw * 0.4)
            frame |= mm
            glass &= ~mm
        sel = np.flatnonzero(glass)
        if sel.size:
            g = _hash(bi[sel], fl[sel])  # per window
            grad = (vv[sel] - lo if np.isscalar(lo) else vv[sel] - lo[sel]) / floor_h
            _set_cols(out, sel, _mix(ga, gb, np.minimum(np.maximum(g * 0.8 + grad * 0.6, 0.0), 1.0)))
        _set_cols(out, frame, fc)
        if shop:
            band = (fl == 0) & (vv > floor_h - 0.55) & (vv < floor_h - 0.1)
            _set_cols(out, band, shop_c)
        return out

    return _with_mean(fn, 0.75 * _mean_of(wall) + 0.25 * ga)


def _building_wall(rng) -> Pattern:
    r = rng.random()
    if r < 0.3:
        c = _hsv(rng.uniform(0.0, 0.07), rng.uniform(0.35, 0.7), rng.uniform(0.25, 0.6))
        return _p_tiles(rng, c, _c_grey(rng, 0.4, 0.8), 0.24, 0.075, 0.01, 0.15, 0.5)
    if r < 0.45:
        return _p_tiles(rng, _c_grey(rng, 0.3, 0.85), _c_grey(rng, 0.2, 0.6), rng.uniform(0.5, 1.5),
                        rng.uniform(0.3, 1.0), 0.01, 0.05)
    c = _c_wall(rng) if rng.random() < 0.7 else _c_grey(rng, 0.25, 0.9)
    return _p_noise(rng, c, c * rng.uniform(0.75, 0.95), rng.uniform(0.3, 2.0), 2, rng.uniform(0.4, 1.2))


def _gap(b: _Builder, rng, street: Street, s: int, z: float, setback: float, kinds: list) -> float:
    """A gap between buildings, with a few trees in it (on urban streets, half the time); returns its length."""
    gap = rng.uniform(4, 15)
    if street.style != "urban" or rng.random() < 0.5:
        for _ in range(int(gap // 5)):
            if rng.random() < 0.6:
                tree(b, rng, s * (street.edge + setback + rng.uniform(1, 10)), z + rng.uniform(0, gap), kinds[0])
    return gap


def _roof_slabs(b: _Builder, rng, xb, z, depth, blen, hgt) -> None:
    """One to three tiled slabs stacked on a residential building, each smaller than the one below."""
    rc = _Mat(_p_tiles(rng, _hsv(rng.uniform(0.0, 0.08), rng.uniform(0.2, 0.7), rng.uniform(0.15, 0.5)),
                       _c_grey(rng, 0.05, 0.2), 0.3, 0.2, 0.01, 0.1, 0.5))
    o = rng.uniform(0.2, 0.6)
    y = hgt
    for k in range(int(rng.integers(1, 4))):
        th = rng.uniform(0.3, 0.8)
        shrink = k * rng.uniform(0.8, 1.5)
        b.box((xb, y + th / 2, z + blen / 2), (depth / 2 + o - shrink, th / 2, blen / 2 + o - shrink), _BUILDING, rc)
        y += th


def _front_yard(b: _Builder, rng, street: Street, s: int, z, blen, setback, kinds: list) -> None:
    """A hedge or a fence along the property line (half the time), and a tree in the yard."""
    ev = street.edge
    if rng.random() < 0.5:
        xh = s * (ev + rng.uniform(0.2, 0.8))
        if rng.random() < 0.5:
            hh = rng.uniform(0.6, 1.6)
            b.box((xh, hh / 2, z + blen / 2), (0.35, hh / 2, blen / 2 - 0.3), _VEGETATION, _Mat(_p_foliage(rng)))
        else:
            hh = rng.uniform(0.8, 1.5)
            fc = _c_wood(rng) if rng.random() < 0.5 else _c_grey(rng, 0.3, 0.95)
            b.box((xh, hh / 2, z + blen / 2), (0.03, hh / 2, blen / 2 - 0.3), _FENCE,
                  _Mat(_p_stripes(rng, fc, fc * 0.3, rng.uniform(0.1, 0.25), 0.7, 0.0)))
    if rng.random() < 0.6:
        tree(b, rng, s * (ev + setback * rng.uniform(0.3, 0.8)), z + rng.uniform(0, blen), kinds[-1])


def _building(b: _Builder, rng, street: Street, s: int, z, setback, blen, hgt, kinds: list) -> None:
    """One building of the row on side s (-1 left, 1 right) from z to z + blen, hgt high."""
    depth = rng.uniform(8, 20)
    xb = s * (street.edge + setback + rng.uniform(0, BUILDINGS[street.style].jitter_m))
    wall = _building_wall(rng)
    fac = _Mat(_p_facade(rng, wall, 0.0), spec=0.05)
    roof = _Mat(_p_noise(rng, c := _c_grey(rng, 0.1, 0.5), c * 0.7, 1.0, 2, 0.7))
    mat = _Mat(wall, faces={0: fac, 1: fac, 4: fac, 5: fac, 3: roof})
    b.box((xb + s * depth / 2, hgt / 2, z + blen / 2), (depth / 2, hgt / 2, blen / 2), _BUILDING, mat)
    if street.style == "residential" and rng.random() < 0.8:
        _roof_slabs(b, rng, xb + s * depth / 2, z, depth, blen, hgt)
    if street.style == "residential":
        _front_yard(b, rng, street, s, z, blen, setback, kinds)


def building_rows(b: _Builder, rng, street: Street, kinds: list) -> None:
    """A row of buildings and gaps on each side, from behind the camera to the end of the street; `kinds`: the
    street's tree species (gap trees are of the first, yard trees of the last)."""
    r = BUILDINGS[street.style]
    for s in (-1, 1):
        z = rng.uniform(*ROW_START_M)
        setback = rng.uniform(*r.setback_m)
        while z < street.length:
            blen, hgt = rng.uniform(*r.length_m), rng.uniform(*r.height_m)
            if rng.random() < r.gap_p:
                z += _gap(b, rng, street, s, z, setback, kinds)
                continue
            _building(b, rng, street, s, z, setback, blen, hgt, kinds)
            z += blen + rng.uniform(*r.spacing_m)


def street_end(b: _Builder, rng, street: Street) -> None:
    """Half the urban streets end at a building across them, 10 m past their end."""
    if street.style == "urban" and rng.random() < 0.5:
        wall = _building_wall(rng)
        fac = _Mat(_p_facade(rng, wall, 0.0))
        hgt = rng.uniform(8, 30)
        b.box((rng.uniform(-10, 10), hgt / 2, street.length + 10), (60.0, hgt / 2, 10.0), _BUILDING,
              _Mat(wall, faces={4: fac}))
