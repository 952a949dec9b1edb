"""A per-frame check of a learned model against the linear fill, on samples held out of the model's own input.

A model trained on renders meets frames unlike any it saw (another sensor, another world), and there it can do worse
than the plain linear fill of the same samples. The input itself can tell: split the n samples into FOLDS disjoint
folds; for each fold, complete the frame from the other folds with the model and with the Delaunay linear fill; so
every sample i is held out once, with the model's value x_m(i) and the linear fill's x_l(i) there, to compare with
its depth y_i, i = 1 .. n. The first fold runs alone first: if the model misses at most half of its samples by more
than the linear fill does, w = 1 and the other folds are not run (where the model fits, the check costs one run of
it). Otherwise, over all n:

    k  = #{i : |x_m(i) - y_i| > |x_l(i) - y_i|}                  held-out samples the model misses by more
    p  = P(Binomial(n, 1/2) >= k)                               one-sided sign test: is the model worse at most?
    w  = 1                                                      if p >= P_VALUE: no evidence against the model
       = clip(sum_i (y_i - x_l(i)) (x_m(i) - x_l(i)) / sum_i (x_m(i) - x_l(i))^2, 0, 1)
                                                                otherwise: least squares of w x_m + (1 - w) x_l = y
    x  = w z + (1 - w) F                                        z, F: the model and the linear fill of every sample

and every measured pixel is set back. Where the model is the better fill (the renders of
`benchmarks/generalisation.py` with the 972,640-image lip-any: 0.662612 -> 0.662305 x linear) w stays 1 on most
frames (it fires on some denser inputs); where it is not (a street model on rooms: 1.48 -> 0.91 x linear) the output
leans on the linear fill. Folds, not one held-out fifth (docs/decisions/0015-cross-check-by-folds.md): with 200 points
one fifth is 40 depths, too few for the test to see a model that loses (one fold: 0.662356 and 0.98 above). Scan lines
are not checked: random held-out returns lie a pixel from their neighbours on the same line, where every fill is right,
so they say nothing of the gaps between the lines (and the LiDAR path keeps its 10 frames/s). Nor is dense input (over
`lipjax.resolution.DENSE` samples per pixel: a depth camera's, stereo's), for the same reason: rooms with holes scored
0.9297 x linear unchecked against 0.9488 checked, and the check cost two Delaunay fills of most of the frame's pixels
(docs/decisions/0016-dense-input-not-checked.md). The held-out runs use the working size the default path gives the
kept samples (`held_out_size`, docs/decisions/0014-held-out-run-size.md): the model sees them as far apart as it was
trained to, in 0.8x the frame's working pixels (a second compiled program per frame size). Chosen on synthetic frames
only, by rules fixed before measuring (docs/decisions/0013-cross-check-against-the-linear-fill.md,
0015-cross-check-by-folds.md). Costs one more run of the model, FOLDS where the first fold goes against it (twice as
many with `flip`) and the linear fill at the held-out samples, plus a full one when it fires; `cross_check=False`
(lipjax.inference.CROSS_CHECK) skips it, and the ONNX graph does not hold it.
XLA runs these models on about one of two CPU cores (480x640 with 200 points, training paused: the frame's and the
first fold's estimates took 26 and 22 ms one after the other, 29 ms together in two threads), so the first fold runs
in a second thread beside the frame's own estimate, and the other folds run side by side too (`_FOLDS_BESIDE`).
"""
from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from lipjax.classical.interpolate import linear_fill, linear_fill_at
from lipjax.defaults import FOLDS, MIN_SAMPLES, P_VALUE, SEED  # why each, and its benchmark: lipjax.defaults
from lipjax.inputs import is_lidar_pattern, quietly
from lipjax.resolution import dense_from, working_size

# Threads that run held-out estimates beside the frame's own (module doc): the first fold, then the others at once.
_FOLDS_BESIDE = ThreadPoolExecutor(max_workers=FOLDS - 1, thread_name_prefix="lipjax-crosscheck")


def applies(sparse_m: np.ndarray, scan_lines: bool | None = None) -> bool:
    """Whether a (H, W) sparse map (metres, 0 = none) is checked: >= MIN_SAMPLES samples, at most DENSE per pixel,
    not LiDAR scan lines (`scan_lines`: is_lidar_pattern of the map, asked here when not given)."""
    n = int(np.count_nonzero(sparse_m > 0))
    if not MIN_SAMPLES <= n < dense_from(sparse_m.size):
        return False
    return not (is_lidar_pattern(sparse_m) if scan_lines is None else scan_lines)


def fold_out(sparse_m: np.ndarray, folds: int = FOLDS, seed: int = SEED) -> Iterator[tuple]:
    """(kept (H, W) metres, rows, cols), one per fold, made as they are asked for (the check often stops after the
    first): a seeded permutation of the n samples cut in `folds` parts of n // folds or one more, largest first;
    kept is the sparse map with that fold's samples (at rows, cols) set to 0."""
    rows, cols = np.nonzero(sparse_m > 0)
    for held in np.array_split(np.random.default_rng(seed).permutation(rows.size), folds):
        kept = np.array(sparse_m, np.float32)
        kept[rows[held], cols[held]] = 0.0
        yield kept, rows[held], cols[held]


def held_out_size(size: tuple[int, int], sparse_m: np.ndarray) -> tuple[int, int]:
    """(h, w) at which every fold's held-out estimate of the (H, W) sparse map runs: the working size
    (lipjax.resolution.working_size) of the spacing sqrt(H W / m) of the m = n - ceil(n / FOLDS) samples the first
    fold keeps (`fold_out`'s largest fold comes first), where the model sees them as far apart as it was trained to;
    one size for all folds (one compiled program), never more pixels than `size`, the frame's own run (which a
    caller's max_side may have capped)."""
    n = int(np.count_nonzero(np.asarray(sparse_m) > 0))
    shape = np.shape(sparse_m)
    own = working_size(shape, math.sqrt(shape[0] * shape[1] / (n - math.ceil(n / FOLDS))))
    return own if own[0] * own[1] < size[0] * size[1] else tuple(size)


def misses_more(y: np.ndarray, x_m: np.ndarray, x_l: np.ndarray) -> int:
    """k of the module doc: how many of the depths y the model's values x_m miss by more than the linear fill's x_l."""
    return int(np.count_nonzero(np.abs(x_m - y) > np.abs(x_l - y)))


def blend_weight(y: np.ndarray, x_m: np.ndarray, x_l: np.ndarray, p_value: float = P_VALUE) -> float:
    """w of the module doc from the held-out depths y and the model's and the linear fill's values x_m, x_l there."""
    from scipy.stats import binomtest

    k = misses_more(y, x_m, x_l)  # k > 0 implies x_m != x_l somewhere
    if binomtest(k, y.size, 0.5, alternative="greater").pvalue >= p_value:
        return 1.0
    d = x_m - x_l
    return float(np.clip(np.sum((y - x_l) * d) / np.sum(d * d), 0.0, 1.0))


def cross_checked(estimate: Callable[[np.ndarray, tuple[int, int]], np.ndarray], sparse_m: np.ndarray,
                  size: tuple[int, int], scan_lines: bool | None = None) -> tuple[np.ndarray, float]:
    """(x, w): z = estimate(sparse_m, size), the model's (H, W) estimate from every sample of `sparse_m` (metres)
    run at working size `size` (h, w), blended with the linear fill as the module doc says; each fold's estimate
    from its kept samples is estimate(kept, held_out_size(size, sparse_m)), run in other threads (the first fold
    beside z's). Measured pixels are not set back here (the caller's final x-update does it). A map the check does
    not apply to (`applies`, given `scan_lines` when the caller knows it) gives (z, 1.0)."""
    if not applies(sparse_m, scan_lines):
        return estimate(sparse_m, size), 1.0
    at = held_out_size(size, sparse_m)
    folds = fold_out(sparse_m)
    kept, rows, cols = next(folds)
    first = _FOLDS_BESIDE.submit(quietly, estimate, kept, at)
    z = estimate(sparse_m, size)
    y, x_l = [sparse_m[rows, cols]], [linear_fill_at(kept, rows, cols)]  # while the fold may still run
    x_m = [first.result()[rows, cols]]
    if 2 * misses_more(y[0], x_m[0], x_l[0]) <= rows.size:
        return z, 1.0  # k <= n / 2 on the first fold: the model fits, the other folds do not run (docs/decisions/0015)
    rest = list(folds)
    beside = [_FOLDS_BESIDE.submit(quietly, estimate, kept, at) for kept, _, _ in rest]
    for (kept, rows, cols), z_kept in zip(rest, (future.result() for future in beside)):
        y.append(sparse_m[rows, cols])
        x_m.append(z_kept[rows, cols])
        x_l.append(linear_fill_at(kept, rows, cols))
    w = blend_weight(np.concatenate(y), np.concatenate(x_m), np.concatenate(x_l))
    if w == 1.0:
        return z, w
    return (w * z + (1.0 - w) * linear_fill(sparse_m)).astype(np.float32), w
