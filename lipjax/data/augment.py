"""Training-time augmentation of a batch: zoomed crop, flip, texture, light, photometric jitter, blur, noise, outliers.

    batch = augment_batch(batch, Augment(...), seed, step, first_example)

Every random draw comes from `example_rng(seed, f"augment/{step}/{i}")` with i the example's index in the global
batch, so an augmented batch is a pure function of (seed, step) whatever the process split (resumable runs).

What each part is for (real sensors and real frames differ from the synthetic renders in these ways):
- zoomed crop: a crop window of (ch / s, cw / s) pixels resized to (ch, cw), s drawn log-uniformly in `zoom`,
  so the prox sees objects at several pixel sizes and samples at several densities (frames larger or smaller
  than the training renders, e.g. full-size KITTI or Middlebury). RGB is resized with area / bilinear
  interpolation, ground truth by nearest neighbour (depths are never averaged across edges), and every sparse
  sample moves to the pixel of the new grid it falls in, the nearest depth winning where several meet.
- quarter turn: with probability `quarter_turn_prob` the whole frame is turned by 90 degrees, either way, before the
  crop (a phone or a robot camera held in portrait; the renders are all upright, and a prox that learned "floor at the
  bottom" costs on portrait frames: 0.775 -> 0.872x linear on rooms turned at test time, research/README.md,
  far_views).
  Only frames whose turned size still holds the crop are turned (a 256x320 render with 128x160 crops; not a 128x416
  street with 128x208 crops, which would have to zoom);
- horizontal flip (geometry stays valid for a pinhole camera; the scenes have no left/right bias);
- photometric jitter: brightness, contrast and saturation factors in [1 - a, 1 + a] and gamma in
  [1 / (1 + g), 1 + g] (camera exposure, white balance, tone curves);
- Gaussian blur with probability `blur_prob`, sigma up to `blur_sigma_px` pixels (defocus, motion);
- camera noise: per-pixel Gaussian noise of standard deviation up to `sensor_noise` (fraction of full scale),
  then with probability `jpeg_prob` a JPEG round trip at quality 30-95 (`camera_noise`): photographs carry shot
  noise and compression blocks, the renders are clean, so a prox trained on clean renders reads every small
  colour step as structure;
- sensor noise: every sample's depth times (1 + n), n ~ N(0, depth_noise) (LiDAR range noise is roughly
  proportional to range at these scales);
- outliers: a fraction of the samples pushed behind their true depth by a factor in [1.1, 3] (the LiDAR and the
  camera see an edge from different viewpoints, so some returns come from the background: "bleed-through");
- texture: with probability `texture_prob`, procedural patterns painted on 1 to `texture_patches` random rectangles
  of the RGB and nowhere in the depth (`paint_texture`): real surfaces carry print, grain and clutter that the
  renders' flat materials lack, so a prox trained on renders alone learns that every colour edge is a depth edge
  and, on real frames (e.g. Middlebury's shelves), invents depth steps at texture. Photographs have 2-3x the
  renders' colour edges (research/edge_statistics.py: 0.24 of NYU's pixels against 0.09 of the rendered rooms');
  one patch raises the rooms to 0.13, three to 0.23, six to 0.34.
- illumination: with probability `illumination_prob`, the RGB times a smooth random gain field exp(a f), f in
  [-1, 1], a in [0, illumination_strength] (`relight`): a photograph's brightness varies smoothly with its lights
  (a lamp's falloff on a wall, a window, a shadow's penumbra) without any change of depth, while the renders'
  shading follows their geometry. (It was added because the photograph costs RMSE on flat ground in the shared
  real frames, research/failure_look.py; relighting renders at inference then changed lip-any's error by 0.3 %,
  so smooth light is not that cost's cause: research/README.md. It stays as robustness to lighting.)
Ground truth is only cropped, zoomed and flipped: the model learns to undo the noise and the outliers.
"""
from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from lipjax.data.frame import Batch
from lipjax.data.sampling import example_rng

OUTLIER_FACTOR = (1.1, 3.0)  # depth multipliers of a bleed-through outlier


@dataclasses.dataclass(frozen=True)
class Augment:
    """Augmentation settings (dimensionless unless named). The defaults change nothing but the crop position."""

    zoom: tuple[float, float] = (1.0, 1.0)
    quarter_turn_prob: float = 0.0
    hflip: bool = False
    brightness: float = 0.0
    contrast: float = 0.0
    saturation: float = 0.0
    gamma: float = 0.0
    blur_prob: float = 0.0
    blur_sigma_px: float = 1.5
    depth_noise: float = 0.0
    outlier_fraction: float = 0.0
    texture_prob: float = 0.0
    texture_strength: float = 0.4
    texture_patches: int = 1
    sensor_noise: float = 0.0
    jpeg_prob: float = 0.0
    illumination_prob: float = 0.0
    illumination_strength: float = 0.7

    def __post_init__(self):
        lo, hi = self.zoom
        if not 0 < lo <= hi:
            raise ValueError(f"zoom must be (min, max) with 0 < min <= max, got {self.zoom}")
        for name in ("brightness", "contrast", "saturation"):
            if not 0 <= getattr(self, name) < 1:
                raise ValueError(f"{name} must be in [0, 1), got {getattr(self, name)}")
        if not all(0 <= p <= 1 for p in (self.blur_prob, self.outlier_fraction, self.texture_prob,
                                         self.quarter_turn_prob)):
            raise ValueError("blur_prob, outlier_fraction, texture_prob and quarter_turn_prob are probabilities in "
                             "[0, 1]")
        if not (0 <= self.sensor_noise < 1 and 0 <= self.jpeg_prob <= 1):
            raise ValueError("sensor_noise must be in [0, 1) and jpeg_prob in [0, 1]")
        if not (0 <= self.illumination_prob <= 1 and self.illumination_strength >= 0):
            raise ValueError("illumination_prob must be in [0, 1] and illumination_strength >= 0")
        if not (isinstance(self.texture_patches, int) and self.texture_patches >= 1):
            raise ValueError(f"texture_patches must be an int >= 1, got {self.texture_patches!r}")
        if not 0 <= self.texture_strength < 1:
            raise ValueError(f"texture_strength must be in [0, 1), got {self.texture_strength}")
        if self.gamma < 0 or self.depth_noise < 0 or self.blur_sigma_px <= 0:
            raise ValueError("gamma and depth_noise must be >= 0 and blur_sigma_px > 0")


# The settings lip-any, the fast prox on streets and `lipjax adapt` train with. Sample noise and outliers are off: a
# run of the fast prox on rooms with depth_noise=0.005 and outlier_fraction=0.01 (and learning rate 1e-3) did not
# improve on its linear start in 1,000 steps (val RMSE 0.2143 m at steps 500 and 1000, linear 0.2153); with them
# off (and 5e-4) it went on to 0.2086 at 1,500. The two changes were made together, so which one mattered is not
# known (the lip-fast-indoor recipe of 2026-11, `git log -p -- experiments/configs/fast.py`).
DEFAULT_TRAINING = Augment(zoom=(0.75, 1.33), hflip=True, brightness=0.2, contrast=0.2, saturation=0.2, gamma=0.2,
                           blur_prob=0.2)


def move_samples(sparse: np.ndarray, top: float, left: float, scale: float, shape: tuple[int, int]) -> np.ndarray:
    """Sparse depth (H, W) metres -> the window's samples on a (h, w) grid scaled by `scale` (new px per old px).

    A sample at pixel centre (r + 0.5, c + 0.5) lands in the new pixel floor((r + 0.5 - top) * scale), likewise
    for columns; samples outside the grid are dropped; where several land in one pixel the nearest wins.
    """
    h, w = shape
    rows, cols = np.nonzero(sparse > 0)
    nr = np.floor((rows + 0.5 - top) * scale).astype(np.int64)
    nc = np.floor((cols + 0.5 - left) * scale).astype(np.int64)
    keep = (nr >= 0) & (nr < h) & (nc >= 0) & (nc < w)
    depth = sparse[rows[keep], cols[keep]]
    out = np.full((h, w), np.inf, np.float32)
    np.minimum.at(out, (nr[keep], nc[keep]), depth)
    return np.where(np.isfinite(out), out, 0.0).astype(np.float32)


def _zoomed_crop(rgb, sparse, gt, valid, crop: tuple[int, int], scale: float, rng: np.random.Generator):
    ch, cw = crop
    h, w = gt.shape
    scale = max(scale, ch / h, cw / w)  # the window (ch / scale, cw / scale) must fit in the frame
    top = int(rng.integers(0, int(np.floor(h - ch / scale)) + 1))
    left = int(rng.integers(0, int(np.floor(w - cw / scale)) + 1))
    if scale == 1.0:
        window = (slice(top, top + ch), slice(left, left + cw))
        return rgb[window], sparse[window], gt[window], valid[window]
    # new pixel centre (x + 0.5) sits at old coordinate (x + 0.5) / scale + left, i.e. pixel (x + 0.5) / scale
    # + left - 0.5 in OpenCV's pixel-centre convention; bilinear for RGB (zoom within 0.75-1.33: little aliasing)
    m = np.array([[1 / scale, 0, left + 0.5 / scale - 0.5], [0, 1 / scale, top + 0.5 / scale - 0.5]])
    warp = cv2.WARP_INVERSE_MAP
    new_rgb = cv2.warpAffine(rgb, m, (cw, ch), flags=cv2.INTER_LINEAR | warp, borderMode=cv2.BORDER_REFLECT)
    new_gt = cv2.warpAffine(gt, m, (cw, ch), flags=cv2.INTER_NEAREST | warp, borderValue=0)
    new_valid = cv2.warpAffine(valid.astype(np.uint8), m, (cw, ch), flags=cv2.INTER_NEAREST | warp, borderValue=0)
    return new_rgb, move_samples(sparse, top, left, scale, crop), new_gt, new_valid.astype(bool)


def photometric(rgb: np.ndarray, aug: Augment, rng: np.random.Generator) -> np.ndarray:
    """(H, W, 3) uint8 -> uint8 with random brightness, contrast, saturation and gamma (see the module doc)."""
    x = rgb.astype(np.float32) / 255.0
    x = x * rng.uniform(1 - aug.brightness, 1 + aug.brightness)
    mean = x.mean()
    x = (x - mean) * rng.uniform(1 - aug.contrast, 1 + aug.contrast) + mean
    grey = x.mean(axis=-1, keepdims=True)
    x = (x - grey) * rng.uniform(1 - aug.saturation, 1 + aug.saturation) + grey
    x = np.clip(x, 0.0, 1.0) ** np.exp(rng.uniform(-1, 1) * np.log1p(aug.gamma))
    return np.round(x * 255.0).astype(np.uint8)


TEXTURE_PERIOD_PX = (3.0, 40.0)  # wavelength range of the painted stripes and blotches, pixels


def paint_texture(rgb: np.ndarray, strength: float, rng: np.random.Generator) -> np.ndarray:
    """(H, W, 3) uint8 -> uint8 with a pattern p in [-1, 1] multiplied in, rgb * (1 + a p), a in [0, strength],
    on a random rectangle (a quarter to all of each side). The pattern is, with equal odds, stripes (a sinusoid
    of random direction, period and phase, optionally squared off like print), or blotches (uniform noise on a
    coarse grid, bicubically enlarged: grain, marble, foliage); grey or per-channel."""
    h, w = rgb.shape[:2]
    rh, rw = (int(rng.integers(max(1, n // 4), n + 1)) for n in (h, w))
    top, left = int(rng.integers(0, h - rh + 1)), int(rng.integers(0, w - rw + 1))
    period = float(np.exp(rng.uniform(*np.log(TEXTURE_PERIOD_PX))))
    channels = 3 if rng.random() < 0.5 else 1
    if rng.random() < 0.5:
        theta, phase = rng.uniform(0, np.pi, channels), rng.uniform(0, 2 * np.pi, channels)
        y, x = np.mgrid[0:rh, 0:rw].astype(np.float32)
        along = x[..., None] * np.cos(theta) + y[..., None] * np.sin(theta)
        pattern = np.sin(2 * np.pi * along / period + phase)
        if rng.random() < 0.5:
            pattern = np.sign(pattern)
    else:
        grid = rng.uniform(-1, 1, (max(2, int(rh / period) + 2), max(2, int(rw / period) + 2), channels))
        pattern = cv2.resize(grid.astype(np.float32), (rw, rh), interpolation=cv2.INTER_CUBIC).reshape(rh, rw, -1)
    factor = 1.0 + rng.uniform(0, strength) * np.clip(pattern, -1.0, 1.0)
    out = rgb.astype(np.float32)
    out[top:top + rh, left:left + rw] *= factor
    return np.clip(np.round(out), 0, 255).astype(np.uint8)


ILLUMINATION_GRID = (2, 5)  # cells per side of the coarse random grid behind a gain field's blobs


def relight(rgb: np.ndarray, strength: float, rng: np.random.Generator) -> np.ndarray:
    """(H, W, 3) uint8 -> uint8 times a smooth gain exp(a f), a ~ U(0, strength), the same for the three channels.

    f = (r + b) / max|r + b|: r a linear ramp of random direction across the frame, b uniform noise on a coarse
    grid of ILLUMINATION_GRID cells per side, bicubically enlarged (light falloff, a window, a soft shadow).
    f has no edges, so no colour edge is added, and depth is untouched."""
    h, w = rgb.shape[:2]
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    theta = rng.uniform(0, 2 * np.pi)
    ramp = (x / max(w - 1, 1) - 0.5) * np.cos(theta) + (y / max(h - 1, 1) - 0.5) * np.sin(theta)
    cells = rng.integers(ILLUMINATION_GRID[0], ILLUMINATION_GRID[1] + 1, 2)
    blobs = cv2.resize(rng.uniform(-1, 1, tuple(cells)).astype(np.float32), (w, h), interpolation=cv2.INTER_CUBIC)
    field = ramp * rng.uniform(0, 2) + blobs
    field = field / max(float(np.abs(field).max()), 1e-6)
    gain = np.exp(rng.uniform(0, strength) * field)[..., None]
    return np.clip(np.round(rgb.astype(np.float32) * gain), 0, 255).astype(np.uint8)


JPEG_QUALITY = (30, 95)  # range of the JPEG round trip's quality setting


def camera_noise(rgb: np.ndarray, aug: Augment, rng: np.random.Generator) -> np.ndarray:
    """(H, W, 3) uint8 -> uint8 with Gaussian noise of std U(0, sensor_noise) * 255 and, with probability
    jpeg_prob, a JPEG encode-decode at a quality drawn in JPEG_QUALITY."""
    out = rgb
    if aug.sensor_noise:
        sigma = rng.uniform(0, aug.sensor_noise) * 255.0
        noisy = rgb.astype(np.float32) + sigma * rng.standard_normal(rgb.shape).astype(np.float32)
        out = np.clip(np.round(noisy), 0, 255).astype(np.uint8)
    if aug.jpeg_prob and rng.random() < aug.jpeg_prob:
        quality = int(rng.integers(JPEG_QUALITY[0], JPEG_QUALITY[1] + 1))
        ok, code = cv2.imencode(".jpg", np.ascontiguousarray(out), [cv2.IMWRITE_JPEG_QUALITY, quality])
        out = cv2.imdecode(code, cv2.IMREAD_UNCHANGED).reshape(rgb.shape) if ok else out
    return out


def perturb_samples(sparse: np.ndarray, aug: Augment, rng: np.random.Generator) -> np.ndarray:
    """Sensor noise and bleed-through outliers on the samples of (H, W) sparse depth in metres (0 stays 0)."""
    out = sparse.copy()
    idx = np.flatnonzero(out > 0)
    flat = out.reshape(-1)
    if aug.depth_noise > 0:
        flat[idx] *= np.maximum(1.0 + aug.depth_noise * rng.standard_normal(idx.size), 0.5).astype(np.float32)
    if aug.outlier_fraction > 0 and idx.size:
        bad = idx[rng.random(idx.size) < aug.outlier_fraction]
        flat[bad] *= rng.uniform(*OUTLIER_FACTOR, bad.size).astype(np.float32)
    return out


def augment_example(rgb, sparse, gt, valid, crop, aug: Augment, rng: np.random.Generator):
    """One example's (rgb, sparse, gt, valid) -> augmented and cropped to `crop` (None: the full frame)."""
    if aug.quarter_turn_prob and rng.random() < aug.quarter_turn_prob:
        turns = int(rng.choice((1, 3)))
        h, w = gt.shape
        if crop is None or (w >= crop[0] and h >= crop[1]):  # the turned frame holds the crop
            rgb, sparse, gt, valid = (np.rot90(a, turns) for a in (rgb, sparse, gt, valid))
    lo, hi = aug.zoom
    scale = float(np.exp(rng.uniform(np.log(lo), np.log(hi))))
    crop = crop or gt.shape
    rgb, sparse, gt, valid = _zoomed_crop(rgb, sparse, gt, valid, crop, scale, rng)
    if aug.hflip and rng.random() < 0.5:
        rgb, sparse, gt, valid = (a[:, ::-1] for a in (rgb, sparse, gt, valid))
    if aug.texture_prob and rng.random() < aug.texture_prob:  # on the surfaces, before the camera's effects
        patches = int(rng.integers(1, aug.texture_patches + 1)) if aug.texture_patches > 1 else 1
        for _ in range(patches):
            rgb = paint_texture(np.ascontiguousarray(rgb), aug.texture_strength, rng)
    if aug.illumination_prob and rng.random() < aug.illumination_prob:  # the scene's light, before the camera
        rgb = relight(np.ascontiguousarray(rgb), aug.illumination_strength, rng)
    if aug.brightness or aug.contrast or aug.saturation or aug.gamma:
        rgb = photometric(rgb, aug, rng)
    if aug.blur_prob and rng.random() < aug.blur_prob:
        rgb = cv2.GaussianBlur(np.ascontiguousarray(rgb), (0, 0), rng.uniform(0.3, aug.blur_sigma_px))
    if aug.sensor_noise or aug.jpeg_prob:
        rgb = camera_noise(np.ascontiguousarray(rgb), aug, rng)
    if aug.depth_noise or aug.outlier_fraction:
        sparse = perturb_samples(sparse, aug, rng)
    return tuple(np.ascontiguousarray(a) for a in (rgb, sparse, gt, valid))


def augment_batch(batch: Batch, aug: Augment, crop: tuple[int, int] | None, seed: int, step: int,
                  first_example: int = 0) -> Batch:
    """Augments and crops every example of a batch (see the module docstring); keyed by (seed, step, example)."""
    examples = [augment_example(batch.rgb[i], batch.sparse[i], batch.gt[i], batch.gt_valid[i], crop, aug,
                                example_rng(seed, f"augment/{step}/{first_example + i}"))
                for i in range(len(batch.gt))]
    rgb, sparse, gt, valid = (np.stack(a) for a in zip(*examples))
    return Batch(rgb=rgb, sparse=sparse, gt=gt, gt_valid=valid)
