"""The outdoor scene: a street (road, sidewalks), buildings, distant hills, cars, poles and signs, trees, bushes,
pedestrians, a KITTI-like camera in a lane, and daylight. Units: metres and radians.

`outdoor_scene(rng)` draws the elements in a fixed order (the order of the calls in it): each frame's scene
depends on that order, so an element's draws stay where they are (see tests/test_synthetic_golden.py). The world
frame is the street's (lipjax.data.synthetic.street).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from lipjax.data.synthetic.buildings import building_rows, street_end
from lipjax.data.synthetic.camera import _camera_model
from lipjax.data.synthetic.cars import traffic
from lipjax.data.synthetic.colour import _c_fabric, _c_grey, _hsv
from lipjax.data.synthetic.constants import _PERSON, _POLE, _TERRAIN, RENDER_FAR_CLIP_M
from lipjax.data.synthetic.materials import _Decal, _Mat
from lipjax.data.synthetic.patterns import _p_noise, _p_poster, _p_solid
from lipjax.data.synthetic.road import road, sidewalks
from lipjax.data.synthetic.scene import Scene, _Builder, _camera_rotation
from lipjax.data.synthetic.sky import daylight
from lipjax.data.synthetic.street import Street, street_layout
from lipjax.data.synthetic.vegetation import bushes, species, tree_rows

# Objects farther than this from the camera (Chebyshev distance, metres) cast no shadow (Scene.shadow_range).
SHADOW_RANGE_M = 70.0


@dataclasses.dataclass(frozen=True)
class StreetFurnitureRanges:
    """Poles on each side unless skipped (`skip_p`), the first at `first_m`, then every `spacing_m` until
    `until_m`; their distance beyond the curb (with / without a sidewalk), height and radius; a lamp arm with
    probability `arm_p`, `arm_m` long; [low, high) signs per side at `sign_m`, `sign_height_m` up, `sign_size_m`
    wide. Metres."""

    skip_p: float = 0.25
    first_m: tuple[float, float] = (3, 25)
    spacing_m: tuple[float, float] = (20, 45)
    until_m: float = 120.0
    on_sidewalk_m: tuple[float, float] = (0.3, 0.6)
    off_road_m: tuple[float, float] = (1.0, 3.0)
    height_m: tuple[float, float] = (5, 9)
    radius_m: tuple[float, float] = (0.07, 0.14)
    arm_p: float = 0.7
    arm_m: tuple[float, float] = (1.0, 2.5)
    signs: tuple[int, int] = (0, 3)
    sign_m: tuple[float, float] = (5, 60)
    sign_height_m: tuple[float, float] = (2.0, 3.0)
    sign_size_m: tuple[float, float] = (0.4, 0.8)


@dataclasses.dataclass(frozen=True)
class OutdoorCameraRanges:
    """The KITTI-like camera: height above the road (metres), the standard deviation of its offset from its lane's
    centre (metres), yaw and pitch (radians; pitch > 0 looks up) and the roll's standard deviation (radians)."""

    height_m: tuple[float, float] = (1.45, 1.85)
    lane_sd_m: float = 0.25
    yaw: tuple[float, float] = (-0.12, 0.12)
    pitch: tuple[float, float] = (-0.07, 0.04)
    roll_sd: float = 0.012


STREET_FURNITURE = StreetFurnitureRanges()
OUTDOOR_CAMERA = OutdoorCameraRanges()


def distant_hills(b: _Builder, rng, street: Street) -> None:
    """One to three huge grassy spheres beyond the end of the street (past the far clip: no valid depth), on
    every non-urban street and on three urban streets in ten."""
    if street.style != "urban" or rng.random() < 0.3:
        hill = _Mat(_p_noise(rng, _hsv(rng.uniform(0.2, 0.35), rng.uniform(0.2, 0.5), rng.uniform(0.15, 0.35)),
                             _hsv(rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.4), rng.uniform(0.25, 0.5)), 0.05, 3, 1.0))
        n = int(rng.integers(1, 4))
        cs, rs = [], []
        for _ in range(n):
            r = rng.uniform(300, 900)
            cs.append((rng.uniform(-500, 500), -r + rng.uniform(8, 40), street.length + rng.uniform(250, 900) + r))
            rs.append(r)
        b.spheres(cs, rs, _TERRAIN, hill, cast=False)


def _sign(b: _Builder, rng, xp, pole_m: _Mat, r: StreetFurnitureRanges) -> None:
    """A sign on its own post at x = xp: red, blue, yellow or grey, with a picture on it."""
    zs = rng.uniform(*r.sign_m)
    hs = rng.uniform(*r.sign_height_m)
    with b.assembly():
        b.cyl((xp, hs / 2, zs), 0.04, hs / 2, _POLE, pole_m)
        sc = [_hsv(0.0, 0.85, 0.75), _hsv(0.6, 0.85, 0.6), _hsv(0.13, 0.9, 0.9), _c_grey(rng, 0.85, 0.95)]
        sign = _Mat(_p_solid(rng, sc[int(rng.integers(0, 4))], 0.02), spec=0.3,
                    decals=[_Decal(0.06, 0.06, 0.54, 0.54, _Mat(_p_poster(rng)))])
        size = rng.uniform(*r.sign_size_m)
        b.box((xp, hs + size / 2, zs), (0.02, size / 2, size / 2), _POLE, sign,
              yaw=rng.uniform(-0.3, 0.3))


def poles_and_signs(b: _Builder, rng, street: Street, r: StreetFurnitureRanges = STREET_FURNITURE) -> None:
    """A line of poles (street lamps, with an arm reaching over the road) and a few signs on each side."""
    pole_m = _Mat(_p_solid(rng, _c_grey(rng, 0.1, 0.6), 0.03), spec=0.2)
    for s in (-1, 1):
        if rng.random() < r.skip_p:
            continue
        z = rng.uniform(*r.first_m)
        spacing = rng.uniform(*r.spacing_m)
        xp = s * (street.half_width + (rng.uniform(*r.on_sidewalk_m) if street.sidewalk > 0
                                       else rng.uniform(*r.off_road_m)))
        while z < min(street.length, r.until_m):
            hp = rng.uniform(*r.height_m)
            with b.assembly():
                b.cyl((xp, hp / 2, z), rng.uniform(*r.radius_m), hp / 2, _POLE, pole_m)
                if rng.random() < r.arm_p:  # lamp arm
                    al = rng.uniform(*r.arm_m)
                    b.box((xp - s * al / 2, hp - 0.1, z), (al / 2, 0.05, 0.06), _POLE, pole_m)
                    b.box((xp - s * al, hp - 0.15, z), (0.3, 0.08, 0.15), _POLE, pole_m)
            z += spacing
        for _ in range(int(rng.integers(*r.signs))):
            _sign(b, rng, xp, pole_m, r)


def pedestrians(b: _Builder, rng, street: Street) -> None:
    """Up to three people on the sidewalks (none without one): legs, torso and head, 1.55-1.9 m tall."""
    half, sw = street.half_width, street.sidewalk
    for _ in range(int(rng.integers(0, 4)) if sw > 0 else 0):
        s = rng.choice([-1.0, 1.0])
        xpn, zpn = s * (half + rng.uniform(0.5, sw)), rng.uniform(6, 45)
        ht = rng.uniform(1.55, 1.9)
        cloth = _Mat(_p_solid(rng, _c_fabric(rng), 0.05))
        with b.assembly():
            b.cyl((xpn, ht * 0.25, zpn), 0.14, ht * 0.25, _PERSON, _Mat(_p_solid(rng, _c_fabric(rng), 0.05)))
            b.cyl((xpn, ht * 0.62, zpn), 0.2, ht * 0.13, _PERSON, cloth)
            b.spheres([(xpn, ht - 0.11, zpn)], [0.11], _PERSON,
                      _Mat(_p_solid(rng, _hsv(0.07, rng.uniform(0.2, 0.6), rng.uniform(0.3, 0.85)), 0.02)))


def outdoor_camera(rng, street: Street, c: OutdoorCameraRanges = OUTDOOR_CAMERA) -> tuple[np.ndarray, np.ndarray]:
    """(position (3,) world metres, camera-to-world rotation (3, 3)): in one of the right-hand lanes at z = 0,
    looking down the street."""
    cam_h = rng.uniform(*c.height_m)
    cam_x = (int(rng.integers(0, street.lanes)) + 0.5) * street.lane_width + rng.normal(0, c.lane_sd_m)
    cam = np.array([cam_x, cam_h, 0.0])
    return cam, _camera_rotation(rng.uniform(*c.yaw), rng.uniform(*c.pitch), rng.normal(0.0, c.roll_sd))


def outdoor_scene(rng) -> Scene:
    """A street seen by a KITTI-like camera, every draw from `rng` (a numpy Generator)."""
    b = _Builder(rng)
    street = street_layout(rng)
    road(b, rng, street)  # the ground beyond the road is labelled terrain by the renderer (Scene.terrain_x)
    sidewalks(b, rng, street)
    kinds = [species(rng) for _ in range(int(rng.integers(1, 3)))]
    building_rows(b, rng, street, kinds)
    street_end(b, rng, street)
    distant_hills(b, rng, street)
    traffic(b, rng, street)
    poles_and_signs(b, rng, street)
    tree_rows(b, rng, street, kinds)
    bushes(b, rng, street)
    pedestrians(b, rng, street)
    cam, R = outdoor_camera(rng, street)
    day = daylight(rng)
    return Scene(
        prims=b.prims, cam_pos=cam, cam_R=R, lights=[day.sun], ambient=day.ambient,
        ambient_up=rng.uniform(0.2, 0.5), extent=street.length + 600.0, sky=day.sky,
        haze_dist=rng.uniform(300.0, 1500.0), haze_color=day.haze_color, max_depth=RENDER_FAR_CLIP_M,
        terrain_x=street.edge, shadow_range=SHADOW_RANGE_M, **_camera_model(rng))
