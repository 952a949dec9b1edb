"""The public entry points: `render`, `render_with_info`, `SyntheticDataset`, `intrinsics_for`, `frame_id`.

Argument checks (`check_kind_split`, `check_size`), per-frame random streams (`frame_rngs`) and sample ids live here;
a frame's scene comes from `scenes.build_scene` and is drawn by `renderer.render_scene`.
"""
from __future__ import annotations

import dataclasses
import hashlib
import math
from typing import Iterator

import numpy as np

from lipjax.data.frame import Frame, Intrinsics
from lipjax.interfaces import MIXED_SCENES
from lipjax.data.synthetic.constants import (
    DEFAULT_HEIGHT,
    DEFAULT_SIZES,
    DEFAULT_WIDTH,
    KITTI_IMAGE_SIZE,
    KITTI_INTRINSICS,
    NYU_IMAGE_SIZE,
    NYU_INTRINSICS,
    SPLITS,
    SYNTHETIC_KINDS,
)
from lipjax.data.synthetic.clutter import add_clutter
from lipjax.data.synthetic.foliage import porous_foliage
from lipjax.data.synthetic.far_view import add_far_view
from lipjax.data.synthetic.renderer import Reflection, render_scene
from lipjax.data.synthetic.build import build_scene


@dataclasses.dataclass(frozen=True)
class SceneInfo:
    """What was rendered, beyond the Frame: for tests, debugging and visualisation.

    Attributes:
      kind: "indoor" or "outdoor".
      camera_to_world: (4, 4) float64; world = R @ camera + t. World y is up and the floor / road is y = 0.
      camera_height_m: height of the camera centre above y = 0.
      labels: (H, W) int8, index into LABELS per pixel (0 = sky).
    """

    kind: str
    camera_to_world: np.ndarray
    camera_height_m: float
    labels: np.ndarray


def check_kind_split(kind: str, split: str) -> None:
    """ValueError unless kind is in SYNTHETIC_KINDS and split in SPLITS."""
    if kind not in SYNTHETIC_KINDS:
        raise ValueError(f"unknown synthetic kind {kind!r}; expected one of {SYNTHETIC_KINDS}")
    if split not in SPLITS:
        raise ValueError(f"unknown split {split!r}; expected one of {SPLITS}")


def _check_index(index) -> int:
    if isinstance(index, (bool, np.bool_)) or not isinstance(index, (int, np.integer)):
        raise ValueError(f"index must be an int, got {index!r}")
    if index < 0:
        raise ValueError(f"index must be >= 0, got {index}")
    return int(index)


def check_size(height, width) -> tuple[int, int]:
    """(height, width) as ints; ValueError unless both are ints >= 8 (pixels)."""
    ints = isinstance(height, (int, np.integer)) and isinstance(width, (int, np.integer))
    if not ints or height < 8 or width < 8:
        raise ValueError(f"height and width must be ints >= 8, got {height!r} x {width!r}")
    return int(height), int(width)


def check_probability(name: str, p) -> float:
    """p as a float; ValueError naming `name` unless 0 <= p <= 1."""
    try:
        value = float(p)
    except (TypeError, ValueError):
        value = math.nan
    if not 0.0 <= value <= 1.0:
        raise ValueError(f"{name} must be a probability in [0, 1], got {p!r}")
    return value


# What a frame of one kind may get on request, with a probability per frame (SyntheticDataset): the probability's
# name -> (the kind whose frames take it, what they are called).
EXTRAS = {"clutter_prob": ("indoor", "rooms"), "foliage_prob": ("outdoor", "streets")}


def check_extra(name: str, p, kind: str) -> float:
    """`p` as a probability (check_probability) of extra `name` (EXTRAS) for frames of `kind`; ValueError if p > 0
    and only frames of another kind take it."""
    value = check_probability(name, p)
    wanted, scenes = EXTRAS[name]
    if value and kind != wanted:
        raise ValueError(f"{name} is for {scenes} (kind '{wanted}'), got kind {kind!r}; leave it at 0")
    return value


def intrinsics_for(kind: str, height: int = DEFAULT_HEIGHT, width: int = DEFAULT_WIDTH) -> Intrinsics:
    """The camera of `kind` ("indoor": NYU v2 `NYU_INTRINSICS`, "outdoor": KITTI `KITTI_INTRINSICS`) scaled
    to height x width pixels, keeping square pixels.

    The reference frame (480x640 / 375x1242) is centre-cropped to the largest window with the render's aspect
    ratio, then resized isotropically (`Intrinsics.cropped`, then `Intrinsics.resized`, pixel-centre
    convention). So a 4:3 render of NYU is exactly `NYU_INTRINSICS.resized(s, s)`; a 256x320 outdoor render
    sees KITTI's vertical field of view (horizon at the same relative row) with a narrower horizontal one,
    like a centre crop of a KITTI frame. A plain per-axis resize would squash KITTI's 3.3:1 frame into 4:5
    and make pixels 2.6x taller than wide, unlike any real KITTI / NYU evaluation crop (lipjax.data.protocols
    keeps pixels square).
    """
    if kind not in SYNTHETIC_KINDS:
        raise ValueError(f"unknown synthetic kind {kind!r}; expected one of {SYNTHETIC_KINDS}")
    height, width = check_size(height, width)
    ref, (h0, w0) = (NYU_INTRINSICS, NYU_IMAGE_SIZE) if kind == "indoor" else (KITTI_INTRINSICS, KITTI_IMAGE_SIZE)
    if width * h0 <= height * w0:  # render narrower than the reference: crop columns
        ch, cw = float(h0), h0 * width / height
    else:  # wider: crop rows
        ch, cw = w0 * height / width, float(w0)
    return ref.cropped((h0 - ch) / 2, (w0 - cw) / 2).resized(height / ch, width / cw)


def frame_id(kind: str, split: str, index: int) -> str:
    """The Frame.id of a synthetic frame, e.g. "synthetic/indoor/val/000042"."""
    return f"synthetic/{kind}/{split}/{index:06d}"


def _seed(name: str) -> int:
    """A 128-bit seed from a stream's name: the first 16 bytes of sha256(name), little-endian."""
    return int.from_bytes(hashlib.sha256(name.encode("utf-8")).digest()[:16], "little")


def focal_factor(kind: str, split: str, index: int, focal_range: tuple[float, float] = (1.0, 1.0)) -> float:
    """The factor on the reference camera's focal length for frame `index`: log-uniform in `focal_range`
    (lo, hi), drawn from a stream of its own (sha256 of "lipjax/synthetic/focal/v1/{kind}/{split}/{index}"), so the
    scene and the sensor noise are those of the same frame at the reference focal length. 1 for (1, 1)."""
    lo, hi = check_focal_range(focal_range)
    if lo == hi:
        return lo
    u = np.random.default_rng(_seed(f"lipjax/synthetic/focal/v1/{kind}/{split}/{index}")).random()
    return float(np.exp(np.log(lo) + u * (np.log(hi) - np.log(lo))))


def check_focal_range(focal_range) -> tuple[float, float]:
    """(lo, hi) as floats; ValueError unless 0 < lo <= hi."""
    try:
        lo, hi = (float(v) for v in focal_range)
    except (TypeError, ValueError):
        raise ValueError(f"focal_range must be (lo, hi), two factors on the focal length, got {focal_range!r}"
                         ) from None
    if not 0 < lo <= hi:
        raise ValueError(f"focal_range must have 0 < lo <= hi, got {focal_range!r}")
    return lo, hi


def frame_rngs(kind: str, split: str, index: int) -> tuple[np.random.Generator, np.random.Generator]:
    """(scene stream, sensor-noise stream) of frame `index` of (kind, split): two numpy Generators spawned from
    sha256("lipjax/synthetic/v1/{kind}/{split}/{index}"), the same in every process."""
    seed = _seed(f"lipjax/synthetic/v1/{kind}/{split}/{index}")
    scene_rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(0,)))
    noise_rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(1,)))
    return scene_rng, noise_rng


def far_view_rng(split: str, index: int) -> np.random.Generator:
    """The stream that decides room `index` of `split`'s window (MixedSyntheticDataset): whether, which view,
    where; sha256 of "lipjax/synthetic/window/v1/{split}/{index}"."""
    return np.random.default_rng(_seed(f"lipjax/synthetic/window/v1/{split}/{index}"))


def clutter_rng(split: str, index: int) -> np.random.Generator:
    """The stream that decides room `index` of `split`'s clutter (SyntheticDataset's clutter_prob): whether, then
    what and where (lipjax.data.synthetic.clutter.add_clutter); sha256 of
    "lipjax/synthetic/clutter/v1/{split}/{index}"."""
    return np.random.default_rng(_seed(f"lipjax/synthetic/clutter/v1/{split}/{index}"))


def foliage_rng(split: str, index: int) -> np.random.Generator:
    """The stream that decides street `index` of `split`'s porous foliage (SyntheticDataset's foliage_prob):
    whether, then its clumps (lipjax.data.synthetic.foliage.porous_foliage); sha256 of
    "lipjax/synthetic/foliage/v1/{split}/{index}"."""
    return np.random.default_rng(_seed(f"lipjax/synthetic/foliage/v1/{split}/{index}"))


def _drawn(stream, split: str, index: int, p: float) -> np.random.Generator | None:
    """`stream(split, index)` if its first draw says frame `index` gets the extra (probability p), else None."""
    if not p:
        return None
    rng = stream(split, index)
    return rng if rng.random() < p else None


def render_with_info(
    kind: str, split: str, index: int, height: int = DEFAULT_HEIGHT, width: int = DEFAULT_WIDTH,
    focal_range: tuple[float, float] = (1.0, 1.0), reflection: Reflection | None = None,
    clutter: np.random.Generator | None = None, foliage: np.random.Generator | None = None,
) -> tuple[Frame, SceneInfo]:
    """Renders frame `index` of (kind, split) at height x width; also returns the camera pose and labels.

    `focal_range`: the camera's focal lengths are intrinsics_for(kind, H, W)'s times `focal_factor` (principal
    point kept): below 1 a wider field of view, above 1 a narrower one, the same scene and pose.
    `reflection`: a polished floor or wet road (lipjax.data.synthetic.renderer.Reflection), the same scene, depth
    and sensor noise; None: matte, as every data set of this package renders its frames.
    `clutter`: a room only; the stream that draws things on its floor (lipjax.data.synthetic.clutter.add_clutter,
    e.g. `clutter_rng(split, index)`); None: the room as built.

    Raises:
      ValueError: unknown kind / split, a negative or non-integer index, or a size below 8 pixels.
    """
    check_kind_split(kind, split)
    index = _check_index(index)
    height, width = check_size(height, width)
    scene_rng, noise_rng = frame_rngs(kind, split, index)
    scene = build_scene(kind, scene_rng)
    if clutter is not None:
        if kind != "indoor":
            raise ValueError(f"clutter is for rooms (kind 'indoor'), got kind {kind!r}")
        scene = add_clutter(scene, clutter)
    if foliage is not None:
        if kind != "outdoor":
            raise ValueError(f"porous foliage is for streets (kind 'outdoor'), got kind {kind!r}")
        scene = porous_foliage(scene, foliage)
    intr = intrinsics_for(kind, height, width)
    f = focal_factor(kind, split, index, focal_range)
    if f != 1.0:
        intr = dataclasses.replace(intr, fx=intr.fx * f, fy=intr.fy * f)
    with np.errstate(all="ignore"):
        rgb, depth, labels = render_scene(scene, height, width, intr, noise_rng, reflection)
    frame = Frame.from_depth(rgb, depth, intr, frame_id(kind, split, index))
    pose = np.eye(4)
    pose[:3, :3] = scene.cam_R
    pose[:3, 3] = scene.cam_pos
    return frame, SceneInfo(kind, pose, float(scene.cam_pos[1]), labels)


def render(kind: str, split: str, index: int, height: int = DEFAULT_HEIGHT, width: int = DEFAULT_WIDTH,
           focal_range: tuple[float, float] = (1.0, 1.0)) -> Frame:
    """Renders frame `index` of the synthetic (kind, split) set as a Frame.

    Args:
      kind: "indoor" or "outdoor".
      split: "train", "val" or "test" (disjoint scenes).
      index: >= 0. Any non-negative int is a valid scene; `SyntheticDataset` bounds it by its size.
      height, width: render size in pixels (the scene does not depend on it).
      focal_range: (lo, hi) factors on the focal length, one drawn per frame (`render_with_info`).
    Returns:
      Frame with rgb (H, W, 3) uint8, depth (H, W) float32 z-depth in metres (0 = invalid: sky, or farther
      than RENDER_FAR_CLIP_M), valid = depth > 0, intrinsics = intrinsics_for(kind, H, W) (focal lengths times
      the frame's `focal_factor`), id = "synthetic/{kind}/{split}/{index:06d}".
    """
    return render_with_info(kind, split, index, height, width, focal_range)[0]


class _IndexOutOfRange(ValueError, IndexError):
    """A ValueError (as documented) that is also an IndexError, so sequence idioms keep working."""


class SyntheticDataset:
    """A sized, indexable view of the procedural set: dataset[i] == render(kind, split, i, height, width).

    Args:
      kind: "indoor" or "outdoor".
      split: "train", "val" or "test".
      size: number of frames; None = DEFAULT_SIZES[split] (train 100000, val 200, test 200).
      height, width: render size in pixels.
      focal_range: (lo, hi) factors on the reference focal length, one per frame (`focal_factor`); (1, 1): the
        reference camera (NYU v2 / KITTI).
      clutter_prob: rooms only: the probability that room i has things on its floor (lipjax.data.synthetic.clutter),
        decided and drawn by `clutter_rng(split, i)`; 0: rooms as built, as `render` gives them.
      foliage_prob: streets only: the probability that street i's trees and bushes are porous
        (lipjax.data.synthetic.foliage), decided and drawn by `foliage_rng(split, i)`; 0: solid, as `render` gives.
    """

    def __init__(self, kind: str, split: str, size: int | None = None, height: int = DEFAULT_HEIGHT,
                 width: int = DEFAULT_WIDTH, focal_range: tuple[float, float] = (1.0, 1.0), clutter_prob: float = 0.0,
                 foliage_prob: float = 0.0):
        check_kind_split(kind, split)
        if size is None:
            size = DEFAULT_SIZES[split]
        if isinstance(size, (bool, np.bool_)) or not isinstance(size, (int, np.integer)) or size < 0:
            raise ValueError(f"size must be a non-negative int or None, got {size!r}")
        self.kind, self.split, self.size = kind, split, int(size)
        self.height, self.width = check_size(height, width)
        self.focal_range = check_focal_range(focal_range)
        self.clutter_prob = check_extra("clutter_prob", clutter_prob, kind)
        self.foliage_prob = check_extra("foliage_prob", foliage_prob, kind)

    def __len__(self) -> int:
        return self.size

    def __getitem__(self, index: int) -> Frame:
        index = _check_index(index)
        if index >= self.size:
            raise _IndexOutOfRange(f"index {index} out of range for SyntheticDataset({self.kind!r}, {self.split!r}) "
                                   f"of size {self.size}")
        return render_with_info(self.kind, self.split, index, self.height, self.width, self.focal_range,
                                clutter=_drawn(clutter_rng, self.split, index, self.clutter_prob),
                                foliage=_drawn(foliage_rng, self.split, index, self.foliage_prob))[0]

    def __iter__(self) -> Iterator[Frame]:
        for i in range(self.size):
            yield self[i]

    @property
    def intrinsics(self) -> Intrinsics:
        """The reference camera at this size (a frame's own, with its focal factor, is its Frame.intrinsics)."""
        return intrinsics_for(self.kind, self.height, self.width)

    def __repr__(self) -> str:
        focal = "" if self.focal_range == (1.0, 1.0) else f", focal_range={self.focal_range}"
        extra = "".join(f", {k}={getattr(self, k)}" for k in EXTRAS if getattr(self, k))
        return (f"SyntheticDataset({self.kind!r}, {self.split!r}, size={self.size}, height={self.height}, "
                f"width={self.width}{focal}{extra})")


class MixedSyntheticDataset:
    """Rooms and streets interleaved, for one model of both: dataset[2 i] == render("indoor", split, i, H, W),
    dataset[2 i + 1] == render("outdoor", split, i, H, W).

    Both kinds are rendered at the same height x width (so that they batch together); the outdoor camera keeps
    KITTI's vertical field of view (`intrinsics_for`). Frame ids are the per-kind ones, so a sampler draws the same
    points from a frame here as from the single-kind set.

    far_view_prob: the probability that a room shows a far view through a window (lipjax.data.synthetic.far_view):
    with it, room i gets a rectangle of street frame j of the same split, j and the rectangle drawn from
    `far_view_rng(split, i)`. 0: closed rooms, as `render` gives them.
    clutter_prob: the rooms' (SyntheticDataset's clutter_prob); foliage_prob: the streets' (SyntheticDataset's),
    and so also those of the far views.
    """

    kind = MIXED_SCENES

    def __init__(self, split: str, size: int | None = None, height: int = DEFAULT_HEIGHT, width: int = DEFAULT_WIDTH,
                 focal_range: tuple[float, float] = (1.0, 1.0), far_view_prob: float = 0.0, clutter_prob: float = 0.0,
                 foliage_prob: float = 0.0):
        self.parts = (SyntheticDataset("indoor", split, None, height, width, focal_range, clutter_prob=clutter_prob),
                      SyntheticDataset("outdoor", split, None, height, width, focal_range, foliage_prob=foliage_prob))
        self.split, self.height, self.width = split, *check_size(height, width)
        self.size = 2 * min(len(p) for p in self.parts) if size is None else int(size)
        self.far_view_prob = check_probability("far_view_prob", far_view_prob)

    def __len__(self) -> int:
        return self.size

    def __getitem__(self, index: int) -> Frame:
        index = _check_index(index)
        if index >= self.size:
            raise _IndexOutOfRange(f"index {index} out of range for MixedSyntheticDataset({self.split!r}) of size "
                                   f"{self.size}")
        frame = self.parts[index % 2][index // 2]
        if index % 2 or self.far_view_prob == 0.0:
            return frame
        rng = far_view_rng(self.split, index // 2)
        if rng.random() >= self.far_view_prob:
            return frame
        return add_far_view(frame, self.parts[1][int(rng.integers(len(self.parts[1])))], rng)

    def __repr__(self) -> str:
        focal = "" if self.parts[0].focal_range == (1.0, 1.0) else f", focal_range={self.parts[0].focal_range}"
        far_view = f", far_view_prob={self.far_view_prob}" if self.far_view_prob else ""
        extra = "".join(f", {k}={getattr(p, k)}" for p in self.parts for k in EXTRAS if getattr(p, k))
        return (f"MixedSyntheticDataset({self.split!r}, size={self.size}, height={self.height}, width={self.width}"
                f"{focal}{far_view}{extra})")
