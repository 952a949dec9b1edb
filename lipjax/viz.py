"""Pictures of depth maps: colour maps with a fixed range, error maps, panels and comparison figures (Fig. 3).

All functions return uint8 RGB images (H, W, 3) and never change global matplotlib state (no pyplot; the
colour tables come from `matplotlib.colormaps`, figures are drawn on an Agg canvas).

Conventions, fixed so that pictures of different frames and methods compare:
  - `colorize_depth(depth_m, min_m=0, max_m=10, cmap="turbo")`: depth is clipped to [min_m, max_m] metres and
    mapped linearly onto the colour map, near = low end (dark blue for turbo), far = high end (dark red).
    The range never adapts to the image: pass min_m / max_m (e.g. 0-10 m indoors, 0-80 m outdoors), or
    `fitting_range(depth_m, max_m)`, the model's range unless the data do not fit it.
    Invalid pixels (depth <= 0, NaN, inf) are black.
  - `error_map(pred, gt, valid, max_error_m=1)`: |pred - gt| in metres on "jet", dark blue (0 m) to dark red
    (>= max_error_m), as the paper's error maps ("the value of the error increases from dark blue to dark red").
    Pixels without valid ground truth are black.
  - `colorize_sparse`: a sparse map with each sample drawn as a small disc, so 200 points stay visible.

A Fig.-3-like figure (per frame: RGB | sparse input | GT | each method's prediction, its error map below):

    frame = Comparison("frame 1", rgb, sparse, gt, {"LIP+AD": pred, "linear": fill})
    save_comparison_grid("fig3.png", [frame], max_m=10, max_error_m=0.5)
"""
from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping, Sequence

import cv2
import numpy as np

from lipjax.interfaces import SCENE_MAX_DEPTH_M

DEFAULT_DEPTH_CMAP = "turbo"
DEFAULT_ERROR_CMAP = "jet"
INVALID_COLOR = (0, 0, 0)


def _lut(cmap: str) -> np.ndarray:
    """(256, 3) uint8 colour table of a matplotlib colour map."""
    import matplotlib

    try:
        colormap = matplotlib.colormaps[cmap]
    except KeyError:
        raise ValueError(f"unknown colour map {cmap!r} "
                         f"(any matplotlib colour map name, e.g. 'turbo', 'magma')") from None
    return np.round(colormap(np.linspace(0.0, 1.0, 256))[:, :3] * 255).astype(np.uint8)


def _apply(values: np.ndarray, lo: float, hi: float, draw: np.ndarray, cmap: str) -> np.ndarray:
    if not hi > lo:
        raise ValueError(f"colour range must have max > min, got [{lo}, {hi}]")
    values = np.asarray(values, dtype=np.float64)
    t = np.clip((np.nan_to_num(values, nan=lo) - lo) / (hi - lo), 0.0, 1.0)
    out = _lut(cmap)[np.round(t * 255).astype(np.intp)]
    out[~draw] = INVALID_COLOR
    return out


def colorize_depth(depth_m: np.ndarray, min_m: float = 0.0, max_m: float = SCENE_MAX_DEPTH_M["indoor"],
                   cmap: str = DEFAULT_DEPTH_CMAP) -> np.ndarray:
    """Depth (H, W) metres -> (H, W, 3) uint8 RGB over the fixed range [min_m, max_m]; invalid (<= 0) black."""
    depth = np.asarray(depth_m)
    if depth.ndim != 2:
        raise ValueError(f"depth must be (H, W), got shape {depth.shape}")
    valid = np.isfinite(depth) & (depth > 0)
    return _apply(depth, min_m, max_m, valid, cmap)


FIT_PERCENTILE = 99.0
"""The depth percentile (of the valid pixels) that `fitting_range` fits the colour range to."""


def fitting_range(depth_m: np.ndarray, max_m: float) -> tuple[float, float]:
    """A colour range (0, top) metres for `depth_m` (any shape; <= 0, NaN and inf are no depth): (0, max_m),
    e.g. the model's range, when its FIT_PERCENTILE-th percentile p of the valid depths lies in [max_m / 4, max_m];
    else (0, p), so that a picture neither saturates (p > max_m) nor uses under a quarter of the colours.
    (0, max_m) when no pixel has depth."""
    depth = np.asarray(depth_m, np.float64)
    valid = depth[np.isfinite(depth) & (depth > 0)]
    if valid.size == 0:
        return 0.0, float(max_m)
    p = float(np.percentile(valid, FIT_PERCENTILE))
    return (0.0, float(max_m)) if max_m / 4 <= p <= max_m else (0.0, p)


def colorize_sparse(sparse_m: np.ndarray, min_m: float = 0.0, max_m: float = SCENE_MAX_DEPTH_M["indoor"],
                    cmap: str = DEFAULT_DEPTH_CMAP, radius: int = 2) -> np.ndarray:
    """A sparse depth map drawn with each sample enlarged to a (2 radius + 1)^2 square, for visibility.

    Where enlarged samples overlap, the nearer one is drawn (as a z-buffer would). Colours as colorize_depth.
    """
    sparse = np.asarray(sparse_m, dtype=np.float32)
    if radius > 0:
        # Dilate 1/depth: max of inverse depth = the nearest sample; empty pixels (inf -> 0) never win.
        with np.errstate(divide="ignore"):
            inverse = np.where(sparse > 0, 1.0 / sparse, 0.0).astype(np.float32)
        inverse = cv2.dilate(inverse, np.ones((2 * radius + 1, 2 * radius + 1), np.uint8))
        with np.errstate(divide="ignore"):
            sparse = np.where(inverse > 0, 1.0 / inverse, 0.0).astype(np.float32)
    return colorize_depth(sparse, min_m, max_m, cmap)


def error_map(pred_m: np.ndarray, gt_m: np.ndarray, valid: np.ndarray | None = None, max_error_m: float = 1.0,
              cmap: str = DEFAULT_ERROR_CMAP) -> np.ndarray:
    """|pred - gt| (H, W) metres -> (H, W, 3) uint8, dark blue (0) to dark red (>= max_error_m).

    `valid` defaults to gt > 0; pixels outside it are black.
    """
    pred, gt = np.asarray(pred_m, np.float64), np.asarray(gt_m, np.float64)
    if pred.shape != gt.shape or pred.ndim != 2:
        raise ValueError(f"pred and gt must be (H, W) of the same size, got {pred.shape} and {gt.shape}")
    valid = (gt > 0) if valid is None else np.asarray(valid, bool)
    valid = valid & np.isfinite(gt) & np.isfinite(pred)
    return _apply(np.abs(pred - gt), 0.0, max_error_m, valid, cmap)


def _as_rgb(image: np.ndarray) -> np.ndarray:
    image = np.asarray(image)
    if image.ndim == 2:
        image = np.repeat(image[..., None], 3, axis=2)
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise ValueError(f"panel images must be uint8 (H, W, 3) or (H, W), got {image.dtype} {image.shape}")
    return image


def write_png(path: str | os.PathLike, image: np.ndarray) -> None:
    """Writes a uint8 RGB (H, W, 3) or grey (H, W) image as PNG (cv2 wants BGR; converted here)."""
    image = np.asarray(image)
    if image.ndim == 3:
        image = cv2.cvtColor(image, cv2.COLOR_RGB2BGR)
    if not cv2.imwrite(os.fspath(path), image):
        raise OSError(f"cannot write image {os.fspath(path)!r} (folder missing or unsupported extension?)")


@dataclasses.dataclass(frozen=True)
class Comparison:
    """One frame of a comparison figure: its label, RGB uint8 (H, W, 3), sparse input, ground truth and each
    method's prediction (metres, (H, W)); `valid` marks the ground truth scored (default gt > 0)."""

    label: str
    rgb: np.ndarray
    sparse_m: np.ndarray
    gt_m: np.ndarray
    predictions: Mapping[str, np.ndarray]
    valid: np.ndarray | None = None


def save_comparison_grid(path: str | os.PathLike, frames: Sequence[Comparison], max_m: float, max_error_m: float,
                         sparse_title: str = "sparse input", cell_inches: float = 1.7, dpi: int = 100,
                         cmap: str = DEFAULT_DEPTH_CMAP) -> None:
    """Writes a figure (PNG / PDF / SVG by extension) that reads at 100 %: per frame two rows, RGB | sparse input |
    ground truth | each method's prediction above, and under each prediction its error map with the frame's RMSE
    (metres, over the valid ground truth). The frame's label sits under its RGB image; one colour bar for depth
    [0, max_m] and one for |error| [0, max_error_m] run under the grid with a gap between them. Methods keep the
    order of each frame's `predictions`; every frame must have the same methods. With the defaults, 3 frames of
    4 methods at the 4:5 aspect of 256x320 make about 950 x 820 pixels."""
    import textwrap

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    if not frames:
        raise ValueError("save_comparison_grid needs at least one frame")
    methods = list(frames[0].predictions)
    ncols = 3 + len(methods)
    h, w = np.shape(frames[0].gt_m)
    cell_h = cell_inches * h / w
    fig = Figure(figsize=(cell_inches * ncols, len(frames) * (2 * cell_h + 0.2) + 0.9), dpi=dpi)
    FigureCanvasAgg(fig)
    outer = fig.add_gridspec(len(frames) + 1, 1, height_ratios=[2 * cell_h] * len(frames) + [0.35], hspace=0.12)

    def show(ax, image=None):
        ax.set_xticks([]), ax.set_yticks([])
        if image is None:
            ax.set_axis_off()
        else:
            ax.imshow(image, interpolation="nearest")

    for f, frame in enumerate(frames):
        if list(frame.predictions) != methods:
            raise ValueError(f"frame {frame.label!r} has methods {list(frame.predictions)}, not {methods}")
        valid = (np.asarray(frame.gt_m) > 0) if frame.valid is None else np.asarray(frame.valid, bool)
        cells = outer[f].subgridspec(2, ncols, hspace=0.04, wspace=0.03)
        top = [_as_rgb(frame.rgb), colorize_sparse(frame.sparse_m, 0.0, max_m, cmap),
               colorize_depth(np.where(valid, frame.gt_m, 0), 0.0, max_m, cmap)]
        top += [colorize_depth(pred, 0.0, max_m, cmap) for pred in frame.predictions.values()]
        for c, (image, title) in enumerate(zip(top, ["RGB", sparse_title, "ground truth"] + methods)):
            ax = fig.add_subplot(cells[0, c])
            show(ax, image)
            if f == 0:
                ax.set_title(title, fontsize=9)
        label = fig.add_subplot(cells[1, 0:3])
        show(label)
        label.text(0.0, 0.5, "\n".join(textwrap.wrap(frame.label, 40)) + "\n\nbelow each prediction: its error",
                   fontsize=8, va="center", transform=label.transAxes)
        for c, pred in enumerate(frame.predictions.values()):
            ax = fig.add_subplot(cells[1, 3 + c])
            show(ax, error_map(pred, frame.gt_m, valid, max_error_m))
            keep = valid & np.isfinite(pred)
            rmse = float(np.sqrt(np.mean((np.asarray(pred)[keep] - np.asarray(frame.gt_m)[keep]) ** 2)))
            ax.text(0.03, 0.05, f"RMSE {rmse:.3f} m", fontsize=7, transform=ax.transAxes,
                    bbox={"facecolor": "white", "alpha": 0.8, "pad": 1.5, "linewidth": 0})
    bars = outer[len(frames)].subgridspec(1, ncols, wspace=0.03)
    left = max(1, (ncols - 1) // 2)  # the depth bar's columns; the error bar takes as many at the right
    for cols, label, vmax, bar_cmap in ((slice(0, left), "depth [m]", max_m, cmap),
                                        (slice(ncols - left, ncols), "|error| [m]", max_error_m, DEFAULT_ERROR_CMAP)):
        cax = fig.add_subplot(bars[0, cols])
        bar = fig.colorbar(ScalarMappable(Normalize(0.0, vmax), bar_cmap), cax=cax, orientation="horizontal")
        bar.set_label(label, fontsize=8)
        bar.ax.tick_params(labelsize=7)
    fig.savefig(os.fspath(path), bbox_inches="tight")
