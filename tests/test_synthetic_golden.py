"""Golden digests of rendered synthetic frames: the renderer's output is frozen bit for bit.

Shipped models, their tables and the rendered training folders depend on every frame staying identical, so a
refactor of the scene builders must keep the same random draws in the same order. The digests below were recorded
from the renderer before it was split into per-element builders (commit 34186e2); a change to any of them means the
frames changed. A deliberate change must bump the seed's version key ("lipjax/synthetic/v1/...") and regenerate the
tables that depend on the frames.

They hold for one numpy / OpenCV build (the project's locked versions): the renderer is deterministic, not portable
across library versions.
"""
from __future__ import annotations

import hashlib

import numpy as np
import pytest

from lipjax.data import synthetic as S
from lipjax.data.rendered import RenderSpec, _render_frame

SMALL = (64, 80)
INDICES = range(12)


def _digest(*arrays: np.ndarray) -> str:
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def _frames_digest(kind: str, split: str, height: int, width: int, indices) -> str:
    """One sha256 over rgb, depth, labels and camera pose of every frame, in order."""
    arrays = []
    for i in indices:
        frame, info = S.render_with_info(kind, split, i, height, width)
        arrays += [frame.rgb, frame.depth, info.labels, info.camera_to_world]
    return _digest(*arrays)


SMALL_DIGESTS = {
    ("indoor", "train"): "383dc4dfff43b674f72ffc39a75de4afd6e170dcd14f4af22681c055d2df9236",
    ("indoor", "val"): "c2575beed18364c117bf409961dd96fad12fc8f289b6b7335614d77f69a483d4",
    ("indoor", "test"): "e302afa6f66fd640ecdd30496a2e966125d7f6ef52b1e6249b68f5b1189507fc",
    ("outdoor", "train"): "9cbd4375ca39331d30d9f7fbbacead79e402f0a3a0d4af6519e7c904e092a53d",
    ("outdoor", "val"): "4d386e42e1128b6669a8246770bdf0df0afbb2b26706c7feac1dcc65ef53931d",
    ("outdoor", "test"): "b67d477a5effe4d19a11d3e722871de256faea3709937523ab85f4d28f1428ab",
}
FULL_DIGESTS = {  # (kind, split, index) at 256x320
    ("indoor", "val", 3): "f8a4b4489dd4b4d98c7373104c4b0fa96ed6e6928253be90e4bc65b500bac46e",
    ("outdoor", "train", 17): "b0e9e3cf74ba5a45ccaefb7923eacebb37cf610320381c4c56ccfe1130f7dbda",
}
WINDOW_DIGESTS = {  # rendered.py's windowed frames: a 64x80 window of a 128x160 frame
    ("indoor", "train", 5): "4664567231e898e55b503f596a53d8a66e56b8560e9dbeff3639c9f820f73f34",
    ("outdoor", "train", 9): "77ba60a457f34c6f8c388ab5b18a6d0c759019b0471dce46ca13a174c6d9bbdc",
}


@pytest.mark.parametrize("kind,split", sorted(SMALL_DIGESTS))
def test_small_frames_are_unchanged(kind, split):
    assert _frames_digest(kind, split, *SMALL, INDICES) == SMALL_DIGESTS[kind, split]


@pytest.mark.parametrize("kind,split,index", sorted(FULL_DIGESTS))
def test_full_size_frame_is_unchanged(kind, split, index):
    assert _frames_digest(kind, split, 256, 320, [index]) == FULL_DIGESTS[kind, split, index]


@pytest.mark.parametrize("kind,split,index", sorted(WINDOW_DIGESTS))
def test_windowed_frame_is_unchanged(kind, split, index):
    spec = RenderSpec(kind, split, count=16, height=128, width=160, window=SMALL)
    rgb, depth = _render_frame(spec, index)
    assert rgb.shape == (*SMALL, 3) and depth.shape == SMALL
    assert _digest(rgb, depth) == WINDOW_DIGESTS[kind, split, index]
