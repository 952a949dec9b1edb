"""The outdoor scene builder: a street with buildings, cars, trees, street furniture, people, sky and sun.

Also the patterns only streets use (facades, car ends, glazing).
"""
from __future__ import annotations

import math

import numpy as np

from lipjax.data.synthetic.arrays import _cols, _set_cols
from lipjax.data.synthetic.camera import _camera_model
from lipjax.data.synthetic.colour import (
    _c_any,
    _c_fabric,
    _c_grey,
    _c_wall,
    _c_wood,
    _hsv,
    _mix,
)
from lipjax.data.synthetic.constants import (
    _BUILDING,
    _F32,
    _FENCE,
    _PERSON,
    _POLE,
    _ROAD,
    _SIDEWALK,
    _TERRAIN,
    _VEGETATION,
    _VEHICLE,
    RENDER_FAR_CLIP_M,
)
from lipjax.data.synthetic.geometry import _rot_z
from lipjax.data.synthetic.materials import _Decal, _Mat
from lipjax.data.synthetic.noise import _box, _fbm, _frac, _hash, _square, _vnoise
from lipjax.data.synthetic.patterns import (
    Pattern,
    _mean_of,
    _p_foliage,
    _p_noise,
    _p_poster,
    _p_solid,
    _p_stripes,
    _p_tiles,
    _with_mean,
)
from lipjax.data.synthetic.primitives import _Ground
from lipjax.data.synthetic.scene import _Builder, _camera_rotation, Light, Scene


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


def _p_car_end(rng, paint_c, W, body_h, rear: bool) -> Pattern:
    """A car's rear (tail lights, plate, bumper) or front (headlights, grille, plate) face."""
    lamp = _hsv(0.0, 0.85, rng.uniform(0.4, 0.8)) if rear else _c_grey(rng, 0.6, 0.9)
    plate_c = _c_grey(rng, 0.8, 0.95)
    dark = _c_grey(rng, 0.01, 0.08)
    lw = rng.uniform(0.2, 0.35)
    l0, l1 = body_h * rng.uniform(0.45, 0.6), body_h * rng.uniform(0.75, 0.9)

    def fn(u, v, fp):
        out = np.empty((3, u.shape[0]), _F32)
        out[:] = paint_c
        _set_cols(out, v < body_h * 0.15, dark)  # bumper / shadowed underside
        du = np.abs(u - W / 2)
        if not rear:
            _set_cols(out, (du < W / 2 - lw - 0.1) & (v > body_h * 0.35) & (v < l1), dark)  # grille
        _set_cols(out, (v > l0) & (v < l1) & (du > W / 2 - lw - 0.04) & (du < W / 2 - 0.04), lamp)
        _set_cols(out, (du < 0.26) & (v > body_h * 0.2) & (v < body_h * 0.2 + 0.11), plate_c)
        return out

    return _with_mean(fn, paint_c)


def _p_glazed(frame_c, glass: Pattern, u0, v0, u1, v1, pillar=None) -> Pattern:
    """Glass in [u0, u1) x [v0, v1) of a face, frame colour around it, an optional pillar at u = pillar."""

    def fn(u, v, fp):
        out = np.empty((3, u.shape[0]), _F32)
        out[:] = frame_c
        m = _box(u, v, u0, v0, u1, v1)
        if pillar is not None:
            m &= np.abs(u - pillar) > 0.05
        sel = np.flatnonzero(m)
        if sel.size:
            _set_cols(out, sel, glass(u[sel], v[sel], fp[sel]))
        return out

    return _with_mean(fn, 0.5 * (frame_c + _mean_of(glass)))


def _car_kit(rng) -> dict:
    """Materials all cars of a scene share (tyres, rims, undersides): evaluated once per frame."""
    rim = _Mat(_p_solid(rng, _c_grey(rng, 0.3, 0.7), 0.0))
    return {"dark": _Mat(_p_solid(rng, _c_grey(rng, 0.01, 0.06), 0.0)),
            "tyre": _Mat(_p_solid(rng, _c_grey(rng, 0.02, 0.06), 0.0), faces={3: rim, 2: rim})}


def _car(b: _Builder, rng, x, z, yaw, kit, detail=True):
    with b.assembly():
        _car_parts(b, rng, x, z, yaw, kit, detail)


def _car_parts(b: _Builder, rng, x, z, yaw, kit, detail):
    L = rng.uniform(3.8, 4.9)
    W = rng.uniform(1.65, 1.9)
    kind = rng.random()
    body_h = rng.uniform(0.55, 0.75) if kind < 0.75 else rng.uniform(0.8, 1.1)
    cab_h = rng.uniform(0.42, 0.55) if kind < 0.75 else rng.uniform(0.5, 0.8)
    clear = rng.uniform(0.22, 0.35)
    col = _c_grey(rng, 0.02, 0.9) if rng.random() < 0.65 else _hsv(rng.random(), rng.uniform(0.5, 0.9),
                                                                   rng.uniform(0.2, 0.8))
    paint = _p_solid(rng, col, 0.01)
    g = _hsv(rng.uniform(0.5, 0.65), rng.uniform(0.0, 0.3), rng.uniform(0.03, 0.12))
    g2 = g * rng.uniform(1.5, 3.0)

    def glass(u, v, fp):  # darker towards the bottom: a cheap stand-in for reflections
        return _mix(g, g2, np.minimum(v * (1.0 / cab_h), 1.0))

    _with_mean(glass, 0.5 * (g + g2))
    spec, shin = rng.uniform(0.2, 0.6), rng.uniform(30, 90)
    dark = kit["dark"]
    # local -z (face 4) is the rear, +z (face 5) the front: a car with yaw 0 drives away from the camera
    body = _Mat(paint, spec=spec, shin=shin, faces={
        2: dark, 4: _Mat(_p_car_end(rng, col, W, body_h, True), spec=spec, shin=shin),
        5: _Mat(_p_car_end(rng, col, W, body_h, False), spec=spec, shin=shin)})
    group = (x, z, yaw)
    b.box((0, clear + body_h / 2, 0), (W / 2, body_h / 2, L / 2), _VEHICLE, body, group=group)
    cl = L * rng.uniform(0.45, 0.6) if kind < 0.75 else L * rng.uniform(0.55, 0.8)
    cz = rng.uniform(0.0, 0.12) * L
    m = 0.07
    side = _Mat(_p_glazed(col, glass, m, 0.03, cl - m, cab_h - m, cl * rng.uniform(0.45, 0.55)), spec=0.6, shin=80)
    end = _Mat(_p_glazed(col, glass, m, 0.02, W * 0.9 - m, cab_h - m), spec=0.6, shin=80)
    cab = _Mat(paint, spec=spec, shin=shin, faces={0: side, 1: side, 4: end, 5: end})
    b.box((0, clear + body_h + cab_h / 2, cz), (W * 0.45, cab_h / 2, cl / 2), _VEHICLE, cab, group=group)
    if detail:  # wheels: one cylinder per axle, visible below the body
        wr = rng.uniform(0.3, 0.36)
        tyre = kit["tyre"]
        axle_R = _rot_z(math.pi / 2)
        for sz in (-1, 1):
            b.cyl((0, wr, sz * (L / 2 - 0.8)), wr, W / 2 - 0.02, _VEHICLE, tyre, group=group, R=axle_R, cast=False)


def _species(rng) -> tuple:
    """A tree species: bark and foliage materials, trunk height and crown size ranges (shared by the trees
    of a street, as on real streets)."""
    bark = _Mat(_p_noise(rng, c := _hsv(rng.uniform(0.05, 0.12), rng.uniform(0.15, 0.5), rng.uniform(0.12, 0.4)),
                         c * 0.6, 6.0, 1, 1.2, stretch=0.2))
    return bark, _Mat(_p_foliage(rng)), rng.uniform(1.5, 3.5), rng.uniform(1.0, 2.6)


def _tree(b: _Builder, rng, x, z, species, scale=1.0):
    with b.assembly():
        _tree_parts(b, rng, x, z, species, scale)


def _tree_parts(b: _Builder, rng, x, z, species, scale):
    bark, leaves, trunk, crown = species
    th = trunk * rng.uniform(0.8, 1.2) * scale
    tr = rng.uniform(0.08, 0.2) * scale * crown / 1.8
    b.cyl((x, th / 2, z), tr, th / 2, _VEGETATION, bark)
    cr = crown * rng.uniform(0.8, 1.2) * scale
    n = int(rng.integers(3, 7)) if z < 40 else int(rng.integers(2, 4))  # fewer, bigger blobs far away
    k = 0.7 if z < 40 else 0.85
    cs = [(x + rng.normal(0, cr * 0.45), th + cr * rng.uniform(0.4, 1.4), z + rng.normal(0, cr * 0.45))
          for _ in range(n)]
    b.spheres(cs, rng.uniform(0.5, 1.0, n) * cr * k, _VEGETATION, leaves)


def outdoor_scene(rng) -> Scene:
    b = _Builder(rng)
    style = ["urban", "residential", "open"][int(rng.choice(3, p=[0.4, 0.4, 0.2]))]
    lanes = int(rng.integers(1, 3)) if style != "residential" else 1
    lane_w = rng.uniform(2.9, 3.7)
    park = rng.uniform(2.0, 2.5) if (style != "open" and rng.random() < 0.75) else 0.0
    half = lanes * lane_w + park
    sw = rng.uniform(1.5, 4.0) if style != "open" else 0.0
    curb = rng.uniform(0.08, 0.18)
    z_end = rng.uniform(70.0, 250.0)

    # Ground: asphalt with markings; terrain beyond the road / sidewalks.
    asphalt = _hsv(rng.uniform(0.0, 0.7), rng.uniform(0.0, 0.06), rng.uniform(0.18, 0.42))
    paint_w = _c_grey(rng, 0.75, 0.95)
    paint_y = _hsv(0.12, 0.7, 0.85)
    marks = []  # (x centre, width, dash period (0 = solid), dash duty, colour)
    centre_solid = rng.random() < 0.3
    marks.append((0.0, rng.uniform(0.1, 0.2), 0.0 if centre_solid else rng.uniform(6, 12), rng.uniform(0.3, 0.5),
                  paint_y if rng.random() < 0.2 else paint_w))
    for s in (-1, 1):
        for k in range(1, lanes):
            marks.append((s * k * lane_w, 0.12, rng.uniform(6, 12), rng.uniform(0.25, 0.5), paint_w))
        if park > 0 or rng.random() < 0.6:
            marks.append((s * lanes * lane_w, 0.15, 0.0, 1.0, paint_w))
    if rng.random() < 0.3 * (style != "residential"):
        marks = marks[:1] if rng.random() < 0.5 else []
    crosswalk = rng.uniform(8, 40) if rng.random() < 0.25 else None
    terrain_kind = rng.random()
    grass = _p_noise(rng, _hsv(rng.uniform(0.13, 0.28), rng.uniform(0.3, 0.7), rng.uniform(0.15, 0.35)),
                     _hsv(rng.uniform(0.1, 0.25), rng.uniform(0.2, 0.6), rng.uniform(0.3, 0.55)),
                     rng.uniform(0.5, 3), 2,
                     1.2)
    pave = _p_tiles(rng, _c_grey(rng, 0.35, 0.7), _c_grey(rng, 0.2, 0.5), rng.uniform(0.3, 1.0),
                    rng.uniform(0.3, 1.0), 0.01, 0.1)
    terrain = grass if (style != "urban" or terrain_kind < 0.3) else pave
    ox, oz = rng.uniform(0, 256, 2)
    ev = half + sw  # edge of the road + sidewalk
    patchy = rng.uniform(0.0, 0.5)

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
    # Ground labels beyond the road are patched in _render via the terrain_x bound.

    z0 = -30.0
    if sw > 0:
        side = _p_tiles(rng, _c_grey(rng, 0.35, 0.75), _c_grey(rng, 0.2, 0.55), rng.uniform(0.3, 1.5),
                        rng.uniform(0.3, 1.5), 0.008, 0.08)
        curb_m = _Mat(_p_solid(rng, _c_grey(rng, 0.4, 0.8), 0.05))
        for s in (-1, 1):
            mat = _Mat(side, faces={0 if s > 0 else 1: curb_m})
            L = z_end + 30.0
            b.box((s * (half + sw / 2), curb / 2, z0 + L / 2), (sw / 2, curb / 2, L / 2), _SIDEWALK, mat, cast=False)

    species = [_species(rng) for _ in range(int(rng.integers(1, 3)))]

    # Buildings.
    for s in (-1, 1):
        z = rng.uniform(-30.0, -5.0)
        setback = rng.uniform(0.0, 0.5) if style == "urban" else rng.uniform(2.5, 10.0) if style == "residential" \
            else rng.uniform(15.0, 60.0)
        while z < z_end:
            if style == "urban":
                blen, hgt, gap_p = rng.uniform(8, 35), rng.uniform(6, 28), 0.15
            elif style == "residential":
                blen, hgt, gap_p = rng.uniform(7, 14), rng.uniform(4, 9), 0.35
            else:
                blen, hgt, gap_p = rng.uniform(8, 30), rng.uniform(4, 12), 0.6
            if rng.random() < gap_p:
                gap = rng.uniform(4, 15)
                if style != "urban" or rng.random() < 0.5:
                    for _ in range(int(gap // 5)):
                        if rng.random() < 0.6:
                            _tree(b, rng, s * (ev + setback + rng.uniform(1, 10)), z + rng.uniform(0, gap), species[0])
                z += gap
                continue
            depth = rng.uniform(8, 20)
            xb = s * (ev + setback + rng.uniform(0, 1.0 if style == "urban" else 3.0))
            wall = _building_wall(rng)
            fac = _Mat(_p_facade(rng, wall, 0.0), spec=0.05)
            roof = _Mat(_p_noise(rng, c := _c_grey(rng, 0.1, 0.5), c * 0.7, 1.0, 2, 0.7))
            mat = _Mat(wall, faces={0: fac, 1: fac, 4: fac, 5: fac, 3: roof})
            b.box((xb + s * depth / 2, hgt / 2, z + blen / 2), (depth / 2, hgt / 2, blen / 2), _BUILDING, mat)
            if style == "residential" and rng.random() < 0.8:  # roof slabs
                rc = _Mat(_p_tiles(rng, _hsv(rng.uniform(0.0, 0.08), rng.uniform(0.2, 0.7), rng.uniform(0.15, 0.5)),
                                   _c_grey(rng, 0.05, 0.2), 0.3, 0.2, 0.01, 0.1, 0.5))
                o = rng.uniform(0.2, 0.6)
                y = hgt
                for k in range(int(rng.integers(1, 4))):
                    th = rng.uniform(0.3, 0.8)
                    shrink = k * rng.uniform(0.8, 1.5)
                    b.box((xb + s * depth / 2, y + th / 2, z + blen / 2),
                          (depth / 2 + o - shrink, th / 2, blen / 2 + o - shrink), _BUILDING, rc)
                    y += th
            if style == "residential":
                if rng.random() < 0.5:  # hedge or fence along the property line
                    xh = s * (ev + rng.uniform(0.2, 0.8))
                    if rng.random() < 0.5:
                        hh = rng.uniform(0.6, 1.6)
                        b.box((xh, hh / 2, z + blen / 2), (0.35, hh / 2, blen / 2 - 0.3), _VEGETATION,
                              _Mat(_p_foliage(rng)))
                    else:
                        hh = rng.uniform(0.8, 1.5)
                        fc = _c_wood(rng) if rng.random() < 0.5 else _c_grey(rng, 0.3, 0.95)
                        b.box((xh, hh / 2, z + blen / 2), (0.03, hh / 2, blen / 2 - 0.3), _FENCE,
                              _Mat(_p_stripes(rng, fc, fc * 0.3, rng.uniform(0.1, 0.25), 0.7, 0.0)))
                if rng.random() < 0.6:
                    _tree(b, rng, s * (ev + setback * rng.uniform(0.3, 0.8)), z + rng.uniform(0, blen), species[-1])
            z += blen + (rng.uniform(0.0, 0.3) if style == "urban" else rng.uniform(2.0, 8.0))
    if style == "urban" and rng.random() < 0.5:  # a building across the end of the street
        wall = _building_wall(rng)
        fac = _Mat(_p_facade(rng, wall, 0.0))
        hgt = rng.uniform(8, 30)
        b.box((rng.uniform(-10, 10), hgt / 2, z_end + 10), (60.0, hgt / 2, 10.0), _BUILDING,
              _Mat(wall, faces={4: fac}))
    if style != "urban" or rng.random() < 0.3:  # distant hills (beyond the valid range)
        hill = _Mat(_p_noise(rng, _hsv(rng.uniform(0.2, 0.35), rng.uniform(0.2, 0.5), rng.uniform(0.15, 0.35)),
                             _hsv(rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.4), rng.uniform(0.25, 0.5)), 0.05, 3, 1.0))
        n = int(rng.integers(1, 4))
        cs, rs = [], []
        for _ in range(n):
            r = rng.uniform(300, 900)
            cs.append((rng.uniform(-500, 500), -r + rng.uniform(8, 40), z_end + rng.uniform(250, 900) + r))
            rs.append(r)
        b.spheres(cs, rs, _TERRAIN, hill, cast=False)

    # Cars: parked along the curbs, and in the lanes.
    kit = _car_kit(rng)
    for s in (-1, 1):
        if park <= 0 or rng.random() < 0.2:
            continue
        z = rng.uniform(1.0, 10.0)
        n = 0
        while z < min(z_end, 75.0) and n < 8:
            x = s * (half - rng.uniform(0.95, 1.2))
            _car(b, rng, x, z + 2.3, rng.normal(0.0, 0.03) + (0.0 if rng.random() < 0.7 else math.pi), kit,
                 detail=z < 30)
            z += rng.uniform(5.0, 6.0) + (rng.uniform(0, 15) if rng.random() < 0.3 else rng.uniform(0.3, 2.0))
            n += 1
    for k in range(lanes):
        for s in (-1, 1):
            if rng.random() < 0.5:
                continue
            z = rng.uniform(8.0, 60.0)
            _car(b, rng, s * (k + 0.5) * lane_w + rng.normal(0, 0.2), z, (0.0 if s > 0 else math.pi) +
                 rng.normal(0, 0.02), kit, detail=z < 30)

    # Poles, street lamps, signs.
    pole_m = _Mat(_p_solid(rng, _c_grey(rng, 0.1, 0.6), 0.03), spec=0.2)
    for s in (-1, 1):
        if rng.random() < 0.25:
            continue
        z = rng.uniform(3, 25)
        spacing = rng.uniform(20, 45)
        xp = s * (half + (rng.uniform(0.3, 0.6) if sw > 0 else rng.uniform(1.0, 3.0)))
        while z < min(z_end, 120.0):
            hp = rng.uniform(5, 9)
            with b.assembly():
                b.cyl((xp, hp / 2, z), rng.uniform(0.07, 0.14), hp / 2, _POLE, pole_m)
                if rng.random() < 0.7:  # lamp arm
                    al = rng.uniform(1.0, 2.5)
                    b.box((xp - s * al / 2, hp - 0.1, z), (al / 2, 0.05, 0.06), _POLE, pole_m)
                    b.box((xp - s * al, hp - 0.15, z), (0.3, 0.08, 0.15), _POLE, pole_m)
            z += spacing
        for _ in range(int(rng.integers(0, 3))):  # signs
            zs = rng.uniform(5, 60)
            hs = rng.uniform(2.0, 3.0)
            b._asm = b._fresh()
            b.cyl((xp, hs / 2, zs), 0.04, hs / 2, _POLE, pole_m)
            sc = [_hsv(0.0, 0.85, 0.75), _hsv(0.6, 0.85, 0.6), _hsv(0.13, 0.9, 0.9), _c_grey(rng, 0.85, 0.95)]
            sign = _Mat(_p_solid(rng, sc[int(rng.integers(0, 4))], 0.02), spec=0.3,
                        decals=[_Decal(0.06, 0.06, 0.54, 0.54, _Mat(_p_poster(rng)))])
            size = rng.uniform(0.4, 0.8)
            b.box((xp, hs + size / 2, zs), (0.02, size / 2, size / 2), _POLE, sign,
                  yaw=rng.uniform(-0.3, 0.3))
            b._asm = None

    # Trees along the road, bushes, pedestrians.
    for s in (-1, 1):
        if rng.random() < (0.5 if style == "urban" else 0.25):
            continue
        z = rng.uniform(0, 15)
        spacing = rng.uniform(10, 22) if style != "open" else rng.uniform(6, 14)
        xt = s * (half + (sw * rng.uniform(0.5, 0.8) if sw > 0 else rng.uniform(1.5, 6.0)))
        sp = species[int(rng.integers(0, len(species)))]
        while z < min(z_end, 75.0):
            _tree(b, rng, xt + rng.normal(0, 0.3 if sw > 0 else 2.0), z, sp, rng.uniform(0.7, 1.3))
            z += spacing * rng.uniform(0.7, 1.3)
    for _ in range(int(rng.integers(0, 6)) if style != "urban" else int(rng.integers(0, 3))):
        s = rng.choice([-1.0, 1.0])
        xb, zb = s * (ev + rng.uniform(0.3, 6.0)), rng.uniform(4, 60)
        n = int(rng.integers(2, 6))
        cs = [(xb + rng.normal(0, 0.6), rng.uniform(0.0, 0.5), zb + rng.normal(0, 1.0)) for _ in range(n)]
        b.spheres(cs, rng.uniform(0.4, 1.0, n), _VEGETATION, _Mat(_p_foliage(rng)))
    for _ in range(int(rng.integers(0, 4)) if sw > 0 else 0):
        s = rng.choice([-1.0, 1.0])
        xpn, zpn = s * (half + rng.uniform(0.5, sw)), rng.uniform(6, 45)
        ht = rng.uniform(1.55, 1.9)
        cloth = _Mat(_p_solid(rng, _c_fabric(rng), 0.05))
        b._asm = b._fresh()
        b.cyl((xpn, ht * 0.25, zpn), 0.14, ht * 0.25, _PERSON, _Mat(_p_solid(rng, _c_fabric(rng), 0.05)))
        b.cyl((xpn, ht * 0.62, zpn), 0.2, ht * 0.13, _PERSON, cloth)
        b.spheres([(xpn, ht - 0.11, zpn)], [0.11], _PERSON,
                  _Mat(_p_solid(rng, _hsv(0.07, rng.uniform(0.2, 0.6), rng.uniform(0.3, 0.85)), 0.02)))
        b._asm = None

    # Camera in a lane (right-hand traffic), looking down the street.
    cam_h = rng.uniform(1.45, 1.85)
    cam_x = (int(rng.integers(0, lanes)) + 0.5) * lane_w + rng.normal(0, 0.25)
    cam = np.array([cam_x, cam_h, 0.0])
    R = _camera_rotation(rng.uniform(-0.12, 0.12), rng.uniform(-0.07, 0.04), rng.normal(0.0, 0.012))

    # Sun, sky, haze.
    overcast = rng.random() < 0.3
    el, az = rng.uniform(0.3, 1.15), rng.uniform(-math.pi, math.pi)
    sun_dir = (math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az))
    sun_c = _hsv(rng.uniform(0.08, 0.13), rng.uniform(0.05, 0.25), 1.0) * (rng.uniform(0.4, 1.0) if overcast
                                                                             else rng.uniform(2.5, 4.0))
    sky_top = _hsv(rng.uniform(0.55, 0.63), rng.uniform(0.0, 0.15) if overcast else rng.uniform(0.3, 0.7),
                   rng.uniform(0.6, 0.95))
    sky_hor = _hsv(rng.uniform(0.55, 0.63), rng.uniform(0.0, 0.2), rng.uniform(0.8, 1.0))
    ambient = (sky_top * 0.5 + sky_hor * 0.5) * (rng.uniform(0.9, 1.5) if overcast else rng.uniform(0.5, 0.9))
    clouds = rng.uniform(0.0, 1.0) if not overcast else rng.uniform(0.6, 1.0)
    cloud_c = _c_grey(rng, 0.75, 1.0)
    sky_gain = rng.uniform(1.3, 2.2)
    cx0, cz0 = rng.uniform(0, 256, 2)

    def sky(dx, dy, dz):
        e = np.clip(dy, 0.0, 1.0)
        col = _mix(sky_hor, sky_top, np.sqrt(e))
        inv = 1.0 / np.maximum(dy, 0.03)
        n = _fbm(dx * inv * 0.7 + cx0, dz * inv * 0.7 + cz0, 4)
        cov = np.clip((n - (1.0 - clouds) * 0.7 - 0.2) * 3.0, 0.0, 1.0) * np.clip(e * 8.0, 0.0, 1.0)
        col = col + (cloud_c * (0.75 + 0.5 * n) - col) * cov
        sd = dx * sun_dir[0] + dy * sun_dir[1] + dz * sun_dir[2]
        glow = np.maximum(sd, 0.0)
        for _ in range(5):  # ** 32
            glow = glow * glow
        glow *= 0.0 if overcast else 2.0
        return col * sky_gain + glow

    return Scene(
        prims=b.prims, cam_pos=cam, cam_R=R,
        lights=[Light(sun_c, direction=sun_dir, shadow_blur=1 if not overcast else 4)],
        ambient=ambient, ambient_up=rng.uniform(0.2, 0.5), extent=z_end + 600.0, sky=sky,
        haze_dist=rng.uniform(300.0, 1500.0), haze_color=sky_hor * sky_gain * 0.8, max_depth=RENDER_FAR_CLIP_M,
        terrain_x=ev, shadow_range=70.0, **_camera_model(rng))
