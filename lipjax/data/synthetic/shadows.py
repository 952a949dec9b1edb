"""Cast shadows: shadow rays from the receivers against the casters whose shadow volume can hold them."""
from __future__ import annotations

import numpy as np

from lipjax.data.synthetic.arrays import _ranges
from lipjax.data.synthetic.constants import _F32
from lipjax.data.synthetic.culling import _rects
from lipjax.data.synthetic.geometry import _shadow_t
from lipjax.data.synthetic.primitives import _BOX_CORNERS, _Spheres
from lipjax.data.synthetic.scene import Light, Scene


def _f32_above(x: np.ndarray) -> np.ndarray:
    """The smallest float32 >= x (float64, elementwise): for float32 a, a >= x <=> a >= it, a < x <=> a < it."""
    y = x.astype(_F32)
    return np.where(y < x, np.nextafter(y, _F32(np.inf)), y)


def _f32_below(x: np.ndarray) -> np.ndarray:
    """The largest float32 <= x (float64, elementwise): for float32 a, a <= x <=> a <= it, a > x <=> a > it."""
    y = x.astype(_F32)
    return np.where(y > x, np.nextafter(y, _F32(-np.inf)), y)


# A sphere cluster of more spheres than this (a porous crown's clumps, lipjax.data.synthetic.foliage) casts as one
# caster per sphere: each sphere's own shadow volume holds far fewer receivers than the whole crown's.
SPLIT_SPHERES = 8


class _SphereCaster:
    """One sphere of a large cluster as a caster of its own: the cluster's shadow job for that sphere."""

    def __init__(self, job: tuple):
        self.job = job

    def shadow_jobs(self) -> list:
        return [self.job]


def _split(group: list) -> list[tuple[list, np.ndarray]]:
    """[(caster, its world AABB corners (8, 3))] for one assembly: itself, or, where it holds a cluster of more than
    SPLIT_SPHERES spheres, its other members together and each of those spheres alone (the same shadow rays, the
    same hits: a receiver outside a sphere's shadow volume cannot be blocked by it)."""
    big = [p for p in group if _big(p)]
    rest = [p for p in group if not _big(p)]
    out = [(rest, _aabb(np.stack([p.hull() for p in rest])))] if rest else []
    for p in big:
        out += [([_SphereCaster(job)], part.hull()) for job, part in zip(p.shadow_jobs(), p.parts())]
    return out


def _big(p) -> bool:
    return isinstance(p, _Spheres) and len(p.rs) > SPLIT_SPHERES


def _aabb(hulls: np.ndarray) -> np.ndarray:
    """(8, 3) corners of the world AABB of (P, 8, 3) hull points."""
    lo, hi = hulls.min((0, 1)), hulls.max((0, 1))
    return 0.5 * (lo + hi) + _BOX_CORNERS * (0.5 * (hi - lo))


def _casters(scene: Scene) -> tuple[list, np.ndarray] | None:
    """(casters, their world AABB corners (C, 8, 3)): one caster per assembly (a car, a tree, a piece of furniture),
    those wholly farther than scene.shadow_range from the camera left out (their shadow would be a few pixels),
    large sphere clusters split into their spheres (`_split`); None without any."""
    members: dict[int, list] = {}
    for p in scene.prims:
        if p.cast and not p.infinite:
            members.setdefault(p.asm if p.asm >= 0 else -1 - id(p), []).append(p)
    if not members:
        return None
    groups = list(members.values())
    flat = [p for g in groups for p in g]
    ph = np.stack([p.hull() for p in flat])  # (P, 8, 3)
    first = np.cumsum([0] + [len(g) for g in groups[:-1]])
    lo = np.minimum.reduceat(ph.min(1), first, axis=0)  # per assembly world AABB
    hi = np.maximum.reduceat(ph.max(1), first, axis=0)
    keep = np.maximum(lo - scene.cam_pos, scene.cam_pos - hi).max(1) < scene.shadow_range
    if not keep.any():
        return None
    casters = [g for g, k in zip(groups, keep.tolist()) if k]
    lo, hi = lo[keep], hi[keep]
    hulls = 0.5 * (lo + hi)[:, None, :] + _BOX_CORNERS[None] * (0.5 * (hi - lo))[:, None, :]
    split = [any(_big(p) for p in g) for g in casters]
    if not any(split):
        return casters, hulls
    pieces = [piece for g, h, s in zip(casters, hulls, split) for piece in (_split(g) if s else [(g, h)])]
    return [c for c, _ in pieces], np.stack([h for _, h in pieces])


def _sun_culling(light: Light, hulls: np.ndarray, recv, px, py, pz):
    """(far ends of the shadow volumes (C, 8, 3), mask(k, sl)) for a directional light: a receiver can only be
    shadowed by a caster whose projection along the light covers it, and which lies towards the light from it."""
    L = np.asarray(light.direction)
    s = (hulls[..., 1].max(1) + 0.1) / max(L[1], 0.05)
    far = hulls - s[:, None, None] * L  # pushed to below the ground
    e1 = np.cross(L, [0.0, 0.0, 1.0] if abs(L[2]) < 0.9 else [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(L, e1)
    frame = np.stack([e1, e2, L])  # (3, 3)
    hl = hulls @ frame.T  # (P, 8, 3)
    lo, hi = hl.min(1) - 1e-3, hl.max(1) + 1e-3
    f = [float(x) for x in frame.ravel()]
    qa = px * f[0] + py * f[1] + pz * f[2]
    qb = px * f[3] + py * f[4] + pz * f[5]
    qc = px * f[6] + py * f[7] + pz * f[8]
    # The culling bounds as float32 numbers that give the same comparisons against float32 arrays (a float64
    # bound would make numpy cast the arrays, twice as slow).
    lo, hi_c, hi = _f32_above(lo), _f32_above(hi[:, 2]), _f32_below(hi)

    def mask(k: int, sl: tuple) -> np.ndarray:
        a, b_, c = qa[sl], qb[sl], qc[sl]
        return recv[sl] & (a >= lo[k, 0]) & (a <= hi[k, 0]) & (b_ >= lo[k, 1]) & (b_ <= hi[k, 1]) & (c < hi_c[k])

    return far, mask


def _point_culling(scene: Scene, light: Light, hulls: np.ndarray, recv, px, py, pz):
    """(far ends of the shadow volumes (C, 8, 3), mask(k, sl) or None to skip caster k) for a point light: the
    caster's bounding sphere seen from the light subtends a cone; receivers outside it, or nearer to the light
    than the caster, cannot be shadowed by it. A caster around the light casts no shadow."""
    Lp = np.asarray(light.position)
    dist = np.linalg.norm(hulls - Lp, axis=-1).min(1)
    lam = 1.0 + scene.extent / np.maximum(dist, 1e-3)
    far = Lp + lam[:, None, None] * (hulls - Lp)  # a homothety centred on the light, out of the scene
    inside = np.all((hulls.min(1) < Lp) & (hulls.max(1) > Lp), axis=1)
    centre = hulls.mean(1)
    rad = np.linalg.norm(hulls - centre[:, None], axis=-1).max(1)
    cd = np.linalg.norm(centre - Lp, axis=-1)
    axis = (centre - Lp) / np.maximum(cd, 1e-9)[:, None]
    cos_half = np.sqrt(np.clip(1.0 - (rad / np.maximum(cd, 1e-9)) ** 2, 0.0, 1.0)) - 1e-4
    ux, uy, uz = px - float(Lp[0]), py - float(Lp[1]), pz - float(Lp[2])
    ud = np.sqrt(ux * ux + uy * uy + uz * uz)
    iu = 1.0 / np.maximum(ud, 1e-9)
    ux, uy, uz = ux * iu, uy * iu, uz * iu
    cos_half32, near = _f32_above(cos_half), _f32_below(cd - rad)  # float32 bounds, as in _sun_culling

    def mask(k: int, sl: tuple) -> np.ndarray | None:
        if inside[k]:
            return None
        if cd[k] > rad[k]:
            ax_, ay_, az_ = (float(x) for x in axis[k])
            return recv[sl] & (ux[sl] * ax_ + uy[sl] * ay_ + uz[sl] * az_ >= cos_half32[k]) & (ud[sl] > near[k])
        return recv[sl]

    return far, mask


def _blocked(scene: Scene, light: Light, tests: list, points: tuple, normals: tuple) -> tuple[np.ndarray, np.ndarray]:
    """(flat receiver indices, whether each is blocked) for the (caster, flat receiver indices) pairs in `tests`;
    points and normals: the flat (x, y, z) arrays of the receivers' positions and normals."""
    pxf, pyf, pzf = points
    nxf, nyf, nzf = normals
    # Shadow-ray origins: the receivers, pushed off their surface along the normal.
    fi = np.concatenate([f for _, f in tests])
    qx, qy, qz = pxf[fi], pyf[fi], pzf[fi]
    off = 2e-3 + 1e-4 * np.abs(qz - float(scene.cam_pos[2]))
    qx = qx + nxf[fi] * off
    qy = qy + nyf[fi] * off
    qz = qz + nzf[fi] * off
    # (receiver, primitive) pairs per kernel kind: ranges of the receivers above, and parameters.
    start = np.cumsum([0] + [f.size for _, f in tests])
    pairs: dict[tuple, list] = {}
    for (group, f), s0 in zip(tests, start.tolist()):
        for prim in group:
            for kind, params in prim.shadow_jobs():
                pairs.setdefault(kind, []).append((s0, f.size, params))
    blocked = np.zeros(fi.size, bool)
    for kind, items in pairs.items():
        s0, n, params = zip(*items)
        idx = _ranges(s0, n)
        P = np.repeat(np.array(params, np.float64).astype(_F32).T, n, axis=1)
        ox, oy, oz = qx[idx], qy[idx], qz[idx]
        if light.direction is not None:
            dl = tuple(_F32(c) for c in np.asarray(light.direction))
            hit = _shadow_t(kind, P, ox, oy, oz, *dl) < np.inf
        else:
            Lp0, Lp1, Lp2 = (float(c) for c in light.position)
            hit = _shadow_t(kind, P, ox, oy, oz, Lp0 - ox, Lp1 - oy, Lp2 - oz) < 1.0
        blocked[idx[hit]] = True
    return fi, blocked


def _shadows(scene: Scene, light: Light, recv, px, py, pz, nx, ny, nz, intr, H, W) -> np.ndarray:
    """(H, W) float32: 0 where the light is blocked before reaching the surface point, else 1.

    recv (H, W) bool: the points to test; px.. (H, W) their positions and normals; intr, H, W: the camera
    of this (possibly subsampled) pixel grid.

    A caster can only shadow points inside its shadow volume: the convex hull of its hull points and those
    points pushed away from the light (to below the ground for the sun; by a homothety centred on a point
    light, far enough to leave the scene). Only receivers inside the volume's screen rectangle are tested,
    and then all (receiver, primitive) pairs of a kernel kind in one call."""
    lit = np.ones((H, W), _F32)
    found = _casters(scene) if recv.any() else None
    if found is None:
        return lit
    casters, hulls = found
    if light.direction is not None:
        far, mask = _sun_culling(light, hulls, recv, px, py, pz)
    else:
        far, mask = _point_culling(scene, light, hulls, recv, px, py, pz)
    rects = _rects(np.concatenate([hulls, far], axis=1), scene.cam_pos, scene.cam_R.T, intr, H, W)
    tests = []  # (caster, flat indices of its candidate receivers)
    for k, p in enumerate(casters):
        r0, r1, c0, c1 = rects[k]
        if r0 >= r1 or c0 >= c1:
            continue
        m = mask(k, (slice(r0, r1), slice(c0, c1)))
        if m is None:
            continue
        rr, cc = np.nonzero(m)
        if rr.size:
            tests.append((p, (rr + r0) * W + (cc + c0)))
    if not tests:
        return lit
    fi, blocked = _blocked(scene, light, tests, tuple(a.ravel() for a in (px, py, pz)),
                           tuple(a.ravel() for a in (nx, ny, nz)))
    lit.ravel()[fi[blocked]] = 0.0  # ravel of a contiguous array: a view
    return lit
