"""Screen-space culling: the pixel rectangles of convex hulls and the pixels inside rectangles."""
from __future__ import annotations

import numpy as np

from lipjax.data.frame import Intrinsics
from lipjax.data.synthetic.arrays import _ranges

_NEAR = 0.02  # near plane used for screen-space culling (metres)


def _pair_indices(k: int) -> tuple[np.ndarray, np.ndarray]:
    i, j = np.triu_indices(k, 1)
    return i, j


def _rects(points: np.ndarray, cam_pos, world_to_cam, intr: Intrinsics, H: int, W: int, zmin_out=None) -> np.ndarray:
    """Conservative pixel rectangles (r0, r1, c0, c1) of the convex hulls of `points` (P, K, 3) (world).

    Hull parts behind the near plane are clipped (exactly: the clipped hull's vertices are the front points
    and the near-plane crossings of the segments between front and back points). zmin_out (P,), if given,
    receives each hull's smallest camera z (>= the near plane): no hit on it can be nearer."""
    P, K, _ = points.shape
    pc = (points - cam_pos) @ world_to_cam.T
    z = pc[..., 2]
    front = z > _NEAR
    out = np.zeros((P, 4), np.int64)
    if zmin_out is not None:
        zmin_out[:] = np.maximum(z.min(1), _NEAR)
    any_front = front.any(1)
    if not any_front.any():
        return out
    umin, umax, vmin, vmax = _screen_bounds(pc, front, intr)
    mixed = np.flatnonzero(any_front & ~front.all(1))
    if mixed.size:  # hulls straddling the near plane: add the crossings (hulls wholly in front have none)
        i, j = _pair_indices(K)
        pm, fm = pc[mixed], front[mixed]
        zi, zj = pm[:, i, 2], pm[:, j, 2]
        cross = fm[:, i] ^ fm[:, j]
        lam = np.where(cross, (_NEAR - zi) / np.where(cross, zj - zi, 1.0), 0.0)
        cp = pm[:, i] + lam[..., None] * (pm[:, j] - pm[:, i])
        for b, bc, f in zip((umin, umax, vmin, vmax), _screen_bounds(cp, cross, intr),
                            (np.minimum, np.maximum, np.minimum, np.maximum)):
            b[mixed] = f(b[mixed], bc)
    out[:, 0] = np.clip(np.floor(vmin), 0, H)
    out[:, 1] = np.clip(np.floor(vmax) + 2, 0, H)
    out[:, 2] = np.clip(np.floor(umin), 0, W)
    out[:, 3] = np.clip(np.floor(umax) + 2, 0, W)
    out[~any_front] = 0
    return out


def _screen_bounds(pc: np.ndarray, ok: np.ndarray, intr: Intrinsics) -> tuple:
    """(umin, umax, vmin, vmax) (P,) pixel coordinates of the points pc (P, M, 3) (camera frame) where ok
    (P, M), +-1e9 where none (z is clamped to the near plane)."""
    zz = np.where(ok, np.maximum(pc[..., 2], _NEAR), 1.0)
    u = intr.fx * pc[..., 0] / zz + intr.cx
    v = intr.fy * pc[..., 1] / zz + intr.cy
    big = 1e9
    return (np.where(ok, u, big).min(1), np.where(ok, u, -big).max(1), np.where(ok, v, big).min(1),
            np.where(ok, v, -big).max(1))


def _rect_pixels(rects: np.ndarray, W: int) -> tuple[np.ndarray, np.ndarray]:
    """Flat indices (n,) of the pixels of rectangles (k, 4) (r0, r1, c0, c1; row-major within each, one
    after the other) in an image W pixels wide, and each rectangle's offset into them (k + 1,)."""
    r0, r1, c0, c1 = rects.T
    h, w = r1 - r0, c1 - c0
    run_rect = np.repeat(np.arange(len(rects)), h)  # one run of w pixels per rectangle row
    run_row = r0[run_rect] + _ranges(np.zeros(len(rects), np.int64), h)
    return _ranges(run_row * W + c0[run_rect], w[run_rect]), np.concatenate([[0], np.cumsum(h * w)])
