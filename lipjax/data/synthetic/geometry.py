"""Frame transforms and ray-primitive intersection kernels.

Rotations, world <-> local transforms (with cheap modes for identity and vertical-axis rotations), and the
box / cylinder / sphere kernels with their camera-ray (`_camera_t`) and shadow-ray (`_shadow_t`) dispatch.
"""
from __future__ import annotations

import math

import numpy as np

_EPS = 1e-4  # minimum ray parameter of a hit (metres of z-depth for camera rays)


def _rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _to_local(r, mode: int, x, y, z):
    """World -> local components of vectors (x, y, z) for the rotation R with row-major entries r (9 values:
    floats, or (n,) float32 arrays, one rotation per point, in batched calls). mode 0: R = I, 1: a rotation
    about the vertical axis only, 2: general; the cheaper modes skip the terms that are exactly 0 or 1."""
    if mode == 0:
        return x, y, z
    if mode == 1:
        return r[0] * x + r[6] * z, y, r[2] * x + r[8] * z
    return (r[0] * x + r[3] * y + r[6] * z, r[1] * x + r[4] * y + r[7] * z, r[2] * x + r[5] * y + r[8] * z)


def _to_world(r, mode: int, x, y, z):
    """Local -> world components (the inverse of `_to_local`)."""
    if mode == 0:
        return x, y, z
    if mode == 1:
        return r[0] * x + r[2] * z, y, r[6] * x + r[8] * z
    return (r[0] * x + r[1] * y + r[2] * z, r[3] * x + r[4] * y + r[5] * z, r[6] * x + r[7] * y + r[8] * z)


# Ray-primitive kernels. Each works on numpy broadcasting: a scalar origin with (h, w) directions (camera
# rays), (n,) origins with scalar or (n,) directions (shadow rays), and Python float parameters (one
# primitive) or (n,) float32 parameter arrays (one primitive per ray: many primitives in one call). A Python
# float parameter and the same value as a float32 array give bit-identical results (numpy casts the Python
# float to float32 first), so the batched and one-at-a-time paths agree exactly.


def _slab_t(planes, ix, iy, iz, inside: bool, eps):
    """Ray parameter of the first hit on an axis-aligned box (inf: none), by the slab method.

    planes: (x0, x1, y0, y1, z0, z1), the box's faces minus the ray origin, per axis; ix, iy, iz: inverse
    ray directions. inside: the ray starts inside the box and the hit is the exit (a room seen from within)."""
    x0, x1, y0, y1, z0, z1 = planes
    a = x0 * ix
    b = x1 * ix
    tn = np.minimum(a, b)
    tf = np.maximum(a, b)
    a = y0 * iy
    b = y1 * iy
    np.maximum(tn, np.minimum(a, b), out=tn)
    np.minimum(tf, np.maximum(a, b), out=tf)
    a = z0 * iz
    b = z1 * iz
    if inside:
        np.minimum(tf, np.maximum(a, b), out=tf)
        return np.where(tf > eps, tf, np.inf)
    np.maximum(tn, np.minimum(a, b), out=tn)
    np.minimum(tf, np.maximum(a, b), out=tf)
    return np.where((tn <= tf) & (tn > eps), tn, np.inf)


def _quadric_t(a, b, c, eps):
    """Nearer root t of a t^2 + 2 b t + c = 0 where it is real and > eps, else inf (spheres, cylinders)."""
    disc = b * b - a * c
    t = (-b - np.sqrt(np.maximum(disc, 0.0))) / a
    return np.where((disc >= 0) & (t > eps), t, np.inf)


def _cyl_t(ox, oy, oz, c, h, rr, caps, dx, dy, dz, eps):
    """Ray parameter of the first hit on the capped cylinder x^2 + z^2 <= rr, |y| <= h (local frame; inf:
    none). o: ray origins, c = ox^2 + oz^2 - rr, d: directions; caps: (cap y - oy) of the caps to test (a
    NaN entry tests none)."""
    t = _quadric_t(dx * dx + dz * dz, ox * dx + oz * dz, c, eps)
    t = np.where(np.abs(oy + t * dy) <= h, t, np.inf)
    for num in caps:
        tc = num / dy
        xc = ox + tc * dx
        zc = oz + tc * dz
        t = np.where((xc * xc + zc * zc <= rr) & (tc > eps) & (tc < t), tc, t)
    return t


def _camera_t(kind: tuple, P, rays: np.ndarray) -> np.ndarray:
    """Ray parameters of camera rays against primitives of one kind.

    kind: from the primitives' `camera_job`; P: its parameters, one float32 array per parameter,
    broadcastable against the per-pixel inputs rays (`_CameraRays.inputs`), (c, ...)."""
    if kind[0] == "box_axis":
        return _slab_t(P[:6], rays[0], rays[1], rays[2], kind[1], _EPS)
    if kind[0] == "box":
        dx, dy, dz = _to_local(P[6:], kind[2], rays[0], rays[1], rays[2])
        return _slab_t(P[:6], 1.0 / dx, 1.0 / dy, 1.0 / dz, kind[1], _EPS)
    if kind[0] == "cyl":
        dx, dy, dz = _to_local(P[7:], kind[1], rays[0], rays[1], rays[2])
        return _cyl_t(P[0], P[1], P[2], P[3], P[4], P[5], (P[6],), dx, dy, dz, _EPS)
    ocx, ocy, ocz, c = P  # sphere
    dx, dy, dz = rays
    return _quadric_t(dx * dx + dy * dy + dz * dz, ocx * dx + ocy * dy + ocz * dz, c, _EPS)


def _shadow_t(kind: tuple, P, ox, oy, oz, dx, dy, dz) -> np.ndarray:
    """Ray parameters (n,) of shadow rays from origins o (n,) along directions d (scalars, or (n,)) against
    primitives of one kind. kind, P: from the primitives' `shadow_jobs` (P: one (n,) float32 array, or
    float, per parameter)."""
    if kind[0] == "sphere":
        cx, cy, cz, rr = P
        ocx, ocy, ocz = ox - cx, oy - cy, oz - cz
        return _quadric_t(dx * dx + dy * dy + dz * dz, ocx * dx + ocy * dy + ocz * dz,
                          ocx * ocx + ocy * ocy + ocz * ocz - rr, 0.0)
    r, mode = P[3:12], kind[1]
    ox, oy, oz = _to_local(r, mode, ox - P[0], oy - P[1], oz - P[2])
    dx, dy, dz = _to_local(r, mode, dx, dy, dz)
    if kind[0] == "box":
        x0, x1, y0, y1, z0, z1 = P[12:18]
        return _slab_t((x0 - ox, x1 - ox, y0 - oy, y1 - oy, z0 - oz, z1 - oz), 1.0 / dx, 1.0 / dy, 1.0 / dz,
                       False, 0.0)
    h, nh, rr = P[12:15]  # cylinder
    return _cyl_t(ox, oy, oz, ox * ox + oz * oz - rr, h, rr, (h - oy, nh - oy), dx, dy, dz, 0.0)
