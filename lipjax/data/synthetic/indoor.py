"""The indoor scene builder: a room with furniture, clutter, decals, ceiling lights and an NYU-like camera."""
from __future__ import annotations

import math

import numpy as np

from lipjax.data.synthetic.arrays import _set_cols
from lipjax.data.synthetic.camera import _camera_model
from lipjax.data.synthetic.colour import (
    _c_any,
    _c_fabric,
    _c_furniture,
    _c_grey,
    _c_wall,
    _c_wood,
    _hsv,
)
from lipjax.data.synthetic.constants import (
    _CEILING,
    _F32,
    _FLOOR,
    _FURNITURE,
    _OBJECT,
    _VEGETATION,
    _WALL,
)
from lipjax.data.synthetic.materials import _Decal, _Mat
from lipjax.data.synthetic.patterns import (
    Pattern,
    _p_books,
    _p_checker,
    _p_foliage,
    _p_fronts,
    _p_noise,
    _p_poster,
    _p_solid,
    _p_stripes,
    _p_tiles,
    _p_window,
    _p_wood,
    _with_mean,
)
from lipjax.data.synthetic.primitives import _Box
from lipjax.data.synthetic.scene import _Builder, _camera_rotation, _Light, _Scene


def _wall_pattern(rng) -> tuple[Pattern, float]:
    r = rng.random()
    c = _c_wall(rng)
    if r < 0.62:
        return _p_solid(rng, c, rng.uniform(0.01, 0.06)), 0.0
    if r < 0.75:
        return _p_stripes(rng, c, c * rng.uniform(0.6, 0.95), rng.uniform(0.05, 0.4), rng.uniform(0.2, 0.8),
                          math.pi / 2), 0.0
    if r < 0.83:
        return _p_tiles(rng, _hsv(rng.uniform(0.0, 0.08), rng.uniform(0.3, 0.7), rng.uniform(0.3, 0.7)),
                        _c_grey(rng, 0.5, 0.85), 0.24, 0.075, 0.012, 0.12, 0.5), 0.0
    if r < 0.9:
        return _p_tiles(rng, _c_wall(rng), _c_grey(rng, 0.5, 0.9), rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.3),
                        0.004, 0.03), 0.15
    if r < 0.95:
        return _p_wood(rng, _c_wood(rng), _c_wood(rng) * 0.6, rng.uniform(0.1, 0.25), 5.0, along_v=True), 0.05
    return _p_noise(rng, c, c * rng.uniform(0.7, 0.95), rng.uniform(1, 6), 2, rng.uniform(0.5, 1.5)), 0.0


def _floor_pattern(rng) -> tuple[Pattern, float]:
    r = rng.random()
    if r < 0.4:
        c = _c_wood(rng)
        return _p_wood(rng, c, c * rng.uniform(0.45, 0.8), rng.uniform(0.08, 0.22), rng.uniform(0.8, 2.2)), 0.25
    if r < 0.62:
        s = rng.uniform(0.25, 0.7)
        c1 = _c_grey(rng, 0.35, 0.9) if rng.random() < 0.6 else _c_any(rng)
        if rng.random() < 0.2:
            return _p_checker(rng, c1, _c_grey(rng, 0.05, 0.6), s, 0.0), 0.2
        return _p_tiles(rng, c1, _c_grey(rng, 0.2, 0.8), s, s, 0.006, 0.08), 0.3
    if r < 0.88:
        c = _c_fabric(rng)
        return _p_noise(rng, c, c * rng.uniform(0.6, 0.9), rng.uniform(5, 25), 2, rng.uniform(0.5, 1.2)), 0.0
    c = _c_grey(rng, 0.3, 0.7)
    return _p_noise(rng, c, c * 0.75, rng.uniform(0.5, 3), 2, 0.8), 0.1


def _rug(rng) -> Pattern:
    c1, c2 = _c_fabric(rng), _c_fabric(rng)
    r = rng.random()
    if r < 0.35:
        inner = _p_stripes(rng, c1, c2, rng.uniform(0.03, 0.25), rng.uniform(0.3, 0.7), rng.choice([0.0, math.pi / 2]))
    elif r < 0.55:
        inner = _p_checker(rng, c1, c2, rng.uniform(0.05, 0.2), 0.0)
    else:
        inner = _p_noise(rng, c1, c2, rng.uniform(4, 20), 2, rng.uniform(0.6, 2.0))
    border = rng.uniform(0.0, 0.1)
    bc = _c_fabric(rng)

    def fn(u, v, fp):
        out = np.array(inner(u, v, fp), dtype=_F32)
        if border > 0:
            m = (u < border) | (u > 1 - border) | (v < border) | (v > 1 - border)
            _set_cols(out, m, bc)
        return out

    return _with_mean(fn, 0.5 * (c1 + c2))


def _furniture_mat(rng, fronts=None) -> _Mat:
    c = _c_furniture(rng)
    if rng.random() < 0.55 and c[0, 0] > c[2, 0] * 1.3:  # woody colour: wood grain
        pat = _p_wood(rng, c, c * rng.uniform(0.5, 0.8), rng.uniform(0.15, 0.5), rng.uniform(0.6, 2.0), gap=0.0)
    else:
        pat = _p_solid(rng, c, rng.uniform(0.01, 0.05))
    return _Mat(pat, spec=rng.choice([0.0, 0.0, 0.05, 0.15]), shin=rng.uniform(10, 60))


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


def _indoor_item(b: _Builder, rng, kind, group, w, d, h):
    """A piece of furniture with its footprint (w along local x, d along local z) centred on the group
    origin, front towards local -z."""
    with b.assembly():
        _indoor_item_parts(b, rng, kind, group, w, d, h)


def _indoor_item_parts(b: _Builder, rng, kind, group, w, d, h):
    if kind in ("cabinet", "wardrobe", "dresser"):
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
    elif kind == "shelf":
        mat = _furniture_mat(rng)
        shelf_c = mat.pattern(np.zeros(1, _F32), np.zeros(1, _F32), np.zeros(1, _F32))[:, :1]
        mat.faces = {4: _Mat(_p_books(rng, shelf_c, rng.uniform(0.28, 0.4), 0.025))}
        b.box((0, h / 2, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)
    elif kind == "desk":
        _table(b, rng, group, w, d, rng.uniform(0.72, 0.78))
        if rng.random() < 0.6:  # its chair, in front, facing the desk
            cx_, _, cz_ = b.place(group, rng.uniform(-0.2, 0.2) * w, 0.0, -d / 2 - 0.25)
            _chair(b, rng, (cx_, cz_, group[2] + math.pi + rng.uniform(-0.4, 0.4)))
    elif kind == "bed":
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
    elif kind == "sofa":
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
    elif kind == "counter":
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
    elif kind == "fridge":
        c = _c_grey(rng, 0.5, 0.95)
        mat = _Mat(_p_solid(rng, c, 0.01), spec=0.3, shin=40,
                   faces={4: _Mat(_p_fronts(rng, _p_solid(rng, c, 0.01), w, h, 1, 2, 0.0, c * 0.4,
                                            _c_grey(rng, 0.1, 0.9)), spec=0.3)})
        b.box((0, h / 2, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)
    elif kind == "tv":
        stand_h = rng.uniform(0.4, 0.6)
        mat = _furniture_mat(rng)
        b.box((0, stand_h / 2, 0), (w / 2, stand_h / 2, d / 2), _FURNITURE, mat, group=group)
        tw = min(w * 0.9, rng.uniform(0.7, 1.4))
        th = tw * 0.58
        scr = _Mat(_p_solid(rng, _c_grey(rng, 0.01, 0.08), 0.02), spec=0.5, shin=60,
                   decals=[_Decal(0.03, 0.04, 0.97, 0.97, _Mat(_p_poster(rng), emit=0.5), 4)]
                   if rng.random() < 0.4 else [])
        b.box((0, stand_h + 0.05 + th / 2, d / 2 - 0.1), (tw / 2, th / 2, 0.03), _OBJECT, scr, group=group)
    elif kind == "plant":
        pot = _Mat(_p_solid(rng, _c_any(rng), 0.03), spec=0.1)
        ph = rng.uniform(0.15, 0.35)
        pr = rng.uniform(0.12, 0.25)
        b.cyl((0, ph, 0), pr, ph, _OBJECT, pot, group=group)
        n = int(rng.integers(3, 8))
        top = 2 * ph
        cs = [(rng.normal(0, pr), top + rng.uniform(0.1, 0.9), rng.normal(0, pr)) for _ in range(n)]
        b.spheres(cs, rng.uniform(0.12, 0.3, n), _VEGETATION, _Mat(_p_foliage(rng)), group=group)
    elif kind == "lamp":
        mat = _Mat(_p_solid(rng, _c_grey(rng, 0.02, 0.9), 0.02), spec=0.3)
        hh = rng.uniform(1.3, 1.7)
        b.cyl((0, 0.015, 0), 0.15, 0.015, _FURNITURE, mat, group=group)
        b.cyl((0, hh / 2, 0), 0.015, hh / 2, _FURNITURE, mat, group=group)
        b.cyl((0, hh + 0.1, 0), rng.uniform(0.15, 0.25), 0.13, _FURNITURE,
              _Mat(_p_solid(rng, _c_wall(rng), 0.02), emit=rng.choice([0.0, 0.6])), group=group)
    elif kind == "bin":
        r = min(w, d) / 2
        b.cyl((0, h / 2, 0), r, h / 2, _OBJECT, _Mat(_p_solid(rng, _c_any(rng), 0.03), spec=0.2), group=group)
    elif kind == "boxes":
        z = 0.0
        y = 0.0
        for _ in range(int(rng.integers(1, 4))):
            hh = rng.uniform(0.1, 0.3)
            c = _hsv(rng.uniform(0.07, 0.11), rng.uniform(0.3, 0.6), rng.uniform(0.35, 0.75)) \
                if rng.random() < 0.6 else _c_any(rng)
            b.box((rng.uniform(-0.05, 0.05), y + hh, z), (w / 2 * rng.uniform(0.7, 1), hh, d / 2 * rng.uniform(0.7, 1)),
                  _OBJECT, _Mat(_p_solid(rng, c, 0.04)), rng.uniform(-0.3, 0.3), group)
            y += 2 * hh
    elif kind == "ball":
        r = min(w, d) / 2
        b.spheres([(0, r, 0)], [r], _OBJECT, _Mat(_p_solid(rng, _c_any(rng), 0.03), spec=0.3), group=group)
    elif kind == "table":
        _table(b, rng, group, w, d, rng.uniform(0.7, 0.78), round_=rng.random() < 0.3)
        cm = _furniture_mat(rng)
        for k in range(int(rng.integers(0, 5))):
            side = k % 4
            off = [(0, -d / 2 - 0.05), (0, d / 2 + 0.05), (-w / 2 - 0.05, 0), (w / 2 + 0.05, 0)][side]
            yaw_c = [math.pi, 0.0, -math.pi / 2, math.pi / 2][side]  # chairs face the table
            gx, _, gz = b.place(group, off[0] + rng.uniform(-0.15, 0.15), 0, off[1])
            _chair(b, rng, (gx, gz, group[2] + yaw_c + rng.uniform(-0.3, 0.3)), cm)
    elif kind == "chair":
        _chair(b, rng, group)
    elif kind == "armchair":
        _indoor_item_parts(b, rng, "sofa", group, w, d, h)


# (kind, width range, depth range, height range, weight) for furniture against walls and in the room
_WALL_ITEMS = (
    ("cabinet", (0.5, 1.6), (0.35, 0.6), (0.6, 1.2), 3),
    ("wardrobe", (0.8, 2.0), (0.5, 0.65), (1.8, 2.3), 1.5),
    ("dresser", (0.6, 1.4), (0.4, 0.55), (0.7, 1.1), 1.5),
    ("shelf", (0.6, 1.8), (0.25, 0.4), (0.8, 2.2), 2.5),
    ("desk", (0.9, 1.8), (0.5, 0.8), (0.75, 0.75), 2.5),
    ("bed", (0.9, 2.0), (1.9, 2.1), (0.5, 0.5), 1.2),
    ("sofa", (1.4, 2.4), (0.75, 0.95), (0.8, 0.8), 1.5),
    ("counter", (1.2, 3.5), (0.55, 0.65), (0.86, 0.94), 1.2),
    ("fridge", (0.6, 0.8), (0.6, 0.7), (1.6, 2.0), 0.6),
    ("tv", (1.0, 2.0), (0.35, 0.5), (0.5, 0.5), 1.0),
    ("plant", (0.4, 0.6), (0.4, 0.6), (1.0, 1.0), 1.0),
    ("lamp", (0.35, 0.35), (0.35, 0.35), (1.7, 1.7), 0.6),
    ("boxes", (0.3, 0.6), (0.3, 0.5), (0.5, 0.5), 0.8),
    ("bin", (0.25, 0.4), (0.25, 0.4), (0.3, 0.6), 0.6),
)
_ROOM_ITEMS = (
    ("table", (0.8, 1.8), (0.7, 1.1), (0.75, 0.75), 3),
    ("chair", (0.5, 0.5), (0.5, 0.5), (0.9, 0.9), 2),
    ("armchair", (0.8, 1.0), (0.8, 0.9), (0.8, 0.8), 1),
    ("plant", (0.4, 0.6), (0.4, 0.6), (1.0, 1.0), 1),
    ("boxes", (0.3, 0.6), (0.3, 0.5), (0.5, 0.5), 1),
    ("ball", (0.15, 0.45), (0.15, 0.45), (0.3, 0.3), 0.5),
    ("bin", (0.25, 0.4), (0.25, 0.4), (0.3, 0.6), 0.7),
    ("lamp", (0.35, 0.35), (0.35, 0.35), (1.7, 1.7), 0.5),
)


def _pick(rng, table):
    w = np.array([t[-1] for t in table], dtype=np.float64)
    return table[int(rng.choice(len(table), p=w / w.sum()))]


def _indoor_scene(rng) -> _Scene:
    b = _Builder(rng)
    W, L, Hc = rng.uniform(3.0, 7.0), rng.uniform(3.5, 8.5), rng.uniform(2.4, 3.2)

    # Room surfaces: face 0 / 1 left / right wall (x = 0 / W), 2 floor, 3 ceiling, 4 / 5 near / far wall.
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
    room_mat = _Mat(_p_solid(rng, np.ones((3, 1), _F32), 0), faces={**walls, 2: floor, 3: ceil})
    wall_len = {0: L, 1: L, 4: W, 5: W}

    # Decals: colour edges that are not depth edges.
    if rng.random() < 0.6:  # skirting board
        bh = rng.uniform(0.05, 0.14)
        bm = _Mat(_p_solid(rng, _c_wood(rng) if rng.random() < 0.5 else _c_grey(rng, 0.1, 0.95), 0.02), spec=0.1)
        for f, m in walls.items():
            m.decals.append(_Decal(-0.01, -0.01, wall_len[f] + 0.01, bh, bm))
    if rng.random() < 0.15:  # wainscoting / tiled lower half
        wh = rng.uniform(0.8, 1.3)
        wm = _Mat(_wall_pattern(rng)[0])
        for f, m in walls.items():
            m.decals.insert(0, _Decal(-0.01, -0.01, wall_len[f] + 0.01, wh, wm))
    for _ in range(int(rng.integers(0, 3))):  # windows
        f = int(rng.choice([0, 1, 5]))
        ww, wh = rng.uniform(0.6, min(2.4, wall_len[f] - 0.4)), rng.uniform(0.9, 1.7)
        u0 = rng.uniform(0.1, wall_len[f] - ww - 0.1)
        v0 = rng.uniform(0.6, max(0.61, Hc - wh - 0.2))
        walls[f].decals.append(_Decal(u0, v0, u0 + ww, v0 + wh, _Mat(_p_window(rng), emit=rng.uniform(1.5, 4.0))))
        if rng.random() < 0.5:  # curtains
            cm = _Mat(_p_stripes(rng, c := _c_fabric(rng), c * 0.75, rng.uniform(0.05, 0.15), 0.5, 0.0))
            cw = rng.uniform(0.25, 0.5)
            top = min(Hc - 0.05, v0 + wh + 0.25)
            walls[f].decals.append(_Decal(u0 - cw * 0.6, 0.05, u0 + cw * 0.4, top, cm))
            walls[f].decals.append(_Decal(u0 + ww - cw * 0.4, 0.05, u0 + ww + cw * 0.6, top, cm))
    if rng.random() < 0.6:  # door
        f = int(rng.choice([0, 1, 4, 5]))
        dw = rng.uniform(0.75, 1.0)
        u0 = rng.uniform(0.1, wall_len[f] - dw - 0.1)
        c = _c_wood(rng) if rng.random() < 0.5 else _c_wall(rng)
        panels = _p_fronts(rng, _p_solid(rng, c, 0.02), 1.0, 1.0, 1, int(rng.integers(1, 3)), 0.0, c * 0.6,
                           _c_grey(rng, 0.1, 0.9))
        walls[f].decals.append(_Decal(u0, 0.0, u0 + dw, rng.uniform(1.98, 2.1), _Mat(panels, spec=0.1)))
    for f in (0, 1, 5, 4):  # posters, paintings, boards, clocks
        for _ in range(int(rng.integers(0, 4))):
            pw = rng.uniform(0.2, 1.2)
            ph = pw * rng.uniform(0.5, 1.5)
            if pw > wall_len[f] - 0.2 or ph > Hc - 1.0:
                continue
            u0 = rng.uniform(0.1, wall_len[f] - pw - 0.1)
            v0 = rng.uniform(0.9, Hc - ph - 0.05)
            walls[f].decals.append(_Decal(u0, v0, u0 + pw, v0 + ph, _Mat(_p_poster(rng), spec=0.1)))
    if rng.random() < 0.15:  # whiteboard / blackboard
        f = int(rng.choice([0, 1, 5]))
        bw = rng.uniform(1.2, min(3.5, wall_len[f] - 0.4))
        u0 = rng.uniform(0.2, wall_len[f] - bw - 0.2)
        board = _c_grey(rng, 0.85, 0.97) if rng.random() < 0.7 else _hsv(rng.uniform(0.3, 0.45), 0.4, 0.2)
        walls[f].decals.append(_Decal(u0, 0.9, u0 + bw, 2.0, _Mat(_p_poster(rng) if rng.random() < 0.3 else
                                                                   _p_noise(rng, board, board * 0.85, 3, 2, 0.5),
                                                                   spec=0.3)))
    for _ in range(int(rng.integers(0, 3)) if rng.random() < 0.6 else 0):  # rugs
        rw, rl = rng.uniform(0.8, min(3.0, W - 0.4)), rng.uniform(0.8, min(4.0, L - 0.4))
        x0, z0 = rng.uniform(0.2, W - rw - 0.2), rng.uniform(0.2, L - rl - 0.2)
        floor.decals.append(_Decal(x0, z0, x0 + rw, z0 + rl, _Mat(_rug(rng))))
    for _ in range(int(rng.integers(0, 5))):  # ceiling light panels
        s = rng.uniform(0.3, 0.7)
        x0, z0 = rng.uniform(0.2, W - s - 0.2), rng.uniform(0.2, L - s - 0.2)
        ceil.decals.append(_Decal(x0, z0, x0 + s, z0 + s * rng.choice([1.0, 2.0]),
                                  _Mat(_p_solid(rng, _c_grey(rng, 0.85, 1.0), 0.0), emit=rng.uniform(1.0, 3.0))))

    room_labels = np.array([_WALL, _WALL, _FLOOR, _CEILING, _WALL, _WALL], dtype=np.int8)
    room = _Box((W / 2, Hc / 2, L / 2), (W / 2, Hc / 2, L / 2), room_labels, room_mat, inside=True, cast=False)
    b.prims.append(room)

    # Camera, near one end of the room looking in.
    cam_h = rng.uniform(0.95, min(1.75, Hc - 0.45))
    cam = np.array([rng.uniform(0.3, 0.7) * W, cam_h, rng.uniform(0.35, min(1.6, 0.3 * L))])
    yaw, pitch, roll = rng.uniform(-0.6, 0.6), rng.uniform(-0.45, 0.08), rng.normal(0.0, 0.02)
    R = _camera_rotation(yaw, pitch, roll)

    # Furniture. Footprints (x0, x1, z0, z1) must not overlap each other or the camera's surroundings.
    taken = [(cam[0] - 0.7, cam[0] + 0.7, cam[2] - 0.9, cam[2] + 0.7)]

    def free(x0, x1, z0, z1):
        return x0 > 0.0 and z0 > 0.0 and x1 < W and z1 < L and all(
            x1 <= a0 or x0 >= a1 or z1 <= b0 or z0 >= b1 for a0, a1, b0, b1 in taken)

    n_wall = int(rng.integers(3, 11))
    for _ in range(n_wall):
        kind, wr, dr, hr, _w = _pick(rng, _WALL_ITEMS)
        for _try in range(6):
            f = int(rng.choice([0, 1, 5, 4], p=[0.3, 0.3, 0.35, 0.05]))
            w, d, h = rng.uniform(*wr), rng.uniform(*dr), rng.uniform(*hr)
            h = min(h, Hc - 0.15)
            if w > wall_len[f] - 0.1:
                continue
            s = rng.uniform(w / 2 + 0.02, wall_len[f] - w / 2 - 0.02)
            gap = 0.005
            if f == 0:
                gx, gz, gyaw, fx, fz = d / 2 + gap, s, -math.pi / 2, d, w
            elif f == 1:
                gx, gz, gyaw, fx, fz = W - d / 2 - gap, s, math.pi / 2, d, w
            elif f == 5:
                gx, gz, gyaw, fx, fz = s, L - d / 2 - gap, 0.0, w, d
            else:
                gx, gz, gyaw, fx, fz = s, d / 2 + gap, math.pi, w, d
            # the desk's chair stands in front of it
            extra = 0.6 if kind == "desk" else 0.0
            fx2 = fx + (extra if f in (0, 1) else 0)
            fz2 = fz + (extra if f in (4, 5) else 0)
            x0 = gx - fx / 2 - (extra if f == 1 else 0)
            z0 = gz - fz / 2 - (extra if f == 5 else 0)
            if not free(x0, x0 + fx2, z0, z0 + fz2):
                continue
            taken.append((x0, x0 + fx2, z0, z0 + fz2))
            _indoor_item(b, rng, kind, (gx, gz, gyaw), w, d, h)
            break
    for _ in range(int(rng.integers(1, 6))):
        kind, wr, dr, hr, _w = _pick(rng, _ROOM_ITEMS)
        w, d, h = rng.uniform(*wr), rng.uniform(*dr), rng.uniform(*hr)
        margin = 0.65 if kind == "table" else 0.1
        for _try in range(6):
            gx, gz = rng.uniform(0.2, W - 0.2), rng.uniform(0.2, L - 0.2)
            r = 0.5 * math.hypot(w, d) + margin
            if not free(gx - r, gx + r, gz - r, gz + r):
                continue
            taken.append((gx - r, gx + r, gz - r, gz + r))
            _indoor_item(b, rng, kind, (gx, gz, rng.uniform(-math.pi, math.pi)), w, d, h)
            break
    for _ in range(int(rng.integers(0, 3))):  # frames / shelves / wall-mounted cabinets sticking out a bit
        f = int(rng.choice([0, 1, 5]))
        w, h, d = rng.uniform(0.3, 1.2), rng.uniform(0.2, 0.9), rng.uniform(0.02, 0.3)
        if w > wall_len[f] - 0.3:
            continue
        s = rng.uniform(w / 2 + 0.1, wall_len[f] - w / 2 - 0.1)
        y = rng.uniform(1.2, Hc - h / 2 - 0.1)
        group = {0: (d / 2, s, -math.pi / 2), 1: (W - d / 2, s, math.pi / 2), 5: (s, L - d / 2, 0.0)}[f]
        mat = _furniture_mat(rng)
        if d < 0.08:
            mat.faces = {4: _Mat(_p_poster(rng), spec=0.15)}
        b.box((0, y, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)

    # Lights: one or two ceiling point lights + ambient.
    lights = []
    for _ in range(int(rng.integers(1, 3))):
        pos = (rng.uniform(0.2, 0.8) * W, Hc - rng.uniform(0.15, 0.5), rng.uniform(0.3, 0.95) * L)
        temp = _hsv(rng.uniform(0.06, 0.15), rng.uniform(0.0, 0.35), 1.0) if rng.random() < 0.7 else \
            _hsv(rng.uniform(0.5, 0.65), rng.uniform(0.0, 0.2), 1.0)
        lights.append(_Light(temp * rng.uniform(1.5, 3.5), position=pos, r0=rng.uniform(1.5, 4.0),
                             shadow_blur=int(rng.integers(1, 4))))
    ambient = _hsv(rng.uniform(0.0, 1.0), rng.uniform(0.0, 0.15), 1.0) * rng.uniform(0.12, 0.4)

    return _Scene(
        prims=b.prims, cam_pos=cam, cam_R=R, lights=lights, ambient=ambient, ambient_up=rng.uniform(0.0, 0.3),
        extent=math.sqrt(W * W + L * L + Hc * Hc), **_camera_model(rng))
