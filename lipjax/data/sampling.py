"""Sparse depth samplers: which ground-truth pixels become the sparse input y (mask m = y > 0).

Every sampler is a frozen dataclass called as `sampler(frame, seed=0) -> (H, W) float32` sparse depth in
metres, 0 = no sample. Randomness comes only from `example_rng(seed, frame.id)`, a numpy Generator seeded
with sha256(f"{seed}/{frame.id}"): an example gets the same points in every run, process and data order,
and "200 points" means the same 200 points at training, validation and test time.

Samplers:
  UniformSampler(n)     exactly n valid pixels, uniformly without replacement.
  BernoulliSampler(n)   each valid pixel kept with probability n / #valid (Ma & Karaman 2018).
  LidarSampler(...)     the scan pattern of a spinning multi-beam LiDAR (presets hdl64, hdl32, vlp32, vlp16).
  KeypointSampler(n)    up to n valid pixels at image corners (a structure-from-motion / visual SLAM map).
  HolesSampler(f)       every valid pixel but occlusion edges and blobs covering f of the frame (stereo, ToF).
  Noisy(sampler, noise) any sampler followed by a Noise model.
  Parallax(sampler, min_m, max_m)
                        any sampler measuring from a sensor min_m-max_m metres off the camera (returns seen
                        through edges, shadowed surfaces: lipjax.data.parallax).

`sampler_from_spec("uniform:200")` builds one from a string (CLIs, configs); grammar in its docstring.
"""
from __future__ import annotations

import dataclasses
import hashlib
import math
from typing import Protocol

import cv2
import numpy as np

from lipjax.data import parallax
from lipjax.data.frame import Frame
from lipjax.zbuffer import nearest_per_cell

DEFAULT_SAMPLER = "uniform:200"  # the sparse input where the data have none of their own (the paper's Table I)
OWN_INPUT = "input"  # "input" / "input:N": a data set's own sparse input, not a sampler here (lipjax.data.sources)

# A noisy sample must stay > 0: 0 means "no sample" and would silently drop the point.
MIN_SPARSE_DEPTH_M = 1e-3


class SparseSampler(Protocol):
    """What every sampler is: called with a Frame (its depth (H, W) float32 metres and validity mask) and a seed,
    it returns the sparse input, (H, W) float32 metres with 0 = no sample; the same (seed, frame.id) always gives
    the same samples (`example_rng`)."""

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray: ...


def example_rng(seed: int, frame_id: str, stream: str = "") -> np.random.Generator:
    """numpy Generator keyed by sha256(f"{seed}/{frame_id}") (plus f"/{stream}" for an independent stream)."""
    key = f"{seed}/{frame_id}" + (f"/{stream}" if stream else "")
    digest = hashlib.sha256(key.encode("utf-8")).digest()
    return np.random.Generator(np.random.PCG64(int.from_bytes(digest[:16], "little")))


def subsample_exact(depth: np.ndarray, num_points: int, rng: np.random.Generator) -> np.ndarray:
    """Keeps exactly min(num_points, #measured) of the measured (> 0) pixels of `depth`, uniformly.

    Args:
      depth: (H, W) depth in metres, 0 = no measurement (a GT map, or a real LiDAR image).
    Returns:
      (H, W) float32, the kept pixels' depth and 0 elsewhere. When fewer than num_points pixels are measured,
      all of them are kept (there is nothing else to give).
    """
    if num_points < 0:
        raise ValueError(f"num_points must be >= 0, got {num_points}")
    flat = np.asarray(depth, dtype=np.float32).reshape(-1)
    candidates = np.flatnonzero(flat > 0)
    if candidates.size > num_points:
        candidates = candidates[rng.choice(candidates.size, size=num_points, replace=False)]
    out = np.zeros_like(flat)
    out[candidates] = flat[candidates]
    return out.reshape(np.shape(depth))


@dataclasses.dataclass(frozen=True)
class UniformSampler:
    """Exactly `num_points` valid ground-truth pixels, uniformly without replacement (all valid pixels when
    there are fewer than num_points)."""

    num_points: int

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        return subsample_exact(np.where(frame.valid, frame.depth, 0), self.num_points, example_rng(seed, frame.id))


@dataclasses.dataclass(frozen=True)
class BernoulliSampler:
    """Each valid pixel kept independently with probability num_points / #valid (Ma & Karaman 2018's protocol):
    num_points only on average."""

    num_points: int

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        valid = frame.valid & (frame.depth > 0)
        n_valid = int(valid.sum())
        prob = min(1.0, self.num_points / n_valid) if n_valid else 0.0
        keep = valid & (example_rng(seed, frame.id).random(frame.shape) < prob)
        return np.where(keep, frame.depth, 0).astype(np.float32)


KEYPOINT_QUALITY = (1e-3, 5e-2)  # range of the corner threshold, relative to the frame's strongest corner
KEYPOINT_MIN_DISTANCE_PX = 3.0


@dataclasses.dataclass(frozen=True)
class KeypointSampler:
    """Up to `num_points` valid pixels at image corners, as a structure-from-motion or visual-SLAM map gives them:
    clustered on texture and outlines, none on plain surfaces.

    Shi-Tomasi corners of the grey image (cv2.goodFeaturesToTrack), strongest first, at least
    KEYPOINT_MIN_DISTANCE_PX apart, on valid pixels only; the threshold (a fraction of the strongest corner's
    response) is drawn log-uniformly in KEYPOINT_QUALITY per example. A frame with few corners gives few points.
    """

    num_points: int

    def __post_init__(self):
        if self.num_points < 0:
            raise ValueError(f"num_points must be >= 0, got {self.num_points}")

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        rng = example_rng(seed, frame.id)
        quality = float(np.exp(rng.uniform(*np.log(KEYPOINT_QUALITY))))
        valid = frame.valid & (frame.depth > 0)
        grey = cv2.cvtColor(np.ascontiguousarray(frame.rgb), cv2.COLOR_RGB2GRAY)
        corners = cv2.goodFeaturesToTrack(grey, maxCorners=self.num_points, qualityLevel=quality,
                                          minDistance=KEYPOINT_MIN_DISTANCE_PX, mask=valid.astype(np.uint8))
        out = np.zeros(frame.shape, np.float32)
        if corners is not None and self.num_points > 0:  # maxCorners=0 means no limit to OpenCV
            cols, rows = np.round(corners.reshape(-1, 2)).astype(np.int64).T  # whole pixels, inside the mask
            out[rows, cols] = frame.depth[rows, cols]
        return out


HOLE_EDGE = 0.05  # log-depth step between neighbours that makes an occlusion edge (5 %)
HOLE_BLOB_CELLS = (4, 12)  # cells along the longer side of the coarse random field whose low values become holes


@dataclasses.dataclass(frozen=True)
class HolesSampler:
    """Dense depth with holes, as a stereo or time-of-flight camera gives it: every valid pixel except

    - both sides of every occlusion edge (|log D(p) - log D(q)| > HOLE_EDGE for 4-neighbours p, q): stereo finds
      no match where one view is occluded and a ToF pixel mixes the two depths;
    - blobs over a fraction `fraction` of the frame (low texture, dark or specular surfaces, out of range): a
      smooth random field, uniform noise on a coarse grid of square cells (HOLE_BLOB_CELLS along the longer
      side) bicubically enlarged, is below its `fraction` quantile there.
    """

    fraction: float

    def __post_init__(self):
        if not 0 <= self.fraction < 1:
            raise ValueError(f"holes fraction must be in [0, 1), got {self.fraction}")

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        rng = example_rng(seed, frame.id)
        h, w = frame.shape
        valid = frame.valid & (frame.depth > 0)
        log_d = np.log(np.where(valid, frame.depth, 1.0))
        edge_y = valid[:-1] & valid[1:] & (np.abs(np.diff(log_d, axis=0)) > HOLE_EDGE)
        edge_x = valid[:, :-1] & valid[:, 1:] & (np.abs(np.diff(log_d, axis=1)) > HOLE_EDGE)
        keep = valid.copy()
        keep[:-1] &= ~edge_y
        keep[1:] &= ~edge_y
        keep[:, :-1] &= ~edge_x
        keep[:, 1:] &= ~edge_x
        if self.fraction > 0:
            n = int(rng.integers(HOLE_BLOB_CELLS[0], HOLE_BLOB_CELLS[1] + 1))  # along the longer side
            cells = (max(2, round(n * h / max(h, w))), max(2, round(n * w / max(h, w))))
            field = cv2.resize(rng.uniform(0, 1, cells).astype(np.float32), (w, h),
                               interpolation=cv2.INTER_CUBIC)
            keep &= field >= np.quantile(field, self.fraction)
        return np.where(keep, frame.depth, 0).astype(np.float32)


@dataclasses.dataclass(frozen=True)
class LidarSampler:
    """A spinning multi-beam LiDAR's pattern, simulated on the valid ground truth.

    Every valid pixel is back-projected with the intrinsics (camera frame: x right, y down, z forward, metres),
    moved into the LiDAR frame, and given an elevation (angle above the LiDAR's horizontal plane) and an
    azimuth (about its vertical axis). Elevation is quantised to the nearest beam, azimuth to multiples of
    azimuth_step_deg; each (beam, azimuth) cell keeps the one pixel nearest (in angle) to the cell centre,
    i.e. the pixel the ray would hit; a cell whose ray misses every valid pixel (it leaves the image, or lands
    on invalid ground truth) keeps none. The result: one scan line per beam that falls in the camera's view,
    with about (horizontal FOV / azimuth_step_deg) points per line.

    The beams start from the camera-visible pixels only; wrap the sampler in `Parallax` for the returns seen
    through edges and the surfaces shadowed by the camera-LiDAR baseline.

    Attributes:
      beams: number of lasers.
      vertical_fov_deg: (lowest, highest) beam elevation, degrees; beams equally spaced in between (the real
        HDL-64E / VLP-32C spacings are not uniform: an approximation).
      azimuth_step_deg: horizontal angular resolution (0.08 - 0.4 deg, depends on the spin rate).
      max_range_m: returns farther than this are dropped.
      mount_height_m: LiDAR origin above the camera centre (metres).
      mount_forward_m: LiDAR origin ahead of the camera centre (negative: behind).
      mount_pitch_deg: LiDAR tilt about the camera x axis, positive = tilted up.
      dropout: fraction of returns lost at random (dark / specular surfaces), drawn from example_rng.
    """

    beams: int
    vertical_fov_deg: tuple[float, float]
    azimuth_step_deg: float = 0.2
    max_range_m: float = 120.0
    mount_height_m: float = 0.0
    mount_forward_m: float = 0.0
    mount_pitch_deg: float = 0.0
    dropout: float = 0.0

    # KITTI rig: Velodyne 1.73 m above ground, cameras 1.65 m, Velodyne 0.27 m behind the cameras.
    KITTI_MOUNT = {"mount_height_m": 0.08, "mount_forward_m": -0.27, "mount_pitch_deg": 0.0}

    @classmethod
    def hdl64(cls, **overrides) -> "LidarSampler":
        """Velodyne HDL-64E (KITTI): 64 beams, +2.0 .. -24.8 deg, 0.17 deg at 10 Hz, KITTI mounting."""
        return cls(**{"beams": 64, "vertical_fov_deg": (-24.8, 2.0), "azimuth_step_deg": 0.17,
                      "max_range_m": 120.0, **cls.KITTI_MOUNT, **overrides})

    @classmethod
    def hdl32(cls, **overrides) -> "LidarSampler":
        """Velodyne HDL-32E: 32 beams, +10.67 .. -30.67 deg, 0.16 deg at 10 Hz, KITTI-like mounting."""
        return cls(**{"beams": 32, "vertical_fov_deg": (-30.67, 10.67), "azimuth_step_deg": 0.16,
                      "max_range_m": 100.0, **cls.KITTI_MOUNT, **overrides})

    @classmethod
    def vlp32(cls, **overrides) -> "LidarSampler":
        """Velodyne VLP-32C: 32 beams, +15 .. -25 deg, 0.2 deg at 10 Hz, KITTI-like mounting."""
        return cls(**{"beams": 32, "vertical_fov_deg": (-25.0, 15.0), "azimuth_step_deg": 0.2,
                      "max_range_m": 200.0, **cls.KITTI_MOUNT, **overrides})

    @classmethod
    def vlp16(cls, **overrides) -> "LidarSampler":
        """Velodyne VLP-16 (Puck): 16 beams, +15 .. -15 deg (2 deg apart), 0.2 deg at 10 Hz, KITTI-like mounting."""
        return cls(**{"beams": 16, "vertical_fov_deg": (-15.0, 15.0), "azimuth_step_deg": 0.2,
                      "max_range_m": 100.0, **cls.KITTI_MOUNT, **overrides})

    def __post_init__(self):
        lo, hi = self.vertical_fov_deg
        if self.beams < 1 or (self.beams > 1 and not hi > lo) or self.azimuth_step_deg <= 0:
            raise ValueError(f"invalid LiDAR parameters: {self}")
        if not 0.0 <= self.dropout < 1.0:
            raise ValueError(f"dropout must be in [0, 1), got {self.dropout}")

    def beam_elevations_deg(self) -> np.ndarray:
        """(beams,) elevation of each laser in degrees, lowest first."""
        lo, hi = self.vertical_fov_deg
        return np.linspace(lo, hi, self.beams) if self.beams > 1 else np.array([lo])

    def angles(self, frame: Frame) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Flat indices of the valid pixels and their LiDAR-frame (elevation, azimuth) in radians and range (m)."""
        idx = np.flatnonzero(frame.valid & (frame.depth > 0))
        v, u = np.divmod(idx, frame.shape[1])
        z = frame.depth.reshape(-1)[idx].astype(np.float64)
        k = frame.intrinsics
        x = (u - k.cx) / k.fx * z
        y = (v - k.cy) / k.fy * z
        # Camera frame -> LiDAR-origin frame: translate, then rotate about x by the pitch.
        y = y + self.mount_height_m
        z = z - self.mount_forward_m
        p = math.radians(self.mount_pitch_deg)
        # LiDAR axes in camera coordinates: forward = (0, -sin p, cos p), down = (0, cos p, sin p).
        y_l = math.cos(p) * y + math.sin(p) * z
        z_l = -math.sin(p) * y + math.cos(p) * z
        horizontal = np.hypot(x, z_l)
        elevation = np.arctan2(-y_l, horizontal)
        azimuth = np.arctan2(x, z_l)
        return idx, elevation, azimuth, np.sqrt(horizontal**2 + y_l**2)

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        idx, elevation, azimuth, rng_m = self.angles(frame)
        beams = np.radians(self.beam_elevations_deg())
        # A single beam has no spacing: give it an (arbitrary) band of +-0.2 deg.
        spacing = (beams[-1] - beams[0]) / (self.beams - 1) if self.beams > 1 else math.radians(0.4)
        # Nearest beam; pixels more than half a spacing outside the fan are dropped below.
        beam = np.clip(np.rint((elevation - beams[0]) / spacing), 0, self.beams - 1).astype(np.int64)
        d_el = elevation - beams[beam]
        step = math.radians(self.azimuth_step_deg)
        column = np.rint(azimuth / step).astype(np.int64)
        d_az = (azimuth - column * step) * np.cos(elevation)
        # A ray hits the pixel that contains it: a pixel more than about half its own angular size away from
        # the cell centre is not hit (the ray leaves the image or falls on invalid ground truth). Local pixel
        # pitch of the camera ray angles: d(elevation)/dv and d(azimuth)/du at this pixel (+10 % margin).
        v, u = np.divmod(idx, frame.shape[1])
        k = frame.intrinsics
        dx, dy = (u - k.cx) / k.fx, (v - k.cy) / k.fy
        el_pitch = np.sqrt(dx**2 + 1) / (dx**2 + dy**2 + 1) / k.fy
        az_pitch = 1.0 / (dx**2 + 1) / k.fx
        keep = (
            (np.abs(d_el) <= spacing / 2)
            & (np.abs(d_el) <= 0.55 * el_pitch)
            & (np.abs(azimuth - column * step) <= 0.55 * az_pitch)
            & (rng_m <= self.max_range_m)
        )
        idx, beam, column, cost = idx[keep], beam[keep], column[keep], (d_el**2 + d_az**2)[keep]
        if idx.size == 0:
            return np.zeros(frame.shape, dtype=np.float32)
        column = column - column.min()
        cell = beam * (int(column.max()) + 1) + column
        chosen = idx[nearest_per_cell(cell, cost, tiebreak=idx)]  # per cell: nearest to the centre
        if self.dropout > 0 and chosen.size:
            chosen = chosen[example_rng(seed, frame.id).random(chosen.size) >= self.dropout]
        out = np.zeros(frame.depth.size, dtype=np.float32)
        out[chosen] = frame.depth.reshape(-1)[chosen]
        return out.reshape(frame.shape)


@dataclasses.dataclass(frozen=True)
class Noise:
    """Measurement noise applied to the sampled points only (zeros stay zeros).

    Per point with depth d: d + N(0, std_m^2 + (relative_std * d)^2); then exactly
    round(outlier_fraction * #points) points are replaced by outliers uniform in outlier_range_m (default: the
    [min, max] of the example's valid ground truth). Results are clamped to >= MIN_SPARSE_DEPTH_M so no point
    disappears. Randomness: example_rng(seed, frame_id, "noise"), independent of the sampler's draws.

    Attributes:
      std_m: additive Gaussian std in metres.
      relative_std: range-proportional std, a fraction of depth (e.g. 0.01 = 1 %).
      outlier_fraction: fraction of the sampled points replaced by outliers, in [0, 1].
      outlier_range_m: (low, high) metres for outliers, or None for the example's GT range.
    """

    std_m: float = 0.0
    relative_std: float = 0.0
    outlier_fraction: float = 0.0
    outlier_range_m: tuple[float, float] | None = None

    def __post_init__(self):
        if self.std_m < 0 or self.relative_std < 0 or not 0 <= self.outlier_fraction <= 1:
            raise ValueError(f"invalid noise parameters: {self}")

    def __call__(self, sparse: np.ndarray, frame: Frame, seed: int = 0) -> np.ndarray:
        """(H, W) sparse metres -> (H, W) float32 noisy sparse metres, same support."""
        rng = example_rng(seed, frame.id, "noise")
        out = np.array(sparse, dtype=np.float32, copy=True)
        idx = np.flatnonzero(out > 0)
        flat = out.reshape(-1)
        d = flat[idx].astype(np.float64)
        std = np.sqrt(self.std_m**2 + (self.relative_std * d) ** 2)
        d = d + rng.standard_normal(d.size) * std
        n_out = int(round(self.outlier_fraction * idx.size))
        if n_out:
            if self.outlier_range_m is not None:
                low, high = self.outlier_range_m
            else:
                gt = frame.depth[frame.valid]
                low, high = (float(gt.min()), float(gt.max())) if gt.size else (MIN_SPARSE_DEPTH_M, 1.0)
            which = rng.choice(idx.size, size=n_out, replace=False)
            d[which] = rng.uniform(low, high, size=n_out)
        flat[idx] = np.maximum(d, MIN_SPARSE_DEPTH_M).astype(np.float32)
        return out


@dataclasses.dataclass(frozen=True)
class Noisy:
    """`sampler` followed by `noise`: same call signature as a sampler."""

    sampler: SparseSampler
    noise: Noise

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        return self.noise(self.sampler(frame, seed), frame, seed)


@dataclasses.dataclass(frozen=True)
class Parallax:
    """`sampler` measuring from a sensor beside the camera, its returns projected into the image.

    Per example a baseline b (metres, camera frame) of length drawn log-uniformly in [min_m, max_m] and direction
    uniform on the sphere, from example_rng(seed, frame.id, "parallax"); `Parallax.at(sampler, b)` fixes it (a
    known rig: KITTI's Velodyne sits at about (0.06, -0.08, -0.27) from its left colour camera). The sampler draws
    on the depth the sensor sees from b (`lipjax.data.parallax.sensor_view`: the camera's hidden background
    continued under edges, its invalid pixels kept invalid), and its returns land back in the camera's pixels
    (`parallax.to_camera`): some on foreground pixels with the background's depth (seen through an edge), none on
    surfaces the sensor cannot see.
    The ground truth is untouched: the model learns which samples to distrust.
    """

    sampler: SparseSampler
    min_m: float = 0.03
    max_m: float = 0.3
    direction: tuple[float, float, float] | None = None  # a fixed unit direction instead of a random one

    def __post_init__(self):
        if not 0 < self.min_m <= self.max_m:
            raise ValueError(f"parallax needs 0 < min_m <= max_m metres, got min_m={self.min_m}, max_m={self.max_m}")
        if self.direction is not None and not math.isclose(float(np.linalg.norm(self.direction)), 1.0, rel_tol=1e-6):
            raise ValueError(f"parallax direction must be a unit vector, got {self.direction}")

    @classmethod
    def at(cls, sampler: SparseSampler, baseline_m) -> "Parallax":
        """`sampler` measuring from the fixed point `baseline_m` (3,) metres, camera frame (x right, y down, z
        forward)."""
        b = np.asarray(baseline_m, np.float64)
        length = float(np.linalg.norm(b))
        if b.shape != (3,) or not length > 0:
            raise ValueError(f"a sensor position needs 3 coordinates in metres, not all 0, got {baseline_m!r}")
        return cls(sampler, length, length, tuple(float(c) for c in b / length))

    def baseline_m(self, frame: Frame, seed: int = 0) -> np.ndarray:
        """(3,) this example's sensor position in the camera frame, metres."""
        rng = example_rng(seed, frame.id, "parallax")
        length = math.exp(rng.uniform(math.log(self.min_m), math.log(self.max_m)))
        direction = rng.standard_normal(3) if self.direction is None else np.asarray(self.direction)
        return length * direction / np.linalg.norm(direction)

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        b = self.baseline_m(frame, seed)
        view = parallax.sensor_view(frame.depth, frame.valid, frame.intrinsics, b)
        seen = Frame.from_depth(frame.rgb, view, frame.intrinsics, frame.id)
        return parallax.to_camera(self.sampler(seen, seed), frame.intrinsics, b)


LIDAR_PRESETS = {"hdl64": LidarSampler.hdl64, "hdl32": LidarSampler.hdl32,
                 "vlp32": LidarSampler.vlp32, "vlp16": LidarSampler.vlp16}
_NOISE_KEYS = {"std": "std_m", "rel": "relative_std", "outliers": "outlier_fraction"}
_PARALLAX_KEYS = {"min_m": "min_m", "max_m": "max_m"}


def _parse_options(text: str, spec: str) -> dict[str, float]:
    options = {}
    for item in filter(None, text.split(",")):
        key, sep, value = item.partition("=")
        if not sep:
            raise ValueError(f"bad option {item!r} in sampler spec {spec!r} (expected key=value)")
        try:
            options[key.strip()] = float(value)
        except ValueError:
            raise ValueError(f"option {key!r} in sampler spec {spec!r} must be a number, got {value!r}") from None
    return options


@dataclasses.dataclass(frozen=True)
class Mixture:
    """Draws each example's sparse input from one of several samplers, chosen by the example's own key.

    Training on a mixture of densities and patterns makes a model that holds up when a user's sensor differs
    from the one it was trained for. The choice is a pure function of (seed, id), like every sampler here.
    """

    samplers: tuple[SparseSampler, ...]

    def __post_init__(self):
        if not self.samplers:
            raise ValueError("Mixture needs at least one sampler")

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        choice = int(example_rng(seed, frame.id, "mixture").integers(len(self.samplers)))
        return self.samplers[choice](frame, seed)


def sampler_from_spec(spec: str) -> SparseSampler:
    """Builds a sampler from a string; "A|B|C" is a Mixture of the samplers A, B and C (see `Mixture`)."""
    if "|" in spec:
        return Mixture(tuple(_single_sampler_from_spec(part) for part in spec.split("|")))
    return _single_sampler_from_spec(spec)


def is_own_input(spec: str) -> bool:
    """Whether `spec` is "input" or "input:N": a data set's own sparse input (lipjax.data.sources), not a sampler
    of this module."""
    return "|" not in spec and spec.split(":")[0].strip().lower() == OWN_INPUT


def draws_scan_lines(spec: str) -> bool:
    """Whether the sparse input of `spec` (see `sampler_from_spec`) may hold LiDAR scan lines for some examples:
    a sampler that draws them, or a data set's own input ("input[:N]", `is_own_input`), whose pattern is the user's
    sensor's and unknown here (a KITTI scan, a folder's sparse/ maps). A model trained on that input has seen its
    pattern, so scan lines are no warning for it (lipjax.inference.Completer.scan_lines_trained); whether a
    data set reads camera intrinsics for it is lipjax.data.sources.uses_intrinsics (own input: never)."""
    if is_own_input(spec):
        return True
    sampler = sampler_from_spec(spec)
    parts = sampler.samplers if isinstance(sampler, Mixture) else (sampler,)
    return any(isinstance(_innermost(part), LidarSampler) for part in parts)


def _innermost(sampler: SparseSampler) -> SparseSampler:
    """The pattern inside any Noisy / Parallax wrappers."""
    return _innermost(sampler.sampler) if isinstance(sampler, (Noisy, Parallax)) else sampler


def _single_sampler_from_spec(spec: str) -> SparseSampler:
    """Builds a sampler from a string.

    Grammar: KIND[+parallax:OPTIONS][+noise:OPTIONS] (wrappers applied left to right) with KIND one of
      uniform:N                       UniformSampler(N)
      bernoulli:N                     BernoulliSampler(N)
      lidar:PRESET[,key=value...]     LidarSampler.PRESET(key=value), PRESET in hdl64 hdl32 vlp32 vlp16,
                                      keys: any float field, e.g. azimuth_step_deg=0.4,mount_pitch_deg=-2
      keypoint:N                      KeypointSampler(N)
      holes:F                         HolesSampler(F), F in [0, 1)
    parallax OPTIONS min_m=<m>,max_m=<m> (`Parallax`) and noise OPTIONS std=<m>,rel=<fraction>,outliers=<fraction>.
    Examples: "uniform:200", "bernoulli:500", "lidar:vlp16", "lidar:hdl64+noise:std=0.02,outliers=0.01",
    "lidar:hdl64+parallax:min_m=0.05,max_m=0.3", "keypoint:500", "holes:0.3".
    """
    base, *suffixes = spec.strip().split("+")
    kind, _, arg = base.partition(":")
    kind = kind.strip().lower()
    sampler: SparseSampler
    if kind in ("uniform", "bernoulli", "keypoint"):
        try:
            n = int(arg)
        except ValueError:
            raise ValueError(
                f"sampler spec {spec!r}: {kind} needs an integer point count, e.g. '{kind}:200'") from None
        sampler = {"uniform": UniformSampler, "bernoulli": BernoulliSampler, "keypoint": KeypointSampler}[kind](n)
    elif kind == "holes":
        try:
            sampler = HolesSampler(float(arg))
        except ValueError:
            raise ValueError(f"sampler spec {spec!r}: holes needs the fraction of the frame in holes, in [0, 1), "
                             "e.g. 'holes:0.3'") from None
    elif kind == "lidar":
        preset, _, options = arg.partition(",")
        if preset not in LIDAR_PRESETS:
            raise ValueError(f"sampler spec {spec!r}: unknown LiDAR preset {preset!r}; known: {sorted(LIDAR_PRESETS)}")
        fields = {f.name for f in dataclasses.fields(LidarSampler)} - {"beams", "vertical_fov_deg"}
        overrides = _parse_options(options, spec)
        unknown = set(overrides) - fields
        if unknown:
            raise ValueError(f"sampler spec {spec!r}: unknown LiDAR option(s) {sorted(unknown)}; "
                             f"known: {sorted(fields)}")
        sampler = LIDAR_PRESETS[preset](**overrides)
    elif kind == OWN_INPUT:
        raise ValueError(f"sampler spec {spec!r}: 'input' is a data set's own sparse input (a folder's sparse/ "
                         "maps, KITTI's scans), not a sampler to mix, wrap or draw on frames without one; give "
                         "'input' or 'input:N' alone for such a data set, else a sampler such as uniform:200")
    else:
        raise ValueError(f"unknown sampler spec {spec!r}; expected uniform:N, bernoulli:N, keypoint:N, holes:F or "
                         f"lidar:{'|'.join(LIDAR_PRESETS)}")
    for suffix in suffixes:
        sampler = _wrapped(sampler, suffix, spec)
    return sampler


def _wrapped(sampler: SparseSampler, suffix: str, spec: str) -> SparseSampler:
    """`sampler` inside the wrapper a "+parallax:..." or "+noise:..." suffix of `spec` names."""
    name, _, options = suffix.partition(":")
    raw = _parse_options(options, spec)
    keys = {"noise": _NOISE_KEYS, "parallax": _PARALLAX_KEYS}.get(name.strip())
    if keys is None:
        raise ValueError(f"sampler spec {spec!r}: expected '+parallax:...' or '+noise:...' after the sampler, "
                         f"got '+{suffix}'")
    unknown = set(raw) - set(keys)
    if unknown:
        raise ValueError(f"sampler spec {spec!r}: unknown {name.strip()} option(s) {sorted(unknown)}; "
                         f"known: {sorted(keys)}")
    kwargs = {keys[k]: v for k, v in raw.items()}
    return Noisy(sampler, Noise(**kwargs)) if name.strip() == "noise" else Parallax(sampler, **kwargs)
