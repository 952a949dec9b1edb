"""Procedural texture patterns shared by the scene builders.

A pattern is fn(u, v, fp) -> (3, n) float32 linear albedo; u, v surface coordinates (metres on surfaces,
[0, 1] inside decals), fp the pixel footprint in the same units. A pattern may instead return
(albedo, emission_weight) to make only part of a decal emissive (window glass but not its frame).
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from lipjax.data.synthetic.arrays import _cols, _set_cols
from lipjax.data.synthetic.colour import _c_any, _c_fabric, _c_grey, _c_wood, _hsv, _mix
from lipjax.data.synthetic.constants import _F32
from lipjax.data.synthetic.noise import _box, _fbm, _frac, _hash, _square, _vnoise

Pattern = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


def _with_mean(fn: Pattern, mean) -> Pattern:
    """Attaches a representative colour (3, 1): objects covering a few pixels are shaded with it."""
    fn.mean = np.asarray(mean, _F32).reshape(3, 1)
    return fn


def _mean_of(fn: Pattern) -> np.ndarray:
    m = getattr(fn, "mean", None)
    return m if m is not None else np.full((3, 1), 0.3, _F32)


def _p_solid(rng, c, amp=0.06) -> Pattern:
    ox, oy, f = rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0.8, 3.0)

    def fn(u, v, fp):
        if amp <= 0 or u.shape[0] < 200:  # a few pixels: the subtle variation would not show
            return np.broadcast_to(c, (3, u.shape[0]))
        n = _vnoise(u * f + ox, v * f + oy)
        return c * (1.0 + 2.0 * amp * (n - 0.5))

    return _with_mean(fn, c)


def _p_noise(rng, c1, c2, freq, octaves=2, contrast=1.0, stretch=1.0) -> Pattern:
    ox, oy = rng.uniform(0, 256), rng.uniform(0, 256)

    def fn(u, v, fp):
        n = _fbm(u * (freq * stretch) + ox, v * freq + oy, octaves, fp * (freq * stretch))
        return _mix(c1, c2, np.clip(0.5 + (n - 0.5) * (2.0 * contrast), 0.0, 1.0))

    return _with_mean(fn, 0.5 * (c1 + c2))


def _p_stripes(rng, c1, c2, period, duty=0.5, angle=0.0, amp=0.04) -> Pattern:
    ca, sa = math.cos(angle), math.sin(angle)
    base = _p_solid(rng, np.ones((3, 1), _F32), amp)

    def fn(u, v, fp):
        w = _square(u * ca + v * sa, period, duty, fp)
        return _mix(c2, c1, w) * base(u, v, fp)

    return _with_mean(fn, duty * c1 + (1.0 - duty) * c2)


def _p_checker(rng, c1, c2, period, angle=0.0, amp=0.04) -> Pattern:
    ca, sa = math.cos(angle), math.sin(angle)
    base = _p_solid(rng, np.ones((3, 1), _F32), amp)

    def fn(u, v, fp):
        a = _square(u * ca + v * sa, 2 * period, 0.5, fp)
        b = _square(v * ca - u * sa, 2 * period, 0.5, fp)
        return _mix(c1, c2, a + b - 2 * a * b) * base(u, v, fp)

    return _with_mean(fn, 0.5 * (c1 + c2))


def _p_tiles(rng, c_tile, c_grout, su, sv, grout, var=0.08, offset=0.0, amp=0.05) -> Pattern:
    """Tiles / bricks / slabs: grout lines every (su, sv); rows shifted by offset * su (bricks: 0.5)."""
    o1, o2 = int(rng.integers(0, 256)), int(rng.integers(0, 256))
    base = _p_solid(rng, np.ones((3, 1), _F32), amp)

    def fn(u, v, fp):
        row = np.floor(v * (1.0 / sv))
        uu = u + row * (offset * su)
        col = np.floor(uu * (1.0 / su))
        g = np.maximum(_square(uu, su, grout / su, fp), _square(v, sv, grout / sv, fp))
        h = _hash(col + o1, row + o2)
        tile = c_tile * (1.0 + 2.0 * var * (h - 0.5)) * base(u, v, fp)
        return tile + (c_grout - tile) * g

    return _with_mean(fn, c_tile)


def _p_wood(rng, c_light, c_dark, plank_w, plank_len, along_v=False, gap=0.004) -> Pattern:
    f_ring = rng.uniform(4.0, 14.0)
    o1 = rng.uniform(0, 100)

    def fn(u, v, fp):
        if along_v:
            u, v = v, u
        row = np.floor(v * (1.0 / plank_w))
        uu = u + _hash(row, 7.0) * plank_len + o1
        col = np.floor(uu * (1.0 / plank_len))
        hp = _hash(col, row)
        grain = _vnoise(uu * 1.3 + hp * 50.0, v * 30.0 + row * 3.1)
        grain = 0.5 + (grain - 0.5) * np.clip(1.5 - 60.0 * fp, 0.0, 1.0)
        ring = _frac(v * f_ring + grain * 2.0 + hp * 5.0)
        w = np.abs(ring - 0.5) * 1.2 + grain * 0.4
        w = 0.5 + (w - 0.5) * np.clip(1.5 - 2.0 * f_ring * fp, 0.0, 1.0)
        col_ = _mix(c_dark, c_light, np.minimum(np.maximum(w, 0.0), 1.0)) * (0.8 + 0.4 * hp)
        g = np.maximum(_square(v, plank_w, gap / plank_w, fp), _square(uu, plank_len, gap / plank_len, fp))
        return col_ * (1.0 - 0.45 * g)

    return _with_mean(fn, 0.5 * (c_light + c_dark))


def _p_books(rng, c_shelf, shelf_h, board) -> Pattern:
    """Bookshelf front: boards every shelf_h, books of random width, height and colour."""
    palette = np.concatenate([_c_fabric(rng) for _ in range(8)], axis=1)  # (3, 8)
    back = _c_grey(rng, 0.03, 0.15)
    o1 = int(rng.integers(0, 256))

    def fn(u, v, fp):
        shelf = np.floor(v * (1.0 / shelf_h))
        vv = v - shelf * shelf_h
        col = np.floor(u * 28.0 + _hash(shelf, 3.0) * 9.0)
        h1 = _hash(col + o1, shelf)
        h2 = _hash(col + 101.0, shelf + 57.0)
        book = _cols(palette, (h1 * 7.999).astype(np.int32)) * (0.55 + 0.6 * h2)
        top = board + (shelf_h - board) * (0.5 + 0.4 * h2)
        present = (vv < top) & (h1 > 0.12)
        out = np.where(present, book, back)
        return np.where(vv < board, c_shelf, out)

    return _with_mean(fn, 0.7 * palette.mean(axis=1, keepdims=True))


def _p_fronts(rng, body: Pattern, w, h, cols, rows, plinth, gap_c, handle_c) -> Pattern:
    """Cabinet / drawer fronts on a face of width w, height h (metres): split lines and handles."""
    cw = w / cols
    rh = (h - plinth) / rows
    vertical_handles = rng.random() < 0.5

    def fn(u, v, fp):
        out = np.array(body(u, v, fp), dtype=_F32)
        lines = np.maximum(_square(u + 0.004, cw, 0.008 / cw, fp), _square(v - plinth + 0.004, rh, 0.008 / rh, fp))
        lines = np.where(v < plinth, 0.6, lines)
        out = out + (gap_c - out) * lines
        cu = _frac(u / cw) * cw
        cv = _frac((v - plinth) / rh) * rh
        if vertical_handles:
            hm = (np.abs(cu - (cw - 0.05)) < 0.012) & (np.abs(cv - rh * 0.55) < min(0.08, rh * 0.3))
        else:
            hm = (np.abs(cu - cw * 0.5) < min(0.07, cw * 0.3)) & (np.abs(cv - (rh - 0.06)) < 0.012)
        hm &= v > plinth
        _set_cols(out, hm, handle_c)
        return out

    return _with_mean(fn, _mean_of(body))


def _p_poster(rng) -> Pattern:
    """A picture / poster / document in [0, 1]^2 decal coordinates, often with a frame."""
    kind = int(rng.integers(0, 4))
    frame = rng.random() < 0.65
    fw = rng.uniform(0.03, 0.09)
    fc = [_c_grey(rng, 0.02, 0.15), _c_grey(rng, 0.8, 0.95), _c_wood(rng)][int(rng.integers(0, 3))]
    if kind == 0:  # painting / photo: a landscape-like gradient with noisy blobs
        top, bot, blob = _c_any(rng), _c_any(rng), _c_any(rng)
        inner = _p_noise(rng, top, bot, rng.uniform(2, 6), 3, rng.uniform(0.8, 2.0))
        horizon = rng.uniform(0.3, 0.7)

        def base(u, v, fp):
            out = inner(u, v, fp)
            m = v < horizon
            m = np.flatnonzero(m)
            _set_cols(out, m, _cols(out, m) * 0.5 + blob * 0.5)
            return out
    elif kind == 1:  # geometric shapes
        bg = _c_any(rng)
        shapes = []
        for _ in range(int(rng.integers(2, 7))):
            x0, y0 = rng.uniform(0, 0.8), rng.uniform(0, 0.8)
            shapes.append((rng.random() < 0.5, x0, y0, x0 + rng.uniform(0.1, 0.6), y0 + rng.uniform(0.1, 0.6),
                           _c_any(rng)))

        def base(u, v, fp):
            out = np.empty((3, u.shape[0]), _F32)
            out[:] = bg
            for circle, x0, y0, x1, y1, c in shapes:
                if circle:
                    r = 0.5 * (x1 - x0)
                    m = (u - 0.5 * (x0 + x1)) ** 2 + (v - 0.5 * (y0 + y1)) ** 2 < r * r
                else:
                    m = _box(u, v, x0, y0, x1, y1)
                _set_cols(out, m, c)
            return out
    elif kind == 2:  # document / notice: paper, a title band, lines of text
        paper = _hsv(rng.uniform(0.1, 0.15), rng.uniform(0, 0.1), rng.uniform(0.82, 0.97))
        ink = _c_grey(rng, 0.02, 0.25)
        title = _c_any(rng)
        pitch = rng.uniform(0.04, 0.09)

        def base(u, v, fp):
            out = np.empty((3, u.shape[0]), _F32)
            out[:] = paper
            line = np.floor(v / pitch)
            length = 0.3 + 0.55 * _hash(line, 11.0)
            text = (_frac(v / pitch) < 0.45) & (u > 0.1) & (u < 0.1 + length) & (v < 0.8)
            text &= _hash(u * 40.0, line) > 0.25
            _set_cols(out, text, ink)
            _set_cols(out, v > 0.84, title)
            return out
    else:  # bands / stripes
        base = _p_stripes(rng, _c_any(rng), _c_any(rng), rng.uniform(0.05, 0.3), rng.uniform(0.2, 0.8),
                          rng.uniform(0, math.pi))

    def fn(u, v, fp):
        out = np.array(base(u, v, fp), dtype=_F32)
        if frame:
            m = (u < fw) | (u > 1 - fw) | (v < fw) | (v > 1 - fw)
            _set_cols(out, m, fc)
        return out

    return _with_mean(fn, _mean_of(base))


def _p_window(rng) -> Pattern:
    """Indoor window: a bright outside view (sky, trees / buildings) behind a frame and mullions.
    Returns (albedo, emission weight): only the glass glows."""
    sky = _hsv(rng.uniform(0.52, 0.62), rng.uniform(0.0, 0.35), rng.uniform(0.85, 1.0))
    ground = _p_noise(rng, _hsv(rng.uniform(0.15, 0.35), rng.uniform(0.2, 0.6), rng.uniform(0.3, 0.7)),
                      _c_grey(rng, 0.4, 0.8), rng.uniform(3, 10), 3, 1.2)
    horizon = rng.uniform(0.0, 0.6)
    fc = _c_grey(rng, 0.05, 0.95) if rng.random() < 0.5 else _c_wood(rng)
    fw = rng.uniform(0.03, 0.07)
    mull_v = rng.random() < 0.7
    mull_h = rng.uniform(0.3, 0.75) if rng.random() < 0.5 else -1.0
    blind = rng.random() < 0.25
    blind_c = _c_grey(rng, 0.6, 0.95)

    def fn(u, v, fp):
        out = np.empty((3, u.shape[0]), _F32)
        out[:] = sky
        below = v < horizon + 0.1 * np.sin(u * 9.0)
        if below.any():
            _set_cols(out, below, ground(u[below], v[below], fp[below]))
        glass = ~((u < fw) | (u > 1 - fw) | (v < fw) | (v > 1 - fw))
        if mull_v:
            glass &= np.abs(u - 0.5) > fw * 0.5
        if mull_h > 0:
            glass &= np.abs(v - mull_h) > fw * 0.5
        _set_cols(out, ~glass, fc)
        emit = glass.astype(_F32)
        if blind:
            slats = _square(v, 0.04, 0.75, fp) * (v > 0.35)
            out = out + (blind_c - out) * slats
            emit *= 1.0 - 0.8 * slats
        return out, emit

    return _with_mean(fn, sky)


def _p_foliage(rng) -> Pattern:
    h = rng.uniform(0.17, 0.33)
    dark = _hsv(h + rng.uniform(-0.03, 0.03), rng.uniform(0.35, 0.75), rng.uniform(0.08, 0.22))
    light = _hsv(h + rng.uniform(-0.05, 0.02), rng.uniform(0.3, 0.65), rng.uniform(0.25, 0.5))
    return _p_noise(rng, dark, light, rng.uniform(3.0, 9.0), 2, rng.uniform(0.6, 1.1))
