"""Materials: a pattern with gloss and emission, per-face overrides and decals.

`_Mat.evaluate_into` writes per-pixel albedo, emission, specular weight and shininess.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from lipjax.data.synthetic.arrays import _set_cols
from lipjax.data.synthetic.constants import _F32
from lipjax.data.synthetic.noise import _box
from lipjax.data.synthetic.patterns import Pattern


@dataclasses.dataclass
class _Decal:
    """A rectangle [u0, u1) x [v0, v1) of a surface (face -1: any face) painted with its own material, in
    [0, 1]^2 decal coordinates."""

    u0: float
    v0: float
    u1: float
    v1: float
    mat: "_Mat"
    face: int = -1


@dataclasses.dataclass
class _Mat:
    pattern: Pattern
    spec: float = 0.0  # Blinn-Phong specular weight
    shin: float = 24.0
    emit: float = 0.0  # > 0: self-lit, adds albedo * emit to the radiance
    faces: dict | None = None  # face id -> _Mat override
    decals: list = dataclasses.field(default_factory=list)
    _groups: tuple | None = dataclasses.field(default=None, repr=False, compare=False)

    def evaluate(self, u, v, face, fp):
        """-> albedo (3, n), emission (n,), specular weight (n,), shininess (n,), all float32."""
        n = u.shape[0]
        out = (np.empty((3, n), _F32), np.empty(n, _F32), np.empty(n, _F32), np.empty(n, _F32))
        self.evaluate_into(out, slice(None), u, v, face, fp)
        return out

    def evaluate_into(self, out: tuple, sel, u, v, face, fp) -> None:
        """Writes the albedo, emission, specular weight and shininess of points (u, v, face, fp) (n,) into
        out = (alb (3, m), emit (m,), spec (m,), shin (m,)) at sel (a slice or (n,) indices): face materials
        and decals write their pixels directly, with no intermediate arrays."""
        n = u.shape[0]
        rest = None
        if self.faces:
            groups, base = self._face_groups()
            if n > 0 and face.min() == face.max():  # one face visible (common): no masks
                f0 = int(face[0])
                for sub, lut in groups:
                    if lut[f0]:
                        return sub.evaluate_into(out, sel, u, v, face, fp)
                groups = []
            covered = False
            for sub, lut in groups:
                s = np.flatnonzero(lut[face])
                if s.size:
                    covered = True
                    sub.evaluate_into(out, _subset(sel, s), *(a.take(s) for a in (u, v, face, fp)))
            if covered:
                rest = np.flatnonzero(base[face])
        if rest is None:
            self._fill(out, sel, u, v, fp)
        elif rest.size:
            self._fill(out, _subset(sel, rest), u.take(rest), v.take(rest), fp.take(rest))
        by_face = {}
        for d in self.decals:
            if d.face >= 0:
                if d.face not in by_face:
                    by_face[d.face] = np.flatnonzero(face == d.face)
                fi = by_face[d.face]
                if fi.size == 0:
                    continue
                s = fi[_box(u[fi], v[fi], d.u0, d.v0, d.u1, d.v1)]
            else:
                s = np.flatnonzero(_box(u, v, d.u0, d.v0, d.u1, d.v1))
            if s.size:
                du, dv = d.u1 - d.u0, d.v1 - d.v0
                d.mat.evaluate_into(out, _subset(sel, s), (u[s] - d.u0) / du, (v[s] - d.v0) / dv, face[s],
                                    fp[s] / min(du, dv))

    def _face_groups(self) -> tuple:
        """([(material, (6,) bool: the faces it covers)], (6,) bool: faces left to self); faces sharing a
        material are evaluated together."""
        if self._groups is None:
            groups = {}
            for f, sub in self.faces.items():
                groups.setdefault(id(sub), (sub, np.zeros(6, bool)))[1][f] = True
            base = np.ones(6, bool)
            for _, lut in groups.values():
                base &= ~lut
            self._groups = (list(groups.values()), base)
        return self._groups

    def _fill(self, out: tuple, sel, u, v, fp) -> None:
        alb, emit, spec, shin = out
        res = self.pattern(u, v, fp)
        if isinstance(res, tuple):
            _set_cols(alb, sel, res[0])
            emit[sel] = self.emit * res[1]
        else:
            _set_cols(alb, sel, res)
            emit[sel] = self.emit
        spec[sel] = self.spec
        shin[sel] = self.shin


def _subset(sel, s: np.ndarray):
    """Indices s into the points selected by sel (a slice with step 1, or indices), as a selection of the
    whole."""
    if isinstance(sel, slice):
        return s if not sel.start else s + sel.start
    return sel[s]
