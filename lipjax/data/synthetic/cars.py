"""Cars: a body and a cabin with glazing, lights, a plate and wheels; parked along the curbs and driving in the
lanes. Units: metres and radians."""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from lipjax.data.synthetic.arrays import _set_cols
from lipjax.data.synthetic.colour import _c_grey, _hsv, _mix
from lipjax.data.synthetic.constants import _F32, _VEHICLE
from lipjax.data.synthetic.geometry import _rot_z
from lipjax.data.synthetic.materials import _Mat
from lipjax.data.synthetic.noise import _box
from lipjax.data.synthetic.patterns import Pattern, _mean_of, _p_solid, _with_mean
from lipjax.data.synthetic.scene import _Builder
from lipjax.data.synthetic.street import Street


@dataclasses.dataclass(frozen=True)
class CarRanges:
    """A car's size (metres): length, width, ground clearance and wheel radius; a saloon (probability
    `saloon_p`) or a taller car, each with its body and cabin heights and its cabin's length (a fraction of the
    car's); the paint is a grey with probability `grey_p`, else a colour."""

    length_m: tuple[float, float] = (3.8, 4.9)
    width_m: tuple[float, float] = (1.65, 1.9)
    saloon_p: float = 0.75
    saloon_body_m: tuple[float, float] = (0.55, 0.75)
    tall_body_m: tuple[float, float] = (0.8, 1.1)
    saloon_cabin_m: tuple[float, float] = (0.42, 0.55)
    tall_cabin_m: tuple[float, float] = (0.5, 0.8)
    clearance_m: tuple[float, float] = (0.22, 0.35)
    grey_p: float = 0.65
    saloon_cabin_length: tuple[float, float] = (0.45, 0.6)
    tall_cabin_length: tuple[float, float] = (0.55, 0.8)
    wheel_radius_m: tuple[float, float] = (0.3, 0.36)


@dataclasses.dataclass(frozen=True)
class TrafficRanges:
    """Where cars are (metres). Parked: on a street with a parking lane, each side unless skipped (`parked_skip_p`),
    from `first_parked_m`, at `curb_gap_m` from the curb, facing away with probability `away_p`, one after another
    (`parked_gap_m` bumper to bumper plus a short or, with probability `long_gap_p`, a long gap) until
    `parked_until_m` or `parked_max` cars. Driving: in each lane with probability `lane_car_p`, at `lane_car_m`.
    Cars nearer than `wheels_within_m` get wheels."""

    parked_skip_p: float = 0.2
    first_parked_m: tuple[float, float] = (1.0, 10.0)
    parked_until_m: float = 75.0
    parked_max: int = 8
    curb_gap_m: tuple[float, float] = (0.95, 1.2)
    away_p: float = 0.7
    parked_gap_m: tuple[float, float] = (5.0, 6.0)
    long_gap_p: float = 0.3
    long_gap_m: tuple[float, float] = (0, 15)
    short_gap_m: tuple[float, float] = (0.3, 2.0)
    lane_car_p: float = 0.5
    lane_car_m: tuple[float, float] = (8.0, 60.0)
    wheels_within_m: float = 30


CAR = CarRanges()
TRAFFIC = TrafficRanges()


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


def car_kit(rng) -> dict:
    """Materials all cars of a scene share (tyres, rims, undersides): evaluated once per frame."""
    rim = _Mat(_p_solid(rng, _c_grey(rng, 0.3, 0.7), 0.0))
    return {"dark": _Mat(_p_solid(rng, _c_grey(rng, 0.01, 0.06), 0.0)),
            "tyre": _Mat(_p_solid(rng, _c_grey(rng, 0.02, 0.06), 0.0), faces={3: rim, 2: rim})}


def car(b: _Builder, rng, x, z, yaw, kit, detail=True):
    """A car standing at (x, z) with yaw (0: driving away from the camera); `kit`: `car_kit`; `detail`: wheels.
    One shadow caster."""
    with b.assembly():
        _car_parts(b, rng, x, z, yaw, kit, detail)


def _car_parts(b: _Builder, rng, x, z, yaw, kit, detail, c: CarRanges = CAR):
    L = rng.uniform(*c.length_m)
    W = rng.uniform(*c.width_m)
    kind = rng.random()
    body_h = rng.uniform(*c.saloon_body_m) if kind < c.saloon_p else rng.uniform(*c.tall_body_m)
    cab_h = rng.uniform(*c.saloon_cabin_m) if kind < c.saloon_p else rng.uniform(*c.tall_cabin_m)
    clear = rng.uniform(*c.clearance_m)
    col = _c_grey(rng, 0.02, 0.9) if rng.random() < c.grey_p else _hsv(rng.random(), rng.uniform(0.5, 0.9),
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
    cl = L * rng.uniform(*c.saloon_cabin_length) if kind < c.saloon_p else L * rng.uniform(*c.tall_cabin_length)
    cz = rng.uniform(0.0, 0.12) * L
    m = 0.07
    side = _Mat(_p_glazed(col, glass, m, 0.03, cl - m, cab_h - m, cl * rng.uniform(0.45, 0.55)), spec=0.6, shin=80)
    end = _Mat(_p_glazed(col, glass, m, 0.02, W * 0.9 - m, cab_h - m), spec=0.6, shin=80)
    cab = _Mat(paint, spec=spec, shin=shin, faces={0: side, 1: side, 4: end, 5: end})
    b.box((0, clear + body_h + cab_h / 2, cz), (W * 0.45, cab_h / 2, cl / 2), _VEHICLE, cab, group=group)
    if detail:  # wheels: one cylinder per axle, visible below the body
        wr = rng.uniform(*c.wheel_radius_m)
        tyre = kit["tyre"]
        axle_R = _rot_z(math.pi / 2)
        for sz in (-1, 1):
            b.cyl((0, wr, sz * (L / 2 - 0.8)), wr, W / 2 - 0.02, _VEHICLE, tyre, group=group, R=axle_R, cast=False)


def traffic(b: _Builder, rng, street: Street, t: TrafficRanges = TRAFFIC) -> None:
    """Parked cars along both curbs (streets with a parking lane), then cars driving in the lanes."""
    kit = car_kit(rng)
    for s in (-1, 1):
        if street.parking <= 0 or rng.random() < t.parked_skip_p:
            continue
        z = rng.uniform(*t.first_parked_m)
        n = 0
        while z < min(street.length, t.parked_until_m) and n < t.parked_max:
            x = s * (street.half_width - rng.uniform(*t.curb_gap_m))
            car(b, rng, x, z + 2.3, rng.normal(0.0, 0.03) + (0.0 if rng.random() < t.away_p else math.pi), kit,
                detail=z < t.wheels_within_m)
            z += rng.uniform(*t.parked_gap_m) + (rng.uniform(*t.long_gap_m) if rng.random() < t.long_gap_p
                                                 else rng.uniform(*t.short_gap_m))
            n += 1
    for k in range(street.lanes):
        for s in (-1, 1):
            if rng.random() < t.lane_car_p:
                continue
            z = rng.uniform(*t.lane_car_m)
            car(b, rng, s * (k + 0.5) * street.lane_width + rng.normal(0, 0.2), z, (0.0 if s > 0 else math.pi) +
                rng.normal(0, 0.02), kit, detail=z < t.wheels_within_m)
