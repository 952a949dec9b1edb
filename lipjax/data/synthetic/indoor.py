"""The indoor scene: a room shell with decals, furniture against the walls and free-standing, things on the walls,
ceiling lights and an NYU-like camera. Units: metres and radians.

`indoor_scene(rng)` draws the elements in a fixed order (room size, room surfaces and their decals, camera,
furniture, lights, camera model): each frame's scene depends on that order, so an element's draws stay where they
are (see tests/test_synthetic_golden.py).

Room frame: x across the room in [0, width], z along it in [0, length] (the camera stands near z = 0), y up in
[0, height]. Room faces: 0 / 1 left / right wall (x = 0 / width), 2 floor, 3 ceiling, 4 / 5 near / far wall.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from lipjax.data.synthetic.camera import _camera_model
from lipjax.data.synthetic.colour import _c_fabric, _c_grey, _c_wall, _c_wood, _hsv
from lipjax.data.synthetic.constants import _CEILING, _F32, _FLOOR, _FURNITURE, _WALL
from lipjax.data.synthetic.furniture import FREE_FURNITURE, WALL_FURNITURE, furniture, pick
from lipjax.data.synthetic.materials import _Decal, _Mat
from lipjax.data.synthetic.patterns import _p_fronts, _p_noise, _p_poster, _p_solid, _p_stripes, _p_tiles, _p_window
from lipjax.data.synthetic.primitives import _Box
from lipjax.data.synthetic.room_materials import _floor_pattern, _furniture_mat, _rug, _wall_pattern
from lipjax.data.synthetic.scene import Light, Scene, _Builder, _camera_rotation


@dataclasses.dataclass(frozen=True)
class Room:
    """A room's size, metres."""

    width: float
    length: float
    height: float

    @property
    def wall_length(self) -> dict[int, float]:
        """Length of each wall along the floor, by face (0, 1: side walls; 4, 5: near and far wall)."""
        return {0: self.length, 1: self.length, 4: self.width, 5: self.width}


@dataclasses.dataclass(frozen=True)
class RoomRanges:
    """The ranges a room's size is drawn from, metres."""

    width_m: tuple[float, float] = (3.0, 7.0)
    length_m: tuple[float, float] = (3.5, 8.5)
    height_m: tuple[float, float] = (2.4, 3.2)


@dataclasses.dataclass(frozen=True)
class IndoorCameraRanges:
    """The NYU-like camera pose: height (metres, at most `ceiling_gap_m` below the ceiling), position as fractions
    of the room's width and metres from the near wall (at most `near_fraction` of the length), yaw and pitch
    (radians; pitch > 0 looks up) and the roll's standard deviation (radians)."""

    height_m: tuple[float, float] = (0.95, 1.75)
    ceiling_gap_m: float = 0.45
    across: tuple[float, float] = (0.3, 0.7)
    from_near_wall_m: tuple[float, float] = (0.35, 1.6)
    near_fraction: float = 0.3
    yaw: tuple[float, float] = (-0.6, 0.6)
    pitch: tuple[float, float] = (-0.45, 0.08)
    roll_sd: float = 0.02


@dataclasses.dataclass(frozen=True)
class FurnishingRanges:
    """How many pieces a room gets ([low, high) counts), the placement tries per piece, and the floor kept free
    around the camera (metres to its left / right, behind, in front)."""

    wall_pieces: tuple[int, int] = (3, 11)
    free_pieces: tuple[int, int] = (1, 6)
    wall_mounted: tuple[int, int] = (0, 3)
    tries: int = 6
    camera_side_m: float = 0.7
    camera_behind_m: float = 0.9
    camera_front_m: float = 0.7


@dataclasses.dataclass(frozen=True)
class CeilingLightRanges:
    """Point lights under the ceiling ([low, high) count; metres below it; position as fractions of the room's width
    and length), their colour (warm with probability `warm_p`, else cool), intensity, falloff radius r0 (metres)
    and shadow blur (pixels); the ambient light's intensity."""

    count: tuple[int, int] = (1, 3)
    below_ceiling_m: tuple[float, float] = (0.15, 0.5)
    across: tuple[float, float] = (0.2, 0.8)
    along: tuple[float, float] = (0.3, 0.95)
    warm_p: float = 0.7
    intensity: tuple[float, float] = (1.5, 3.5)
    falloff_m: tuple[float, float] = (1.5, 4.0)
    shadow_blur_px: tuple[int, int] = (1, 4)
    ambient: tuple[float, float] = (0.12, 0.4)


ROOM = RoomRanges()
INDOOR_CAMERA = IndoorCameraRanges()
FURNISHING = FurnishingRanges()
CEILING_LIGHTS = CeilingLightRanges()


# ---------------------------------------------------------------- room shell

def _room_surfaces(rng) -> tuple[dict[int, _Mat], _Mat, _Mat]:
    """(walls by face, floor, ceiling) materials, without decals."""
    wall_pat, wall_spec = _wall_pattern(rng)
    walls = {f: _Mat(wall_pat, spec=wall_spec) for f in (0, 1, 4, 5)}
    if rng.random() < 0.25:  # an accent wall
        walls[int(rng.choice([0, 1, 5]))].pattern = _wall_pattern(rng)[0]
    floor_pat, floor_spec = _floor_pattern(rng)
    floor = _Mat(floor_pat, spec=floor_spec, shin=rng.uniform(20, 80))
    if rng.random() < 0.75:
        ceil = _Mat(_p_solid(rng, _hsv(0.1, rng.uniform(0, 0.08), rng.uniform(0.75, 0.95)), 0.02))
    else:
        ceil = _Mat(_p_tiles(rng, _c_grey(rng, 0.7, 0.95), _c_grey(rng, 0.4, 0.8), 0.6, 0.6, 0.02, 0.03))
    return walls, floor, ceil


def _wall_bands(rng, room: Room, walls: dict[int, _Mat]) -> None:
    """A skirting board and, rarely, wainscoting (a lower band of another finish) around the room."""
    if rng.random() < 0.6:  # skirting board
        bh = rng.uniform(0.05, 0.14)
        bm = _Mat(_p_solid(rng, _c_wood(rng) if rng.random() < 0.5 else _c_grey(rng, 0.1, 0.95), 0.02), spec=0.1)
        for f, m in walls.items():
            m.decals.append(_Decal(-0.01, -0.01, room.wall_length[f] + 0.01, bh, bm))
    if rng.random() < 0.15:  # wainscoting / tiled lower half
        wh = rng.uniform(0.8, 1.3)
        wm = _Mat(_wall_pattern(rng)[0])
        for f, m in walls.items():
            m.decals.insert(0, _Decal(-0.01, -0.01, room.wall_length[f] + 0.01, wh, wm))


def _windows(rng, room: Room, walls: dict[int, _Mat]) -> None:
    """Zero to two bright windows on the side or far walls, half of them with curtains."""
    for _ in range(int(rng.integers(0, 3))):
        f = int(rng.choice([0, 1, 5]))
        ww, wh = rng.uniform(0.6, min(2.4, room.wall_length[f] - 0.4)), rng.uniform(0.9, 1.7)
        u0 = rng.uniform(0.1, room.wall_length[f] - ww - 0.1)
        v0 = rng.uniform(0.6, max(0.61, room.height - wh - 0.2))
        walls[f].decals.append(_Decal(u0, v0, u0 + ww, v0 + wh, _Mat(_p_window(rng), emit=rng.uniform(1.5, 4.0))))
        if rng.random() < 0.5:  # curtains
            cm = _Mat(_p_stripes(rng, c := _c_fabric(rng), c * 0.75, rng.uniform(0.05, 0.15), 0.5, 0.0))
            cw = rng.uniform(0.25, 0.5)
            top = min(room.height - 0.05, v0 + wh + 0.25)
            walls[f].decals.append(_Decal(u0 - cw * 0.6, 0.05, u0 + cw * 0.4, top, cm))
            walls[f].decals.append(_Decal(u0 + ww - cw * 0.4, 0.05, u0 + ww + cw * 0.6, top, cm))


def _door(rng, room: Room, walls: dict[int, _Mat]) -> None:
    """A panelled door on any wall, six rooms in ten."""
    if rng.random() < 0.6:
        f = int(rng.choice([0, 1, 4, 5]))
        dw = rng.uniform(0.75, 1.0)
        u0 = rng.uniform(0.1, room.wall_length[f] - dw - 0.1)
        c = _c_wood(rng) if rng.random() < 0.5 else _c_wall(rng)
        panels = _p_fronts(rng, _p_solid(rng, c, 0.02), 1.0, 1.0, 1, int(rng.integers(1, 3)), 0.0, c * 0.6,
                           _c_grey(rng, 0.1, 0.9))
        walls[f].decals.append(_Decal(u0, 0.0, u0 + dw, rng.uniform(1.98, 2.1), _Mat(panels, spec=0.1)))


def _wall_art(rng, room: Room, walls: dict[int, _Mat]) -> None:
    """Posters, paintings, boards and clocks on every wall, and sometimes a whiteboard or blackboard."""
    for f in (0, 1, 5, 4):
        for _ in range(int(rng.integers(0, 4))):
            pw = rng.uniform(0.2, 1.2)
            ph = pw * rng.uniform(0.5, 1.5)
            if pw > room.wall_length[f] - 0.2 or ph > room.height - 1.0:
                continue
            u0 = rng.uniform(0.1, room.wall_length[f] - pw - 0.1)
            v0 = rng.uniform(0.9, room.height - ph - 0.05)
            walls[f].decals.append(_Decal(u0, v0, u0 + pw, v0 + ph, _Mat(_p_poster(rng), spec=0.1)))
    if rng.random() < 0.15:  # whiteboard / blackboard
        f = int(rng.choice([0, 1, 5]))
        bw = rng.uniform(1.2, min(3.5, room.wall_length[f] - 0.4))
        u0 = rng.uniform(0.2, room.wall_length[f] - bw - 0.2)
        board = _c_grey(rng, 0.85, 0.97) if rng.random() < 0.7 else _hsv(rng.uniform(0.3, 0.45), 0.4, 0.2)
        walls[f].decals.append(_Decal(u0, 0.9, u0 + bw, 2.0, _Mat(_p_poster(rng) if rng.random() < 0.3 else
                                                                   _p_noise(rng, board, board * 0.85, 3, 2, 0.5),
                                                                   spec=0.3)))


def _rugs_and_ceiling_panels(rng, room: Room, floor: _Mat, ceil: _Mat) -> None:
    for _ in range(int(rng.integers(0, 3)) if rng.random() < 0.6 else 0):  # rugs
        rw, rl = rng.uniform(0.8, min(3.0, room.width - 0.4)), rng.uniform(0.8, min(4.0, room.length - 0.4))
        x0, z0 = rng.uniform(0.2, room.width - rw - 0.2), rng.uniform(0.2, room.length - rl - 0.2)
        floor.decals.append(_Decal(x0, z0, x0 + rw, z0 + rl, _Mat(_rug(rng))))
    for _ in range(int(rng.integers(0, 5))):  # ceiling light panels
        s = rng.uniform(0.3, 0.7)
        x0, z0 = rng.uniform(0.2, room.width - s - 0.2), rng.uniform(0.2, room.length - s - 0.2)
        ceil.decals.append(_Decal(x0, z0, x0 + s, z0 + s * rng.choice([1.0, 2.0]),
                                  _Mat(_p_solid(rng, _c_grey(rng, 0.85, 1.0), 0.0), emit=rng.uniform(1.0, 3.0))))


def room_shell(b: _Builder, rng, room: Room) -> None:
    """The room's six faces as one inside-out box, with their materials and decals: colour edges that are not
    depth edges (skirting, windows, a door, wall art, rugs, light panels)."""
    walls, floor, ceil = _room_surfaces(rng)
    room_mat = _Mat(_p_solid(rng, np.ones((3, 1), _F32), 0), faces={**walls, 2: floor, 3: ceil})
    _wall_bands(rng, room, walls)
    _windows(rng, room, walls)
    _door(rng, room, walls)
    _wall_art(rng, room, walls)
    _rugs_and_ceiling_panels(rng, room, floor, ceil)
    W, L, Hc = room.width, room.length, room.height
    room_labels = np.array([_WALL, _WALL, _FLOOR, _CEILING, _WALL, _WALL], dtype=np.int8)
    b.prims.append(_Box((W / 2, Hc / 2, L / 2), (W / 2, Hc / 2, L / 2), room_labels, room_mat, inside=True,
                        cast=False))


# ---------------------------------------------------------------- camera and furniture

def indoor_camera(rng, room: Room, c: IndoorCameraRanges = INDOOR_CAMERA) -> tuple[np.ndarray, np.ndarray]:
    """(position (3,) world metres, camera-to-world rotation (3, 3)): near the near wall, looking into the room."""
    cam_h = rng.uniform(c.height_m[0], min(c.height_m[1], room.height - c.ceiling_gap_m))
    cam = np.array([rng.uniform(*c.across) * room.width, cam_h,
                    rng.uniform(c.from_near_wall_m[0], min(c.from_near_wall_m[1], c.near_fraction * room.length))])
    yaw, pitch, roll = rng.uniform(*c.yaw), rng.uniform(*c.pitch), rng.normal(0.0, c.roll_sd)
    return cam, _camera_rotation(yaw, pitch, roll)


class _FloorPlan:
    """The footprints (x0, x1, z0, z1) taken on the floor: pieces must not overlap each other or the camera's
    surroundings."""

    def __init__(self, room: Room, cam: np.ndarray, f: FurnishingRanges):
        self.room = room
        self.taken = [(cam[0] - f.camera_side_m, cam[0] + f.camera_side_m, cam[2] - f.camera_behind_m,
                       cam[2] + f.camera_front_m)]

    def free(self, x0, x1, z0, z1) -> bool:
        return x0 > 0.0 and z0 > 0.0 and x1 < self.room.width and z1 < self.room.length and all(
            x1 <= a0 or x0 >= a1 or z1 <= b0 or z0 >= b1 for a0, a1, b0, b1 in self.taken)


def _against_wall(f: int, room: Room, s: float, w: float, d: float) -> tuple[float, float, float, float, float]:
    """(x, z, yaw) of a w x d piece with its back to wall f at position s along it, and its (x, z) footprint."""
    gap = 0.005
    if f == 0:
        return d / 2 + gap, s, -math.pi / 2, d, w
    if f == 1:
        return room.width - d / 2 - gap, s, math.pi / 2, d, w
    if f == 5:
        return s, room.length - d / 2 - gap, 0.0, w, d
    return s, d / 2 + gap, math.pi, w, d


def _wall_furniture(b: _Builder, rng, room: Room, plan: _FloorPlan, ranges: FurnishingRanges) -> None:
    """Pieces with their backs to a wall (mostly the side and far walls); a piece that does not fit is dropped."""
    for _ in range(int(rng.integers(*ranges.wall_pieces))):
        item = pick(rng, WALL_FURNITURE)
        for _try in range(ranges.tries):
            f = int(rng.choice([0, 1, 5, 4], p=[0.3, 0.3, 0.35, 0.05]))
            w, d, h = rng.uniform(*item.width_m), rng.uniform(*item.depth_m), rng.uniform(*item.height_m)
            h = min(h, room.height - 0.15)
            if w > room.wall_length[f] - 0.1:
                continue
            s = rng.uniform(w / 2 + 0.02, room.wall_length[f] - w / 2 - 0.02)
            gx, gz, gyaw, fx, fz = _against_wall(f, room, s, w, d)
            # the desk's chair stands in front of it
            extra = 0.6 if item.kind == "desk" else 0.0
            fx2 = fx + (extra if f in (0, 1) else 0)
            fz2 = fz + (extra if f in (4, 5) else 0)
            x0 = gx - fx / 2 - (extra if f == 1 else 0)
            z0 = gz - fz / 2 - (extra if f == 5 else 0)
            if not plan.free(x0, x0 + fx2, z0, z0 + fz2):
                continue
            plan.taken.append((x0, x0 + fx2, z0, z0 + fz2))
            furniture(b, rng, item.kind, (gx, gz, gyaw), w, d, h)
            break


def _free_furniture(b: _Builder, rng, room: Room, plan: _FloorPlan, ranges: FurnishingRanges) -> None:
    """Pieces standing free at any yaw (a table keeps room for its chairs)."""
    for _ in range(int(rng.integers(*ranges.free_pieces))):
        item = pick(rng, FREE_FURNITURE)
        w, d, h = rng.uniform(*item.width_m), rng.uniform(*item.depth_m), rng.uniform(*item.height_m)
        margin = 0.65 if item.kind == "table" else 0.1
        for _try in range(ranges.tries):
            gx, gz = rng.uniform(0.2, room.width - 0.2), rng.uniform(0.2, room.length - 0.2)
            r = 0.5 * math.hypot(w, d) + margin
            if not plan.free(gx - r, gx + r, gz - r, gz + r):
                continue
            plan.taken.append((gx - r, gx + r, gz - r, gz + r))
            furniture(b, rng, item.kind, (gx, gz, rng.uniform(-math.pi, math.pi)), w, d, h)
            break


def _wall_mounted(b: _Builder, rng, room: Room, ranges: FurnishingRanges) -> None:
    """Frames, shelves and wall cabinets sticking out of the side or far walls above 1.2 m."""
    for _ in range(int(rng.integers(*ranges.wall_mounted))):
        f = int(rng.choice([0, 1, 5]))
        w, h, d = rng.uniform(0.3, 1.2), rng.uniform(0.2, 0.9), rng.uniform(0.02, 0.3)
        if w > room.wall_length[f] - 0.3:
            continue
        s = rng.uniform(w / 2 + 0.1, room.wall_length[f] - w / 2 - 0.1)
        y = rng.uniform(1.2, room.height - h / 2 - 0.1)
        group = {0: (d / 2, s, -math.pi / 2), 1: (room.width - d / 2, s, math.pi / 2),
                 5: (s, room.length - d / 2, 0.0)}[f]
        mat = _furniture_mat(rng)
        if d < 0.08:
            mat.faces = {4: _Mat(_p_poster(rng), spec=0.15)}
        b.box((0, y, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)


def furnish(b: _Builder, rng, room: Room, cam: np.ndarray, f: FurnishingRanges = FURNISHING) -> None:
    """Wall furniture, then free-standing furniture, then wall-mounted pieces, none in front of the camera."""
    plan = _FloorPlan(room, cam, f)
    _wall_furniture(b, rng, room, plan, f)
    _free_furniture(b, rng, room, plan, f)
    _wall_mounted(b, rng, room, f)


def ceiling_lights(rng, room: Room, c: CeilingLightRanges = CEILING_LIGHTS) -> tuple[list[Light], np.ndarray]:
    """(point lights near the ceiling, ambient colour (3, 1) linear)."""
    lights = []
    for _ in range(int(rng.integers(*c.count))):
        pos = (rng.uniform(*c.across) * room.width, room.height - rng.uniform(*c.below_ceiling_m),
               rng.uniform(*c.along) * room.length)
        temp = _hsv(rng.uniform(0.06, 0.15), rng.uniform(0.0, 0.35), 1.0) if rng.random() < c.warm_p else \
            _hsv(rng.uniform(0.5, 0.65), rng.uniform(0.0, 0.2), 1.0)
        lights.append(Light(temp * rng.uniform(*c.intensity), position=pos, r0=rng.uniform(*c.falloff_m),
                            shadow_blur=int(rng.integers(*c.shadow_blur_px))))
    ambient = _hsv(rng.uniform(0.0, 1.0), rng.uniform(0.0, 0.15), 1.0) * rng.uniform(*c.ambient)
    return lights, ambient


def indoor_scene(rng) -> Scene:
    """A furnished room seen by an NYU-like camera, every draw from `rng` (a numpy Generator)."""
    b = _Builder(rng)
    room = Room(rng.uniform(*ROOM.width_m), rng.uniform(*ROOM.length_m), rng.uniform(*ROOM.height_m))
    room_shell(b, rng, room)
    cam, R = indoor_camera(rng, room)
    furnish(b, rng, room, cam)
    lights, ambient = ceiling_lights(rng, room)
    W, L, Hc = room.width, room.length, room.height
    return Scene(
        prims=b.prims, cam_pos=cam, cam_R=R, lights=lights, ambient=ambient, ambient_up=rng.uniform(0.0, 0.3),
        extent=math.sqrt(W * W + L * L + Hc * Hc), **_camera_model(rng))
