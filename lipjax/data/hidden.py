"""Self-supervision from sparse depth alone: samples hidden from a frame's own input become its ground truth.

    hidden = hidden_samples(sparse, 0.2, rng)    # 20 % of the samples, or whole scan-line segments
    size = working_shape(sparse)                # where the default path runs a learned model on this input
    small = reproject(sparse, size)

A frame of your sensor without dense ground truth still has ground truth at its samples. A self-supervised example
hides a share of its own samples from the input and asks the model for their depth: the input is the rest, the
ground truth the hidden samples alone (`without_input`), so the loss never sees an input sample and copying the input
earns nothing. Scattered samples hide a random share of their points; LiDAR scan lines
(lipjax.inputs.is_lidar_pattern) hide whole segments of scan lines (`scan_line_segments`): the gaps between lines are
what the model fills at test time, and a point hidden between its neighbours on a line would teach little.

Examples are made at the size at which the default path (lipjax.inference.frame_size) runs a learned model on the
frame's whole input (`AtWorkingSize`), so that the model adapts to what it sees there. The samples are hidden at full
size and then moved onto that grid as the default path moves them (`reproject`: the nearest wins in a pixel).

`HiddenInput` is the sampler of the spec "hide[:F]" (lipjax.data.sources: a folder's sparse/ maps, F the share hidden,
HIDE_SHARE by default). Two flags tell lipjax.data.pipeline what it is: `withholds` (an example's ground truth is the
frame's samples less the input: `without_input`) and `redraw_each_epoch` (training hides other samples each epoch,
keyed by the run's seed and the epoch; validation keeps the fixed draw of its seed).
"""
from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import cv2
import numpy as np

from lipjax.data.frame import Frame
from lipjax.data.sampling import example_rng
from lipjax.inputs import is_lidar_pattern
from lipjax.resolution import is_capped, sample_spacing_px, working_size
from lipjax.zbuffer import splat_nearest

HIDE = "hide"  # the spec "hide" / "hide:F"
HIDE_SHARE = 0.2  # of a frame's samples hidden from its input (benchmarks/real_frames.py hides 20 % as well)
LINE_LINK_SPACINGS = 8  # samples of a scan line join across gaps in their row of up to this many line spacings ...
LINE_LINK_WIDTH_SHARE = 1 / 16  # ... and at most this share of the frame's width


def hide_share(spec: str) -> float | None:
    """The share of spec "hide" (HIDE_SHARE) or "hide:F" (F in (0, 1)); None for any other spec. One-line
    ValueError for a "hide" spec whose share is no number in (0, 1)."""
    kind, _, arg = spec.strip().partition(":")
    if "|" in spec or kind.strip().lower() != HIDE:
        return None
    try:
        share = float(arg) if arg.strip() else HIDE_SHARE
    except ValueError:
        share = float("nan")
    if not 0 < share < 1:
        raise ValueError(f"sampler spec {spec!r}: expected 'hide' or 'hide:F' with F, the share of the samples "
                         "hidden from the input, in (0, 1), e.g. 'hide:0.2'")
    return share


def scan_line_segments(sparse: np.ndarray) -> np.ndarray:
    """(H, W) int32: the scan-line segment of each sample of a (H, W) map in LiDAR scan lines, -1 where none.

    Two samples are in one segment when a chain of samples joins them, each link at most one row up or down and at
    most L pixels along the row: L = LINE_LINK_SPACINGS line spacings (the median gap down a column, as
    lipjax.inputs.is_lidar_pattern measures it), at most LINE_LINK_WIDTH_SHARE of the width. A line broken by a
    longer gap (no return: sky, glass, a black car) is several segments. On the 3 shared KITTI frames with the
    HDL-64 pattern (benchmarks.common.frames_and_inputs), every segment holds one beam's points alone (as
    benchmarks/real_frames.py's beam_index labels them), about 6 segments a beam."""
    on = np.asarray(sparse) > 0
    rows, cols = np.divmod(np.flatnonzero(on), on.shape[1])
    order = np.lexsort((rows, cols))
    rows, cols = rows[order], cols[order]
    down = (rows[1:] - rows[:-1])[cols[1:] == cols[:-1]]
    spacing = float(np.median(down)) if down.size else 1.0
    link = int(max(2, min(round(LINE_LINK_SPACINGS * spacing), round(LINE_LINK_WIDTH_SHARE * on.shape[1]))))
    # each sample's run to the right reaches the next sample of its row within `link` px; runs one row apart touch
    grown = cv2.dilate(on.astype(np.uint8), np.ones((1, link), np.uint8), anchor=(0, 0))
    _, labels = cv2.connectedComponents(grown, connectivity=8)
    return np.where(on, labels - 1, -1).astype(np.int32)


def hidden_samples(sparse: np.ndarray, share: float, rng: np.random.Generator,
                   scan_lines: bool | None = None) -> np.ndarray:
    """(H, W) bool: the samples of a (H, W) map (metres, 0 = none) hidden from the input, about `share` of them.

    Scattered samples: round(share x n) of the n samples, at random. LiDAR scan lines (`scan_lines`, asked of
    lipjax.inputs.is_lidar_pattern when None): whole segments (`scan_line_segments`) in random order until round(share
    x n) samples are hidden, a segment that would take the count past 1.5 times that skipped (two beams a merged
    segment holds); random points where no segment fits."""
    on = np.asarray(sparse) > 0
    target = int(round(share * np.count_nonzero(on)))
    hidden = np.zeros(on.shape, bool)
    if target == 0:
        return hidden
    lines = is_lidar_pattern(sparse) if scan_lines is None else scan_lines
    if lines:
        labels = scan_line_segments(sparse)
        ids, sizes = np.unique(labels[labels >= 0], return_counts=True)
        taken, count = [], 0
        for i in rng.permutation(ids.size):
            if count >= target:
                break
            if count + sizes[i] <= target + target // 2:
                taken.append(ids[i])
                count += int(sizes[i])
        if taken:
            return np.isin(labels, taken)
    hidden.reshape(-1)[rng.choice(np.flatnonzero(on), target, replace=False)] = True
    return hidden


def working_shape(sparse: np.ndarray, scan_lines: bool | None = None) -> tuple[int, int]:
    """(h, w) at which the default path runs a learned model on a frame with these (H, W) samples (metres): the
    working size of their spacing and pattern (lipjax.resolution.working_size, capped for scan lines and dense
    maps), as lipjax.inference.frame_size gives it for a learned model; the frame's own size without samples."""
    shape = tuple(np.shape(sparse))
    spacing = sample_spacing_px(sparse)
    if spacing == float("inf"):
        return shape
    lines = is_lidar_pattern(sparse) if scan_lines is None else scan_lines
    return working_size(shape, spacing, capped=is_capped(int(np.count_nonzero(np.asarray(sparse) > 0)), shape, lines))


def reproject(sparse: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """(h, w) float32 metres: each sample of a (H, W) map moved to the pixel of the (h, w) grid its centre falls in,
    the nearest where several meet (as lipjax.inference.reproject_sparse moves the default path's samples)."""
    sparse = np.asarray(sparse, np.float32)
    big_h, big_w = sparse.shape
    h, w = size
    flat = np.flatnonzero(sparse > 0)
    rows, cols = np.divmod(flat, big_w)
    r = np.minimum(((rows + 0.5) * h / big_h).astype(np.int64), h - 1)
    c = np.minimum(((cols + 0.5) * w / big_w).astype(np.int64), w - 1)
    return splat_nearest(r * w + c, sparse.ravel()[flat], (h, w))


@dataclasses.dataclass(frozen=True)
class AtWorkingSize:
    """A protocol step for Frames whose depth is their own sparse map (lipjax.data.folder.FolderDataset with
    depth_dir=SPARSE_DIR): the Frame at `working_shape` of its samples, the RGB area-resized (as the default path
    resizes it), the samples moved by `reproject`, the intrinsics scaled; the same Frame at its own size."""

    def __call__(self, frame: Frame) -> Frame:
        size = working_shape(frame.depth)
        if size == frame.shape:
            return frame
        h, w = size
        rgb = cv2.resize(frame.rgb, (w, h), interpolation=cv2.INTER_AREA)
        intrinsics = frame.intrinsics.resized(h / frame.shape[0], w / frame.shape[1])
        return Frame.from_depth(rgb, reproject(frame.depth, size), intrinsics, frame.id)


def without_input(frame: Frame, sparse: np.ndarray) -> Frame:
    """`frame` with its ground truth only where it has some and the input `sparse` (metres, 0 = none) has none:
    the samples hidden from the input, all that a self-supervised loss may see."""
    hidden = frame.valid & (np.asarray(sparse) <= 0)
    return dataclasses.replace(frame, depth=np.where(hidden, frame.depth, 0).astype(np.float32), valid=hidden)


@dataclasses.dataclass(frozen=True)
class HiddenInput:
    """Sampler of spec "hide[:F]": a frame's own samples less `share` of them hidden (`hidden_samples`, drawn by
    example_rng(seed, frame.id, "hidden") at full size), moved onto the frame's grid when it is at its working size
    (`AtWorkingSize`).

    full: what reads a frame's full-size sparse map, full.read(frame.id) -> (H, W) float32 metres
    (lipjax.data.sources.FolderInput). A pipeline gives the example the hidden samples alone as its ground truth
    (`withholds`) and training draws other hidden samples each epoch (`redraw_each_epoch`)."""

    full: Any
    share: float = HIDE_SHARE
    withholds: ClassVar[bool] = True
    redraw_each_epoch: ClassVar[bool] = True

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        full = self.full.read(frame.id)
        kept = np.where(hidden_samples(full, self.share, example_rng(seed, frame.id, "hidden")), 0.0, full)
        kept = kept.astype(np.float32)
        return kept if kept.shape == frame.shape else reproject(kept, frame.shape)
