"""Piecewise-linear interpolation of the samples over their Delaunay triangulation (pixel coordinates).

Exact at the samples and for any planar depth d = a + b x + c y inside the convex hull of the samples; outside
the hull (where linear interpolation is undefined) each pixel takes its nearest sample's depth. Fewer than three
samples, or all samples on one line (e.g. a single LiDAR scan line), admit no triangulation: then the whole map
is the nearest-neighbour fill.

Only the samples on the edge of the sampled region are triangulated (`_edge_samples`: those with an unsampled or
out-of-frame pixel among their 4 neighbours), which makes dense depth with holes (a depth camera's, stereo's) fast
(a synthetic 480x640 room with holes: 240,474 samples, 7,863 of them on the edge; 22 s -> 0.7-0.9 s beside a
training run) and leaves scattered samples and scan lines as they were (nearly every such sample is on the edge).
The fill at the unsampled pixels is still a Delaunay linear fill of all the samples: a Delaunay triangle that holds
an unsampled lattice pixel other than its corners has an edge of length >= 2 (a lattice triangle with edges of 1 and
sqrt(2) holds none), so a circumradius R >= 1; a circle through a sample of radius R > 1/sqrt(2) has one of its 4
neighbours strictly inside (the one within 45 degrees of the way to the centre: 1 < 2 R cos 45); so no corner of
such a triangle is a sample with all 4 neighbours sampled, and the triangle is Delaunay for the edge samples too.
Conversely, every corner of all the samples' hull is an edge sample (its neighbour beyond the hull is unsampled), so
both triangulations tile the same hull and every triangle of the edge samples that holds an unsampled pixel is one
of all the samples'. (Where four or more samples are cocircular, Delaunay triangulations are not unique and the two
may pick different ones.) The nearest sample of an unsampled pixel is an edge sample as well: a step from any other
sample towards the pixel, along the axis where it is farther, lands on a sample closer to it.

Implementation note: the triangulation is scipy's (Qhull), but the triangles are rasterised here in numpy
(scanline spans from exact integer edge tests, `_rasterise_triangles`) instead of querying
`scipy.interpolate.LinearNDInterpolator`, which gives the same values (tested) but computes per-simplex
transforms with many tiny multi-threaded LAPACK calls: on a loaded 2-core machine a 256x1216 frame with 20k
samples took 8-15 s that way. Measured once with this rasteriser (same frame size and sample count, 2-core
machine at load average ~2.5): 0.6 s a call, of which 0.45 s is Qhull's triangulation and 0.13 s the
rasterisation; LinearNDInterpolator, single-threaded, took 0.16-0.2 s on the same triangulation.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from scipy import ndimage, spatial

from lipjax.classical.nearest import nearest_fill
from lipjax.inputs import check_frame


# linear_fill_at: (pixels x samples) per pixel of the frame above which the full fill is faster (measured crossover
# 1-2 on 256x320 and 480x640 frames with 200-1,600 samples, runs/scratch timings) and uses less memory.
POINTWISE_PAIRS_PER_PIXEL = 1.0


def _rasterise_triangles(points: np.ndarray, values: np.ndarray, simplices: np.ndarray, shape) -> np.ndarray:
    """Linear interpolation on integer pixel centres of every triangle (edges included); NaN outside all triangles.

    points: (N, 2) int64 (y, x) pixel coordinates; values: (N,) float64; simplices: (T, 3) int vertex indices.

    Scanline rasterisation: for each row y a triangle covers, the pixels x with all three barycentric coordinates
    >= 0 form one span, whose ends follow from the edge equations in exact integer arithmetic (integer
    vertices), so no pixel on an edge is lost to rounding; each span is then filled from the triangle's plane
    d = d_2 + g_x (x - x_2) + g_y (y - y_2). Only covered pixels are visited (a bounding-box rasteriser visits
    about twice as many).
    """
    h, w = shape
    tri = points[simplices]  # (T, 3, 2)
    val = values[simplices]  # (T, 3)
    y0, y1, y2 = tri[:, 0, 0], tri[:, 1, 0], tri[:, 2, 0]
    x0, x1, x2 = tri[:, 0, 1], tri[:, 1, 1], tri[:, 2, 1]
    den = (y1 - y2) * (x0 - x2) + (x2 - x1) * (y0 - y2)  # twice the signed area
    keep = den != 0  # Qhull may return zero-area slivers for collinear points on integer grids
    tri, val, den = tri[keep], val[keep], den[keep]
    y0, y1, y2, x0, x1, x2 = (a[keep] for a in (y0, y1, y2, x0, x1, x2))
    v0, v1, v2 = val[:, 0] - val[:, 2], val[:, 1] - val[:, 2], val[:, 2]
    gx = (v0 * (y1 - y2) + v1 * (y2 - y0)) / den
    gy = (v0 * (x2 - x1) + v1 * (x0 - x2)) / den

    # One entry per (triangle, row) pair.
    ymin = np.clip(tri[:, :, 0].min(1), 0, h - 1)
    ymax = np.clip(tri[:, :, 0].max(1), 0, h - 1)
    rows = ymax - ymin + 1
    t = np.repeat(np.arange(len(rows)), rows)
    y = ymin[t] + np.arange(rows.sum()) - np.repeat(np.cumsum(rows) - rows, rows)
    # den * l_i = a_i x + c_i(y) for the barycentric coordinates l_0, l_1, l_2 = 1 - l_0 - l_1; a pixel is
    # inside where every sign(den) (a_i x + c_i) >= 0.
    sign = np.sign(den)[t]
    a0, a1 = (y1 - y2)[t], (y2 - y0)[t]
    c0 = -a0 * x2[t] + (x2 - x1)[t] * (y - y2[t])
    c1 = -a1 * x2[t] + (x0 - x2)[t] * (y - y2[t])
    lo = np.zeros_like(y)
    hi = np.full_like(y, w - 1)
    for a, c in ((a0, c0), (a1, c1), (-a0 - a1, den[t] - c0 - c1)):
        a, c = sign * a, sign * c
        pos, neg = a > 0, a < 0
        lo[pos] = np.maximum(lo[pos], -(c[pos] // a[pos]))  # x >= ceil(-c / a)
        hi[neg] = np.minimum(hi[neg], c[neg] // -a[neg])  # x <= floor(c / -a)
        hi[(a == 0) & (c < 0)] = -1  # this row misses the triangle
    n = np.maximum(hi - lo + 1, 0)
    # Per span: the flat index and the depth of its first pixel, and the depth step per pixel (g_x); then one
    # entry per covered pixel. A pixel on an edge shared by two triangles gets either triangle's value (equal up
    # to rounding): numpy does not fix which write wins for repeated indices.
    first = y * w + lo
    start_depth = v2[t] + gx[t] * (lo - x2[t]) + gy[t] * (y - y2[t])
    k = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)  # pixel index within its span
    dense = np.full(shape, np.nan)
    dense.reshape(-1)[np.repeat(first, n) + k] = np.repeat(start_depth, n) + np.repeat(gx[t], n) * k
    return dense


def _edge_samples(sparse: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rows, cols) of the samples with an unsampled or out-of-frame pixel among their 4 neighbours: the only
    corners of Delaunay triangles that hold unsampled pixels (module doc)."""
    sampled = sparse > 0
    return np.nonzero(sampled & ~ndimage.binary_erosion(sampled, border_value=0))  # the 4-neighbour cross


def _delaunay(ys: np.ndarray, xs: np.ndarray) -> np.ndarray | None:
    """(T, 3) indices into ys, xs of their Delaunay triangles; None for fewer than 3 or collinear points."""
    if ys.size < 3:
        return None
    try:
        return spatial.Delaunay(np.stack([ys, xs], axis=1).astype(np.float64)).simplices
    except spatial.QhullError:  # all samples collinear: no 2-D triangulation exists
        return None


def linear_fill(sparse: np.ndarray) -> np.ndarray:
    """(H, W) float32 metres, 0 = no sample -> (H, W) float32 dense. Assumes at least one sample."""
    ys, xs = _edge_samples(sparse)
    simplices = _delaunay(ys, xs)
    if simplices is None:
        return nearest_fill(sparse)
    dense = _rasterise_triangles(np.stack([ys, xs], axis=1), sparse[ys, xs].astype(np.float64), simplices,
                                 sparse.shape)
    outside = np.isnan(dense)
    if outside.any():
        dense[outside] = nearest_fill(sparse)[outside]
    sampled = sparse > 0
    dense[sampled] = sparse[sampled]
    return dense.astype(np.float32)


def linear_fill_at(sparse: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """`linear_fill(sparse)[rows, cols]` (float32 metres) without filling the whole frame: the same Delaunay
    triangulation, each pixel interpolated in a triangle that holds it (edges included, by the rasteriser's exact
    integer test), its nearest sample where none does (a pixel exactly as far from two samples asks scipy's distance
    transform, as the full fill does, which breaks such ties its own way). Equal to the full fill up to rounding; for
    a few pixels of a large frame (lipjax.crosscheck's held-out samples) it skips the rasterisation and, without
    ties, the transform. Every pixel is tested against every sample and triangle, so above
    POINTWISE_PAIRS_PER_PIXEL pairs per pixel of the frame the full fill is computed and read instead."""
    ys, xs = _edge_samples(sparse)
    rows, cols = np.asarray(rows, np.int64), np.asarray(cols, np.int64)
    if rows.size * ys.size > POINTWISE_PAIRS_PER_PIXEL * sparse.size:
        return linear_fill(sparse)[rows, cols]
    d2 = (rows[:, None] - ys[None, :]) ** 2 + (cols[:, None] - xs[None, :]) ** 2  # (n, N) integers: exact
    values = sparse[ys, xs].astype(np.float64)
    out = values[np.argmin(d2, axis=1)]
    inside = np.zeros(rows.shape, bool)
    simplices = _delaunay(ys, xs)  # None: the full fill is the nearest fill
    if simplices is not None:
        (y0, y1, y2), (x0, x1, x2) = ys[simplices].T, xs[simplices].T  # (T,) each
        den = (y1 - y2) * (x0 - x2) + (x2 - x1) * (y0 - y2)  # twice the signed area; 0: a sliver, skipped
        qy, qx = rows[:, None], cols[:, None]  # against (T,): (n, T) integers
        a0 = (y1 - y2) * (qx - x2) + (x2 - x1) * (qy - y2)  # den * the barycentric coordinates
        a1 = (y2 - y0) * (qx - x2) + (x0 - x2) * (qy - y2)
        sign = np.sign(den)
        holds = (den != 0) & (sign * a0 >= 0) & (sign * a1 >= 0) & (sign * (den - a0 - a1) >= 0)
        inside = holds.any(axis=1)
        t = np.argmax(holds, axis=1)[inside]
        l0, l1 = a0[inside, t] / den[t], a1[inside, t] / den[t]
        corners = values[simplices[t]]
        out[inside] = corners[:, 2] + l0 * (corners[:, 0] - corners[:, 2]) + l1 * (corners[:, 1] - corners[:, 2])
    tied = ~inside & ((d2 == d2.min(axis=1, keepdims=True)).sum(axis=1) > 1)
    if tied.any():
        out[tied] = nearest_fill(sparse)[rows[tied], cols[tied]]
    at_sample = sparse[rows, cols] > 0  # the full fill keeps every sample
    out[at_sample] = sparse[rows, cols][at_sample]
    return out.astype(np.float32)


@dataclasses.dataclass(frozen=True)
class LinearFill:
    """DepthCompleter: Delaunay piecewise-linear interpolation, nearest fill outside the convex hull (ignores RGB)."""

    name: str = "linear"

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray:
        _, sparse = check_frame(rgb, sparse)
        return linear_fill(sparse)
