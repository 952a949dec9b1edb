"""Camera rays and visibility: the nearest primitive and its z-depth per pixel."""
from __future__ import annotations

import functools
import math

import numpy as np

from lipjax.data.frame import Intrinsics
from lipjax.data.synthetic.arrays import _cols
from lipjax.data.synthetic.constants import _F32
from lipjax.data.synthetic.culling import _rect_pixels, _rects
from lipjax.data.synthetic.geometry import _EPS, _camera_t
from lipjax.data.synthetic.scene import Scene


class _CameraRays:
    """The camera rays of an H x W image, and per-pixel quantities that the intersection kernels share.

    origin: the camera centre (3 floats, world); d: (3, H, W) float32 world directions whose camera-frame z
    component is 1, so the ray parameter t of a hit is its z-depth. The inverse directions (axis-aligned
    boxes) are computed on first use."""

    def __init__(self, scene: Scene, H: int, W: int, intr: Intrinsics):
        self.origin = tuple(float(x) for x in scene.cam_pos)
        r = [float(x) for x in scene.cam_R.ravel()]
        xn = ((np.arange(W, dtype=np.float64) - intr.cx) / intr.fx).astype(_F32)
        yn = ((np.arange(H, dtype=np.float64) - intr.cy) / intr.fy).astype(_F32)
        # World direction of pixel (v, u): R @ (xn[u], yn[v], 1).
        self.d = np.empty((3, H, W), _F32)
        for i in range(3):
            np.add((r[3 * i] * xn)[None, :], (r[3 * i + 1] * yn + r[3 * i + 2])[:, None], out=self.d[i])
        self.H, self.W = H, W

    @functools.cached_property
    def inv(self) -> np.ndarray:
        """(3, H, W): 1 / d (axis-aligned boxes)."""
        return 1.0 / self.d

    def inputs(self, kind: tuple) -> np.ndarray:
        """(3, H, W): the per-pixel inputs of the `_camera_t` kernel `kind`: inverse directions for
        axis-aligned boxes, else directions."""
        return self.inv if kind[0] == "box_axis" else self.d

    def gather(self, kind: tuple, pix: np.ndarray) -> np.ndarray:
        """The inputs of kernel `kind` at flat pixel indices pix (n,): (3, n) float32."""
        src = self.inputs(kind)
        return _cols(src.reshape(len(src), -1), pix)


# Parts whose screen rectangle has at most this many pixels are intersected together, one kernel call per
# kind over the concatenated pixels of their rectangles: per-call overhead, not pixels, dominates their cost.
_BATCH_PIXELS = 1024


def _visibility(prims: list, scene: Scene, rays: _CameraRays, intr: Intrinsics) -> tuple[np.ndarray, np.ndarray]:
    """Nearest hit per pixel: z-depth (H, W) float32 (inf: none) and index into `prims` (H, W) int16 (-1).

    Parts (convex pieces of the primitives) are merged into the depth buffer front to back, by the nearest
    z of their hulls; a part whose screen rectangle is already covered by nearer surfaces is skipped. On a
    tie the earlier part keeps the pixel. The ray parameters of small parts are computed ahead of the merge,
    all parts of a kind in one kernel call."""
    H, W = rays.H, rays.W
    zbuf = np.full((H, W), np.inf, _F32)
    ids = np.full((H, W), -1, np.int16)
    parts = [(k, part) for k, p in enumerate(prims) for part in p.parts()]
    finite = [i for i, (_, part) in enumerate(parts) if not part.infinite]
    rects = np.zeros((len(parts), 4), np.int64)
    rects[:] = (0, H, 0, W)
    zmin = np.full(len(parts), np.inf)  # infinite parts (room, ground) go last and are never skipped
    if finite:
        zf_ = np.empty(len(finite))
        rects[finite] = _rects(np.stack([parts[i][1].hull() for i in finite]), scene.cam_pos, scene.cam_R.T, intr, H,
                               W, zf_)
        zmin[finite] = zf_
    order = [i for i in np.argsort(zmin, kind="stable").tolist() if rects[i, 0] < rects[i, 1] and
             rects[i, 2] < rects[i, 3]]
    rects = rects.tolist()
    zmin = zmin.tolist()
    jobs = {i: parts[i][1].camera_job(*rays.origin) for i in order}

    # Small parts: one kernel call per kind over the concatenated pixels of their rectangles.
    batches: dict[tuple, list] = {}
    for i in order:
        r0, r1, c0, c1 = rects[i]
        if jobs[i][0] is not None and (r1 - r0) * (c1 - c0) <= _BATCH_PIXELS:
            batches.setdefault(jobs[i][0], []).append(i)
    batched = {}  # part index -> its ray parameters (h, w)
    for kind, members in batches.items():
        pix, offsets = _rect_pixels(np.array([rects[i] for i in members]), W)
        params = np.array([jobs[i][1] for i in members], np.float64).astype(_F32).T
        t = _camera_t(kind, np.repeat(params, np.diff(offsets), axis=1), rays.gather(kind, pix))
        for j, i in enumerate(members):
            r0, r1, c0, c1 = rects[i]
            batched[i] = t[offsets[j]:offsets[j + 1]].reshape(r1 - r0, c1 - c0)

    for i in order:
        r0, r1, c0, c1 = rects[i]
        zb = zbuf[r0:r1, c0:c1]
        if zmin[i] < math.inf and float(zb.max()) <= zmin[i]:
            continue
        t = batched.get(i)
        if t is None:
            kind, params = jobs[i]
            if kind is None:
                t = parts[i][1].intersect(*rays.origin, *rays.d[:, r0:r1, c0:c1], _EPS)
            else:
                t = _camera_t(kind, params, rays.inputs(kind)[:, r0:r1, c0:c1])
        closer = t < zb
        np.copyto(zb, t, where=closer)
        np.copyto(ids[r0:r1, c0:c1], parts[i][0], where=closer)
    return zbuf, ids
