"""Procedural RGB-D scenes: lipjax's embedded default data set (no download, no files).

Every frame is ray-cast, in numpy on the CPU, from an analytic scene seen by a pinhole camera:

* ``indoor``: a room (floor, four walls, ceiling) with furniture built from boxes, cylinders and spheres,
  against the walls and free-standing: cabinets, dressers, wardrobes, bookshelves, desks with chairs,
  tables with chairs, beds, sofas, armchairs, kitchen counters with wall cabinets, fridges, TV stands,
  floor lamps, plants, bins, stacked boxes, balls, wall shelves / frames, and clutter on the tops (books,
  cups, bottles, fruit, monitors, lamps). NYU-v2-like camera (`NYU_INTRINSICS`), 0.95-1.75 m above the
  floor, pitch -26..+5 deg, yaw +-34 deg, roll ~1 deg. Depth about 0.6-8.5 m (at most ~11 m in the
  largest rooms); every pixel is valid (the room is closed).
* ``outdoor``: a straight street, urban / residential / open road: asphalt with lane markings, tyre
  tracks, patches and crosswalks; raised sidewalks with curbs; buildings on both sides (facades with
  windows, shop fronts, stepped roofs; gaps, side yards, a building closing the street); parked and
  moving cars (body, cabin with windows, wheels, lights, plates); street lamps, poles, signs; trees,
  hedges, bushes, fences, pedestrians; distant hills; a sky with clouds and sun glow. KITTI-like camera
  (`KITTI_INTRINSICS`), 1.45-1.85 m above the road (KITTI: 1.65 m), in a lane, yaw +-7 deg, pitch
  -4..+2 deg, roll ~0.7 deg. Sky and surfaces farther than `OUTDOOR_MAX_DEPTH_M` (80 m, a LiDAR's range)
  are invalid (depth 0); valid depth starts at ~3-5 m.

RGB: procedural textures with per-object random colours (stripes, checkers, value noise, wood, tiles,
bricks, books, cabinet fronts, facades, foliage, asphalt) and decals that are colour edges but not depth
edges (posters, paintings, documents, whiteboards, doors, windows with curtains or blinds, skirting
boards, rugs, blankets, lane markings, crosswalks, car lights and plates). Shading: Lambertian from one or
two lights (indoor: point lights near the ceiling with soft 1 / (1 + d^2 / r0^2) falloff; outdoor: the
sun, sometimes overcast) plus hemispheric ambient, cast shadows (softened), a Blinn-Phong-like gloss on
some materials, emissive windows / lamps / screens, distance haze outdoors. Camera model: slight optical
blur, random exposure and white balance, vignetting, signal-dependent Gaussian noise, a tone curve with a
highlight shoulder and gamma 2.0-2.4, 8-bit quantisation.

Camera intrinsics: `intrinsics_for(kind, H, W)` scales the reference camera to the render size with
square pixels (largest centred crop of the reference frame with the render's aspect ratio, then an
isotropic resize); see its docstring.

Conventions:
  * Camera frame: x right, y down, z forward (OpenCV). Pixel (row v, column u) has its centre at (u, v);
    its ray is ((u - cx) / fx, (v - cy) / fy, 1) in the camera frame.
  * `Sample.depth` is z-depth (distance along the optical axis, as in NYU and KITTI), not the ray length:
    float32 metres, 0 = invalid, `Sample.valid = depth > 0`.
  * World frame (exposed through `SceneInfo` from `render_with_info`): y up, floor / road on the plane
    y = 0, x to the right of and z ahead of an unrotated camera. `SceneInfo.camera_to_world` maps
    camera-frame points to world points (its rotation has determinant -1: camera y is down, world y up).
  * Units: metres and pixels.

Determinism: a frame depends only on (kind, split, index, height, width). The scene (geometry, materials,
lights, camera pose, camera-model parameters) comes from a numpy Generator seeded with
sha256("lipjax/synthetic/v1/{kind}/{split}/{index}") and does not depend on the render size; the sensor
noise comes from a second stream of the same seed. Python's salted hash() is never used, so frames are
bit-identical across processes and runs (for a fixed numpy / OpenCV version). Each split has its own
seeds: train, val and test never share a scene.

Approximations made for speed (all deterministic): shadow rays are cast for one pixel in each 2x2 block;
outdoors, objects wholly farther than 70 m cast no shadow; the sky is shaded at 1/4 resolution; objects
covering fewer than 32 pixels get their material's mean colour instead of the full texture.

Speed (`taskset -c 0 .venv/bin/python benchmarks/synthetic_fps.py --frames 40`, one pinned core of the 2-CPU
development machine with the training jobs paused): frames/s of CPU time, 256x320: indoor 30.4 (val split,
unpinned: 27.8), outdoor 25.0 (val: 21.7); 128x160: indoor 55, outdoor 31-34. With a training job beside it
(load ~5): outdoor 256x320 20-22. Outdoor frames cost more: ~140 primitives against ~30 indoors. Per-primitive numpy calls are batched where the arithmetic
allows it without changing a bit of the output (small parts' camera rays, box and cylinder surfaces, shadow
rays: one call per primitive kind); textures (one call per material) and scene construction (Python) remain
per object.

Public API: `render`, `render_with_info`, `SyntheticDataset`, `intrinsics_for`, `sample_id`, `SceneInfo`,
`LABELS` and the constants below.
"""
from __future__ import annotations

import colorsys
import dataclasses
import functools
import hashlib
import math
from typing import Callable, Iterator

import cv2
import numpy as np

from lipjax.data.sample import Intrinsics, Sample

__all__ = [
    "SYNTHETIC_KINDS",
    "SPLITS",
    "TRAIN_SIZE",
    "VAL_SIZE",
    "TEST_SIZE",
    "DEFAULT_SIZES",
    "DEFAULT_HEIGHT",
    "DEFAULT_WIDTH",
    "NYU_IMAGE_SIZE",
    "NYU_INTRINSICS",
    "KITTI_IMAGE_SIZE",
    "KITTI_INTRINSICS",
    "KITTI_CAMERA_HEIGHT_M",
    "OUTDOOR_MAX_DEPTH_M",
    "LABELS",
    "SceneInfo",
    "SyntheticDataset",
    "intrinsics_for",
    "render",
    "render_with_info",
    "sample_id",
]

SYNTHETIC_KINDS = ("indoor", "outdoor")
SPLITS = ("train", "val", "test")

# Default data set sizes. The generator is procedural, so "train" is effectively unbounded: 100k distinct
# scenes is more than any run here consumes; val / test are small and fixed so evaluations are cheap.
TRAIN_SIZE = 100_000
VAL_SIZE = 200
TEST_SIZE = 200
DEFAULT_SIZES = {"train": TRAIN_SIZE, "val": VAL_SIZE, "test": TEST_SIZE}

DEFAULT_HEIGHT = 256
DEFAULT_WIDTH = 320

# NYU Depth v2 (Kinect v1) colour camera, at its native 480x640.
NYU_IMAGE_SIZE = (480, 640)
NYU_INTRINSICS = Intrinsics(fx=518.86, fy=519.47, cx=325.58, cy=253.74)
# KITTI (raw / depth completion, camera 02), at about 375x1242.
KITTI_IMAGE_SIZE = (375, 1242)
KITTI_INTRINSICS = Intrinsics(fx=721.5, fy=721.5, cx=609.6, cy=172.9)
KITTI_CAMERA_HEIGHT_M = 1.65
# Outdoor surfaces farther than this are invalid (depth 0), like returns beyond a LiDAR's range.
OUTDOOR_MAX_DEPTH_M = 80.0

# Per-pixel semantic labels in SceneInfo.labels (index into this tuple).
LABELS = (
    "sky", "floor", "wall", "ceiling", "furniture", "object", "road", "sidewalk", "terrain",
    "building", "vehicle", "pole", "vegetation", "person", "fence",
)
(_SKY, _FLOOR, _WALL, _CEILING, _FURNITURE, _OBJECT, _ROAD, _SIDEWALK, _TERRAIN, _BUILDING, _VEHICLE, _POLE,
 _VEGETATION, _PERSON, _FENCE) = range(len(LABELS))

_F32 = np.float32
_EPS = 1e-4  # minimum ray parameter of a hit (metres of z-depth for camera rays)
_NEAR = 0.02  # near plane used for screen-space culling (metres)
_TINY_PIXELS = 32  # objects covering fewer pixels are shaded with their material's mean colour


# ----------------------------------------------------------------------------------------------- public API


@dataclasses.dataclass(frozen=True)
class SceneInfo:
    """What was rendered, beyond the Sample: for tests, debugging and visualisation.

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


def _check_kind_split(kind: str, split: str) -> None:
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


def _check_size(height, width) -> tuple[int, int]:
    if not isinstance(height, (int, np.integer)) or not isinstance(width, (int, np.integer)) or height < 8 or width < 8:
        raise ValueError(f"height and width must be ints >= 8, got {height!r} x {width!r}")
    return int(height), int(width)


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
    height, width = _check_size(height, width)
    ref, (h0, w0) = (NYU_INTRINSICS, NYU_IMAGE_SIZE) if kind == "indoor" else (KITTI_INTRINSICS, KITTI_IMAGE_SIZE)
    if width * h0 <= height * w0:  # render narrower than the reference: crop columns
        ch, cw = float(h0), h0 * width / height
    else:  # wider: crop rows
        ch, cw = w0 * height / width, float(w0)
    return ref.cropped((h0 - ch) / 2, (w0 - cw) / 2).resized(height / ch, width / cw)


def sample_id(kind: str, split: str, index: int) -> str:
    """The Sample.id of a synthetic frame, e.g. "synthetic/indoor/val/000042"."""
    return f"synthetic/{kind}/{split}/{index:06d}"


def _seed(kind: str, split: str, index: int) -> int:
    digest = hashlib.sha256(f"lipjax/synthetic/v1/{kind}/{split}/{index}".encode("utf-8")).digest()
    return int.from_bytes(digest[:16], "little")


def render_with_info(
    kind: str, split: str, index: int, height: int = DEFAULT_HEIGHT, width: int = DEFAULT_WIDTH
) -> tuple[Sample, SceneInfo]:
    """Renders frame `index` of (kind, split) at height x width; also returns the camera pose and labels.

    Raises:
      ValueError: unknown kind / split, a negative or non-integer index, or a size below 8 pixels.
    """
    _check_kind_split(kind, split)
    index = _check_index(index)
    height, width = _check_size(height, width)
    seed = _seed(kind, split, index)
    scene_rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(0,)))
    noise_rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(1,)))
    scene = _indoor_scene(scene_rng) if kind == "indoor" else _outdoor_scene(scene_rng)
    intr = intrinsics_for(kind, height, width)
    with np.errstate(all="ignore"):
        rgb, depth, labels = _render(scene, height, width, intr, noise_rng)
    sample = Sample.from_depth(rgb, depth, intr, sample_id(kind, split, index))
    pose = np.eye(4)
    pose[:3, :3] = scene.cam_R
    pose[:3, 3] = scene.cam_pos
    return sample, SceneInfo(kind, pose, float(scene.cam_pos[1]), labels)


def render(kind: str, split: str, index: int, height: int = DEFAULT_HEIGHT, width: int = DEFAULT_WIDTH) -> Sample:
    """Renders frame `index` of the synthetic (kind, split) set as a Sample.

    Args:
      kind: "indoor" or "outdoor".
      split: "train", "val" or "test" (disjoint scenes).
      index: >= 0. Any non-negative int is a valid scene; `SyntheticDataset` bounds it by its size.
      height, width: render size in pixels (the scene does not depend on it).
    Returns:
      Sample with rgb (H, W, 3) uint8, depth (H, W) float32 z-depth in metres (0 = invalid: sky, or farther
      than OUTDOOR_MAX_DEPTH_M), valid = depth > 0, intrinsics = intrinsics_for(kind, H, W),
      id = "synthetic/{kind}/{split}/{index:06d}".
    """
    return render_with_info(kind, split, index, height, width)[0]


class _IndexOutOfRange(ValueError, IndexError):
    """A ValueError (as documented) that is also an IndexError, so sequence idioms keep working."""


class SyntheticDataset:
    """A sized, indexable view of the procedural set: dataset[i] == render(kind, split, i, height, width).

    Args:
      kind: "indoor" or "outdoor".
      split: "train", "val" or "test".
      size: number of frames; None = DEFAULT_SIZES[split] (train 100000, val 200, test 200).
      height, width: render size in pixels.
    """

    def __init__(self, kind: str, split: str, size: int | None = None, height: int = DEFAULT_HEIGHT,
                 width: int = DEFAULT_WIDTH):
        _check_kind_split(kind, split)
        if size is None:
            size = DEFAULT_SIZES[split]
        if isinstance(size, (bool, np.bool_)) or not isinstance(size, (int, np.integer)) or size < 0:
            raise ValueError(f"size must be a non-negative int or None, got {size!r}")
        self.kind, self.split, self.size = kind, split, int(size)
        self.height, self.width = _check_size(height, width)

    def __len__(self) -> int:
        return self.size

    def __getitem__(self, index: int) -> Sample:
        index = _check_index(index)
        if index >= self.size:
            raise _IndexOutOfRange(f"index {index} out of range for SyntheticDataset({self.kind!r}, {self.split!r}) "
                                   f"of size {self.size}")
        return render(self.kind, self.split, index, self.height, self.width)

    def __iter__(self) -> Iterator[Sample]:
        for i in range(self.size):
            yield render(self.kind, self.split, i, self.height, self.width)

    @property
    def intrinsics(self) -> Intrinsics:
        return intrinsics_for(self.kind, self.height, self.width)

    def __repr__(self) -> str:
        return f"SyntheticDataset({self.kind!r}, {self.split!r}, size={self.size}, height={self.height}, width={self.width})"


# --------------------------------------------------------------------------------------------- noise, colour

# A fixed table of uniform values: the lattice of the value noise and a cheap per-cell hash. A constant,
# not random state: it never changes, so textures are reproducible.
_TABLE = np.random.default_rng(0x1D5EED).random(65536, dtype=_F32)
# The same lattice padded to 257 x 257 (row 256 = row 0, column 256 = column 0): the four corners of a cell
# are then at base, base + 1, base + 257, base + 258, one index computation instead of four.
_TABLE_PAD = np.pad(_TABLE.reshape(256, 256), ((0, 1), (0, 1)), mode="wrap").ravel()
# The four corners of every cell side by side, (255 * 257 + 256, 4) (one row per base index): one gather of
# 16 bytes per point fetches them.
_TABLE_CORNERS = np.stack([_TABLE_PAD[i:i + 255 * 257 + 256] for i in (0, 1, 257, 258)], axis=1)


def _lattice(i: np.ndarray, j: np.ndarray) -> np.ndarray:
    return ((j & 255) << 8) | (i & 255)


def _hash(x: np.ndarray, y: np.ndarray | float = 0.0) -> np.ndarray:
    """Uniform [0, 1) value per integer cell (x, y) (floats are floored)."""
    i = np.floor(x).astype(np.int32)
    j = np.floor(y).astype(np.int32) if not np.isscalar(y) else np.int32(int(math.floor(y)))
    return _TABLE.take(_lattice(i, j))


def _vnoise(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Smooth value noise in [0, 1) with unit lattice spacing."""
    xf = np.floor(x)
    yf = np.floor(y)
    fx = x - xf
    fy = y - yf
    base = (yf.astype(np.int32) & 255) * 257 + (xf.astype(np.int32) & 255)
    a, b, c, d = _TABLE_CORNERS.take(base, axis=0).T
    sx = fx * fx * (3.0 - 2.0 * fx)
    sy = fy * fy * (3.0 - 2.0 * fy)
    ab = a + (b - a) * sx
    return ab + (c + (d - c) * sx - ab) * sy


def _fbm(x: np.ndarray, y: np.ndarray, octaves: int, fp: np.ndarray | None = None) -> np.ndarray:
    """Fractal value noise in ~[0, 1]. fp: pixel footprint in lattice units; octaves finer than a pixel
    fade to their mean instead of aliasing."""
    total = np.zeros_like(x)
    amp, norm = 1.0, 0.0
    for _ in range(octaves):
        n = _vnoise(x, y) - 0.5
        if fp is not None:
            n *= np.minimum(np.maximum(1.5 - 2.0 * fp, 0.0), 1.0)
            fp = fp * 2.03
        total += amp * n
        norm += amp
        amp *= 0.5
        x = x * 2.03 + 17.13
        y = y * 2.03 + 31.71
    return total * (1.0 / norm) + 0.5


def _frac(x):
    return x - np.floor(x)


def _square(s: np.ndarray, period: float, duty: float, fp: np.ndarray) -> np.ndarray:
    """Anti-aliased square wave: ~1 where frac(s / period) < duty, else ~0; tends to `duty` when a pixel
    covers a whole period."""
    inv = 1.0 / period
    f = _frac(s * inv)
    w = fp * inv + 1e-4
    sd = np.where(f < duty, np.minimum(f, duty - f), -np.minimum(f - duty, 1.0 - f))
    val = np.minimum(np.maximum(0.5 + sd / w, 0.0), 1.0)
    k = np.minimum(np.maximum(2.0 * w - 0.5, 0.0), 1.0)
    return val + (duty - val) * k


def _box(u, v, u0, v0, u1, v1):
    return (u >= u0) & (u < u1) & (v >= v0) & (v < v1)


def _cols(a: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """a[:, idx] for a (c, n) array and indices idx (k,): `take` is ~4x faster than 2-D fancy indexing."""
    return a.take(idx, axis=1)


def _set_cols(a: np.ndarray, idx, val) -> None:
    """a[:, idx] = val for a (c, n) array, idx indices (k,), a boolean mask (n,) or a slice, val (c, k) or
    (c, 1). Row by row: ~3x faster than 2-D fancy assignment."""
    if isinstance(idx, np.ndarray) and idx.dtype == bool:
        idx = np.flatnonzero(idx)
    for row, x in zip(a, val):
        row[idx] = x


def _mix(c1: np.ndarray, c2: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(3, n): c1 where w = 0, c2 where w = 1 (colours (3, 1) or (3, n), w (n,))."""
    return c1 + (c2 - c1) * w


def _hsv(h, s, v) -> np.ndarray:
    """HSV in [0, 1] (sRGB-like) -> linear float32 colour column (3, 1)."""
    rgb = colorsys.hsv_to_rgb(h % 1.0, min(max(s, 0.0), 1.0), min(max(v, 0.0), 1.0))
    return np.array([[rgb[0] ** 2.2], [rgb[1] ** 2.2], [rgb[2] ** 2.2]], _F32)


def _c_any(rng) -> np.ndarray:
    return _hsv(rng.random(), rng.uniform(0.0, 0.95), rng.uniform(0.12, 0.95))


def _c_grey(rng, lo=0.2, hi=0.9) -> np.ndarray:
    return _hsv(rng.random(), rng.uniform(0.0, 0.07), rng.uniform(lo, hi))


def _c_wall(rng) -> np.ndarray:
    if rng.random() < 0.55:
        return _hsv(rng.uniform(0.05, 0.16), rng.uniform(0.0, 0.18), rng.uniform(0.62, 0.95))  # whites, beiges
    return _hsv(rng.random(), rng.uniform(0.05, 0.45), rng.uniform(0.45, 0.92))


def _c_wood(rng) -> np.ndarray:
    return _hsv(rng.uniform(0.04, 0.11), rng.uniform(0.35, 0.8), rng.uniform(0.22, 0.85))


def _c_fabric(rng) -> np.ndarray:
    return _hsv(rng.random(), rng.uniform(0.05, 0.75), rng.uniform(0.15, 0.85))


def _c_furniture(rng) -> np.ndarray:
    r = rng.random()
    if r < 0.45:
        return _c_wood(rng)
    if r < 0.75:
        return _c_grey(rng, 0.08, 0.95)
    return _c_fabric(rng)


# ------------------------------------------------------------------------------------------------ patterns
# Colours are (3, 1) float32 columns and colour arrays are planar (3, n): numpy broadcasts a (3, 1) colour
# against (n,) weights with long inner loops, 10-30x faster than (n, 3) rows against (n, 1).
# A pattern is fn(u, v, fp) -> (3, n) float32 linear albedo; u, v surface coordinates (metres on surfaces,
# [0, 1] inside decals), fp the pixel footprint in the same units. A pattern may instead return
# (albedo, emission_weight) to make only part of a decal emissive (window glass but not its frame).

Pattern = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


def _with_mean(fn: Pattern, mean) -> Pattern:
    """Attaches a representative colour (3, 1): objects covering a few pixels are shaded with it."""
    fn.mean = np.asarray(mean, _F32).reshape(3, 1)
    return fn


def _mean_of(fn: Pattern) -> np.ndarray:
    m = getattr(fn, "mean", None)
    return m if m is not None else np.full((3, 1), 0.3, _F32)


def _p_solid(rng, c, amp=0.06) -> Pattern:
    ox, oy, f = rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0.8, 3.0)

    def fn(u, v, fp):
        if amp <= 0 or u.shape[0] < 200:  # a few pixels: the subtle variation would not show
            return np.broadcast_to(c, (3, u.shape[0]))
        n = _vnoise(u * f + ox, v * f + oy)
        return c * (1.0 + 2.0 * amp * (n - 0.5))

    return _with_mean(fn, c)


def _p_noise(rng, c1, c2, freq, octaves=2, contrast=1.0, stretch=1.0) -> Pattern:
    ox, oy = rng.uniform(0, 256), rng.uniform(0, 256)

    def fn(u, v, fp):
        n = _fbm(u * (freq * stretch) + ox, v * freq + oy, octaves, fp * (freq * stretch))
        return _mix(c1, c2, np.clip(0.5 + (n - 0.5) * (2.0 * contrast), 0.0, 1.0))

    return _with_mean(fn, 0.5 * (c1 + c2))


def _p_stripes(rng, c1, c2, period, duty=0.5, angle=0.0, amp=0.04) -> Pattern:
    ca, sa = math.cos(angle), math.sin(angle)
    base = _p_solid(rng, np.ones((3, 1), _F32), amp)

    def fn(u, v, fp):
        w = _square(u * ca + v * sa, period, duty, fp)
        return _mix(c2, c1, w) * base(u, v, fp)

    return _with_mean(fn, duty * c1 + (1.0 - duty) * c2)


def _p_checker(rng, c1, c2, period, angle=0.0, amp=0.04) -> Pattern:
    ca, sa = math.cos(angle), math.sin(angle)
    base = _p_solid(rng, np.ones((3, 1), _F32), amp)

    def fn(u, v, fp):
        a = _square(u * ca + v * sa, 2 * period, 0.5, fp)
        b = _square(v * ca - u * sa, 2 * period, 0.5, fp)
        return _mix(c1, c2, a + b - 2 * a * b) * base(u, v, fp)

    return _with_mean(fn, 0.5 * (c1 + c2))


def _p_tiles(rng, c_tile, c_grout, su, sv, grout, var=0.08, offset=0.0, amp=0.05) -> Pattern:
    """Tiles / bricks / slabs: grout lines every (su, sv); rows shifted by offset * su (bricks: 0.5)."""
    o1, o2 = int(rng.integers(0, 256)), int(rng.integers(0, 256))
    base = _p_solid(rng, np.ones((3, 1), _F32), amp)

    def fn(u, v, fp):
        row = np.floor(v * (1.0 / sv))
        uu = u + row * (offset * su)
        col = np.floor(uu * (1.0 / su))
        g = np.maximum(_square(uu, su, grout / su, fp), _square(v, sv, grout / sv, fp))
        h = _hash(col + o1, row + o2)
        tile = c_tile * (1.0 + 2.0 * var * (h - 0.5)) * base(u, v, fp)
        return tile + (c_grout - tile) * g

    return _with_mean(fn, c_tile)


def _p_wood(rng, c_light, c_dark, plank_w, plank_len, along_v=False, gap=0.004) -> Pattern:
    f_ring = rng.uniform(4.0, 14.0)
    o1 = rng.uniform(0, 100)

    def fn(u, v, fp):
        if along_v:
            u, v = v, u
        row = np.floor(v * (1.0 / plank_w))
        uu = u + _hash(row, 7.0) * plank_len + o1
        col = np.floor(uu * (1.0 / plank_len))
        hp = _hash(col, row)
        grain = _vnoise(uu * 1.3 + hp * 50.0, v * 30.0 + row * 3.1)
        grain = 0.5 + (grain - 0.5) * np.clip(1.5 - 60.0 * fp, 0.0, 1.0)
        ring = _frac(v * f_ring + grain * 2.0 + hp * 5.0)
        w = np.abs(ring - 0.5) * 1.2 + grain * 0.4
        w = 0.5 + (w - 0.5) * np.clip(1.5 - 2.0 * f_ring * fp, 0.0, 1.0)
        col_ = _mix(c_dark, c_light, np.minimum(np.maximum(w, 0.0), 1.0)) * (0.8 + 0.4 * hp)
        g = np.maximum(_square(v, plank_w, gap / plank_w, fp), _square(uu, plank_len, gap / plank_len, fp))
        return col_ * (1.0 - 0.45 * g)

    return _with_mean(fn, 0.5 * (c_light + c_dark))


def _p_books(rng, c_shelf, shelf_h, board) -> Pattern:
    """Bookshelf front: boards every shelf_h, books of random width, height and colour."""
    palette = np.concatenate([_c_fabric(rng) for _ in range(8)], axis=1)  # (3, 8)
    back = _c_grey(rng, 0.03, 0.15)
    o1 = int(rng.integers(0, 256))

    def fn(u, v, fp):
        shelf = np.floor(v * (1.0 / shelf_h))
        vv = v - shelf * shelf_h
        col = np.floor(u * 28.0 + _hash(shelf, 3.0) * 9.0)
        h1 = _hash(col + o1, shelf)
        h2 = _hash(col + 101.0, shelf + 57.0)
        book = _cols(palette, (h1 * 7.999).astype(np.int32)) * (0.55 + 0.6 * h2)
        top = board + (shelf_h - board) * (0.5 + 0.4 * h2)
        present = (vv < top) & (h1 > 0.12)
        out = np.where(present, book, back)
        return np.where(vv < board, c_shelf, out)

    return _with_mean(fn, 0.7 * palette.mean(axis=1, keepdims=True))


def _p_fronts(rng, body: Pattern, w, h, cols, rows, plinth, gap_c, handle_c) -> Pattern:
    """Cabinet / drawer fronts on a face of width w, height h (metres): split lines and handles."""
    cw = w / cols
    rh = (h - plinth) / rows
    vertical_handles = rng.random() < 0.5

    def fn(u, v, fp):
        out = np.array(body(u, v, fp), dtype=_F32)
        lines = np.maximum(_square(u + 0.004, cw, 0.008 / cw, fp), _square(v - plinth + 0.004, rh, 0.008 / rh, fp))
        lines = np.where(v < plinth, 0.6, lines)
        out = out + (gap_c - out) * lines
        cu = _frac(u / cw) * cw
        cv = _frac((v - plinth) / rh) * rh
        if vertical_handles:
            hm = (np.abs(cu - (cw - 0.05)) < 0.012) & (np.abs(cv - rh * 0.55) < min(0.08, rh * 0.3))
        else:
            hm = (np.abs(cu - cw * 0.5) < min(0.07, cw * 0.3)) & (np.abs(cv - (rh - 0.06)) < 0.012)
        hm &= v > plinth
        _set_cols(out, hm, handle_c)
        return out

    return _with_mean(fn, _mean_of(body))


def _p_poster(rng) -> Pattern:
    """A picture / poster / document in [0, 1]^2 decal coordinates, often with a frame."""
    kind = int(rng.integers(0, 4))
    frame = rng.random() < 0.65
    fw = rng.uniform(0.03, 0.09)
    fc = [_c_grey(rng, 0.02, 0.15), _c_grey(rng, 0.8, 0.95), _c_wood(rng)][int(rng.integers(0, 3))]
    if kind == 0:  # painting / photo: a landscape-like gradient with noisy blobs
        top, bot, blob = _c_any(rng), _c_any(rng), _c_any(rng)
        inner = _p_noise(rng, top, bot, rng.uniform(2, 6), 3, rng.uniform(0.8, 2.0))
        horizon = rng.uniform(0.3, 0.7)

        def base(u, v, fp):
            out = inner(u, v, fp)
            m = v < horizon
            m = np.flatnonzero(m)
            _set_cols(out, m, _cols(out, m) * 0.5 + blob * 0.5)
            return out
    elif kind == 1:  # geometric shapes
        bg = _c_any(rng)
        shapes = []
        for _ in range(int(rng.integers(2, 7))):
            x0, y0 = rng.uniform(0, 0.8), rng.uniform(0, 0.8)
            shapes.append((rng.random() < 0.5, x0, y0, x0 + rng.uniform(0.1, 0.6), y0 + rng.uniform(0.1, 0.6),
                           _c_any(rng)))

        def base(u, v, fp):
            out = np.empty((3, u.shape[0]), _F32)
            out[:] = bg
            for circle, x0, y0, x1, y1, c in shapes:
                if circle:
                    r = 0.5 * (x1 - x0)
                    m = (u - 0.5 * (x0 + x1)) ** 2 + (v - 0.5 * (y0 + y1)) ** 2 < r * r
                else:
                    m = _box(u, v, x0, y0, x1, y1)
                _set_cols(out, m, c)
            return out
    elif kind == 2:  # document / notice: paper, a title band, lines of text
        paper = _hsv(rng.uniform(0.1, 0.15), rng.uniform(0, 0.1), rng.uniform(0.82, 0.97))
        ink = _c_grey(rng, 0.02, 0.25)
        title = _c_any(rng)
        pitch = rng.uniform(0.04, 0.09)

        def base(u, v, fp):
            out = np.empty((3, u.shape[0]), _F32)
            out[:] = paper
            line = np.floor(v / pitch)
            length = 0.3 + 0.55 * _hash(line, 11.0)
            text = (_frac(v / pitch) < 0.45) & (u > 0.1) & (u < 0.1 + length) & (v < 0.8)
            text &= _hash(u * 40.0, line) > 0.25
            _set_cols(out, text, ink)
            _set_cols(out, v > 0.84, title)
            return out
    else:  # bands / stripes
        base = _p_stripes(rng, _c_any(rng), _c_any(rng), rng.uniform(0.05, 0.3), rng.uniform(0.2, 0.8),
                          rng.uniform(0, math.pi))

    def fn(u, v, fp):
        out = np.array(base(u, v, fp), dtype=_F32)
        if frame:
            m = (u < fw) | (u > 1 - fw) | (v < fw) | (v > 1 - fw)
            _set_cols(out, m, fc)
        return out

    return _with_mean(fn, _mean_of(base))


def _p_window(rng) -> Pattern:
    """Indoor window: a bright outside view (sky, trees / buildings) behind a frame and mullions.
    Returns (albedo, emission weight): only the glass glows."""
    sky = _hsv(rng.uniform(0.52, 0.62), rng.uniform(0.0, 0.35), rng.uniform(0.85, 1.0))
    ground = _p_noise(rng, _hsv(rng.uniform(0.15, 0.35), rng.uniform(0.2, 0.6), rng.uniform(0.3, 0.7)),
                      _c_grey(rng, 0.4, 0.8), rng.uniform(3, 10), 3, 1.2)
    horizon = rng.uniform(0.0, 0.6)
    fc = _c_grey(rng, 0.05, 0.95) if rng.random() < 0.5 else _c_wood(rng)
    fw = rng.uniform(0.03, 0.07)
    mull_v = rng.random() < 0.7
    mull_h = rng.uniform(0.3, 0.75) if rng.random() < 0.5 else -1.0
    blind = rng.random() < 0.25
    blind_c = _c_grey(rng, 0.6, 0.95)

    def fn(u, v, fp):
        out = np.empty((3, u.shape[0]), _F32)
        out[:] = sky
        below = v < horizon + 0.1 * np.sin(u * 9.0)
        if below.any():
            _set_cols(out, below, ground(u[below], v[below], fp[below]))
        glass = ~((u < fw) | (u > 1 - fw) | (v < fw) | (v > 1 - fw))
        if mull_v:
            glass &= np.abs(u - 0.5) > fw * 0.5
        if mull_h > 0:
            glass &= np.abs(v - mull_h) > fw * 0.5
        _set_cols(out, ~glass, fc)
        emit = glass.astype(_F32)
        if blind:
            slats = _square(v, 0.04, 0.75, fp) * (v > 0.35)
            out = out + (blind_c - out) * slats
            emit *= 1.0 - 0.8 * slats
        return out, emit

    return _with_mean(fn, sky)


def _p_foliage(rng) -> Pattern:
    h = rng.uniform(0.17, 0.33)
    dark = _hsv(h + rng.uniform(-0.03, 0.03), rng.uniform(0.35, 0.75), rng.uniform(0.08, 0.22))
    light = _hsv(h + rng.uniform(-0.05, 0.02), rng.uniform(0.3, 0.65), rng.uniform(0.25, 0.5))
    return _p_noise(rng, dark, light, rng.uniform(3.0, 9.0), 2, rng.uniform(0.6, 1.1))


# ----------------------------------------------------------------------------------------------- materials


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


# ----------------------------------------------------------------------------------------------- geometry


def _rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


_EYE3 = np.eye(3)


def _to_local(r, mode: int, x, y, z):
    """World -> local components of vectors (x, y, z) for the rotation R with row-major entries r (9 values:
    floats, or (n,) float32 arrays, one rotation per point, in batched calls). mode 0: R = I, 1: a rotation
    about the vertical axis only, 2: general; the cheaper modes skip the terms that are exactly 0 or 1."""
    if mode == 0:
        return x, y, z
    if mode == 1:
        return r[0] * x + r[6] * z, y, r[2] * x + r[8] * z
    return (r[0] * x + r[3] * y + r[6] * z, r[1] * x + r[4] * y + r[7] * z, r[2] * x + r[5] * y + r[8] * z)


def _to_world(r, mode: int, x, y, z):
    """Local -> world components (the inverse of `_to_local`)."""
    if mode == 0:
        return x, y, z
    if mode == 1:
        return r[0] * x + r[2] * z, y, r[6] * x + r[8] * z
    return (r[0] * x + r[1] * y + r[2] * z, r[3] * x + r[4] * y + r[5] * z, r[6] * x + r[7] * y + r[8] * z)


# Ray-primitive kernels. Each works on numpy broadcasting: a scalar origin with (h, w) directions (camera
# rays), (n,) origins with scalar or (n,) directions (shadow rays), and Python float parameters (one
# primitive) or (n,) float32 parameter arrays (one primitive per ray: many primitives in one call). A Python
# float parameter and the same value as a float32 array give bit-identical results (numpy casts the Python
# float to float32 first), so the batched and one-at-a-time paths agree exactly.


def _slab_t(planes, ix, iy, iz, inside: bool, eps):
    """Ray parameter of the first hit on an axis-aligned box (inf: none), by the slab method.

    planes: (x0, x1, y0, y1, z0, z1), the box's faces minus the ray origin, per axis; ix, iy, iz: inverse
    ray directions. inside: the ray starts inside the box and the hit is the exit (a room seen from within)."""
    x0, x1, y0, y1, z0, z1 = planes
    a = x0 * ix
    b = x1 * ix
    tn = np.minimum(a, b)
    tf = np.maximum(a, b)
    a = y0 * iy
    b = y1 * iy
    np.maximum(tn, np.minimum(a, b), out=tn)
    np.minimum(tf, np.maximum(a, b), out=tf)
    a = z0 * iz
    b = z1 * iz
    if inside:
        np.minimum(tf, np.maximum(a, b), out=tf)
        return np.where(tf > eps, tf, np.inf)
    np.maximum(tn, np.minimum(a, b), out=tn)
    np.minimum(tf, np.maximum(a, b), out=tf)
    return np.where((tn <= tf) & (tn > eps), tn, np.inf)


def _quadric_t(a, b, c, eps):
    """Nearer root t of a t^2 + 2 b t + c = 0 where it is real and > eps, else inf (spheres, cylinders)."""
    disc = b * b - a * c
    t = (-b - np.sqrt(np.maximum(disc, 0.0))) / a
    return np.where((disc >= 0) & (t > eps), t, np.inf)


def _cyl_t(ox, oy, oz, c, h, rr, caps, dx, dy, dz, eps):
    """Ray parameter of the first hit on the capped cylinder x^2 + z^2 <= rr, |y| <= h (local frame; inf:
    none). o: ray origins, c = ox^2 + oz^2 - rr, d: directions; caps: (cap y - oy) of the caps to test (a
    NaN entry tests none)."""
    t = _quadric_t(dx * dx + dz * dz, ox * dx + oz * dz, c, eps)
    t = np.where(np.abs(oy + t * dy) <= h, t, np.inf)
    for num in caps:
        tc = num / dy
        xc = ox + tc * dx
        zc = oz + tc * dz
        t = np.where((xc * xc + zc * zc <= rr) & (tc > eps) & (tc < t), tc, t)
    return t
_BOX_CORNERS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)


class _Prim:
    """A primitive with a rigid local frame: world = R @ local + c. Subclasses implement camera_job (the
    kernel and parameters of camera rays against one of its parts, see `_camera_t`), shadow_jobs (the same
    for shadow rays, see `_shadow_t`) and surface (normals, uv, face id)."""

    infinite = False
    asm = -1  # assembly id: primitives of one object share a shadow-culling volume

    def __init__(self, label, mat: _Mat, c=(0.0, 0.0, 0.0), R=None, cast=True):
        self.label = label  # int, or a (6,) int array: label per face
        self.mat = mat
        self.c = tuple(float(x) for x in c)
        self.cast = cast
        if R is None:
            self.mode = 0
            R = _EYE3
        else:
            R = np.asarray(R, dtype=np.float64)
            r = R.ravel().tolist()
            if r == [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]:
                self.mode = 0
            elif r[4] == 1.0 and r[1] == 0.0 and r[7] == 0.0 and r[3] == 0.0 and r[5] == 0.0:
                self.mode = 1  # rotation about the vertical axis only
            else:
                self.mode = 2
        self.R = R
        self.r = tuple(R.ravel().tolist())

    def local_pt(self, x, y, z):
        return self.local_dir(x - self.c[0], y - self.c[1], z - self.c[2])

    def local_dir(self, x, y, z):
        return _to_local(self.r, self.mode, x, y, z)

    def local_box(self) -> np.ndarray:
        raise NotImplementedError

    def parts(self) -> list:
        """Convex pieces (each with hull() and camera_job()) for culling; a hit on any is a hit on self."""
        return [self]

    def hull(self) -> np.ndarray:
        """(8, 3) world points whose convex hull contains the primitive (cached: primitives never move)."""
        h = self.__dict__.get("_hull")
        if h is None:
            if self.mode == 0:
                h = _BOX_CORNERS * self.local_box() + self.c
            else:
                h = (_BOX_CORNERS * self.local_box()) @ self.R.T + self.c
            self._hull = h
        return h


class _Box(_Prim):
    def __init__(self, c, half, label, mat, R=None, inside=False, cast=True):
        super().__init__(label, mat, c, R, cast)
        self.h = tuple(float(x) for x in half)
        self.inside = inside
        self.infinite = inside

    def local_box(self):
        return np.asarray(self.h)

    def camera_job(self, ox: float, oy: float, oz: float) -> tuple:
        """(kernel kind, parameters) of camera rays from (ox, oy, oz) against this box (see `_camera_t`).
        Axis-aligned boxes use the world-frame planes and the shared inverse ray directions."""
        if self.mode == 0:
            (cx, cy, cz), (hx, hy, hz) = self.c, self.h
            return ("box_axis", self.inside), (cx - hx - ox, cx + hx - ox, cy - hy - oy, cy + hy - oy,
                                               cz - hz - oz, cz + hz - oz)
        (lx, ly, lz), (hx, hy, hz) = self.local_pt(ox, oy, oz), self.h
        return ("box", self.inside, self.mode), (-hx - lx, hx - lx, -hy - ly, hy - ly, -hz - lz, hz - lz) + self.r

    def shadow_jobs(self) -> list:
        """[(kernel kind, parameters)] of shadow rays against this box (see `_shadow_t`)."""
        hx, hy, hz = self.h
        return [(("box", self.mode), self.c + self.r + (-hx, hx, -hy, hy, -hz, hz))]

    def surface_job(self) -> tuple:
        """(kind, parameters) of `_box_surface` for this box: boxes of one kind are shaded in one call."""
        hx, hy, hz = self.h
        return ("box", self.mode, self.inside), self.c + self.h + (1 / hx, 1 / hy, 1 / hz) + self.r

    def surface(self, px, py, pz):
        return _box_surface(*self.surface_job(), px, py, pz)


def _box_surface(kind: tuple, P, px, py, pz) -> tuple:
    """Normals (world), uv (metres) and face id (0..5: -x, +x, -y, +y, -z, +z) at surface points p (n,) of
    boxes. kind: ("box", rotation mode, inside); P: `_Box.surface_job` parameters, floats or (n,) float32
    arrays (one box per point)."""
    _, mode, inside = kind
    hx, hy, hz, ihx, ihy, ihz = P[3:9]
    x, y, z = _to_local(P[9:], mode, px - P[0], py - P[1], pz - P[2])
    rx, ry, rz = np.abs(x) * ihx, np.abs(y) * ihy, np.abs(z) * ihz
    isx = (rx >= ry) & (rx >= rz)
    isy = ~isx & (ry >= rz)
    isz = ~(isx | isy)
    sgn = _F32(-1.0 if inside else 1.0)  # float32 scalars: the normals are built in float32 directly
    nx = np.where(isx, np.where(x > 0, sgn, -sgn), _F32(0.0))
    ny = np.where(isy, np.where(y > 0, sgn, -sgn), _F32(0.0))
    nz = np.where(isz, np.where(z > 0, sgn, -sgn), _F32(0.0))
    pos = np.where(isx, x > 0, np.where(isy, y > 0, z > 0))
    face = np.where(isx, 0, np.where(isy, 2, 4)) + pos
    u = np.where(isx, z + hz, x + hx)
    v = np.where(isy, z + hz, y + hy)
    return (*_to_world(P[9:], mode, nx, ny, nz), u, v, face)


class _Cyl(_Prim):
    """Capped cylinder along local y: radius r, half height h."""

    def __init__(self, c, r, h, label, mat, R=None, cast=True):
        super().__init__(label, mat, c, R, cast)
        self.rad, self.h = float(r), float(h)

    def local_box(self):
        return np.array([self.rad, self.h, self.rad])

    def camera_job(self, ox: float, oy: float, oz: float) -> tuple:
        """(kernel kind, parameters) of camera rays from (ox, oy, oz) against this cylinder (see
        `_camera_t`). One origin: only the cap facing it can be hit first; the cap term is NaN when the origin
        is level with the side (no cap test)."""
        ox, oy, oz = self.local_pt(ox, oy, oz)
        r, h = self.rad, self.h
        cap = h - oy if oy > h else -h - oy if oy < -h else math.nan
        return ("cyl", self.mode), (ox, oy, oz, ox * ox + oz * oz - r * r, h, r * r, cap) + self.r

    def shadow_jobs(self) -> list:
        """[(kernel kind, parameters)] of shadow rays against this cylinder (see `_shadow_t`)."""
        return [(("cyl", self.mode), self.c + self.r + (self.h, -self.h, self.rad * self.rad))]

    def surface_job(self) -> tuple:
        """(kind, parameters) of `_cyl_surface` for this cylinder (see `_Box.surface_job`)."""
        return ("cyl", self.mode), self.c + (1 / self.h, 1 / self.rad, self.rad, self.h) + self.r

    def surface(self, px, py, pz):
        return _cyl_surface(*self.surface_job(), px, py, pz)


def _cyl_surface(kind: tuple, P, px, py, pz) -> tuple:
    """Normals (world), uv (metres) and face id (0: side, 2 / 3: bottom / top cap) at surface points p (n,)
    of cylinders. kind: ("cyl", rotation mode); P: `_Cyl.surface_job` parameters, floats or (n,) float32
    arrays (one cylinder per point)."""
    ih, irad, rad, h = P[3:7]
    x, y, z = _to_local(P[7:], kind[1], px - P[0], py - P[1], pz - P[2])
    rho = np.sqrt(x * x + z * z)
    cap = np.abs(y) * ih > rho * irad
    inv = 1.0 / np.maximum(rho, 1e-6)
    nx = np.where(cap, 0.0, x * inv).astype(_F32)
    nz = np.where(cap, 0.0, z * inv).astype(_F32)
    ny = np.where(cap, np.sign(y), 0.0).astype(_F32)
    u = np.where(cap, x + rad, np.arctan2(x, z) * rad)
    v = np.where(cap, z + rad, y + h)
    face = np.where(cap, np.where(y > 0, 3, 2), 0)
    return (*_to_world(P[7:], kind[1], nx, ny, nz), u, v, face)


class _Sphere:
    """One sphere: a visibility / shadow part of _Spheres."""

    infinite = False

    def __init__(self, c, r, hull):
        self.c = tuple(float(x) for x in c)
        self.r = float(r)
        self._hull = hull

    def hull(self):
        return self._hull

    def camera_job(self, ox: float, oy: float, oz: float) -> tuple:
        """(kernel kind, parameters) of camera rays from (ox, oy, oz) against this sphere (see `_camera_t`)."""
        ocx, ocy, ocz = ox - self.c[0], oy - self.c[1], oz - self.c[2]
        return ("sphere",), (ocx, ocy, ocz, ocx * ocx + ocy * ocy + ocz * ocz - self.r * self.r)


class _Spheres(_Prim):
    """A cluster of spheres (foliage, bushes, heads, fruit): one object for shading, one part per sphere for
    visibility and shadows."""

    def __init__(self, centres, radii, label, mat, cast=True):
        super().__init__(label, mat, (0, 0, 0), None, cast)
        self.cs = np.asarray(centres, dtype=_F32).reshape(-1, 3)
        self.rs = np.asarray(radii, dtype=_F32).reshape(-1)

    def parts(self):
        ps = self.__dict__.get("_parts")
        if ps is None:
            # hulls of all spheres at once: centre + corners * radius, in float64
            hulls = self.cs.astype(np.float64)[:, None, :] + _BOX_CORNERS * self.rs.astype(np.float64)[:, None, None]
            ps = self._parts = [_Sphere(c, r, h) for c, r, h in zip(self.cs.tolist(), self.rs.tolist(), hulls)]
        return ps

    def hull(self):
        h = self.__dict__.get("_hull")
        if h is None:
            lo = (self.cs - self.rs[:, None]).min(0).astype(np.float64)
            hi = (self.cs + self.rs[:, None]).max(0).astype(np.float64)
            h = self._hull = 0.5 * (lo + hi) + _BOX_CORNERS * (0.5 * (hi - lo))
        return h

    def shadow_jobs(self) -> list:
        """[(kernel kind, parameters)] of shadow rays against each sphere (see `_shadow_t`); one cull per
        cluster (the caller's) is cheaper than one per sphere."""
        rr = (self.rs * self.rs).tolist()  # float32 products, as float32 parameters
        return [(("sphere",), (cx, cy, cz, r2)) for (cx, cy, cz), r2 in zip(self.cs.tolist(), rr)]

    def surface(self, px, py, pz):
        dxs = px[None, :] - self.cs[:, 0:1]
        dys = py[None, :] - self.cs[:, 1:2]
        dzs = pz[None, :] - self.cs[:, 2:3]
        dist = np.sqrt(dxs * dxs + dys * dys + dzs * dzs)
        k = np.abs(dist - self.rs[:, None]).argmin(axis=0)
        cols = np.arange(px.shape[0])
        inv = 1.0 / self.rs[k]
        nx, ny, nz = dxs[k, cols] * inv, dys[k, cols] * inv, dzs[k, cols] * inv
        u = np.arctan2(nx, nz) * self.rs[k] + k * 7.0
        v = py
        return nx, ny, nz, u, v, np.zeros(px.shape[0], np.int64)


class _Ground(_Prim):
    """The infinite plane y = 0 seen from above; its pattern gets world (x, z) as (u, v)."""

    infinite = True

    def __init__(self, label, mat):
        super().__init__(label, mat, cast=False)

    def intersect(self, ox, oy, oz, dx, dy, dz, eps):
        t = -oy / dy
        return np.where(t > eps, t, np.inf)

    def camera_job(self, ox: float, oy: float, oz: float) -> tuple:
        return None, ()  # one per scene: intersected directly

    def surface(self, px, py, pz):
        n = px.shape[0]
        z = np.zeros(n, _F32)
        return z, np.ones(n, _F32), z, px, pz, np.full(n, 3)


# ------------------------------------------------------------------------------------------------ scenes


@dataclasses.dataclass
class _Light:
    color: np.ndarray  # (3,) linear, intensity included
    direction: tuple | None = None  # unit vector towards a directional light
    position: tuple | None = None  # point light
    r0: float = 3.0  # point light falloff radius: 1 / (1 + d^2 / r0^2)
    shadow_blur: int = 1


@dataclasses.dataclass
class _Scene:
    prims: list
    cam_pos: np.ndarray
    cam_R: np.ndarray  # camera-to-world rotation
    lights: list
    ambient: np.ndarray  # (3,) linear
    ambient_up: float  # hemispheric ambient: ambient * (1 + ambient_up * n_y)
    extent: float  # bound on scene size (metres), for shadow volumes
    sky: Callable | None = None  # (dx, dy, dz) unit world directions -> (3, n) radiance
    haze_dist: float = 0.0
    haze_color: np.ndarray | None = None
    max_depth: float = np.inf
    terrain_x: float | None = None  # outdoor: ground with |x| beyond this is labelled terrain, not road
    shadow_range: float = np.inf  # objects farther than this (Chebyshev distance, metres) cast no shadow
    # camera model
    exposure: float = 0.2  # target mean linear luminance
    wb: np.ndarray = dataclasses.field(default_factory=lambda: np.ones(3, _F32))
    blur: float = 0.1
    noise_read: float = 0.005
    noise_shot: float = 0.01
    vignette: float = 0.2
    gamma: float = 2.2


def _camera_rotation(yaw: float, pitch: float, roll: float) -> np.ndarray:
    """Camera-to-world rotation (world y up). yaw about world y (positive turns right, towards +x), pitch
    positive = looking up, roll about the optical axis."""
    f = np.array([math.cos(pitch) * math.sin(yaw), math.sin(pitch), math.cos(pitch) * math.cos(yaw)])
    up = np.array([0.0, 1.0, 0.0])
    right = np.cross(up, f)
    right /= np.linalg.norm(right)
    down = np.cross(right, f)
    cr, sr = math.cos(roll), math.sin(roll)
    r2 = cr * right + sr * down
    d2 = -sr * right + cr * down
    return np.stack([r2, d2, f], axis=1)


class _Builder:
    """Collects primitives; group transforms place parts given in a local frame (x right, y up, z back,
    front faces towards -z) at floor position (gx, gz) with yaw."""

    def __init__(self, rng):
        self.rng = rng
        self.prims: list[_Prim] = []
        self._asm = None
        self._next_asm = 0

    def assembly(self) -> "_Builder":
        """`with b.assembly():` groups the primitives made inside into one shadow caster (one cull)."""
        return self

    def __enter__(self):
        self._asm = self._fresh()

    def __exit__(self, *exc):
        self._asm = None

    def _fresh(self) -> int:
        self._next_asm += 1
        return self._next_asm

    def _add(self, p):
        p.asm = self._asm if self._asm is not None else self._fresh()
        self.prims.append(p)
        return p

    @staticmethod
    def place(group, lx, ly, lz):
        if group is None:
            return lx, ly, lz
        gx, gz, yaw = group
        c, s = math.cos(yaw), math.sin(yaw)
        return gx + c * lx + s * lz, ly, gz - s * lx + c * lz

    @staticmethod
    def _R(group, yaw, R):
        a = (group[2] if group else 0.0) + yaw
        if R is not None:
            return _rot_y(a) @ R if a else R
        return _rot_y(a) if a else None

    def box(self, center, half, label, mat, yaw=0.0, group=None, cast=True, R=None):
        return self._add(_Box(self.place(group, *center), half, label, mat, self._R(group, yaw, R), cast=cast))

    def cyl(self, center, r, h, label, mat, yaw=0.0, group=None, cast=True, R=None):
        return self._add(_Cyl(self.place(group, *center), r, h, label, mat, self._R(group, yaw, R), cast=cast))

    def spheres(self, centres, radii, label, mat, group=None, cast=True):
        cs = [self.place(group, *c) for c in centres]
        return self._add(_Spheres(cs, radii, label, mat, cast=cast))


# --- indoor -------------------------------------------------------------------------------------------------


def _wall_pattern(rng) -> tuple[Pattern, float]:
    r = rng.random()
    c = _c_wall(rng)
    if r < 0.62:
        return _p_solid(rng, c, rng.uniform(0.01, 0.06)), 0.0
    if r < 0.75:
        return _p_stripes(rng, c, c * rng.uniform(0.6, 0.95), rng.uniform(0.05, 0.4), rng.uniform(0.2, 0.8),
                          math.pi / 2), 0.0
    if r < 0.83:
        return _p_tiles(rng, _hsv(rng.uniform(0.0, 0.08), rng.uniform(0.3, 0.7), rng.uniform(0.3, 0.7)),
                        _c_grey(rng, 0.5, 0.85), 0.24, 0.075, 0.012, 0.12, 0.5), 0.0
    if r < 0.9:
        return _p_tiles(rng, _c_wall(rng), _c_grey(rng, 0.5, 0.9), rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.3),
                        0.004, 0.03), 0.15
    if r < 0.95:
        return _p_wood(rng, _c_wood(rng), _c_wood(rng) * 0.6, rng.uniform(0.1, 0.25), 5.0, along_v=True), 0.05
    return _p_noise(rng, c, c * rng.uniform(0.7, 0.95), rng.uniform(1, 6), 2, rng.uniform(0.5, 1.5)), 0.0


def _floor_pattern(rng) -> tuple[Pattern, float]:
    r = rng.random()
    if r < 0.4:
        c = _c_wood(rng)
        return _p_wood(rng, c, c * rng.uniform(0.45, 0.8), rng.uniform(0.08, 0.22), rng.uniform(0.8, 2.2)), 0.25
    if r < 0.62:
        s = rng.uniform(0.25, 0.7)
        c1 = _c_grey(rng, 0.35, 0.9) if rng.random() < 0.6 else _c_any(rng)
        if rng.random() < 0.2:
            return _p_checker(rng, c1, _c_grey(rng, 0.05, 0.6), s, 0.0), 0.2
        return _p_tiles(rng, c1, _c_grey(rng, 0.2, 0.8), s, s, 0.006, 0.08), 0.3
    if r < 0.88:
        c = _c_fabric(rng)
        return _p_noise(rng, c, c * rng.uniform(0.6, 0.9), rng.uniform(5, 25), 2, rng.uniform(0.5, 1.2)), 0.0
    c = _c_grey(rng, 0.3, 0.7)
    return _p_noise(rng, c, c * 0.75, rng.uniform(0.5, 3), 2, 0.8), 0.1


def _rug(rng) -> Pattern:
    c1, c2 = _c_fabric(rng), _c_fabric(rng)
    r = rng.random()
    if r < 0.35:
        inner = _p_stripes(rng, c1, c2, rng.uniform(0.03, 0.25), rng.uniform(0.3, 0.7), rng.choice([0.0, math.pi / 2]))
    elif r < 0.55:
        inner = _p_checker(rng, c1, c2, rng.uniform(0.05, 0.2), 0.0)
    else:
        inner = _p_noise(rng, c1, c2, rng.uniform(4, 20), 2, rng.uniform(0.6, 2.0))
    border = rng.uniform(0.0, 0.1)
    bc = _c_fabric(rng)

    def fn(u, v, fp):
        out = np.array(inner(u, v, fp), dtype=_F32)
        if border > 0:
            m = (u < border) | (u > 1 - border) | (v < border) | (v > 1 - border)
            _set_cols(out, m, bc)
        return out

    return _with_mean(fn, 0.5 * (c1 + c2))


def _furniture_mat(rng, fronts=None) -> _Mat:
    c = _c_furniture(rng)
    if rng.random() < 0.55 and c[0, 0] > c[2, 0] * 1.3:  # woody colour: wood grain
        pat = _p_wood(rng, c, c * rng.uniform(0.5, 0.8), rng.uniform(0.15, 0.5), rng.uniform(0.6, 2.0), gap=0.0)
    else:
        pat = _p_solid(rng, c, rng.uniform(0.01, 0.05))
    return _Mat(pat, spec=rng.choice([0.0, 0.0, 0.05, 0.15]), shin=rng.uniform(10, 60))


def _small_object(b: _Builder, rng, x, y, z, group, max_size):
    """One tabletop object standing at (x, y, z) in the group frame."""
    r = rng.random()
    mat = _Mat(_p_solid(rng, _c_any(rng), 0.04), spec=rng.choice([0.0, 0.1, 0.3]), shin=rng.uniform(10, 80))
    if r < 0.3:  # book / box / stack of books
        n = int(rng.integers(1, 4))
        w, d = rng.uniform(0.12, min(0.35, max_size)), rng.uniform(0.1, min(0.3, max_size))
        yaw = rng.uniform(-0.5, 0.5)
        for _ in range(n):
            hh = rng.uniform(0.015, 0.05)
            b.box((x, y + hh, z), (w / 2, hh, d / 2), _OBJECT, _Mat(_p_solid(rng, _c_any(rng), 0.03)), yaw, group)
            y += 2 * hh
    elif r < 0.6:  # cup, bottle, vase, can
        rad = rng.uniform(0.03, 0.09)
        hh = rng.uniform(0.04, 0.16)
        b.cyl((x, y + hh, z), rad, hh, _OBJECT, mat, group=group)
    elif r < 0.75:  # fruit / ball
        rad = rng.uniform(0.04, 0.12)
        b.spheres([(x, y + rad, z)], [rad], _OBJECT, mat, group=group)
    elif r < 0.9:  # monitor / picture on a stand
        w = rng.uniform(0.35, min(0.75, 2 * max_size + 0.2))
        hh = w * rng.uniform(0.28, 0.4)
        body = _Mat(_p_solid(rng, _c_grey(rng, 0.02, 0.2), 0.02), spec=0.2,
                    decals=[_Decal(0.04, 0.06, 0.96, 0.96, _Mat(_p_poster(rng), emit=rng.choice([0.0, 0.6])), 4)])
        b.box((x, y + 0.1 + hh, z), (w / 2, hh, 0.02), _OBJECT, body, rng.uniform(-0.4, 0.4), group)
        b.box((x, y + 0.05, z + 0.02), (0.04, 0.05, 0.03), _OBJECT, body, 0.0, group)
    else:  # lamp
        b.cyl((x, y + 0.02, z), 0.07, 0.02, _OBJECT, mat, group=group)
        b.cyl((x, y + 0.2, z), 0.012, 0.18, _OBJECT, mat, group=group)
        b.cyl((x, y + 0.42, z), rng.uniform(0.08, 0.14), 0.08, _OBJECT,
              _Mat(_p_solid(rng, _c_grey(rng, 0.6, 0.95), 0.02), emit=rng.choice([0.0, 0.8])), group=group)


def _clutter(b: _Builder, rng, group, w, d, top, n):
    for _ in range(n):
        x = rng.uniform(-0.4, 0.4) * w
        z = rng.uniform(-0.35, 0.35) * d
        _small_object(b, rng, x, top, z, group, min(w, d) * 0.5)


def _table(b, rng, group, w, d, h, round_=False):
    top_mat = _furniture_mat(rng)
    leg_mat = top_mat if rng.random() < 0.5 else _Mat(_p_solid(rng, _c_grey(rng, 0.03, 0.8), 0.02), spec=0.2)
    th = rng.uniform(0.02, 0.05)
    if round_:
        r = 0.5 * min(w, d)
        b.cyl((0, h - th / 2, 0), r, th / 2, _FURNITURE, top_mat, group=group)
        b.cyl((0, (h - th) / 2, 0), rng.uniform(0.03, 0.07), (h - th) / 2, _FURNITURE, leg_mat, group=group)
        b.cyl((0, 0.015, 0), r * 0.5, 0.015, _FURNITURE, leg_mat, group=group)
        w = d = r * 1.4
    else:
        b.box((0, h - th / 2, 0), (w / 2, th / 2, d / 2), _FURNITURE, top_mat, group=group)
        lw = rng.uniform(0.02, 0.045)
        lh = (h - th) / 2
        for sx in (-1, 1):
            for sz in (-1, 1):
                b.box((sx * (w / 2 - lw - 0.03), lh, sz * (d / 2 - lw - 0.03)), (lw, lh, lw), _FURNITURE, leg_mat,
                      group=group)
    _clutter(b, rng, group, w, d, h, int(rng.integers(0, 5)))


def _chair(b, rng, group, mat=None):
    mat = mat or _furniture_mat(rng)
    w = rng.uniform(0.4, 0.5)
    sh = rng.uniform(0.42, 0.48)
    lw = 0.018
    b.box((0, sh, 0), (w / 2, 0.025, w / 2), _FURNITURE, mat, group=group)
    bh = rng.uniform(0.3, 0.5)
    b.box((0, sh + bh / 2, w / 2 - 0.02), (w / 2, bh / 2, 0.02), _FURNITURE, mat, group=group)
    for sx in (-1, 1):
        for sz in (-1, 1):
            b.box((sx * (w / 2 - lw), sh / 2, sz * (w / 2 - lw)), (lw, sh / 2, lw), _FURNITURE, mat, group=group)


def _indoor_item(b: _Builder, rng, kind, group, w, d, h):
    """A piece of furniture with its footprint (w along local x, d along local z) centred on the group
    origin, front towards local -z."""
    with b.assembly():
        _indoor_item_parts(b, rng, kind, group, w, d, h)


def _indoor_item_parts(b: _Builder, rng, kind, group, w, d, h):
    if kind in ("cabinet", "wardrobe", "dresser"):
        mat = _furniture_mat(rng)
        cols = max(1, int(round(w / rng.uniform(0.4, 0.6))))
        rows = 1 if kind == "wardrobe" else int(rng.integers(1, 5))
        front = _Mat(_p_fronts(rng, mat.pattern, w, h, cols, rows, rng.choice([0.0, 0.08]),
                               mat.pattern(np.zeros(1, _F32), np.zeros(1, _F32), np.zeros(1, _F32))[:, :1] * 0.35,
                               _c_grey(rng, 0.05, 0.9)), spec=mat.spec)
        mat.faces = {4: front}
        b.box((0, h / 2, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)
        if h < 1.3:
            _clutter(b, rng, group, w, d, h, int(rng.integers(0, 4)))
    elif kind == "shelf":
        mat = _furniture_mat(rng)
        shelf_c = mat.pattern(np.zeros(1, _F32), np.zeros(1, _F32), np.zeros(1, _F32))[:, :1]
        mat.faces = {4: _Mat(_p_books(rng, shelf_c, rng.uniform(0.28, 0.4), 0.025))}
        b.box((0, h / 2, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)
    elif kind == "desk":
        _table(b, rng, group, w, d, rng.uniform(0.72, 0.78))
        if rng.random() < 0.6:  # its chair, in front, facing the desk
            cx_, _, cz_ = b.place(group, rng.uniform(-0.2, 0.2) * w, 0.0, -d / 2 - 0.25)
            _chair(b, rng, (cx_, cz_, group[2] + math.pi + rng.uniform(-0.4, 0.4)))
    elif kind == "bed":
        frame = _furniture_mat(rng)
        fh = rng.uniform(0.15, 0.3)
        b.box((0, fh / 2, 0), (w / 2, fh / 2, d / 2), _FURNITURE, frame, group=group)
        mh = rng.uniform(0.15, 0.25)
        sheet = _Mat(_p_solid(rng, _c_fabric(rng), 0.03))
        cover_pat = [_rug(rng), _p_solid(rng, _c_fabric(rng), 0.05)][int(rng.integers(0, 2))]
        sheet.decals = [_Decal(-1.0, -1.0, 2 * w, d * rng.uniform(0.45, 0.8), _Mat(cover_pat))]  # a blanket
        b.box((0, fh + mh / 2, 0), (w / 2 - 0.03, mh / 2, d / 2 - 0.03), _FURNITURE, sheet, group=group)
        hb = rng.uniform(0.5, 1.1)
        b.box((0, hb / 2, d / 2 - 0.03), (w / 2, hb / 2, 0.03), _FURNITURE, frame, group=group)
        pm = _Mat(_p_solid(rng, _c_fabric(rng), 0.03))
        for sx in ((-0.25, 0.25) if w > 1.2 else (0.0,)):
            b.box((sx * w, fh + mh + 0.06, d / 2 - 0.3), (0.3 if w > 1.2 else 0.28, 0.06, 0.18), _OBJECT, pm,
                  group=group)
    elif kind == "sofa":
        mat = _Mat(_p_noise(rng, c := _c_fabric(rng), c * 0.8, rng.uniform(8, 30), 2, 0.6))
        sh = rng.uniform(0.38, 0.46)
        aw = rng.uniform(0.1, 0.22)
        b.box((0, sh / 2, -0.05), (w / 2 - aw, sh / 2, d / 2 - 0.05), _FURNITURE, mat, group=group)
        bh = rng.uniform(0.75, 0.95)
        b.box((0, bh / 2, d / 2 - 0.1), (w / 2, bh / 2, 0.1), _FURNITURE, mat, group=group)
        ah = rng.uniform(0.5, 0.65)
        for sx in (-1, 1):
            b.box((sx * (w / 2 - aw / 2), ah / 2, 0), (aw / 2, ah / 2, d / 2), _FURNITURE, mat, group=group)
        if rng.random() < 0.6:
            pm = _Mat(_p_solid(rng, _c_fabric(rng), 0.04))
            for sx in rng.uniform(-0.35, 0.35, int(rng.integers(1, 3))):
                b.box((sx * w, sh + 0.18, d / 2 - 0.25), (0.2, 0.18, 0.06), _OBJECT, pm, rng.uniform(-0.3, 0.3), group)
    elif kind == "counter":
        mat = _furniture_mat(rng)
        fronts = _p_fronts(rng, mat.pattern, w, h, max(1, int(w / 0.55)), 1, 0.1, _c_grey(rng, 0.05, 0.3),
                           _c_grey(rng, 0.1, 0.9))
        mat.faces = {4: _Mat(fronts)}
        b.box((0, (h - 0.03) / 2, 0.02), (w / 2, (h - 0.03) / 2, d / 2 - 0.02), _FURNITURE, mat, group=group)
        top = _Mat(_p_noise(rng, c := _c_grey(rng, 0.1, 0.9), c * 0.7, rng.uniform(5, 20), 2, 0.8), spec=0.3)
        b.box((0, h - 0.015, 0), (w / 2 + 0.01, 0.015, d / 2), _FURNITURE, top, group=group)
        _clutter(b, rng, group, w, d, h, int(rng.integers(1, 5)))
        if rng.random() < 0.7:  # wall cabinets
            uh = rng.uniform(0.6, 0.9)
            b.box((0, 1.45 + uh / 2, d / 2 - 0.18), (w / 2, uh / 2, 0.18), _FURNITURE,
                  _Mat(mat.pattern, faces={4: _Mat(_p_fronts(rng, mat.pattern, w, uh, max(1, int(w / 0.55)), 1, 0.0,
                                                             _c_grey(rng, 0.05, 0.3), _c_grey(rng, 0.1, 0.9)))}),
                  group=group)
    elif kind == "fridge":
        c = _c_grey(rng, 0.5, 0.95)
        mat = _Mat(_p_solid(rng, c, 0.01), spec=0.3, shin=40,
                   faces={4: _Mat(_p_fronts(rng, _p_solid(rng, c, 0.01), w, h, 1, 2, 0.0, c * 0.4,
                                            _c_grey(rng, 0.1, 0.9)), spec=0.3)})
        b.box((0, h / 2, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)
    elif kind == "tv":
        stand_h = rng.uniform(0.4, 0.6)
        mat = _furniture_mat(rng)
        b.box((0, stand_h / 2, 0), (w / 2, stand_h / 2, d / 2), _FURNITURE, mat, group=group)
        tw = min(w * 0.9, rng.uniform(0.7, 1.4))
        th = tw * 0.58
        scr = _Mat(_p_solid(rng, _c_grey(rng, 0.01, 0.08), 0.02), spec=0.5, shin=60,
                   decals=[_Decal(0.03, 0.04, 0.97, 0.97, _Mat(_p_poster(rng), emit=0.5), 4)]
                   if rng.random() < 0.4 else [])
        b.box((0, stand_h + 0.05 + th / 2, d / 2 - 0.1), (tw / 2, th / 2, 0.03), _OBJECT, scr, group=group)
    elif kind == "plant":
        pot = _Mat(_p_solid(rng, _c_any(rng), 0.03), spec=0.1)
        ph = rng.uniform(0.15, 0.35)
        pr = rng.uniform(0.12, 0.25)
        b.cyl((0, ph, 0), pr, ph, _OBJECT, pot, group=group)
        n = int(rng.integers(3, 8))
        top = 2 * ph
        cs = [(rng.normal(0, pr), top + rng.uniform(0.1, 0.9), rng.normal(0, pr)) for _ in range(n)]
        b.spheres(cs, rng.uniform(0.12, 0.3, n), _VEGETATION, _Mat(_p_foliage(rng)), group=group)
    elif kind == "lamp":
        mat = _Mat(_p_solid(rng, _c_grey(rng, 0.02, 0.9), 0.02), spec=0.3)
        hh = rng.uniform(1.3, 1.7)
        b.cyl((0, 0.015, 0), 0.15, 0.015, _FURNITURE, mat, group=group)
        b.cyl((0, hh / 2, 0), 0.015, hh / 2, _FURNITURE, mat, group=group)
        b.cyl((0, hh + 0.1, 0), rng.uniform(0.15, 0.25), 0.13, _FURNITURE,
              _Mat(_p_solid(rng, _c_wall(rng), 0.02), emit=rng.choice([0.0, 0.6])), group=group)
    elif kind == "bin":
        r = min(w, d) / 2
        b.cyl((0, h / 2, 0), r, h / 2, _OBJECT, _Mat(_p_solid(rng, _c_any(rng), 0.03), spec=0.2), group=group)
    elif kind == "boxes":
        z = 0.0
        y = 0.0
        for _ in range(int(rng.integers(1, 4))):
            hh = rng.uniform(0.1, 0.3)
            c = _hsv(rng.uniform(0.07, 0.11), rng.uniform(0.3, 0.6), rng.uniform(0.35, 0.75)) \
                if rng.random() < 0.6 else _c_any(rng)
            b.box((rng.uniform(-0.05, 0.05), y + hh, z), (w / 2 * rng.uniform(0.7, 1), hh, d / 2 * rng.uniform(0.7, 1)),
                  _OBJECT, _Mat(_p_solid(rng, c, 0.04)), rng.uniform(-0.3, 0.3), group)
            y += 2 * hh
    elif kind == "ball":
        r = min(w, d) / 2
        b.spheres([(0, r, 0)], [r], _OBJECT, _Mat(_p_solid(rng, _c_any(rng), 0.03), spec=0.3), group=group)
    elif kind == "table":
        _table(b, rng, group, w, d, rng.uniform(0.7, 0.78), round_=rng.random() < 0.3)
        cm = _furniture_mat(rng)
        for k in range(int(rng.integers(0, 5))):
            side = k % 4
            off = [(0, -d / 2 - 0.05), (0, d / 2 + 0.05), (-w / 2 - 0.05, 0), (w / 2 + 0.05, 0)][side]
            yaw_c = [math.pi, 0.0, -math.pi / 2, math.pi / 2][side]  # chairs face the table
            gx, _, gz = b.place(group, off[0] + rng.uniform(-0.15, 0.15), 0, off[1])
            _chair(b, rng, (gx, gz, group[2] + yaw_c + rng.uniform(-0.3, 0.3)), cm)
    elif kind == "chair":
        _chair(b, rng, group)
    elif kind == "armchair":
        _indoor_item_parts(b, rng, "sofa", group, w, d, h)


# (kind, width range, depth range, height range, weight) for furniture against walls and in the room
_WALL_ITEMS = (
    ("cabinet", (0.5, 1.6), (0.35, 0.6), (0.6, 1.2), 3),
    ("wardrobe", (0.8, 2.0), (0.5, 0.65), (1.8, 2.3), 1.5),
    ("dresser", (0.6, 1.4), (0.4, 0.55), (0.7, 1.1), 1.5),
    ("shelf", (0.6, 1.8), (0.25, 0.4), (0.8, 2.2), 2.5),
    ("desk", (0.9, 1.8), (0.5, 0.8), (0.75, 0.75), 2.5),
    ("bed", (0.9, 2.0), (1.9, 2.1), (0.5, 0.5), 1.2),
    ("sofa", (1.4, 2.4), (0.75, 0.95), (0.8, 0.8), 1.5),
    ("counter", (1.2, 3.5), (0.55, 0.65), (0.86, 0.94), 1.2),
    ("fridge", (0.6, 0.8), (0.6, 0.7), (1.6, 2.0), 0.6),
    ("tv", (1.0, 2.0), (0.35, 0.5), (0.5, 0.5), 1.0),
    ("plant", (0.4, 0.6), (0.4, 0.6), (1.0, 1.0), 1.0),
    ("lamp", (0.35, 0.35), (0.35, 0.35), (1.7, 1.7), 0.6),
    ("boxes", (0.3, 0.6), (0.3, 0.5), (0.5, 0.5), 0.8),
    ("bin", (0.25, 0.4), (0.25, 0.4), (0.3, 0.6), 0.6),
)
_ROOM_ITEMS = (
    ("table", (0.8, 1.8), (0.7, 1.1), (0.75, 0.75), 3),
    ("chair", (0.5, 0.5), (0.5, 0.5), (0.9, 0.9), 2),
    ("armchair", (0.8, 1.0), (0.8, 0.9), (0.8, 0.8), 1),
    ("plant", (0.4, 0.6), (0.4, 0.6), (1.0, 1.0), 1),
    ("boxes", (0.3, 0.6), (0.3, 0.5), (0.5, 0.5), 1),
    ("ball", (0.15, 0.45), (0.15, 0.45), (0.3, 0.3), 0.5),
    ("bin", (0.25, 0.4), (0.25, 0.4), (0.3, 0.6), 0.7),
    ("lamp", (0.35, 0.35), (0.35, 0.35), (1.7, 1.7), 0.5),
)


def _pick(rng, table):
    w = np.array([t[-1] for t in table], dtype=np.float64)
    return table[int(rng.choice(len(table), p=w / w.sum()))]


def _indoor_scene(rng) -> _Scene:
    b = _Builder(rng)
    W, L, Hc = rng.uniform(3.0, 7.0), rng.uniform(3.5, 8.5), rng.uniform(2.4, 3.2)

    # Room surfaces: face 0 / 1 left / right wall (x = 0 / W), 2 floor, 3 ceiling, 4 / 5 near / far wall.
    wall_pat, wall_spec = _wall_pattern(rng)
    walls = {f: _Mat(wall_pat, spec=wall_spec) for f in (0, 1, 4, 5)}
    if rng.random() < 0.25:  # an accent wall
        walls[int(rng.choice([0, 1, 5]))].pattern = _wall_pattern(rng)[0]
    floor_pat, floor_spec = _floor_pattern(rng)
    floor = _Mat(floor_pat, spec=floor_spec, shin=rng.uniform(20, 80))
    if rng.random() < 0.75:
        ceil = _Mat(_p_solid(rng, _hsv(0.1, rng.uniform(0, 0.08), rng.uniform(0.75, 0.95)), 0.02))
    else:
        ceil = _Mat(_p_tiles(rng, _c_grey(rng, 0.7, 0.95), _c_grey(rng, 0.4, 0.8), 0.6, 0.6, 0.02, 0.03))
    room_mat = _Mat(_p_solid(rng, np.ones((3, 1), _F32), 0), faces={**walls, 2: floor, 3: ceil})
    wall_len = {0: L, 1: L, 4: W, 5: W}

    # Decals: colour edges that are not depth edges.
    if rng.random() < 0.6:  # skirting board
        bh = rng.uniform(0.05, 0.14)
        bm = _Mat(_p_solid(rng, _c_wood(rng) if rng.random() < 0.5 else _c_grey(rng, 0.1, 0.95), 0.02), spec=0.1)
        for f, m in walls.items():
            m.decals.append(_Decal(-0.01, -0.01, wall_len[f] + 0.01, bh, bm))
    if rng.random() < 0.15:  # wainscoting / tiled lower half
        wh = rng.uniform(0.8, 1.3)
        wm = _Mat(_wall_pattern(rng)[0])
        for f, m in walls.items():
            m.decals.insert(0, _Decal(-0.01, -0.01, wall_len[f] + 0.01, wh, wm))
    for _ in range(int(rng.integers(0, 3))):  # windows
        f = int(rng.choice([0, 1, 5]))
        ww, wh = rng.uniform(0.6, min(2.4, wall_len[f] - 0.4)), rng.uniform(0.9, 1.7)
        u0 = rng.uniform(0.1, wall_len[f] - ww - 0.1)
        v0 = rng.uniform(0.6, max(0.61, Hc - wh - 0.2))
        walls[f].decals.append(_Decal(u0, v0, u0 + ww, v0 + wh, _Mat(_p_window(rng), emit=rng.uniform(1.5, 4.0))))
        if rng.random() < 0.5:  # curtains
            cm = _Mat(_p_stripes(rng, c := _c_fabric(rng), c * 0.75, rng.uniform(0.05, 0.15), 0.5, 0.0))
            cw = rng.uniform(0.25, 0.5)
            top = min(Hc - 0.05, v0 + wh + 0.25)
            walls[f].decals.append(_Decal(u0 - cw * 0.6, 0.05, u0 + cw * 0.4, top, cm))
            walls[f].decals.append(_Decal(u0 + ww - cw * 0.4, 0.05, u0 + ww + cw * 0.6, top, cm))
    if rng.random() < 0.6:  # door
        f = int(rng.choice([0, 1, 4, 5]))
        dw = rng.uniform(0.75, 1.0)
        u0 = rng.uniform(0.1, wall_len[f] - dw - 0.1)
        c = _c_wood(rng) if rng.random() < 0.5 else _c_wall(rng)
        panels = _p_fronts(rng, _p_solid(rng, c, 0.02), 1.0, 1.0, 1, int(rng.integers(1, 3)), 0.0, c * 0.6,
                           _c_grey(rng, 0.1, 0.9))
        walls[f].decals.append(_Decal(u0, 0.0, u0 + dw, rng.uniform(1.98, 2.1), _Mat(panels, spec=0.1)))
    for f in (0, 1, 5, 4):  # posters, paintings, boards, clocks
        for _ in range(int(rng.integers(0, 4))):
            pw = rng.uniform(0.2, 1.2)
            ph = pw * rng.uniform(0.5, 1.5)
            if pw > wall_len[f] - 0.2 or ph > Hc - 1.0:
                continue
            u0 = rng.uniform(0.1, wall_len[f] - pw - 0.1)
            v0 = rng.uniform(0.9, Hc - ph - 0.05)
            walls[f].decals.append(_Decal(u0, v0, u0 + pw, v0 + ph, _Mat(_p_poster(rng), spec=0.1)))
    if rng.random() < 0.15:  # whiteboard / blackboard
        f = int(rng.choice([0, 1, 5]))
        bw = rng.uniform(1.2, min(3.5, wall_len[f] - 0.4))
        u0 = rng.uniform(0.2, wall_len[f] - bw - 0.2)
        board = _c_grey(rng, 0.85, 0.97) if rng.random() < 0.7 else _hsv(rng.uniform(0.3, 0.45), 0.4, 0.2)
        walls[f].decals.append(_Decal(u0, 0.9, u0 + bw, 2.0, _Mat(_p_poster(rng) if rng.random() < 0.3 else
                                                                   _p_noise(rng, board, board * 0.85, 3, 2, 0.5),
                                                                   spec=0.3)))
    for _ in range(int(rng.integers(0, 3)) if rng.random() < 0.6 else 0):  # rugs
        rw, rl = rng.uniform(0.8, min(3.0, W - 0.4)), rng.uniform(0.8, min(4.0, L - 0.4))
        x0, z0 = rng.uniform(0.2, W - rw - 0.2), rng.uniform(0.2, L - rl - 0.2)
        floor.decals.append(_Decal(x0, z0, x0 + rw, z0 + rl, _Mat(_rug(rng))))
    for _ in range(int(rng.integers(0, 5))):  # ceiling light panels
        s = rng.uniform(0.3, 0.7)
        x0, z0 = rng.uniform(0.2, W - s - 0.2), rng.uniform(0.2, L - s - 0.2)
        ceil.decals.append(_Decal(x0, z0, x0 + s, z0 + s * rng.choice([1.0, 2.0]),
                                  _Mat(_p_solid(rng, _c_grey(rng, 0.85, 1.0), 0.0), emit=rng.uniform(1.0, 3.0))))

    room_labels = np.array([_WALL, _WALL, _FLOOR, _CEILING, _WALL, _WALL], dtype=np.int8)
    room = _Box((W / 2, Hc / 2, L / 2), (W / 2, Hc / 2, L / 2), room_labels, room_mat, inside=True, cast=False)
    b.prims.append(room)

    # Camera, near one end of the room looking in.
    cam_h = rng.uniform(0.95, min(1.75, Hc - 0.45))
    cam = np.array([rng.uniform(0.3, 0.7) * W, cam_h, rng.uniform(0.35, min(1.6, 0.3 * L))])
    yaw, pitch, roll = rng.uniform(-0.6, 0.6), rng.uniform(-0.45, 0.08), rng.normal(0.0, 0.02)
    R = _camera_rotation(yaw, pitch, roll)

    # Furniture. Footprints (x0, x1, z0, z1) must not overlap each other or the camera's surroundings.
    taken = [(cam[0] - 0.7, cam[0] + 0.7, cam[2] - 0.9, cam[2] + 0.7)]

    def free(x0, x1, z0, z1):
        return x0 > 0.0 and z0 > 0.0 and x1 < W and z1 < L and all(
            x1 <= a0 or x0 >= a1 or z1 <= b0 or z0 >= b1 for a0, a1, b0, b1 in taken)

    n_wall = int(rng.integers(3, 11))
    for _ in range(n_wall):
        kind, wr, dr, hr, _w = _pick(rng, _WALL_ITEMS)
        for _try in range(6):
            f = int(rng.choice([0, 1, 5, 4], p=[0.3, 0.3, 0.35, 0.05]))
            w, d, h = rng.uniform(*wr), rng.uniform(*dr), rng.uniform(*hr)
            h = min(h, Hc - 0.15)
            if w > wall_len[f] - 0.1:
                continue
            s = rng.uniform(w / 2 + 0.02, wall_len[f] - w / 2 - 0.02)
            gap = 0.005
            if f == 0:
                gx, gz, gyaw, fx, fz = d / 2 + gap, s, -math.pi / 2, d, w
            elif f == 1:
                gx, gz, gyaw, fx, fz = W - d / 2 - gap, s, math.pi / 2, d, w
            elif f == 5:
                gx, gz, gyaw, fx, fz = s, L - d / 2 - gap, 0.0, w, d
            else:
                gx, gz, gyaw, fx, fz = s, d / 2 + gap, math.pi, w, d
            # the desk's chair stands in front of it
            extra = 0.6 if kind == "desk" else 0.0
            fx2 = fx + (extra if f in (0, 1) else 0)
            fz2 = fz + (extra if f in (4, 5) else 0)
            x0 = gx - fx / 2 - (extra if f == 1 else 0)
            z0 = gz - fz / 2 - (extra if f == 5 else 0)
            if not free(x0, x0 + fx2, z0, z0 + fz2):
                continue
            taken.append((x0, x0 + fx2, z0, z0 + fz2))
            _indoor_item(b, rng, kind, (gx, gz, gyaw), w, d, h)
            break
    for _ in range(int(rng.integers(1, 6))):
        kind, wr, dr, hr, _w = _pick(rng, _ROOM_ITEMS)
        w, d, h = rng.uniform(*wr), rng.uniform(*dr), rng.uniform(*hr)
        margin = 0.65 if kind == "table" else 0.1
        for _try in range(6):
            gx, gz = rng.uniform(0.2, W - 0.2), rng.uniform(0.2, L - 0.2)
            r = 0.5 * math.hypot(w, d) + margin
            if not free(gx - r, gx + r, gz - r, gz + r):
                continue
            taken.append((gx - r, gx + r, gz - r, gz + r))
            _indoor_item(b, rng, kind, (gx, gz, rng.uniform(-math.pi, math.pi)), w, d, h)
            break
    for _ in range(int(rng.integers(0, 3))):  # frames / shelves / wall-mounted cabinets sticking out a bit
        f = int(rng.choice([0, 1, 5]))
        w, h, d = rng.uniform(0.3, 1.2), rng.uniform(0.2, 0.9), rng.uniform(0.02, 0.3)
        if w > wall_len[f] - 0.3:
            continue
        s = rng.uniform(w / 2 + 0.1, wall_len[f] - w / 2 - 0.1)
        y = rng.uniform(1.2, Hc - h / 2 - 0.1)
        group = {0: (d / 2, s, -math.pi / 2), 1: (W - d / 2, s, math.pi / 2), 5: (s, L - d / 2, 0.0)}[f]
        mat = _furniture_mat(rng)
        if d < 0.08:
            mat.faces = {4: _Mat(_p_poster(rng), spec=0.15)}
        b.box((0, y, 0), (w / 2, h / 2, d / 2), _FURNITURE, mat, group=group)

    # Lights: one or two ceiling point lights + ambient.
    lights = []
    for _ in range(int(rng.integers(1, 3))):
        pos = (rng.uniform(0.2, 0.8) * W, Hc - rng.uniform(0.15, 0.5), rng.uniform(0.3, 0.95) * L)
        temp = _hsv(rng.uniform(0.06, 0.15), rng.uniform(0.0, 0.35), 1.0) if rng.random() < 0.7 else \
            _hsv(rng.uniform(0.5, 0.65), rng.uniform(0.0, 0.2), 1.0)
        lights.append(_Light(temp * rng.uniform(1.5, 3.5), position=pos, r0=rng.uniform(1.5, 4.0),
                             shadow_blur=int(rng.integers(1, 4))))
    ambient = _hsv(rng.uniform(0.0, 1.0), rng.uniform(0.0, 0.15), 1.0) * rng.uniform(0.12, 0.4)

    return _Scene(
        prims=b.prims, cam_pos=cam, cam_R=R, lights=lights, ambient=ambient, ambient_up=rng.uniform(0.0, 0.3),
        extent=math.sqrt(W * W + L * L + Hc * Hc), **_camera_model(rng))


def _camera_model(rng) -> dict:
    return dict(
        exposure=rng.uniform(0.1, 0.28),
        wb=np.array([rng.uniform(0.85, 1.15), 1.0, rng.uniform(0.85, 1.15)], _F32),
        blur=rng.uniform(0.05, 0.22),
        # in linear units, before the ~1/2.2 gamma that amplifies it in the shadows
        noise_read=rng.uniform(0.0002, 0.002),
        noise_shot=rng.uniform(0.002, 0.015),
        vignette=rng.uniform(0.0, 0.35),
        gamma=float(rng.choice([2.0, 2.2, 2.4])),
    )


# --- outdoor ------------------------------------------------------------------------------------------------


def _p_facade(rng, wall: Pattern, length_u0: float) -> Pattern:
    floor_h = rng.uniform(2.8, 3.6)
    bay = rng.uniform(1.8, 4.0)
    win_w = bay * rng.uniform(0.3, 0.7)
    win_h = floor_h * rng.uniform(0.35, 0.6)
    sill = rng.uniform(0.6, 1.0)
    off = length_u0 + rng.uniform(0, bay)
    ga = _hsv(rng.uniform(0.5, 0.65), rng.uniform(0.05, 0.4), rng.uniform(0.05, 0.25))
    gb = _hsv(rng.uniform(0.5, 0.65), rng.uniform(0.0, 0.25), rng.uniform(0.25, 0.7))
    fc = _c_grey(rng, 0.1, 0.95)
    fw = rng.uniform(0.04, 0.12)
    shop = rng.random() < 0.4
    shop_c = _c_any(rng)
    mullion = win_w > 1.1

    def fn(u, v, fp):
        out = np.array(wall(u, v, fp), dtype=_F32)
        fl = np.floor(v / floor_h)
        vv = v - fl * floor_h
        uo = u - off
        bi = np.floor(uo / bay)
        ub = uo - bi * bay
        uu = ub - (bay - win_w) / 2
        if shop:
            ground = fl == 0
            uu = np.where(ground, ub - 0.25, uu)
            ww = np.where(ground, bay - 0.5, win_w)
            lo = np.where(ground, 0.35, sill)
            hi = np.where(ground, floor_h - 0.6, sill + win_h)
        else:
            ww, lo, hi = win_w, sill, sill + win_h
        glass = (uu > 0) & (uu < ww) & (vv > lo) & (vv < hi)
        frame = (uu > -fw) & (uu < ww + fw) & (vv > lo - fw) & (vv < hi + fw) & ~glass
        if mullion:
            mm = glass & (np.abs(uu - ww * 0.5) < fw * 0.4)
            frame |= mm
            glass &= ~mm
        sel = np.flatnonzero(glass)
        if sel.size:
            g = _hash(bi[sel], fl[sel])  # per window
            grad = (vv[sel] - lo if np.isscalar(lo) else vv[sel] - lo[sel]) / floor_h
            _set_cols(out, sel, _mix(ga, gb, np.minimum(np.maximum(g * 0.8 + grad * 0.6, 0.0), 1.0)))
        _set_cols(out, frame, fc)
        if shop:
            band = (fl == 0) & (vv > floor_h - 0.55) & (vv < floor_h - 0.1)
            _set_cols(out, band, shop_c)
        return out

    return _with_mean(fn, 0.75 * _mean_of(wall) + 0.25 * ga)


def _building_wall(rng) -> Pattern:
    r = rng.random()
    if r < 0.3:
        c = _hsv(rng.uniform(0.0, 0.07), rng.uniform(0.35, 0.7), rng.uniform(0.25, 0.6))
        return _p_tiles(rng, c, _c_grey(rng, 0.4, 0.8), 0.24, 0.075, 0.01, 0.15, 0.5)
    if r < 0.45:
        return _p_tiles(rng, _c_grey(rng, 0.3, 0.85), _c_grey(rng, 0.2, 0.6), rng.uniform(0.5, 1.5),
                        rng.uniform(0.3, 1.0), 0.01, 0.05)
    c = _c_wall(rng) if rng.random() < 0.7 else _c_grey(rng, 0.25, 0.9)
    return _p_noise(rng, c, c * rng.uniform(0.75, 0.95), rng.uniform(0.3, 2.0), 2, rng.uniform(0.4, 1.2))


def _p_car_end(rng, paint_c, W, body_h, rear: bool) -> Pattern:
    """A car's rear (tail lights, plate, bumper) or front (headlights, grille, plate) face."""
    lamp = _hsv(0.0, 0.85, rng.uniform(0.4, 0.8)) if rear else _c_grey(rng, 0.6, 0.9)
    plate_c = _c_grey(rng, 0.8, 0.95)
    dark = _c_grey(rng, 0.01, 0.08)
    lw = rng.uniform(0.2, 0.35)
    l0, l1 = body_h * rng.uniform(0.45, 0.6), body_h * rng.uniform(0.75, 0.9)

    def fn(u, v, fp):
        out = np.empty((3, u.shape[0]), _F32)
        out[:] = paint_c
        _set_cols(out, v < body_h * 0.15, dark)  # bumper / shadowed underside
        du = np.abs(u - W / 2)
        if not rear:
            _set_cols(out, (du < W / 2 - lw - 0.1) & (v > body_h * 0.35) & (v < l1), dark)  # grille
        _set_cols(out, (v > l0) & (v < l1) & (du > W / 2 - lw - 0.04) & (du < W / 2 - 0.04), lamp)
        _set_cols(out, (du < 0.26) & (v > body_h * 0.2) & (v < body_h * 0.2 + 0.11), plate_c)
        return out

    return _with_mean(fn, paint_c)


def _p_glazed(frame_c, glass: Pattern, u0, v0, u1, v1, pillar=None) -> Pattern:
    """Glass in [u0, u1) x [v0, v1) of a face, frame colour around it, an optional pillar at u = pillar."""

    def fn(u, v, fp):
        out = np.empty((3, u.shape[0]), _F32)
        out[:] = frame_c
        m = _box(u, v, u0, v0, u1, v1)
        if pillar is not None:
            m &= np.abs(u - pillar) > 0.05
        sel = np.flatnonzero(m)
        if sel.size:
            _set_cols(out, sel, glass(u[sel], v[sel], fp[sel]))
        return out

    return _with_mean(fn, 0.5 * (frame_c + _mean_of(glass)))


def _car_kit(rng) -> dict:
    """Materials all cars of a scene share (tyres, rims, undersides): evaluated once per frame."""
    rim = _Mat(_p_solid(rng, _c_grey(rng, 0.3, 0.7), 0.0))
    return {"dark": _Mat(_p_solid(rng, _c_grey(rng, 0.01, 0.06), 0.0)),
            "tyre": _Mat(_p_solid(rng, _c_grey(rng, 0.02, 0.06), 0.0), faces={3: rim, 2: rim})}


def _car(b: _Builder, rng, x, z, yaw, kit, detail=True):
    with b.assembly():
        _car_parts(b, rng, x, z, yaw, kit, detail)


def _car_parts(b: _Builder, rng, x, z, yaw, kit, detail):
    L = rng.uniform(3.8, 4.9)
    W = rng.uniform(1.65, 1.9)
    kind = rng.random()
    body_h = rng.uniform(0.55, 0.75) if kind < 0.75 else rng.uniform(0.8, 1.1)
    cab_h = rng.uniform(0.42, 0.55) if kind < 0.75 else rng.uniform(0.5, 0.8)
    clear = rng.uniform(0.22, 0.35)
    col = _c_grey(rng, 0.02, 0.9) if rng.random() < 0.65 else _hsv(rng.random(), rng.uniform(0.5, 0.9),
                                                                   rng.uniform(0.2, 0.8))
    paint = _p_solid(rng, col, 0.01)
    g = _hsv(rng.uniform(0.5, 0.65), rng.uniform(0.0, 0.3), rng.uniform(0.03, 0.12))
    g2 = g * rng.uniform(1.5, 3.0)

    def glass(u, v, fp):  # darker towards the bottom: a cheap stand-in for reflections
        return _mix(g, g2, np.minimum(v * (1.0 / cab_h), 1.0))

    _with_mean(glass, 0.5 * (g + g2))
    spec, shin = rng.uniform(0.2, 0.6), rng.uniform(30, 90)
    dark = kit["dark"]
    # local -z (face 4) is the rear, +z (face 5) the front: a car with yaw 0 drives away from the camera
    body = _Mat(paint, spec=spec, shin=shin, faces={
        2: dark, 4: _Mat(_p_car_end(rng, col, W, body_h, True), spec=spec, shin=shin),
        5: _Mat(_p_car_end(rng, col, W, body_h, False), spec=spec, shin=shin)})
    group = (x, z, yaw)
    b.box((0, clear + body_h / 2, 0), (W / 2, body_h / 2, L / 2), _VEHICLE, body, group=group)
    cl = L * rng.uniform(0.45, 0.6) if kind < 0.75 else L * rng.uniform(0.55, 0.8)
    cz = rng.uniform(0.0, 0.12) * L
    m = 0.07
    side = _Mat(_p_glazed(col, glass, m, 0.03, cl - m, cab_h - m, cl * rng.uniform(0.45, 0.55)), spec=0.6, shin=80)
    end = _Mat(_p_glazed(col, glass, m, 0.02, W * 0.9 - m, cab_h - m), spec=0.6, shin=80)
    cab = _Mat(paint, spec=spec, shin=shin, faces={0: side, 1: side, 4: end, 5: end})
    b.box((0, clear + body_h + cab_h / 2, cz), (W * 0.45, cab_h / 2, cl / 2), _VEHICLE, cab, group=group)
    if detail:  # wheels: one cylinder per axle, visible below the body
        wr = rng.uniform(0.3, 0.36)
        tyre = kit["tyre"]
        axle_R = _rot_z(math.pi / 2)
        for sz in (-1, 1):
            b.cyl((0, wr, sz * (L / 2 - 0.8)), wr, W / 2 - 0.02, _VEHICLE, tyre, group=group, R=axle_R, cast=False)


def _species(rng) -> tuple:
    """A tree species: bark and foliage materials, trunk height and crown size ranges (shared by the trees
    of a street, as on real streets)."""
    bark = _Mat(_p_noise(rng, c := _hsv(rng.uniform(0.05, 0.12), rng.uniform(0.15, 0.5), rng.uniform(0.12, 0.4)),
                         c * 0.6, 6.0, 1, 1.2, stretch=0.2))
    return bark, _Mat(_p_foliage(rng)), rng.uniform(1.5, 3.5), rng.uniform(1.0, 2.6)


def _tree(b: _Builder, rng, x, z, species, scale=1.0):
    with b.assembly():
        _tree_parts(b, rng, x, z, species, scale)


def _tree_parts(b: _Builder, rng, x, z, species, scale):
    bark, leaves, trunk, crown = species
    th = trunk * rng.uniform(0.8, 1.2) * scale
    tr = rng.uniform(0.08, 0.2) * scale * crown / 1.8
    b.cyl((x, th / 2, z), tr, th / 2, _VEGETATION, bark)
    cr = crown * rng.uniform(0.8, 1.2) * scale
    n = int(rng.integers(3, 7)) if z < 40 else int(rng.integers(2, 4))  # fewer, bigger blobs far away
    k = 0.7 if z < 40 else 0.85
    cs = [(x + rng.normal(0, cr * 0.45), th + cr * rng.uniform(0.4, 1.4), z + rng.normal(0, cr * 0.45))
          for _ in range(n)]
    b.spheres(cs, rng.uniform(0.5, 1.0, n) * cr * k, _VEGETATION, leaves)


def _outdoor_scene(rng) -> _Scene:
    b = _Builder(rng)
    style = ["urban", "residential", "open"][int(rng.choice(3, p=[0.4, 0.4, 0.2]))]
    lanes = int(rng.integers(1, 3)) if style != "residential" else 1
    lane_w = rng.uniform(2.9, 3.7)
    park = rng.uniform(2.0, 2.5) if (style != "open" and rng.random() < 0.75) else 0.0
    half = lanes * lane_w + park
    sw = rng.uniform(1.5, 4.0) if style != "open" else 0.0
    curb = rng.uniform(0.08, 0.18)
    z_end = rng.uniform(70.0, 250.0)

    # Ground: asphalt with markings; terrain beyond the road / sidewalks.
    asphalt = _hsv(rng.uniform(0.0, 0.7), rng.uniform(0.0, 0.06), rng.uniform(0.18, 0.42))
    paint_w = _c_grey(rng, 0.75, 0.95)
    paint_y = _hsv(0.12, 0.7, 0.85)
    marks = []  # (x centre, width, dash period (0 = solid), dash duty, colour)
    centre_solid = rng.random() < 0.3
    marks.append((0.0, rng.uniform(0.1, 0.2), 0.0 if centre_solid else rng.uniform(6, 12), rng.uniform(0.3, 0.5),
                  paint_y if rng.random() < 0.2 else paint_w))
    for s in (-1, 1):
        for k in range(1, lanes):
            marks.append((s * k * lane_w, 0.12, rng.uniform(6, 12), rng.uniform(0.25, 0.5), paint_w))
        if park > 0 or rng.random() < 0.6:
            marks.append((s * lanes * lane_w, 0.15, 0.0, 1.0, paint_w))
    if rng.random() < 0.3 * (style != "residential"):
        marks = marks[:1] if rng.random() < 0.5 else []
    crosswalk = rng.uniform(8, 40) if rng.random() < 0.25 else None
    terrain_kind = rng.random()
    grass = _p_noise(rng, _hsv(rng.uniform(0.13, 0.28), rng.uniform(0.3, 0.7), rng.uniform(0.15, 0.35)),
                     _hsv(rng.uniform(0.1, 0.25), rng.uniform(0.2, 0.6), rng.uniform(0.3, 0.55)), rng.uniform(0.5, 3), 2,
                     1.2)
    pave = _p_tiles(rng, _c_grey(rng, 0.35, 0.7), _c_grey(rng, 0.2, 0.5), rng.uniform(0.3, 1.0),
                    rng.uniform(0.3, 1.0), 0.01, 0.1)
    terrain = grass if (style != "urban" or terrain_kind < 0.3) else pave
    ox, oz = rng.uniform(0, 256, 2)
    ev = half + sw  # edge of the road + sidewalk
    patchy = rng.uniform(0.0, 0.5)

    def ground(x, z, fp):
        col = np.empty((3, x.shape[0]), _F32)
        ax = np.abs(x)
        out = np.flatnonzero(ax > half)
        if out.size:
            _set_cols(col, out, terrain(x.take(out), z.take(out), fp.take(out)))
        road = np.flatnonzero(ax <= half)
        if road.size == 0:
            return col
        x, z, fp, ax = x.take(road), z.take(road), fp.take(road), ax.take(road)
        n = _vnoise(x * 4.0 + ox, z * 4.0 + oz)
        n = 0.5 + (n - 0.5) * np.minimum(np.maximum(1.5 - 8.0 * fp, 0.0), 1.0)
        n2 = _vnoise(x * 0.25 + oz, z * 0.1 + ox)
        shade = (0.8 + 0.4 * n) * np.where(n2 > 0.6, 1.0 - 0.4 * patchy, 1.0).astype(_F32)
        lanepos = _frac(ax * (1.0 / lane_w))  # tyre tracks: slightly darker bands along the lanes
        shade[(np.abs(lanepos - 0.25) < 0.08) | (np.abs(lanepos - 0.75) < 0.08)] *= 0.94
        rc = asphalt * shade
        for xc, w, period, duty, c in marks:  # only the pixels near each line
            near = np.flatnonzero(np.abs(x - xc) < w / 2 + fp)
            if near.size == 0:
                continue
            fpn = fp[near]
            m = np.minimum(np.maximum(0.5 + (w / 2 - np.abs(x[near] - xc)) / (fpn + 1e-4), 0.0), 1.0)
            if period:
                m *= _square(z[near] + xc, period, duty, fpn)
            m *= 0.6 + 0.4 * n[near]  # worn paint
            old = _cols(rc, near)
            _set_cols(rc, near, old + (c - old) * m)
        if crosswalk is not None:
            near = np.flatnonzero((z > crosswalk) & (z < crosswalk + 3.0))
            if near.size:
                m = _square(x[near], 1.0, 0.5, fp[near]) * (0.6 + 0.4 * n[near])
                old = _cols(rc, near)
                _set_cols(rc, near, old + (paint_w - old) * m)
        _set_cols(col, road, rc)
        return col

    _with_mean(ground, asphalt)

    b.prims.append(_Ground(np.array([_ROAD, _ROAD, _ROAD, _ROAD, _ROAD, _ROAD], np.int8), _Mat(ground)))
    # Ground labels beyond the road are patched in _render via the terrain_x bound.

    z0 = -30.0
    if sw > 0:
        side = _p_tiles(rng, _c_grey(rng, 0.35, 0.75), _c_grey(rng, 0.2, 0.55), rng.uniform(0.3, 1.5),
                        rng.uniform(0.3, 1.5), 0.008, 0.08)
        curb_m = _Mat(_p_solid(rng, _c_grey(rng, 0.4, 0.8), 0.05))
        for s in (-1, 1):
            mat = _Mat(side, faces={0 if s > 0 else 1: curb_m})
            L = z_end + 30.0
            b.box((s * (half + sw / 2), curb / 2, z0 + L / 2), (sw / 2, curb / 2, L / 2), _SIDEWALK, mat, cast=False)

    species = [_species(rng) for _ in range(int(rng.integers(1, 3)))]

    # Buildings.
    for s in (-1, 1):
        z = rng.uniform(-30.0, -5.0)
        setback = rng.uniform(0.0, 0.5) if style == "urban" else rng.uniform(2.5, 10.0) if style == "residential" \
            else rng.uniform(15.0, 60.0)
        while z < z_end:
            if style == "urban":
                blen, hgt, gap_p = rng.uniform(8, 35), rng.uniform(6, 28), 0.15
            elif style == "residential":
                blen, hgt, gap_p = rng.uniform(7, 14), rng.uniform(4, 9), 0.35
            else:
                blen, hgt, gap_p = rng.uniform(8, 30), rng.uniform(4, 12), 0.6
            if rng.random() < gap_p:
                gap = rng.uniform(4, 15)
                if style != "urban" or rng.random() < 0.5:
                    for _ in range(int(gap // 5)):
                        if rng.random() < 0.6:
                            _tree(b, rng, s * (ev + setback + rng.uniform(1, 10)), z + rng.uniform(0, gap), species[0])
                z += gap
                continue
            depth = rng.uniform(8, 20)
            xb = s * (ev + setback + rng.uniform(0, 1.0 if style == "urban" else 3.0))
            wall = _building_wall(rng)
            fac = _Mat(_p_facade(rng, wall, 0.0), spec=0.05)
            roof = _Mat(_p_noise(rng, c := _c_grey(rng, 0.1, 0.5), c * 0.7, 1.0, 2, 0.7))
            mat = _Mat(wall, faces={0: fac, 1: fac, 4: fac, 5: fac, 3: roof})
            b.box((xb + s * depth / 2, hgt / 2, z + blen / 2), (depth / 2, hgt / 2, blen / 2), _BUILDING, mat)
            if style == "residential" and rng.random() < 0.8:  # roof slabs
                rc = _Mat(_p_tiles(rng, _hsv(rng.uniform(0.0, 0.08), rng.uniform(0.2, 0.7), rng.uniform(0.15, 0.5)),
                                   _c_grey(rng, 0.05, 0.2), 0.3, 0.2, 0.01, 0.1, 0.5))
                o = rng.uniform(0.2, 0.6)
                y = hgt
                for k in range(int(rng.integers(1, 4))):
                    th = rng.uniform(0.3, 0.8)
                    shrink = k * rng.uniform(0.8, 1.5)
                    b.box((xb + s * depth / 2, y + th / 2, z + blen / 2),
                          (depth / 2 + o - shrink, th / 2, blen / 2 + o - shrink), _BUILDING, rc)
                    y += th
            if style == "residential":
                if rng.random() < 0.5:  # hedge or fence along the property line
                    xh = s * (ev + rng.uniform(0.2, 0.8))
                    if rng.random() < 0.5:
                        hh = rng.uniform(0.6, 1.6)
                        b.box((xh, hh / 2, z + blen / 2), (0.35, hh / 2, blen / 2 - 0.3), _VEGETATION,
                              _Mat(_p_foliage(rng)))
                    else:
                        hh = rng.uniform(0.8, 1.5)
                        fc = _c_wood(rng) if rng.random() < 0.5 else _c_grey(rng, 0.3, 0.95)
                        b.box((xh, hh / 2, z + blen / 2), (0.03, hh / 2, blen / 2 - 0.3), _FENCE,
                              _Mat(_p_stripes(rng, fc, fc * 0.3, rng.uniform(0.1, 0.25), 0.7, 0.0)))
                if rng.random() < 0.6:
                    _tree(b, rng, s * (ev + setback * rng.uniform(0.3, 0.8)), z + rng.uniform(0, blen), species[-1])
            z += blen + (rng.uniform(0.0, 0.3) if style == "urban" else rng.uniform(2.0, 8.0))
    if style == "urban" and rng.random() < 0.5:  # a building across the end of the street
        wall = _building_wall(rng)
        fac = _Mat(_p_facade(rng, wall, 0.0))
        hgt = rng.uniform(8, 30)
        b.box((rng.uniform(-10, 10), hgt / 2, z_end + 10), (60.0, hgt / 2, 10.0), _BUILDING,
              _Mat(wall, faces={4: fac}))
    if style != "urban" or rng.random() < 0.3:  # distant hills (beyond the valid range)
        hill = _Mat(_p_noise(rng, _hsv(rng.uniform(0.2, 0.35), rng.uniform(0.2, 0.5), rng.uniform(0.15, 0.35)),
                             _hsv(rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.4), rng.uniform(0.25, 0.5)), 0.05, 3, 1.0))
        n = int(rng.integers(1, 4))
        cs, rs = [], []
        for _ in range(n):
            r = rng.uniform(300, 900)
            cs.append((rng.uniform(-500, 500), -r + rng.uniform(8, 40), z_end + rng.uniform(250, 900) + r))
            rs.append(r)
        b.spheres(cs, rs, _TERRAIN, hill, cast=False)

    # Cars: parked along the curbs, and in the lanes.
    kit = _car_kit(rng)
    for s in (-1, 1):
        if park <= 0 or rng.random() < 0.2:
            continue
        z = rng.uniform(1.0, 10.0)
        n = 0
        while z < min(z_end, 75.0) and n < 8:
            x = s * (half - rng.uniform(0.95, 1.2))
            _car(b, rng, x, z + 2.3, rng.normal(0.0, 0.03) + (0.0 if rng.random() < 0.7 else math.pi), kit,
                 detail=z < 30)
            z += rng.uniform(5.0, 6.0) + (rng.uniform(0, 15) if rng.random() < 0.3 else rng.uniform(0.3, 2.0))
            n += 1
    for k in range(lanes):
        for s in (-1, 1):
            if rng.random() < 0.5:
                continue
            z = rng.uniform(8.0, 60.0)
            _car(b, rng, s * (k + 0.5) * lane_w + rng.normal(0, 0.2), z, (0.0 if s > 0 else math.pi) +
                 rng.normal(0, 0.02), kit, detail=z < 30)

    # Poles, street lamps, signs.
    pole_m = _Mat(_p_solid(rng, _c_grey(rng, 0.1, 0.6), 0.03), spec=0.2)
    for s in (-1, 1):
        if rng.random() < 0.25:
            continue
        z = rng.uniform(3, 25)
        spacing = rng.uniform(20, 45)
        xp = s * (half + (rng.uniform(0.3, 0.6) if sw > 0 else rng.uniform(1.0, 3.0)))
        while z < min(z_end, 120.0):
            hp = rng.uniform(5, 9)
            with b.assembly():
                b.cyl((xp, hp / 2, z), rng.uniform(0.07, 0.14), hp / 2, _POLE, pole_m)
                if rng.random() < 0.7:  # lamp arm
                    al = rng.uniform(1.0, 2.5)
                    b.box((xp - s * al / 2, hp - 0.1, z), (al / 2, 0.05, 0.06), _POLE, pole_m)
                    b.box((xp - s * al, hp - 0.15, z), (0.3, 0.08, 0.15), _POLE, pole_m)
            z += spacing
        for _ in range(int(rng.integers(0, 3))):  # signs
            zs = rng.uniform(5, 60)
            hs = rng.uniform(2.0, 3.0)
            b._asm = b._fresh()
            b.cyl((xp, hs / 2, zs), 0.04, hs / 2, _POLE, pole_m)
            sc = [_hsv(0.0, 0.85, 0.75), _hsv(0.6, 0.85, 0.6), _hsv(0.13, 0.9, 0.9), _c_grey(rng, 0.85, 0.95)]
            sign = _Mat(_p_solid(rng, sc[int(rng.integers(0, 4))], 0.02), spec=0.3,
                        decals=[_Decal(0.06, 0.06, 0.54, 0.54, _Mat(_p_poster(rng)))])
            size = rng.uniform(0.4, 0.8)
            b.box((xp, hs + size / 2, zs), (0.02, size / 2, size / 2), _POLE, sign,
                  yaw=rng.uniform(-0.3, 0.3))
            b._asm = None

    # Trees along the road, bushes, pedestrians.
    for s in (-1, 1):
        if rng.random() < (0.5 if style == "urban" else 0.25):
            continue
        z = rng.uniform(0, 15)
        spacing = rng.uniform(10, 22) if style != "open" else rng.uniform(6, 14)
        xt = s * (half + (sw * rng.uniform(0.5, 0.8) if sw > 0 else rng.uniform(1.5, 6.0)))
        sp = species[int(rng.integers(0, len(species)))]
        while z < min(z_end, 75.0):
            _tree(b, rng, xt + rng.normal(0, 0.3 if sw > 0 else 2.0), z, sp, rng.uniform(0.7, 1.3))
            z += spacing * rng.uniform(0.7, 1.3)
    for _ in range(int(rng.integers(0, 6)) if style != "urban" else int(rng.integers(0, 3))):
        s = rng.choice([-1.0, 1.0])
        xb, zb = s * (ev + rng.uniform(0.3, 6.0)), rng.uniform(4, 60)
        n = int(rng.integers(2, 6))
        cs = [(xb + rng.normal(0, 0.6), rng.uniform(0.0, 0.5), zb + rng.normal(0, 1.0)) for _ in range(n)]
        b.spheres(cs, rng.uniform(0.4, 1.0, n), _VEGETATION, _Mat(_p_foliage(rng)))
    for _ in range(int(rng.integers(0, 4)) if sw > 0 else 0):
        s = rng.choice([-1.0, 1.0])
        xpn, zpn = s * (half + rng.uniform(0.5, sw)), rng.uniform(6, 45)
        ht = rng.uniform(1.55, 1.9)
        cloth = _Mat(_p_solid(rng, _c_fabric(rng), 0.05))
        b._asm = b._fresh()
        b.cyl((xpn, ht * 0.25, zpn), 0.14, ht * 0.25, _PERSON, _Mat(_p_solid(rng, _c_fabric(rng), 0.05)))
        b.cyl((xpn, ht * 0.62, zpn), 0.2, ht * 0.13, _PERSON, cloth)
        b.spheres([(xpn, ht - 0.11, zpn)], [0.11], _PERSON,
                  _Mat(_p_solid(rng, _hsv(0.07, rng.uniform(0.2, 0.6), rng.uniform(0.3, 0.85)), 0.02)))
        b._asm = None

    # Camera in a lane (right-hand traffic), looking down the street.
    cam_h = rng.uniform(1.45, 1.85)
    cam_x = (int(rng.integers(0, lanes)) + 0.5) * lane_w + rng.normal(0, 0.25)
    cam = np.array([cam_x, cam_h, 0.0])
    R = _camera_rotation(rng.uniform(-0.12, 0.12), rng.uniform(-0.07, 0.04), rng.normal(0.0, 0.012))

    # Sun, sky, haze.
    overcast = rng.random() < 0.3
    el, az = rng.uniform(0.3, 1.15), rng.uniform(-math.pi, math.pi)
    sun_dir = (math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az))
    sun_c = _hsv(rng.uniform(0.08, 0.13), rng.uniform(0.05, 0.25), 1.0) * (rng.uniform(0.4, 1.0) if overcast
                                                                             else rng.uniform(2.5, 4.0))
    sky_top = _hsv(rng.uniform(0.55, 0.63), rng.uniform(0.0, 0.15) if overcast else rng.uniform(0.3, 0.7),
                   rng.uniform(0.6, 0.95))
    sky_hor = _hsv(rng.uniform(0.55, 0.63), rng.uniform(0.0, 0.2), rng.uniform(0.8, 1.0))
    ambient = (sky_top * 0.5 + sky_hor * 0.5) * (rng.uniform(0.9, 1.5) if overcast else rng.uniform(0.5, 0.9))
    clouds = rng.uniform(0.0, 1.0) if not overcast else rng.uniform(0.6, 1.0)
    cloud_c = _c_grey(rng, 0.75, 1.0)
    sky_gain = rng.uniform(1.3, 2.2)
    cx0, cz0 = rng.uniform(0, 256, 2)

    def sky(dx, dy, dz):
        e = np.clip(dy, 0.0, 1.0)
        col = _mix(sky_hor, sky_top, np.sqrt(e))
        inv = 1.0 / np.maximum(dy, 0.03)
        n = _fbm(dx * inv * 0.7 + cx0, dz * inv * 0.7 + cz0, 4)
        cov = np.clip((n - (1.0 - clouds) * 0.7 - 0.2) * 3.0, 0.0, 1.0) * np.clip(e * 8.0, 0.0, 1.0)
        col = col + (cloud_c * (0.75 + 0.5 * n) - col) * cov
        sd = dx * sun_dir[0] + dy * sun_dir[1] + dz * sun_dir[2]
        glow = np.maximum(sd, 0.0)
        for _ in range(5):  # ** 32
            glow = glow * glow
        glow *= 0.0 if overcast else 2.0
        return col * sky_gain + glow

    return _Scene(
        prims=b.prims, cam_pos=cam, cam_R=R,
        lights=[_Light(sun_c, direction=sun_dir, shadow_blur=1 if not overcast else 4)],
        ambient=ambient, ambient_up=rng.uniform(0.2, 0.5), extent=z_end + 600.0, sky=sky,
        haze_dist=rng.uniform(300.0, 1500.0), haze_color=sky_hor * sky_gain * 0.8, max_depth=OUTDOOR_MAX_DEPTH_M,
        terrain_x=ev, shadow_range=70.0, **_camera_model(rng))


# ---------------------------------------------------------------------------------------------- rendering


def _pair_indices(k: int) -> tuple[np.ndarray, np.ndarray]:
    i, j = np.triu_indices(k, 1)
    return i, j


def _rects(points: np.ndarray, cam_pos, world_to_cam, intr: Intrinsics, H: int, W: int, zmin_out=None) -> np.ndarray:
    """Conservative pixel rectangles (r0, r1, c0, c1) of the convex hulls of `points` (P, K, 3) (world).

    Hull parts behind the near plane are clipped (exactly: the clipped hull's vertices are the front points
    and the near-plane crossings of the segments between front and back points). zmin_out (P,), if given,
    receives each hull's smallest camera z (>= the near plane): no hit on it can be nearer."""
    P, K, _ = points.shape
    pc = (points - cam_pos) @ world_to_cam.T
    z = pc[..., 2]
    front = z > _NEAR
    out = np.zeros((P, 4), np.int64)
    if zmin_out is not None:
        zmin_out[:] = np.maximum(z.min(1), _NEAR)
    any_front = front.any(1)
    if not any_front.any():
        return out
    umin, umax, vmin, vmax = _screen_bounds(pc, front, intr)
    mixed = np.flatnonzero(any_front & ~front.all(1))
    if mixed.size:  # hulls straddling the near plane: add the crossings (hulls wholly in front have none)
        i, j = _pair_indices(K)
        pm, fm = pc[mixed], front[mixed]
        zi, zj = pm[:, i, 2], pm[:, j, 2]
        cross = fm[:, i] ^ fm[:, j]
        lam = np.where(cross, (_NEAR - zi) / np.where(cross, zj - zi, 1.0), 0.0)
        cp = pm[:, i] + lam[..., None] * (pm[:, j] - pm[:, i])
        for b, bc, f in zip((umin, umax, vmin, vmax), _screen_bounds(cp, cross, intr),
                            (np.minimum, np.maximum, np.minimum, np.maximum)):
            b[mixed] = f(b[mixed], bc)
    out[:, 0] = np.clip(np.floor(vmin), 0, H)
    out[:, 1] = np.clip(np.floor(vmax) + 2, 0, H)
    out[:, 2] = np.clip(np.floor(umin), 0, W)
    out[:, 3] = np.clip(np.floor(umax) + 2, 0, W)
    out[~any_front] = 0
    return out


def _screen_bounds(pc: np.ndarray, ok: np.ndarray, intr: Intrinsics) -> tuple:
    """(umin, umax, vmin, vmax) (P,) pixel coordinates of the points pc (P, M, 3) (camera frame) where ok
    (P, M), +-1e9 where none (z is clamped to the near plane)."""
    zz = np.where(ok, np.maximum(pc[..., 2], _NEAR), 1.0)
    u = intr.fx * pc[..., 0] / zz + intr.cx
    v = intr.fy * pc[..., 1] / zz + intr.cy
    big = 1e9
    return (np.where(ok, u, big).min(1), np.where(ok, u, -big).max(1), np.where(ok, v, big).min(1),
            np.where(ok, v, -big).max(1))


@functools.lru_cache(maxsize=16)
def _tone_lut(gamma: float) -> np.ndarray:
    """Linear [0, _LUT_MAX] -> uint8 with a soft highlight shoulder and 1/gamma encoding."""
    x = np.linspace(0.0, _LUT_MAX, _LUT_SIZE)
    y = np.where(x < 0.7, x, 0.7 + 0.3 * (1.0 - np.exp(-(x - 0.7) / 0.3)))
    return np.round(255.0 * np.clip(y, 0, 1) ** (1.0 / gamma)).astype(np.uint8)


_LUT_MAX = 4.0
_LUT_SIZE = 1 << 16


@functools.lru_cache(maxsize=1)
def _noise_bank() -> np.ndarray:
    # Gaussian noise is the slowest part of the camera model; a fixed bank read at a random offset is as
    # good for sensor noise and ~10x cheaper than drawing it per frame.
    return np.random.default_rng(0xB0A7).standard_normal(1 << 21, dtype=_F32)


@functools.lru_cache(maxsize=16)
def _vignette(H: int, W: int) -> np.ndarray:
    yy = (np.arange(H, dtype=_F32) - (H - 1) / 2) / (H / 2)
    xx = (np.arange(W, dtype=_F32) - (W - 1) / 2) / (W / 2)
    return (xx[None, :] ** 2 + yy[:, None] ** 2) * 0.5


def _by_material(prims: list) -> list:
    """The primitives reordered so that those sharing a material are adjacent (stable), so that a material
    is evaluated once for all of them."""
    first: dict[int, int] = {}
    for i, p in enumerate(prims):
        first.setdefault(id(p.mat), i)
    return sorted(prims, key=lambda p: first[id(p.mat)])


class _CameraRays:
    """The camera rays of an H x W image, and per-pixel quantities that the intersection kernels share.

    origin: the camera centre (3 floats, world); d: (3, H, W) float32 world directions whose camera-frame z
    component is 1, so the ray parameter t of a hit is its z-depth. The inverse directions (axis-aligned
    boxes) are computed on first use."""

    def __init__(self, scene: _Scene, H: int, W: int, intr: Intrinsics):
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


def _camera_t(kind: tuple, P, rays: np.ndarray) -> np.ndarray:
    """Ray parameters of camera rays against primitives of one kind.

    kind: from the primitives' `camera_job`; P: its parameters, one float32 array per parameter,
    broadcastable against the per-pixel inputs rays (`_CameraRays.inputs`), (c, ...)."""
    if kind[0] == "box_axis":
        return _slab_t(P[:6], rays[0], rays[1], rays[2], kind[1], _EPS)
    if kind[0] == "box":
        dx, dy, dz = _to_local(P[6:], kind[2], rays[0], rays[1], rays[2])
        return _slab_t(P[:6], 1.0 / dx, 1.0 / dy, 1.0 / dz, kind[1], _EPS)
    if kind[0] == "cyl":
        dx, dy, dz = _to_local(P[7:], kind[1], rays[0], rays[1], rays[2])
        return _cyl_t(P[0], P[1], P[2], P[3], P[4], P[5], (P[6],), dx, dy, dz, _EPS)
    ocx, ocy, ocz, c = P  # sphere
    dx, dy, dz = rays
    return _quadric_t(dx * dx + dy * dy + dz * dz, ocx * dx + ocy * dy + ocz * dz, c, _EPS)


def _shadow_t(kind: tuple, P, ox, oy, oz, dx, dy, dz) -> np.ndarray:
    """Ray parameters (n,) of shadow rays from origins o (n,) along directions d (scalars, or (n,)) against
    primitives of one kind. kind, P: from the primitives' `shadow_jobs` (P: one (n,) float32 array, or
    float, per parameter)."""
    if kind[0] == "sphere":
        cx, cy, cz, rr = P
        ocx, ocy, ocz = ox - cx, oy - cy, oz - cz
        return _quadric_t(dx * dx + dy * dy + dz * dz, ocx * dx + ocy * dy + ocz * dz,
                          ocx * ocx + ocy * ocy + ocz * ocz - rr, 0.0)
    r, mode = P[3:12], kind[1]
    ox, oy, oz = _to_local(r, mode, ox - P[0], oy - P[1], oz - P[2])
    dx, dy, dz = _to_local(r, mode, dx, dy, dz)
    if kind[0] == "box":
        x0, x1, y0, y1, z0, z1 = P[12:18]
        return _slab_t((x0 - ox, x1 - ox, y0 - oy, y1 - oy, z0 - oz, z1 - oz), 1.0 / dx, 1.0 / dy, 1.0 / dz,
                       False, 0.0)
    h, nh, rr = P[12:15]  # cylinder
    return _cyl_t(ox, oy, oz, ox * ox + oz * oz - rr, h, rr, (h - oy, nh - oy), dx, dy, dz, 0.0)


def _ranges(starts, counts) -> np.ndarray:
    """The concatenation of arange(s, s + c) for (s, c) in zip(starts, counts), int64."""
    counts = np.asarray(counts, np.int64)
    before = np.cumsum(counts) - counts
    return np.arange(int(counts.sum())) + np.repeat(np.asarray(starts, np.int64) - before, counts)


def _rect_pixels(rects: np.ndarray, W: int) -> tuple[np.ndarray, np.ndarray]:
    """Flat indices (n,) of the pixels of rectangles (k, 4) (r0, r1, c0, c1; row-major within each, one
    after the other) in an image W pixels wide, and each rectangle's offset into them (k + 1,)."""
    r0, r1, c0, c1 = rects.T
    h, w = r1 - r0, c1 - c0
    run_rect = np.repeat(np.arange(len(rects)), h)  # one run of w pixels per rectangle row
    run_row = r0[run_rect] + _ranges(np.zeros(len(rects), np.int64), h)
    return _ranges(run_row * W + c0[run_rect], w[run_rect]), np.concatenate([[0], np.cumsum(h * w)])


# Parts whose screen rectangle has at most this many pixels are intersected together, one kernel call per
# kind over the concatenated pixels of their rectangles: per-call overhead, not pixels, dominates their cost.
_BATCH_PIXELS = 1024


def _visibility(prims: list, scene: _Scene, rays: _CameraRays, intr: Intrinsics) -> tuple[np.ndarray, np.ndarray]:
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


def _cache_hulls(prims: list) -> None:
    """Computes the hulls (`_Prim.hull`) of all finite boxes and cylinders at once, per rotation mode: the
    same arithmetic as one at a time, without its per-primitive overhead."""
    todo = [p for p in prims if isinstance(p, (_Box, _Cyl)) and not p.infinite and "_hull" not in p.__dict__]
    for rotated in (False, True):
        ps = [p for p in todo if (p.mode != 0) == rotated]
        if not ps:
            continue
        h = _BOX_CORNERS * np.stack([p.local_box() for p in ps])[:, None, :]  # (P, 8, 3) local corners
        if rotated:
            h = h @ np.stack([p.R for p in ps]).transpose(0, 2, 1)
        h = h + np.array([p.c for p in ps])[:, None, :]
        for p, hp in zip(ps, h):
            p._hull = hp


def _render(scene: _Scene, H: int, W: int, intr: Intrinsics, noise_rng) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    prims = _by_material(scene.prims)
    _cache_hulls(prims)
    rays = _CameraRays(scene, H, W, intr)
    ox, oy, oz = rays.origin
    dx, dy, dz = rays.d
    r = [float(x) for x in scene.cam_R.ravel()]  # camera-to-world rotation, row-major (sky rays below)
    zbuf, ids = _visibility(prims, scene, rays, intr)

    # ---- surfaces: normals, albedo, emission, gloss per pixel
    N = H * W
    idf = ids.ravel()
    zf = zbuf.ravel()
    hit = idf >= 0
    tz = np.where(hit, zf, 0.0).astype(_F32)
    dxf, dyf, dzf = dx.ravel(), dy.ravel(), dz.ravel()
    px, py, pz = ox + tz * dxf, oy + tz * dyf, oz + tz * dzf
    # Sort the hit pixels by primitive once: every primitive then works on contiguous slices, and the
    # results are scattered back with one write per quantity.
    order = np.argsort(idf, kind="stable")
    counts = np.bincount(idf.astype(np.int64) + 1, minlength=len(prims) + 1)
    sel = order[counts[0]:]
    counts = counts[1:]  # pixels per primitive
    spx, spy, spz = px.take(sel), py.take(sel), pz.take(sel)  # (take: faster than fancy indexing)
    sfp = tz.take(sel) * (1.0 / min(intr.fx, intr.fy))  # pixel footprint in metres at that depth
    mat_out, normals, hit_labels = _surfaces(prims, counts, spx, spy, spz, sfp)
    alb = np.zeros((3, N), _F32)
    nx, ny, nz = np.zeros(N, _F32), np.zeros(N, _F32), np.zeros(N, _F32)
    emit = np.zeros(N, _F32)
    spec = np.zeros(N, _F32)
    shin = np.ones(N, _F32)
    labels = np.zeros(N, np.int8)
    if sel.size:
        _set_cols(alb, sel, mat_out[0])
        for arr, val in zip((nx, ny, nz, emit, spec, shin, labels), (*normals, *mat_out[1:], hit_labels)):
            arr[sel] = val
    terrain_x = getattr(scene, "terrain_x", None)
    if terrain_x is not None:
        labels[(labels == _ROAD) & (np.abs(px) > terrain_x)] = _TERRAIN

    # ---- lighting
    E = scene.ambient * (1.0 + scene.ambient_up * ny)  # (3, N)
    glossy = np.flatnonzero(spec > 0)
    spec_rgb = np.zeros((3, glossy.size), _F32)
    if glossy.size:
        vx, vy, vz = -dxf[glossy], -dyf[glossy], -dzf[glossy]
        vn = 1.0 / np.sqrt(vx * vx + vy * vy + vz * vz)
        vx, vy, vz = vx * vn, vy * vn, vz * vn
    nx2, ny2, nz2 = nx.reshape(H, W), ny.reshape(H, W), nz.reshape(H, W)
    for light in scene.lights:
        if light.direction is not None:
            lx, ly, lz = (float(c) for c in light.direction)
            ndl = nx * lx + ny * ly + nz * lz
            fall = None
        else:
            lx, ly, lz = light.position[0] - px, light.position[1] - py, light.position[2] - pz
            d2 = lx * lx + ly * ly + lz * lz
            il = 1.0 / np.sqrt(d2)
            lx, ly, lz = lx * il, ly * il, lz * il
            ndl = nx * lx + ny * ly + nz * lz
            fall = 1.0 / (1.0 + d2 * (1.0 / (light.r0 * light.r0)))
        recv = hit & (ndl > 0) & (emit <= 0)
        # Shadow rays for one pixel in each 2x2 block (the mask is then upsampled and softened): a quarter of
        # the work, at the cost of shadow edges resolved to 2 pixels.
        sub = (slice(0, None, 2), slice(0, None, 2))
        lit = _shadows(scene, light, *(np.ascontiguousarray(a.reshape(H, W)[sub]) for a in (recv, px, py, pz)),
                       *(np.ascontiguousarray(a[sub]) for a in (nx2, ny2, nz2)),
                       Intrinsics(intr.fx / 2, intr.fy / 2, intr.cx / 2, intr.cy / 2), (H + 1) // 2, (W + 1) // 2)
        lit = np.repeat(np.repeat(lit, 2, axis=0), 2, axis=1)[:H, :W]
        if light.shadow_blur > 0:  # a box blur: penumbrae, and it hides the stair steps
            k = 2 * light.shadow_blur + 1
            lit = cv2.blur(lit, (k, k), borderType=cv2.BORDER_REPLICATE)
        shade = lit.ravel()
        w = np.maximum(ndl, 0.0) * shade
        if fall is not None:
            w = w * fall
        E += light.color * w
        if glossy.size:
            if np.ndim(lx):
                gx, gy, gz = lx[glossy], ly[glossy], lz[glossy]
            else:
                gx, gy, gz = lx, ly, lz
            hx, hy, hz = gx + vx, gy + vy, gz + vz
            hn = 1.0 / np.sqrt(hx * hx + hy * hy + hz * hz + 1e-12)
            ndh = np.maximum((nx[glossy] * hx + ny[glossy] * hy + nz[glossy] * hz) * hn, 0.0)
            sh = shin[glossy]
            lobe = ndh / (sh - sh * ndh + ndh + 1e-6)  # Schlick's cheap stand-in for ndh ** shininess
            spec_rgb += light.color * (spec[glossy] * lobe * w[glossy])
    lin = alb * (E + emit)
    if glossy.size:
        _set_cols(lin, glossy, _cols(lin, glossy) + spec_rgb)
    if scene.haze_dist > 0:  # aerial perspective (sky pixels are overwritten below)
        f = np.exp(tz * (-1.0 / scene.haze_dist))
        lin *= f
        lin += scene.haze_color * (1.0 - f)
    if scene.sky is not None:
        sky_px = ~hit
        if sky_px.any():  # the sky is smooth: shade it at 1/4 resolution, upsample bilinearly
            hs, ws = -(-H // 4), -(-W // 4)
            xs = ((4.0 * np.arange(ws) + 1.5 - intr.cx) / intr.fx).astype(_F32)
            ys = ((4.0 * np.arange(hs) + 1.5 - intr.cy) / intr.fy).astype(_F32)
            sx = ((r[0] * xs)[None, :] + (r[1] * ys + r[2])[:, None]).ravel()
            sy = ((r[3] * xs)[None, :] + (r[4] * ys + r[5])[:, None]).ravel()
            sz = ((r[6] * xs)[None, :] + (r[7] * ys + r[8])[:, None]).ravel()
            inv = 1.0 / np.sqrt(sx * sx + sy * sy + sz * sz)
            small = scene.sky(sx * inv, sy * inv, sz * inv).reshape(3, hs, ws)
            for c in range(3):
                np.copyto(lin[c], cv2.resize(small[c], (W, H), interpolation=cv2.INTER_LINEAR).ravel(), where=sky_px)

    # ---- camera: blur, exposure + white balance, vignetting, noise, tone curve, 8 bits
    a = scene.blur
    kernel = np.array([a, 1.0 - 2.0 * a, a], _F32)
    img = lin.reshape(3, H, W)
    for c in range(3):
        img[c] = cv2.sepFilter2D(img[c], -1, kernel, kernel, borderType=cv2.BORDER_REPLICATE)
    lum = 0.2126 * float(img[0, ::3, ::3].mean()) + 0.7152 * float(img[1, ::3, ::3].mean()) + \
        0.0722 * float(img[2, ::3, ::3].mean())
    gain = scene.exposure / max(lum, 1e-6)
    img *= 1.0 - scene.vignette * _vignette(H, W)
    img *= (gain * scene.wb)[:, None, None]
    # Signal-dependent noise sqrt(max(img, 0) * shot^2 + read^2) * g, computed in place.
    noise = np.maximum(img, 0.0)
    noise *= scene.noise_shot ** 2
    noise += scene.noise_read ** 2
    np.sqrt(noise, out=noise)
    n = img.size
    bank = _noise_bank()
    negate = False
    if n <= bank.size // 2:
        off = int(noise_rng.integers(0, bank.size - n))
        g = bank[off:off + n].reshape(img.shape)
        negate = noise_rng.random() < 0.5  # img - noise * g is exactly img + noise * (-g)
    else:
        g = noise_rng.standard_normal(img.shape, dtype=_F32)
    noise *= g
    if negate:
        img -= noise
    else:
        img += noise
    img *= _LUT_SIZE / _LUT_MAX
    q = np.clip(img, 0, _LUT_SIZE - 1, out=img).astype(np.int32)
    # planar (3, H, W) -> interleaved (H, W, 3): cv2.merge is ~4x faster than numpy's transposing copy
    rgb = cv2.merge(list(_tone_lut(scene.gamma).take(q)))

    depth = np.where(hit & (zf <= scene.max_depth), zf, 0.0).astype(_F32).reshape(H, W)
    return rgb, depth, labels.reshape(H, W)


def _f32_above(x: np.ndarray) -> np.ndarray:
    """The smallest float32 >= x (float64, elementwise): for float32 a, a >= x <=> a >= it, a < x <=> a < it."""
    y = x.astype(_F32)
    return np.where(y < x, np.nextafter(y, _F32(np.inf)), y)


def _f32_below(x: np.ndarray) -> np.ndarray:
    """The largest float32 <= x (float64, elementwise): for float32 a, a <= x <=> a <= it, a > x <=> a > it."""
    y = x.astype(_F32)
    return np.where(y > x, np.nextafter(y, _F32(-np.inf)), y)


def _shadows(scene: _Scene, light: _Light, recv, px, py, pz, nx, ny, nz, intr, H, W) -> np.ndarray:
    """(H, W) float32: 0 where the light is blocked before reaching the surface point, else 1.

    recv (H, W) bool: the points to test; px.. (H, W) their positions and normals; intr, H, W: the camera
    of this (possibly subsampled) pixel grid.

    A caster can only shadow points inside its shadow volume: the convex hull of its hull points and those
    points pushed away from the light (to below the ground for the sun; by a homothety centred on a point
    light, far enough to leave the scene). Only receivers inside the volume's screen rectangle are tested,
    and then all (receiver, primitive) pairs of a kernel kind in one call."""
    members: dict[int, list] = {}  # one caster per assembly (a car, a tree, a piece of furniture)
    for p in scene.prims:
        if p.cast and not p.infinite:
            members.setdefault(p.asm if p.asm >= 0 else -1 - id(p), []).append(p)
    lit = np.ones((H, W), _F32)
    litf = lit.ravel()  # a view
    pxf, pyf, pzf, nxf, nyf, nzf = (a.ravel() for a in (px, py, pz, nx, ny, nz))
    if not members or not recv.any():
        return lit
    groups = list(members.values())
    flat = [p for g in groups for p in g]
    ph = np.stack([p.hull() for p in flat])  # (P, 8, 3)
    first = np.cumsum([0] + [len(g) for g in groups[:-1]])
    lo = np.minimum.reduceat(ph.min(1), first, axis=0)  # per assembly world AABB
    hi = np.maximum.reduceat(ph.max(1), first, axis=0)
    # assemblies wholly far from the camera cast no shadow (it would be a few pixels)
    keep = np.maximum(lo - scene.cam_pos, scene.cam_pos - hi).max(1) < scene.shadow_range
    if not keep.any():
        return lit
    casters = [g for g, k in zip(groups, keep.tolist()) if k]
    lo, hi = lo[keep], hi[keep]
    hulls = 0.5 * (lo + hi)[:, None, :] + _BOX_CORNERS[None] * (0.5 * (hi - lo))[:, None, :]
    if light.direction is not None:
        L = np.asarray(light.direction)
        s = (hulls[..., 1].max(1) + 0.1) / max(L[1], 0.05)
        far = hulls - s[:, None, None] * L
        dl = tuple(_F32(c) for c in L)
        # Light-space culling: a receiver can only be shadowed by a caster whose projection along L covers
        # it, and which lies towards the light from it.
        e1 = np.cross(L, [0.0, 0.0, 1.0] if abs(L[2]) < 0.9 else [1.0, 0.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(L, e1)
        frame = np.stack([e1, e2, L])  # (3, 3)
        hl = hulls @ frame.T  # (P, 8, 3)
        lo, hi = hl.min(1) - 1e-3, hl.max(1) + 1e-3
        f = [float(x) for x in frame.ravel()]
        qa = px * f[0] + py * f[1] + pz * f[2]
        qb = px * f[3] + py * f[4] + pz * f[5]
        qc = px * f[6] + py * f[7] + pz * f[8]
    else:
        Lp = np.asarray(light.position)
        dist = np.linalg.norm(hulls - Lp, axis=-1).min(1)
        lam = 1.0 + scene.extent / np.maximum(dist, 1e-3)
        far = Lp + lam[:, None, None] * (hulls - Lp)
        inside = np.all((hulls.min(1) < Lp) & (hulls.max(1) > Lp), axis=1)
        # Cone culling: the caster's bounding sphere seen from the light subtends a cone; receivers outside
        # it, or nearer to the light than the caster, cannot be shadowed by it.
        centre = hulls.mean(1)
        rad = np.linalg.norm(hulls - centre[:, None], axis=-1).max(1)
        cd = np.linalg.norm(centre - Lp, axis=-1)
        axis = (centre - Lp) / np.maximum(cd, 1e-9)[:, None]
        cos_half = np.sqrt(np.clip(1.0 - (rad / np.maximum(cd, 1e-9)) ** 2, 0.0, 1.0)) - 1e-4
        ux, uy, uz = px - float(Lp[0]), py - float(Lp[1]), pz - float(Lp[2])
        ud = np.sqrt(ux * ux + uy * uy + uz * uz)
        iu = 1.0 / np.maximum(ud, 1e-9)
        ux, uy, uz = ux * iu, uy * iu, uz * iu
    rects = _rects(np.concatenate([hulls, far], axis=1), scene.cam_pos, scene.cam_R.T, intr, H, W)
    # The culling bounds as float32 numbers that give the same comparisons against float32 arrays (a float64
    # bound would make numpy cast the arrays, twice as slow).
    if light.direction is not None:
        lo, hi_c, hi = _f32_above(lo), _f32_above(hi[:, 2]), _f32_below(hi)
    else:
        cos_half, near = _f32_above(cos_half), _f32_below(cd - rad)
    tests = []  # (caster, flat indices of its candidate receivers)
    for k, p in enumerate(casters):
        r0, r1, c0, c1 = rects[k]
        if r0 >= r1 or c0 >= c1:
            continue
        sl = (slice(r0, r1), slice(c0, c1))
        if light.direction is not None:
            a, b_, c = qa[sl], qb[sl], qc[sl]
            m = recv[sl] & (a >= lo[k, 0]) & (a <= hi[k, 0]) & (b_ >= lo[k, 1]) & (b_ <= hi[k, 1]) & (c < hi_c[k])
        elif inside[k]:
            continue
        elif cd[k] > rad[k]:
            ax_, ay_, az_ = (float(x) for x in axis[k])
            m = recv[sl] & (ux[sl] * ax_ + uy[sl] * ay_ + uz[sl] * az_ >= cos_half[k]) & (ud[sl] > near[k])
        else:
            m = recv[sl]
        rr, cc = np.nonzero(m)
        if rr.size:
            tests.append((p, (rr + r0) * W + (cc + c0)))
    if not tests:
        return lit
    # Shadow-ray origins: the receivers, pushed off their surface along the normal.
    fi = np.concatenate([f for _, f in tests])
    qx, qy, qz = pxf[fi], pyf[fi], pzf[fi]
    off = 2e-3 + 1e-4 * np.abs(qz - float(scene.cam_pos[2]))
    qx = qx + nxf[fi] * off
    qy = qy + nyf[fi] * off
    qz = qz + nzf[fi] * off
    # (receiver, primitive) pairs per kernel kind: ranges of the receivers above, and parameters.
    start = np.cumsum([0] + [f.size for _, f in tests])
    pairs: dict[tuple, list] = {}
    for (group, f), s0 in zip(tests, start.tolist()):
        for prim in group:
            for kind, params in prim.shadow_jobs():
                pairs.setdefault(kind, []).append((s0, f.size, params))
    blocked = np.zeros(fi.size, bool)
    for kind, items in pairs.items():
        s0, n, params = zip(*items)
        idx = _ranges(s0, n)
        P = np.repeat(np.array(params, np.float64).astype(_F32).T, n, axis=1)
        ox, oy, oz = qx[idx], qy[idx], qz[idx]
        if light.direction is not None:
            hit = _shadow_t(kind, P, ox, oy, oz, *dl) < np.inf
        else:
            Lp0, Lp1, Lp2 = (float(c) for c in light.position)
            hit = _shadow_t(kind, P, ox, oy, oz, Lp0 - ox, Lp1 - oy, Lp2 - oz) < 1.0
        blocked[idx[hit]] = True
    litf[fi[blocked]] = 0.0
    return lit
