"""Surface attributes of the visible pixels: normals, labels and materials, batched per kind and material."""
from __future__ import annotations

from typing import Iterator

import numpy as np

from lipjax.data.synthetic.arrays import _ranges, _set_cols
from lipjax.data.synthetic.constants import _F32
from lipjax.data.synthetic.primitives import _Box, _box_surface, _Cyl, _cyl_surface

_TINY_PIXELS = 32  # objects covering fewer pixels are shaded with their material's mean colour


def _material_runs(prims: list) -> Iterator[tuple[int, int]]:
    """(k0, k1) for each run prims[k0:k1] of adjacent primitives sharing a material."""
    k0 = 0
    while k0 < len(prims):
        k1 = k0 + 1
        while k1 < len(prims) and prims[k1].mat is prims[k0].mat:
            k1 += 1
        yield k0, k1
        k0 = k1


def _surfaces(prims: list, counts: np.ndarray, px, py, pz, fp) -> tuple:
    """Surface attributes of the hit pixels, sorted by primitive: counts (P,) pixels of each of `prims` in
    turn; p (n,) their world positions, fp (n,) their footprints (metres).

    -> (albedo (3, n), emission (n,), specular weight (n,), shininess (n,)), normals (3, n) and labels (n,)
    int8. Boxes and cylinders (most primitives) get their geometry in one call per kind, the others one at a
    time; each material is evaluated once for the run of primitives that share it."""
    n = px.shape[0]
    ends = np.cumsum(counts)
    first = ends - counts
    normals = np.empty((3, n), _F32)
    u_all, v_all, face_all = np.empty(n, _F32), np.empty(n, _F32), np.empty(n, np.int64)
    jobs = {j: p.surface_job() for j, p in enumerate(prims) if counts[j] and isinstance(p, (_Box, _Cyl))}
    for kind in dict.fromkeys(job[0] for job in jobs.values()):
        js = [j for j, job in jobs.items() if job[0] == kind]
        idx = _ranges(first[js], counts[js])
        P = np.repeat(np.array([jobs[j][1] for j in js], np.float64).astype(_F32).T, counts[js], axis=1)
        kernel = _box_surface if kind[0] == "box" else _cyl_surface
        *nrm, u, v, face = kernel(kind, P, px.take(idx), py.take(idx), pz.take(idx))
        _set_cols(normals, idx, nrm)
        u_all[idx], v_all[idx], face_all[idx] = u, v, face
    own = {}  # the other primitives' (u, v, face): their uv may be float64, and are kept as they are
    for j, p in enumerate(prims):
        if counts[j] and j not in jobs:
            s = slice(first[j], ends[j])
            *nrm, u, v, face = p.surface(px[s], py[s], pz[s])
            _set_cols(normals, s, nrm)
            face_all[s] = face
            own[j] = (u, v, face)
    label_of = np.array([p.label if isinstance(p.label, np.ndarray) else np.full(6, p.label) for p in prims],
                        np.int8).reshape(len(prims), 6)  # per primitive and face
    labels = label_of.ravel().take(np.repeat(np.arange(0, 6 * len(prims), 6), counts) + face_all)

    mat_out = (np.empty((3, n), _F32), np.empty(n, _F32), np.empty(n, _F32), np.empty(n, _F32))
    for k0, k1 in _material_runs(prims):
        run = slice(first[k0], ends[k1 - 1])
        if run.start == run.stop:
            continue
        mat = prims[k0].mat
        mean = getattr(mat.pattern, "mean", None)
        if run.stop - run.start < _TINY_PIXELS and mean is not None and mat.emit <= 0:
            # a few pixels: the texture would not show, its call overhead would
            for arr, val in zip(mat_out, (mean, 0.0, mat.spec, mat.shin)):
                arr[..., run] = val
            continue
        if any(j in own for j in range(k0, k1)):
            pieces = [own.get(j) or tuple(a[first[j]:ends[j]] for a in (u_all, v_all, face_all))
                      for j in range(k0, k1) if counts[j]]
            u, v, face = (g[0] if len(g) == 1 else np.concatenate(g) for g in zip(*pieces))
        else:
            u, v, face = u_all[run], v_all[run], face_all[run]
        mat.evaluate_into(mat_out, run, u, v, face, fp[run])
    return mat_out, normals, labels
