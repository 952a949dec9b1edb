"""Furniture and the things on it: one builder per kind of piece, with the size ranges each kind is drawn from.

A piece is built in a local frame (x right, y up, z back; front towards -z) centred on its footprint, w wide along
local x, d deep along local z and h high (metres), and placed by its group (floor x, floor z, yaw).
"""
from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from lipjax.data.synthetic.colour import _c_any, _c_fabric, _c_grey, _c_wall, _hsv
from lipjax.data.synthetic.constants import _F32, _FURNITURE, _OBJECT, _VEGETATION
from lipjax.data.synthetic.materials import _Decal, _Mat
from lipjax.data.synthetic.patterns import _p_books, _p_foliage, _p_fronts, _p_noise, _p_poster, _p_solid
from lipjax.data.synthetic.room_materials import _furniture_mat, _rug
from lipjax.data.synthetic.scene import _Builder


def _small_object(b: _Builder, rng, x, y, z, group, max_size):
    """One tabletop object standing at (x, y, z) in the group frame."""
    r = rng.random()
    mat = _Mat(_p_solid(rng, _c_any(rng), 0.04), spec=rng.choice([0.0, 0.1, 0.3]), shin=rng.uniform(10, 80))
    if r < 0.3:  # book / box / stack of books
        n = int(rng.integers(1, 4))
        w, d = rng.uniform(0.12, min(0.35, max_size)), rng.uniform(0.1, min(0.3, max_size))
        yaw = rng.uniform(-0.5, 0.5)
        for _ in range(n):
            hh = rng.uniform(0.015, 0.05)
            b.box((x, y + hh, z), (w / 2, hh, d / 2), _OBJECT, _Mat(_p_solid(rng, _c_any(rng), 0.03)), yaw, group)
            y += 2 * hh
    elif r < 0.6:  # cup, bottle, vase, can
        rad = rng.uniform(0.03, 0.09)
        hh = rng.uniform(0.04, 0.16)
        b.cyl((x, y + hh, z), rad, hh, _OBJECT, mat, group=group)
    elif r < 0.75:  # fruit / ball
        rad = rng.uniform(0.04, 0.12)
        b.spheres([(x, y + rad, z)], [rad], _OBJECT, mat, group=group)
    elif r < 0.9:  # monitor / picture on a stand
        w = rng.uniform(0.35, min(0.75, 2 * max_size + 0.2))
        hh = w * rng.uniform(0.28, 0.4)
        body = _Mat(_p_solid(rng, _c_grey(rng, 0.02, 0.2), 0.02), spec=0.2,
                    decals=[_Decal(0.04, 0.06, 0.96, 0.96, _Mat(_p_poster(rng), emit=rng.choice([0.0, 0.6])), 4)])
        b.box((x, y + 0.1 + hh, z), (w / 2, hh, 0.02), _OBJECT, body, rng.uniform(-0.4, 0.4), group)
        b.box((x, y + 0.05, z + 0.02), (0.04, 0.05, 0.03), _OBJECT, body, 0.0, group)
    else:  # lamp
        b.cyl((x, y + 0.02, z), 0.07, 0.02, _OBJECT, mat, group=group)
        b.cyl((x, y + 0.2, z), 0.012, 0.18, _OBJECT, mat, group=group)
        b.cyl((x, y + 0.42, z), rng.uniform(0.08, 0.14), 0.08, _OBJECT,
              _Mat(_p_solid(rng, _c_grey(rng, 0.6, 0.95), 0.02), emit=rng.choice([0.0, 0.8])), group=group)


def _clutter(b: _Builder, rng, group, w, d, top, n):
    """n small objects on a top at height `top` (metres) of a w x d footprint."""
    for _ in range(n):
        x = rng.uniform(-0.4, 0.4) * w
        z = rng.uniform(-0.35, 0.35) * d
        _small_object(b, rng, x, top, z, group, min(w, d) * 0.5)


def _table(b, rng, group, w, d, h, round_=False):
    top_mat = _furniture_mat(rng)
    leg_mat = top_mat if rng.random() < 0.5 else _Mat(_p_solid(rng, _c_grey(rng, 0.03, 0.8), 0.02), spec=0.2)
    th = rng.uniform(0.02, 0.05)
    if round_:
        r = 0.5 * min(w, d)
        b.cyl((0, h - th / 2, 0), r, th / 2, _FURNITURE, top_mat, group=group)
        b.cyl((0, (h - th) / 2, 0), rng.uniform(0.03, 0.07), (h - th) / 2, _FURNITURE, leg_mat, group=group)
        b.cyl((0, 0.015, 0), r * 0.5, 0.015, _FURNITURE, leg_mat, group=group)
        w = d = r * 1.4
    else:
        b.box((0, h - th / 2, 0), (w / 2, th / 2, d / 2), _FURNITURE, top_mat, group=group)
        lw = rng.uniform(0.02, 0.045)
        lh = (h - th) / 2
        for sx in (-1, 1):
            for sz in (-1, 1):
                b.box((sx * (w / 2 - lw - 0.03), lh, sz * (d / 2 - lw - 0.03)), (lw, lh, lw), _FURNITURE, leg_mat,
                      group=group)
    _clutter(b, rng, group, w, d, h, int(rng.integers(0, 5)))


def _chair(b, rng, group, mat=None):
    mat = mat or _furniture_mat(rng)
    w = rng.uniform(0.4, 0.5)
    sh = rng.uniform(0.42, 0.48)
    lw = 0.018
    b.box((0, sh, 0), (w / 2, 0.025, w / 2), _FURNITURE, mat, group=group)
    bh = rng.uniform(0.3, 0.5)
    b.box((0, sh + bh / 2, w / 2 - 0.02), (w / 2, bh / 2, 0.02), _FURNITURE, mat, group=group)
    for sx in (-1, 1):
        for sz in (-1, 1):
            b.box((sx * (w / 2 - lw), sh / 2, sz * (w / 2 - lw)), (lw, sh / 2, lw), _FURNITURE, mat, group=group)


# ---------------------------------------------------------------- one builder per kind: (b, rng, group, w, d, h)

def _cabinet(b: _Builder, rng, group, w, d, h, kind="cabinet"):
    """A cabinet, dresser or wardrobe (one row of doors): a box with a front of doors / drawers; things on it when
    it is low."""
    mat = _furniture_mat(rng)
    cols = max(1, int(round(w / rng.uniform(0.4, 0.6))))
    rows = 1 if kind == "wardrobe" else int(rng.integers(1, 5))
    front = _Mat(_p_fronts(rng, mat.pattern, w, h, cols, rows, rng.choice([0.0, 0.08]),
                           mat.pattern(np.zeros(1, _F32), np.zeros(1, _F32), np.zeros(1, _F32))[:, :1] * 0.35,
                           _c_grey(rng, 0.05, 0.9)), spec=mat.spec)
    mat.faces = {4: front}
    b.box((0, h / 2, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)
    if h < 1.3:
        _clutter(b, rng, group, w, d, h, int(rng.integers(0, 4)))


def _shelf(b: _Builder, rng, group, w, d, h):
    mat = _furniture_mat(rng)
    shelf_c = mat.pattern(np.zeros(1, _F32), np.zeros(1, _F32), np.zeros(1, _F32))[:, :1]
    mat.faces = {4: _Mat(_p_books(rng, shelf_c, rng.uniform(0.28, 0.4), 0.025))}
    b.box((0, h / 2, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)


def _desk(b: _Builder, rng, group, w, d, h):
    _table(b, rng, group, w, d, rng.uniform(0.72, 0.78))
    if rng.random() < 0.6:  # its chair, in front, facing the desk
        cx_, _, cz_ = b.place(group, rng.uniform(-0.2, 0.2) * w, 0.0, -d / 2 - 0.25)
        _chair(b, rng, (cx_, cz_, group[2] + math.pi + rng.uniform(-0.4, 0.4)))


def _bed(b: _Builder, rng, group, w, d, h):
    frame = _furniture_mat(rng)
    fh = rng.uniform(0.15, 0.3)
    b.box((0, fh / 2, 0), (w / 2, fh / 2, d / 2), _FURNITURE, frame, group=group)
    mh = rng.uniform(0.15, 0.25)
    sheet = _Mat(_p_solid(rng, _c_fabric(rng), 0.03))
    cover_pat = [_rug(rng), _p_solid(rng, _c_fabric(rng), 0.05)][int(rng.integers(0, 2))]
    sheet.decals = [_Decal(-1.0, -1.0, 2 * w, d * rng.uniform(0.45, 0.8), _Mat(cover_pat))]  # a blanket
    b.box((0, fh + mh / 2, 0), (w / 2 - 0.03, mh / 2, d / 2 - 0.03), _FURNITURE, sheet, group=group)
    hb = rng.uniform(0.5, 1.1)
    b.box((0, hb / 2, d / 2 - 0.03), (w / 2, hb / 2, 0.03), _FURNITURE, frame, group=group)
    pm = _Mat(_p_solid(rng, _c_fabric(rng), 0.03))
    for sx in ((-0.25, 0.25) if w > 1.2 else (0.0,)):
        b.box((sx * w, fh + mh + 0.06, d / 2 - 0.3), (0.3 if w > 1.2 else 0.28, 0.06, 0.18), _OBJECT, pm,
              group=group)


def _sofa(b: _Builder, rng, group, w, d, h):
    """A sofa or an armchair: seat, back, two arms, sometimes cushions."""
    mat = _Mat(_p_noise(rng, c := _c_fabric(rng), c * 0.8, rng.uniform(8, 30), 2, 0.6))
    sh = rng.uniform(0.38, 0.46)
    aw = rng.uniform(0.1, 0.22)
    b.box((0, sh / 2, -0.05), (w / 2 - aw, sh / 2, d / 2 - 0.05), _FURNITURE, mat, group=group)
    bh = rng.uniform(0.75, 0.95)
    b.box((0, bh / 2, d / 2 - 0.1), (w / 2, bh / 2, 0.1), _FURNITURE, mat, group=group)
    ah = rng.uniform(0.5, 0.65)
    for sx in (-1, 1):
        b.box((sx * (w / 2 - aw / 2), ah / 2, 0), (aw / 2, ah / 2, d / 2), _FURNITURE, mat, group=group)
    if rng.random() < 0.6:
        pm = _Mat(_p_solid(rng, _c_fabric(rng), 0.04))
        for sx in rng.uniform(-0.35, 0.35, int(rng.integers(1, 3))):
            b.box((sx * w, sh + 0.18, d / 2 - 0.25), (0.2, 0.18, 0.06), _OBJECT, pm, rng.uniform(-0.3, 0.3), group)


def _counter(b: _Builder, rng, group, w, d, h):
    """A kitchen counter with its worktop, things on it, and often wall cabinets above."""
    mat = _furniture_mat(rng)
    fronts = _p_fronts(rng, mat.pattern, w, h, max(1, int(w / 0.55)), 1, 0.1, _c_grey(rng, 0.05, 0.3),
                       _c_grey(rng, 0.1, 0.9))
    mat.faces = {4: _Mat(fronts)}
    b.box((0, (h - 0.03) / 2, 0.02), (w / 2, (h - 0.03) / 2, d / 2 - 0.02), _FURNITURE, mat, group=group)
    top = _Mat(_p_noise(rng, c := _c_grey(rng, 0.1, 0.9), c * 0.7, rng.uniform(5, 20), 2, 0.8), spec=0.3)
    b.box((0, h - 0.015, 0), (w / 2 + 0.01, 0.015, d / 2), _FURNITURE, top, group=group)
    _clutter(b, rng, group, w, d, h, int(rng.integers(1, 5)))
    if rng.random() < 0.7:  # wall cabinets
        uh = rng.uniform(0.6, 0.9)
        b.box((0, 1.45 + uh / 2, d / 2 - 0.18), (w / 2, uh / 2, 0.18), _FURNITURE,
              _Mat(mat.pattern, faces={4: _Mat(_p_fronts(rng, mat.pattern, w, uh, max(1, int(w / 0.55)), 1, 0.0,
                                                         _c_grey(rng, 0.05, 0.3), _c_grey(rng, 0.1, 0.9)))}),
              group=group)


def _fridge(b: _Builder, rng, group, w, d, h):
    c = _c_grey(rng, 0.5, 0.95)
    mat = _Mat(_p_solid(rng, c, 0.01), spec=0.3, shin=40,
               faces={4: _Mat(_p_fronts(rng, _p_solid(rng, c, 0.01), w, h, 1, 2, 0.0, c * 0.4,
                                        _c_grey(rng, 0.1, 0.9)), spec=0.3)})
    b.box((0, h / 2, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)


def _tv(b: _Builder, rng, group, w, d, h):
    """A TV stand with a screen on it (sometimes on, showing a picture)."""
    stand_h = rng.uniform(0.4, 0.6)
    mat = _furniture_mat(rng)
    b.box((0, stand_h / 2, 0), (w / 2, stand_h / 2, d / 2), _FURNITURE, mat, group=group)
    tw = min(w * 0.9, rng.uniform(0.7, 1.4))
    th = tw * 0.58
    scr = _Mat(_p_solid(rng, _c_grey(rng, 0.01, 0.08), 0.02), spec=0.5, shin=60,
               decals=[_Decal(0.03, 0.04, 0.97, 0.97, _Mat(_p_poster(rng), emit=0.5), 4)]
               if rng.random() < 0.4 else [])
    b.box((0, stand_h + 0.05 + th / 2, d / 2 - 0.1), (tw / 2, th / 2, 0.03), _OBJECT, scr, group=group)


def _plant(b: _Builder, rng, group, w, d, h):
    pot = _Mat(_p_solid(rng, _c_any(rng), 0.03), spec=0.1)
    ph = rng.uniform(0.15, 0.35)
    pr = rng.uniform(0.12, 0.25)
    b.cyl((0, ph, 0), pr, ph, _OBJECT, pot, group=group)
    n = int(rng.integers(3, 8))
    top = 2 * ph
    cs = [(rng.normal(0, pr), top + rng.uniform(0.1, 0.9), rng.normal(0, pr)) for _ in range(n)]
    b.spheres(cs, rng.uniform(0.12, 0.3, n), _VEGETATION, _Mat(_p_foliage(rng)), group=group)


def _floor_lamp(b: _Builder, rng, group, w, d, h):
    mat = _Mat(_p_solid(rng, _c_grey(rng, 0.02, 0.9), 0.02), spec=0.3)
    hh = rng.uniform(1.3, 1.7)
    b.cyl((0, 0.015, 0), 0.15, 0.015, _FURNITURE, mat, group=group)
    b.cyl((0, hh / 2, 0), 0.015, hh / 2, _FURNITURE, mat, group=group)
    b.cyl((0, hh + 0.1, 0), rng.uniform(0.15, 0.25), 0.13, _FURNITURE,
          _Mat(_p_solid(rng, _c_wall(rng), 0.02), emit=rng.choice([0.0, 0.6])), group=group)


def _bin(b: _Builder, rng, group, w, d, h):
    r = min(w, d) / 2
    b.cyl((0, h / 2, 0), r, h / 2, _OBJECT, _Mat(_p_solid(rng, _c_any(rng), 0.03), spec=0.2), group=group)


def _boxes(b: _Builder, rng, group, w, d, h):
    """One to three boxes stacked, cardboard-coloured more often than not."""
    z = 0.0
    y = 0.0
    for _ in range(int(rng.integers(1, 4))):
        hh = rng.uniform(0.1, 0.3)
        c = _hsv(rng.uniform(0.07, 0.11), rng.uniform(0.3, 0.6), rng.uniform(0.35, 0.75)) \
            if rng.random() < 0.6 else _c_any(rng)
        b.box((rng.uniform(-0.05, 0.05), y + hh, z), (w / 2 * rng.uniform(0.7, 1), hh, d / 2 * rng.uniform(0.7, 1)),
              _OBJECT, _Mat(_p_solid(rng, c, 0.04)), rng.uniform(-0.3, 0.3), group)
        y += 2 * hh


def _ball(b: _Builder, rng, group, w, d, h):
    r = min(w, d) / 2
    b.spheres([(0, r, 0)], [r], _OBJECT, _Mat(_p_solid(rng, _c_any(rng), 0.03), spec=0.3), group=group)


def _dining_table(b: _Builder, rng, group, w, d, h):
    """A table (round three times in ten) with up to four chairs facing it."""
    _table(b, rng, group, w, d, rng.uniform(0.7, 0.78), round_=rng.random() < 0.3)
    cm = _furniture_mat(rng)
    for k in range(int(rng.integers(0, 5))):
        side = k % 4
        off = [(0, -d / 2 - 0.05), (0, d / 2 + 0.05), (-w / 2 - 0.05, 0), (w / 2 + 0.05, 0)][side]
        yaw_c = [math.pi, 0.0, -math.pi / 2, math.pi / 2][side]  # chairs face the table
        gx, _, gz = b.place(group, off[0] + rng.uniform(-0.15, 0.15), 0, off[1])
        _chair(b, rng, (gx, gz, group[2] + yaw_c + rng.uniform(-0.3, 0.3)), cm)


def _lone_chair(b: _Builder, rng, group, w, d, h):
    _chair(b, rng, group)


_BUILDERS = {
    "cabinet": _cabinet,
    "wardrobe": functools.partial(_cabinet, kind="wardrobe"),
    "dresser": _cabinet,
    "shelf": _shelf,
    "desk": _desk,
    "bed": _bed,
    "sofa": _sofa,
    "armchair": _sofa,
    "counter": _counter,
    "fridge": _fridge,
    "tv": _tv,
    "plant": _plant,
    "lamp": _floor_lamp,
    "bin": _bin,
    "boxes": _boxes,
    "ball": _ball,
    "table": _dining_table,
    "chair": _lone_chair,
}


def furniture(b: _Builder, rng, kind: str, group, w, d, h):
    """A piece of furniture of `kind` (see FurnitureKind) with its footprint (w along local x, d along local z)
    centred on the group origin, front towards local -z; one shadow caster."""
    with b.assembly():
        _BUILDERS[kind](b, rng, group, w, d, h)


@dataclasses.dataclass(frozen=True)
class FurnitureKind:
    """A kind of piece and the ranges its footprint and height are drawn from (metres), with its weight among the
    kinds of its table (relative frequency)."""

    kind: str
    width_m: tuple[float, float]
    depth_m: tuple[float, float]
    height_m: tuple[float, float]
    weight: float


# Furniture that stands against a wall, its back to it.
WALL_FURNITURE = (
    FurnitureKind("cabinet", (0.5, 1.6), (0.35, 0.6), (0.6, 1.2), 3),
    FurnitureKind("wardrobe", (0.8, 2.0), (0.5, 0.65), (1.8, 2.3), 1.5),
    FurnitureKind("dresser", (0.6, 1.4), (0.4, 0.55), (0.7, 1.1), 1.5),
    FurnitureKind("shelf", (0.6, 1.8), (0.25, 0.4), (0.8, 2.2), 2.5),
    FurnitureKind("desk", (0.9, 1.8), (0.5, 0.8), (0.75, 0.75), 2.5),
    FurnitureKind("bed", (0.9, 2.0), (1.9, 2.1), (0.5, 0.5), 1.2),
    FurnitureKind("sofa", (1.4, 2.4), (0.75, 0.95), (0.8, 0.8), 1.5),
    FurnitureKind("counter", (1.2, 3.5), (0.55, 0.65), (0.86, 0.94), 1.2),
    FurnitureKind("fridge", (0.6, 0.8), (0.6, 0.7), (1.6, 2.0), 0.6),
    FurnitureKind("tv", (1.0, 2.0), (0.35, 0.5), (0.5, 0.5), 1.0),
    FurnitureKind("plant", (0.4, 0.6), (0.4, 0.6), (1.0, 1.0), 1.0),
    FurnitureKind("lamp", (0.35, 0.35), (0.35, 0.35), (1.7, 1.7), 0.6),
    FurnitureKind("boxes", (0.3, 0.6), (0.3, 0.5), (0.5, 0.5), 0.8),
    FurnitureKind("bin", (0.25, 0.4), (0.25, 0.4), (0.3, 0.6), 0.6),
)
# Furniture that stands free in the room, at any yaw.
FREE_FURNITURE = (
    FurnitureKind("table", (0.8, 1.8), (0.7, 1.1), (0.75, 0.75), 3),
    FurnitureKind("chair", (0.5, 0.5), (0.5, 0.5), (0.9, 0.9), 2),
    FurnitureKind("armchair", (0.8, 1.0), (0.8, 0.9), (0.8, 0.8), 1),
    FurnitureKind("plant", (0.4, 0.6), (0.4, 0.6), (1.0, 1.0), 1),
    FurnitureKind("boxes", (0.3, 0.6), (0.3, 0.5), (0.5, 0.5), 1),
    FurnitureKind("ball", (0.15, 0.45), (0.15, 0.45), (0.3, 0.3), 0.5),
    FurnitureKind("bin", (0.25, 0.4), (0.25, 0.4), (0.3, 0.6), 0.7),
    FurnitureKind("lamp", (0.35, 0.35), (0.35, 0.35), (1.7, 1.7), 0.5),
)


def pick(rng, table: tuple[FurnitureKind, ...]) -> FurnitureKind:
    """One kind of a table, drawn by weight."""
    w = np.array([t.weight for t in table], dtype=np.float64)
    return table[int(rng.choice(len(table), p=w / w.sum()))]
