"""The materials of rooms: wall and floor finishes, rugs, furniture surfaces (random per frame)."""
from __future__ import annotations

import math

import numpy as np

from lipjax.data.synthetic.arrays import _set_cols
from lipjax.data.synthetic.colour import _c_any, _c_fabric, _c_furniture, _c_grey, _c_wall, _c_wood, _hsv
from lipjax.data.synthetic.constants import _F32
from lipjax.data.synthetic.materials import _Mat
from lipjax.data.synthetic.patterns import (
    Pattern,
    _p_checker,
    _p_noise,
    _p_solid,
    _p_stripes,
    _p_tiles,
    _p_wood,
    _with_mean,
)


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
