"""The jit-compiled inference entry point: `Completer` (a model with its parameters); inputs checked by lipjax.inputs.

Also `load_model` (a saved model by name or path), `default_model` (the shipped default of a scene), and
`complete_frame`, which runs a learned model at its working size (lipjax.resolution) and returns full-size depth.
Names of every kind of completer (learned, classical, a path) resolve in lipjax.methods.get_completer.

`Completer.__call__` takes RGB uint8 (H, W, 3) or (B, H, W, 3) and sparse depth in metres (0 = missing) of the
same size, and returns dense depth in metres. The solver is compiled once per (config, input shape): jit caches
one executable per shape, and `compiled_apply` caches the jitted function per config (the training loop's
validation uses it too, so one compilation serves both).
"""
from __future__ import annotations

import dataclasses
import functools
import os
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import jax
import numpy as np

from lipjax import crosscheck, model_io
from lipjax.inputs import InputError, check_inputs, is_lidar_pattern, quietly  # noqa: F401  (lipjax.InputError)
from lipjax.interfaces import MIXED_SCENES, LearnedModel
from lipjax.model import LIPConfig
from lipjax.resolution import MIN_MAX_SIDE_PX, is_capped, max_side_size, sample_spacing_px, working_size
from lipjax.shipped import DEFAULT_MODEL, DEFAULT_MODELS
from lipjax.spread import spread_on_host
from lipjax.utils import warn_user
from lipjax.zbuffer import splat_nearest


@functools.lru_cache(maxsize=None)
def compiled_apply(config: LearnedModel, return_trajectory: bool = False):
    """jit(config.apply) as (params, rgb, sparse, extra) -> (depth, trajectory or None); extra holds the
    host-computed inputs (`config.host_inputs(sparse)`), e.g. {"z0": ...}, or is empty."""

    def run(params, rgb, sparse, extra):
        return config.apply(params, rgb, sparse, return_trajectory=return_trajectory, **extra)

    return jax.jit(run)


@dataclasses.dataclass(frozen=True, eq=False)
class Completer:
    """A learned model (any `LearnedModel`) with its parameters, callable on images. Built by `load_model` or
    `Completer.random`."""

    config: LearnedModel  # a LIPConfig or an end-to-end network's config (lipjax.interfaces)
    params: Any
    name: str = "lip"
    metadata: dict = dataclasses.field(default_factory=dict)

    @classmethod
    def random(cls, config: LIPConfig | None = None, seed: int = 0) -> "Completer":
        """An untrained model (its network prox is the identity, so it returns the initial fill)."""
        config = config or LIPConfig()
        return cls(config, config.init(jax.random.key(seed)), name="random")

    def with_iterations(self, num_iterations: int) -> "Completer":
        """The same model run for fewer iterations (uses the first K of its per-iteration operators)."""
        config, params = self.config.with_iterations(self.params, num_iterations)
        return self if config is self.config else Completer(config, params, self.name, self.metadata)

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray:
        """Dense depth in metres, (H, W) or (B, H, W) like the input: the model itself, at the input's size.

        `lipjax.complete(rgb, sparse, model=completer)` is the default path instead (`complete_frame`): the model at
        the working size of the samples (lipjax.resolution), every measured pixel set back. On 200 points on 480x640
        synthetic rooms the two differ a lot: lip-any is 0.95x a linear fill at full size and 0.82x at the working size
        (`python -m benchmarks.working_resolution`; docs/decisions/0001-working-resolution.md)."""
        rgb, sparse, batched = check_inputs(rgb, sparse, self.config.max_depth_m, self.name, self.scan_lines_trained,
                                             self.both_scenes)
        depth, _ = compiled_apply(self.config, False)(self.params, rgb, sparse, self.config.host_inputs(sparse))
        depth = np.maximum(np.asarray(depth), 0.0)
        return depth if batched else depth[0]

    def trajectory(self, rgb: np.ndarray, sparse: np.ndarray):
        """(final depth, Trajectory) for a batch, as jax arrays: depth (B, H, W) metres, not clamped at 0 (the
        solver's own output, as training sees it); each trajectory array is (K, B, H, W) metres."""
        rgb, sparse, _ = check_inputs(rgb, sparse, self.config.max_depth_m, self.name, self.scan_lines_trained,
                                      self.both_scenes)
        return compiled_apply(self.config, True)(self.params, rgb, sparse, self.config.host_inputs(sparse))

    def parameter_count(self) -> int:
        return self.config.parameter_count(self.params)

    @property
    def both_scenes(self) -> bool:
        """Whether the model was trained on rooms and streets together (its metadata's `data` is "mixed", recorded
        at export by lipjax.train.run)."""
        return self.metadata.get("data") == MIXED_SCENES

    @functools.cached_property  # read on every call: the spec is parsed once
    def scan_lines_trained(self) -> bool:
        """Whether the model's training input may have included LiDAR scan lines (its metadata's `train_sampler`,
        recorded at export; older models record none), so that lipjax.inputs does not warn about scan lines.

        A lipjax.data.sampling spec says so (`draws_scan_lines`). "input" / "input:N", the training data's own sparse
        input (a folder's sparse/ maps, KITTI's scans), says True: its pattern, unknown here, is the user's sensor's,
        which the model was trained on, so the same sensor's scan lines are no warning. So is a spec this version
        cannot read (a sampler of a later version): the model loads and runs, with no warning about the pattern."""
        from lipjax.data.sampling import draws_scan_lines

        spec = self.metadata.get("train_sampler")
        if spec is None:
            return False
        try:
            return draws_scan_lines(spec)
        except ValueError:
            return True


def load_model(name_or_path: str | os.PathLike = DEFAULT_MODEL) -> Completer:
    """A shipped model by name (see `lipjax.available_models()`) or a saved model by path."""
    config, params, metadata = model_io.load(name_or_path)
    return Completer(config, params, name=str(name_or_path), metadata=metadata)


@functools.lru_cache(maxsize=2)
def default_model(scene: str = "indoor") -> Completer:
    """The shipped default model of `scene` (DEFAULT_MODELS; loaded once), or, while no weights are shipped, an
    untrained model (warns)."""
    name = DEFAULT_MODELS[scene]
    if name in model_io.available():
        return load_model(name)
    warn_user(f"no trained weights shipped ({name!r} is not in `lipjax models`): using an UNTRAINED model, whose "
              "output is only a smooth fill of the samples; pass a model name or path")
    return Completer.random()


# Whether the default path (`complete_at`, `lipjax.complete`, `lipjax complete`, the ONNX graph) averages a learned
# model's estimate with that of the mirror-image frame (`mirror_averaged`) where the caller does not say
# (mirror=None): on LiDAR scan lines, where the check against the linear fill (lipjax.crosscheck) does not run and
# leaves the second core free (docs/decisions/0020-flip-averaging-on-scan-lines.md: the 1,260,640-image lip-any's
# synthetic suite 0.6350 -> 0.6323 x linear, streets with HDL-64 0.404 -> 0.391; the 352x1216 street in two threads 37
# -> 42 ms). Not on scattered samples: there the check's held-out fold takes that core (480x640 with 200 points 36 ->
# 61 ms with both). `mirror=True` / `--mirror` asks for it on any input, `mirror=False` / `--no-mirror` nowhere.
MIRROR_SCAN_LINES = True
# Threads that run the mirror image's estimate beside the frame's (`mirror_averaged`, on the CPU): a pool of its own,
# as a held-out fold running in lipjax.crosscheck's threads asks for one (its tasks wait on nothing, so a full pool
# only queues them); one per fold and one for the frame.
_MIRROR_BESIDE = ThreadPoolExecutor(max_workers=crosscheck.FOLDS + 1, thread_name_prefix="lipjax-mirror")

# Whether the default path checks a learned model against the linear fill on held-out samples and leans on the
# fill where the model is the worse of the two (`lipjax.crosscheck`; scattered samples only). On: chosen by rules on
# synthetic frames (docs/decisions/0013-cross-check-against-the-linear-fill.md and 0015-cross-check-by-folds.md). Off
# (`cross_check=False`, `lipjax complete --no-cross-check`): the model's estimate alone, run once instead of twice (six
# times where the first held-out fold goes against the model) on scattered samples (480x640 with 200 points, training
# paused: 36 ms checked, the held-out run in a second thread at the kept samples' own working size
# (docs/decisions/0014-held-out-run-size.md), against 26 ms); what the ONNX graph computes.
CROSS_CHECK = True

# Whether the default path (`complete_at`, the ONNX graph) spreads the samples' residuals over the frame after
# resizing a working-size estimate back to full size (`lipjax.spread`). On: docs/decisions/0018-residual-spreading.md,
# with the 724,000-image lip-any: `python -m benchmarks.generalisation --frames 8 --no-cross-check` 0.708148 ->
# 0.706272 (streets HDL-64 0.428 -> 0.421, VLP-32 0.806 -> 0.798, no setting worse) and 24 synthetic streets with
# HDL-64 scored where KITTI's ground truth would lie (`python -m benchmarks.kitti_like_gt`) 1.114 -> 1.028 x linear;
# scan lines with sigmas of their own (docs/decisions/0019-scan-line-sigmas.md; 772,000-image lip-any: suite 0.696992
# -> 0.696054, those streets 1.024 -> 0.991 x linear).
SPREAD_RESIDUALS = True

# A frame above this many pixels runs slowly and needs gigabytes at full size: callers suggest max_side.
LARGE_FRAME_PIXELS = 2_000_000


def reproject_sparse(sparse_m: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """Moves each measured pixel of a (H, W) sparse map to the pixel of a (h, w) grid its centre falls in.

    Values are kept (never averaged or interpolated); where several samples land in one pixel the nearest
    (smallest depth) wins, as a z-buffer. Returns (h, w) float32 metres, 0 = no sample.
    """
    sparse = np.asarray(sparse_m, np.float32)
    big_h, big_w = sparse.shape
    h, w = size
    flat = np.flatnonzero(sparse > 0)  # not np.nonzero: several times faster on a KITTI frame
    rows, cols = np.divmod(flat, big_w)
    r = np.minimum(((rows + 0.5) * h / big_h).astype(np.int64), h - 1)
    c = np.minimum(((cols + 0.5) * w / big_w).astype(np.int64), w - 1)
    return splat_nearest(r * w + c, sparse.ravel()[flat], (h, w))


def frame_size(completer, sparse_m: np.ndarray, max_side: int | None = None, *,
               scan_lines: bool | None = None) -> tuple[int, int]:
    """(h, w) at which `completer` runs on a frame with (H, W) sparse depth `sparse_m` (metres, 0 = none).

    `max_side` (pixels, >= MIN_MAX_SIDE_PX) caps the longer side; without it a learned model runs at the
    working size of its samples' spacing and pattern (`lipjax.resolution.working_size`) and a classical fill at
    full size. `scan_lines`: lipjax.inputs.is_lidar_pattern of `sparse_m`, asked here when not given.
    """
    shape = tuple(np.shape(sparse_m))
    if max_side is not None:
        if max_side < MIN_MAX_SIDE_PX:
            raise InputError(f"max_side {max_side}: too small to hold a depth map; use at least {MIN_MAX_SIDE_PX} "
                             "pixels (or none: the working size then follows the samples)")
        return max_side_size(shape, max_side)
    if not isinstance(completer, Completer):
        return shape
    spacing = sample_spacing_px(sparse_m)
    if spacing == float("inf"):
        return shape
    lines = is_lidar_pattern(sparse_m) if scan_lines is None else scan_lines
    return working_size(shape, spacing, capped=is_capped(int(np.count_nonzero(sparse_m > 0)), shape, lines))


def complete_frame(completer, rgb: np.ndarray, sparse_m: np.ndarray, max_side: int | None = None, *,
                   mirror: bool | None = None, cross_check: bool = CROSS_CHECK) -> np.ndarray:
    """Dense (H, W) float32 metres for one frame, the model run at its working size (`frame_size`, `complete_at`);
    `max_side` caps the longer side instead (pixels), `mirror` and `cross_check` as in `complete_at`."""
    # asked once for both (about 1 ms on a KITTI scan); for a classical fill after complete_at's input checks
    lines = is_lidar_pattern(sparse_m) if isinstance(completer, Completer) else None
    return complete_at(completer, rgb, sparse_m, frame_size(completer, sparse_m, max_side, scan_lines=lines),
                       mirror=mirror, cross_check=cross_check, scan_lines=lines)


@dataclasses.dataclass(frozen=True)
class AtWorkingSize:
    """`completer` run one frame at a time as `lipjax.complete` runs it (`complete_frame`: a learned model at the
    working size of the samples, every measured pixel set back; a hand-crafted method as it is), named as
    `completer`: for scoring the default path (`lipjax evaluate --working-size`) rather than the model at the
    input's size."""

    completer: Any

    @property
    def name(self) -> str:
        return self.completer.name

    def __call__(self, rgb: np.ndarray, sparse_m: np.ndarray) -> np.ndarray:
        return complete_frame(self.completer, rgb, sparse_m)


def mirror_averaged(completer: Completer, rgb: np.ndarray, sparse_m: np.ndarray) -> np.ndarray:
    """(z(I, y) + flip(z(flip(I), flip(y)))) / 2 for one frame, rgb (h, w, 3) and sparse (h, w) metres: the model's
    estimate averaged with its estimate of the mirror-image frame, flipped back. On the CPU the two run side by side
    in two threads, as XLA runs a model on about one core (lip-any on the 352x1216 street at 132x455, training
    paused: 32 ms in two threads, 52 ms as one batch of two, 26 ms for one frame); elsewhere as one batch of two."""
    if jax.default_backend() != "cpu":
        both = completer(np.stack([rgb, rgb[:, ::-1]]), np.stack([sparse_m, sparse_m[:, ::-1]]))
        return 0.5 * (both[0] + both[1][:, ::-1])
    mirrored = _MIRROR_BESIDE.submit(quietly, completer, rgb[:, ::-1], sparse_m[:, ::-1])  # checked as the frame is
    z = completer(rgb, sparse_m)
    return 0.5 * (z + mirrored.result()[:, ::-1])


def mirrors(completer, scan_lines: bool, mirror: bool | None) -> bool:
    """Whether the default path averages `completer`'s estimate of a frame with the mirror image's: `mirror` where
    it is given, else (None) for a learned model on LiDAR scan lines (`scan_lines`: lipjax.inputs.is_lidar_pattern
    of the frame's samples; MIRROR_SCAN_LINES)."""
    if mirror is not None:
        return mirror
    return MIRROR_SCAN_LINES and scan_lines and isinstance(completer, Completer)


def complete_at(completer, rgb: np.ndarray, sparse_m: np.ndarray, size: tuple[int, int], *,
                mirror: bool | None = None, cross_check: bool = CROSS_CHECK,
                spread: bool = SPREAD_RESIDUALS, scan_lines: bool | None = None) -> np.ndarray:
    """Dense (H, W) float32 metres for one frame, `completer` run at `size` (h, w).

    Below full size the RGB is area-resized, the samples move onto the small grid (`reproject_sparse`), and the
    estimate z (h, w) is resized back (bilinear) and, with `spread` (SPREAD_RESIDUALS), the samples' residuals
    y - z are spread over it (`lipjax.spread`; scan lines get their own sigmas). Then, for a learned model at any
    size, the final x-update runs at full size: with rho -> 0 at the measured pixels (m = 1),
    x = (m y + rho z) / (m + rho) sets every measured pixel back to its measured value (the model's own last
    x-update, with its learned rho, keeps them only approximately); likewise for any completer run below full size.
    Any other completer at full size (the hand-crafted methods, lipjax.methods.CLASSICAL) is returned as it
    returns: IP-Basic, as published, replaces background returns seen through gaps in the foreground.
    With `mirror` a learned model's estimate is `mirror_averaged`; None (the default) does so on LiDAR scan lines
    (`mirrors`; MIRROR_SCAN_LINES says why). With `cross_check` (CROSS_CHECK) a learned model's estimate of
    scattered samples is checked against the linear fill on held-out samples and blended with it where it is the
    worse (`lipjax.crosscheck.cross_checked`). `scan_lines`: lipjax.inputs.is_lidar_pattern of `sparse_m`, asked
    here when not given.
    (Carrying the prox's correction over to a full-size linear fill, F * bilinear(z / f), was tried instead of
    bilinear(z): it was worse on every synthetic setting of benchmarks/working_resolution.py, 0.83 against 0.67 x
    linear on 352x1216 streets with 64 beams.)
    """
    import cv2

    rgb, sparse, batched = check_inputs(rgb, sparse_m)  # before any resize could hide a size mismatch
    if batched:
        raise InputError(f"one frame at a time: rgb (H, W, 3) and sparse (H, W), got rgb {np.shape(rgb)}; loop over "
                         "a batch, or call the completer itself at one size")
    rgb, sparse_m = rgb[0], sparse[0]
    big_h, big_w = sparse_m.shape
    h, w = size
    if mirror and not isinstance(completer, Completer):
        raise InputError(f"mirror averaging is for learned models; drop --mirror (mirror=True) for {completer.name}")
    lines = is_lidar_pattern(sparse_m) if scan_lines is None else scan_lines  # the mirror, the sigmas, the check
    run = functools.partial(mirror_averaged, completer) if mirrors(completer, lines, mirror) else completer

    def estimate(sparse: np.ndarray, at: tuple[int, int]) -> np.ndarray:  # z (H, W) from a sparse map, run at `at`
        if at == (big_h, big_w):
            return np.array(run(rgb, sparse), np.float32)
        small_rgb = cv2.resize(rgb, at[::-1], interpolation=cv2.INTER_AREA)
        small = np.asarray(run(small_rgb, reproject_sparse(sparse, at)), np.float32)
        z = cv2.resize(small, (big_w, big_h), interpolation=cv2.INTER_LINEAR)
        return spread_on_host(z, sparse, at, lines) if spread else z  # before any set-back; sigmas of the pattern

    if cross_check and isinstance(completer, Completer):
        dense, _ = crosscheck.cross_checked(estimate, sparse_m, (h, w), scan_lines=lines)
    else:
        dense = estimate(sparse_m, (h, w))
    if isinstance(completer, Completer) or (h, w) != (big_h, big_w):  # a hand-crafted method at full size: as is
        measured = sparse_m > 0
        dense[measured] = sparse_m[measured]
    return dense
