"""Scene primitives: boxes, cylinders, sphere clusters and the ground plane.

Each gives its culling hull, its camera-ray and shadow-ray intersection jobs (see `geometry`) and its surface
attributes (normals, uv, face id).
"""
from __future__ import annotations

import math

import numpy as np

from lipjax.data.synthetic.constants import _F32
from lipjax.data.synthetic.geometry import _to_local, _to_world
from lipjax.data.synthetic.materials import _Mat

_EYE3 = np.eye(3)
_BOX_CORNERS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)


class _Prim:
    """A primitive with a rigid local frame: world = R @ local + c. Subclasses implement camera_job (the
    kernel and parameters of camera rays against one of its parts, see `_camera_t`), shadow_jobs (the same
    for shadow rays, see `_shadow_t`) and surface (normals, uv, face id)."""

    infinite = False
    asm = -1  # assembly id: primitives of one object share a shadow-culling volume

    def __init__(self, label, mat: _Mat, c=(0.0, 0.0, 0.0), R=None, cast=True):
        self.label = label  # int, or a (6,) int array: label per face
        self.mat = mat
        self.c = tuple(float(x) for x in c)
        self.cast = cast
        if R is None:
            self.mode = 0
            R = _EYE3
        else:
            R = np.asarray(R, dtype=np.float64)
            r = R.ravel().tolist()
            if r == [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]:
                self.mode = 0
            elif r[4] == 1.0 and r[1] == 0.0 and r[7] == 0.0 and r[3] == 0.0 and r[5] == 0.0:
                self.mode = 1  # rotation about the vertical axis only
            else:
                self.mode = 2
        self.R = R
        self.r = tuple(R.ravel().tolist())

    def local_pt(self, x, y, z):
        return self.local_dir(x - self.c[0], y - self.c[1], z - self.c[2])

    def local_dir(self, x, y, z):
        return _to_local(self.r, self.mode, x, y, z)

    def local_box(self) -> np.ndarray:
        raise NotImplementedError

    def parts(self) -> list:
        """Convex pieces (each with hull() and camera_job()) for culling; a hit on any is a hit on self."""
        return [self]

    def hull(self) -> np.ndarray:
        """(8, 3) world points whose convex hull contains the primitive (cached: primitives never move)."""
        h = self.__dict__.get("_hull")
        if h is None:
            if self.mode == 0:
                h = _BOX_CORNERS * self.local_box() + self.c
            else:
                h = (_BOX_CORNERS * self.local_box()) @ self.R.T + self.c
            self._hull = h
        return h


class _Box(_Prim):
    def __init__(self, c, half, label, mat, R=None, inside=False, cast=True):
        super().__init__(label, mat, c, R, cast)
        self.h = tuple(float(x) for x in half)
        self.inside = inside
        self.infinite = inside

    def local_box(self):
        return np.asarray(self.h)

    def camera_job(self, ox: float, oy: float, oz: float) -> tuple:
        """(kernel kind, parameters) of camera rays from (ox, oy, oz) against this box (see `_camera_t`).
        Axis-aligned boxes use the world-frame planes and the shared inverse ray directions."""
        if self.mode == 0:
            (cx, cy, cz), (hx, hy, hz) = self.c, self.h
            return ("box_axis", self.inside), (cx - hx - ox, cx + hx - ox, cy - hy - oy, cy + hy - oy,
                                               cz - hz - oz, cz + hz - oz)
        (lx, ly, lz), (hx, hy, hz) = self.local_pt(ox, oy, oz), self.h
        return ("box", self.inside, self.mode), (-hx - lx, hx - lx, -hy - ly, hy - ly, -hz - lz, hz - lz) + self.r

    def shadow_jobs(self) -> list:
        """[(kernel kind, parameters)] of shadow rays against this box (see `_shadow_t`)."""
        hx, hy, hz = self.h
        return [(("box", self.mode), self.c + self.r + (-hx, hx, -hy, hy, -hz, hz))]

    def surface_job(self) -> tuple:
        """(kind, parameters) of `_box_surface` for this box: boxes of one kind are shaded in one call."""
        hx, hy, hz = self.h
        return ("box", self.mode, self.inside), self.c + self.h + (1 / hx, 1 / hy, 1 / hz) + self.r

    def surface(self, px, py, pz):
        return _box_surface(*self.surface_job(), px, py, pz)


def _box_surface(kind: tuple, P, px, py, pz) -> tuple:
    """Normals (world), uv (metres) and face id (0..5: -x, +x, -y, +y, -z, +z) at surface points p (n,) of
    boxes. kind: ("box", rotation mode, inside); P: `_Box.surface_job` parameters, floats or (n,) float32
    arrays (one box per point)."""
    _, mode, inside = kind
    hx, hy, hz, ihx, ihy, ihz = P[3:9]
    x, y, z = _to_local(P[9:], mode, px - P[0], py - P[1], pz - P[2])
    rx, ry, rz = np.abs(x) * ihx, np.abs(y) * ihy, np.abs(z) * ihz
    isx = (rx >= ry) & (rx >= rz)
    isy = ~isx & (ry >= rz)
    isz = ~(isx | isy)
    sgn = _F32(-1.0 if inside else 1.0)  # float32 scalars: the normals are built in float32 directly
    nx = np.where(isx, np.where(x > 0, sgn, -sgn), _F32(0.0))
    ny = np.where(isy, np.where(y > 0, sgn, -sgn), _F32(0.0))
    nz = np.where(isz, np.where(z > 0, sgn, -sgn), _F32(0.0))
    pos = np.where(isx, x > 0, np.where(isy, y > 0, z > 0))
    face = np.where(isx, 0, np.where(isy, 2, 4)) + pos
    u = np.where(isx, z + hz, x + hx)
    v = np.where(isy, z + hz, y + hy)
    return (*_to_world(P[9:], mode, nx, ny, nz), u, v, face)


class _Cyl(_Prim):
    """Capped cylinder along local y: radius r, half height h."""

    def __init__(self, c, r, h, label, mat, R=None, cast=True):
        super().__init__(label, mat, c, R, cast)
        self.rad, self.h = float(r), float(h)

    def local_box(self):
        return np.array([self.rad, self.h, self.rad])

    def camera_job(self, ox: float, oy: float, oz: float) -> tuple:
        """(kernel kind, parameters) of camera rays from (ox, oy, oz) against this cylinder (see
        `_camera_t`). One origin: only the cap facing it can be hit first; the cap term is NaN when the origin
        is level with the side (no cap test)."""
        ox, oy, oz = self.local_pt(ox, oy, oz)
        r, h = self.rad, self.h
        cap = h - oy if oy > h else -h - oy if oy < -h else math.nan
        return ("cyl", self.mode), (ox, oy, oz, ox * ox + oz * oz - r * r, h, r * r, cap) + self.r

    def shadow_jobs(self) -> list:
        """[(kernel kind, parameters)] of shadow rays against this cylinder (see `_shadow_t`)."""
        return [(("cyl", self.mode), self.c + self.r + (self.h, -self.h, self.rad * self.rad))]

    def surface_job(self) -> tuple:
        """(kind, parameters) of `_cyl_surface` for this cylinder (see `_Box.surface_job`)."""
        return ("cyl", self.mode), self.c + (1 / self.h, 1 / self.rad, self.rad, self.h) + self.r

    def surface(self, px, py, pz):
        return _cyl_surface(*self.surface_job(), px, py, pz)


def _cyl_surface(kind: tuple, P, px, py, pz) -> tuple:
    """Normals (world), uv (metres) and face id (0: side, 2 / 3: bottom / top cap) at surface points p (n,)
    of cylinders. kind: ("cyl", rotation mode); P: `_Cyl.surface_job` parameters, floats or (n,) float32
    arrays (one cylinder per point)."""
    ih, irad, rad, h = P[3:7]
    x, y, z = _to_local(P[7:], kind[1], px - P[0], py - P[1], pz - P[2])
    rho = np.sqrt(x * x + z * z)
    cap = np.abs(y) * ih > rho * irad
    inv = 1.0 / np.maximum(rho, 1e-6)
    nx = np.where(cap, 0.0, x * inv).astype(_F32)
    nz = np.where(cap, 0.0, z * inv).astype(_F32)
    ny = np.where(cap, np.sign(y), 0.0).astype(_F32)
    u = np.where(cap, x + rad, np.arctan2(x, z) * rad)
    v = np.where(cap, z + rad, y + h)
    face = np.where(cap, np.where(y > 0, 3, 2), 0)
    return (*_to_world(P[7:], kind[1], nx, ny, nz), u, v, face)


class _Sphere:
    """One sphere: a visibility / shadow part of _Spheres."""

    infinite = False

    def __init__(self, c, r, hull):
        self.c = tuple(float(x) for x in c)
        self.r = float(r)
        self._hull = hull

    def hull(self):
        return self._hull

    def camera_job(self, ox: float, oy: float, oz: float) -> tuple:
        """(kernel kind, parameters) of camera rays from (ox, oy, oz) against this sphere (see `_camera_t`)."""
        ocx, ocy, ocz = ox - self.c[0], oy - self.c[1], oz - self.c[2]
        return ("sphere",), (ocx, ocy, ocz, ocx * ocx + ocy * ocy + ocz * ocz - self.r * self.r)


class _Spheres(_Prim):
    """A cluster of spheres (foliage, bushes, heads, fruit): one object for shading, one part per sphere for
    visibility and shadows."""

    def __init__(self, centres, radii, label, mat, cast=True):
        super().__init__(label, mat, (0, 0, 0), None, cast)
        self.cs = np.asarray(centres, dtype=_F32).reshape(-1, 3)
        self.rs = np.asarray(radii, dtype=_F32).reshape(-1)

    def parts(self):
        ps = self.__dict__.get("_parts")
        if ps is None:
            # hulls of all spheres at once: centre + corners * radius, in float64
            hulls = self.cs.astype(np.float64)[:, None, :] + _BOX_CORNERS * self.rs.astype(np.float64)[:, None, None]
            ps = self._parts = [_Sphere(c, r, h) for c, r, h in zip(self.cs.tolist(), self.rs.tolist(), hulls)]
        return ps

    def hull(self):
        h = self.__dict__.get("_hull")
        if h is None:
            lo = (self.cs - self.rs[:, None]).min(0).astype(np.float64)
            hi = (self.cs + self.rs[:, None]).max(0).astype(np.float64)
            h = self._hull = 0.5 * (lo + hi) + _BOX_CORNERS * (0.5 * (hi - lo))
        return h

    def shadow_jobs(self) -> list:
        """[(kernel kind, parameters)] of shadow rays against each sphere (see `_shadow_t`); one cull per
        cluster (the caller's) is cheaper than one per sphere."""
        rr = (self.rs * self.rs).tolist()  # float32 products, as float32 parameters
        return [(("sphere",), (cx, cy, cz, r2)) for (cx, cy, cz), r2 in zip(self.cs.tolist(), rr)]

    def surface(self, px, py, pz):
        dxs = px[None, :] - self.cs[:, 0:1]
        dys = py[None, :] - self.cs[:, 1:2]
        dzs = pz[None, :] - self.cs[:, 2:3]
        dist = np.sqrt(dxs * dxs + dys * dys + dzs * dzs)
        k = np.abs(dist - self.rs[:, None]).argmin(axis=0)
        cols = np.arange(px.shape[0])
        inv = 1.0 / self.rs[k]
        nx, ny, nz = dxs[k, cols] * inv, dys[k, cols] * inv, dzs[k, cols] * inv
        u = np.arctan2(nx, nz) * self.rs[k] + k * 7.0
        v = py
        return nx, ny, nz, u, v, np.zeros(px.shape[0], np.int64)


class _Ground(_Prim):
    """The infinite plane y = 0 seen from above; its pattern gets world (x, z) as (u, v)."""

    infinite = True

    def __init__(self, label, mat):
        super().__init__(label, mat, cast=False)

    def intersect(self, ox, oy, oz, dx, dy, dz, eps):
        t = -oy / dy
        return np.where(t > eps, t, np.inf)

    def camera_job(self, ox: float, oy: float, oz: float) -> tuple:
        return None, ()  # one per scene: intersected directly

    def surface(self, px, py, pz):
        n = px.shape[0]
        z = np.zeros(n, _F32)
        return z, np.ones(n, _F32), z, px, pz, np.full(n, 3)


def _cache_hulls(prims: list) -> None:
    """Computes the hulls (`_Prim.hull`) of all finite boxes and cylinders at once, per rotation mode: the
    same arithmetic as one at a time, without its per-primitive overhead."""
    todo = [p for p in prims if isinstance(p, (_Box, _Cyl)) and not p.infinite and "_hull" not in p.__dict__]
    for rotated in (False, True):
        ps = [p for p in todo if (p.mode != 0) == rotated]
        if not ps:
            continue
        h = _BOX_CORNERS * np.stack([p.local_box() for p in ps])[:, None, :]  # (P, 8, 3) local corners
        if rotated:
            h = h @ np.stack([p.R for p in ps]).transpose(0, 2, 1)
        h = h + np.array([p.c for p in ps])[:, None, :]
        for p, hp in zip(ps, h):
            p._hull = hp
