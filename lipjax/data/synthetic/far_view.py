"""Far views: a street through a window inside a room, so that one frame spans the depths of both scene kinds.

A rendered room is closed (every depth within ~11 m); a photograph of a room often is not: windows, open doors
and glass walls show buildings and trees tens of metres away, and a sparse sensor samples them as it samples the
walls. A prox trained on closed rooms takes such samples for outliers (`python -m research.far_views`: the
228,000-image lip-any, 0.781x linear on 12 closed test rooms, is 1.014x with their windows; research/README.md).
`add_far_view` pastes a rectangle of a street render into a room render of the same size:

    (t, l, h, w)   the window in the room: h / H in WINDOW_HEIGHT, w / W in WINDOW_WIDTH, t / H in WINDOW_TOP
    (t', l')       where the view is cut from the street frame: t' in its upper VIEW_ROWS (facades, trees, sky)
    rgb[t:t+h, l:l+w]   = view.rgb[t':t'+h, l':l'+w]
    depth[t:t+h, l:l+w] = view.depth[t':t'+h, l':l'+w]     metres; the view's sky stays 0 (invalid, no return)

The window's border is a colour edge and a depth edge at once, as a window frame is. `MixedSyntheticDataset`
(far_view_prob) draws every choice from `lipjax.data.synthetic.dataset.far_view_rng`, a stream of its own, so a room
keeps its scene, camera and noise with or without its window.
"""
from __future__ import annotations

import numpy as np

from lipjax.data.frame import Frame

WINDOW_HEIGHT = (0.2, 0.45)  # window height / frame height
WINDOW_WIDTH = (0.15, 0.4)  # window width / frame width
WINDOW_TOP = (0.0, 0.35)  # window top edge / frame height: windows and door tops sit in a wall's upper part
VIEW_ROWS = 0.5  # the view is cut from the street frame's upper half


def far_view_box(shape: tuple[int, int], rng: np.random.Generator) -> tuple[int, int, int, int, int, int]:
    """(t, l, h, w, t', l'): the window in the room and the top-left corner of the view it shows (pixels)."""
    H, W = shape
    h = max(1, int(round(H * rng.uniform(*WINDOW_HEIGHT))))
    w = max(1, int(round(W * rng.uniform(*WINDOW_WIDTH))))
    t = min(int(H * rng.uniform(*WINDOW_TOP)), H - h)
    l = int(rng.integers(0, W - w + 1))
    t_view = int(rng.integers(0, max(int(H * VIEW_ROWS) - h, 0) + 1))
    l_view = int(rng.integers(0, W - w + 1))
    return t, l, h, w, t_view, l_view


def add_far_view(room: Frame, view: Frame, rng: np.random.Generator) -> Frame:
    """`room` with a window onto `view` (the module docstring); the room's intrinsics and id are kept.

    Raises:
      ValueError: the two frames differ in size.
    """
    if room.shape != view.shape:
        raise ValueError(f"a window needs a view of the room's size {room.shape}, got {view.shape}")
    t, l, h, w, tv, lv = far_view_box(room.shape, rng)
    rgb, depth = room.rgb.copy(), np.where(room.valid, room.depth, 0.0).astype(np.float32)
    rgb[t:t + h, l:l + w] = view.rgb[tv:tv + h, lv:lv + w]
    depth[t:t + h, l:l + w] = np.where(view.valid, view.depth, 0.0)[tv:tv + h, lv:lv + w]
    return Frame.from_depth(rgb, depth, room.intrinsics, room.id)
