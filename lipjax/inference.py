"""The jit-compiled inference entry point: `Completer` (a model with its parameters); inputs checked by lipjax.inputs.

Also `load_model` (a saved model by name or path), `default_model` (the shipped default), and the default path of
`lipjax.complete` and `lipjax complete` as data plus one function: `plan_frame` decides once per frame what happens
to it (a frozen `FramePlan`: the samples' pattern, the working size, the initial estimate, flip averaging, residual
spreading, the cross-check), and `complete_frame` runs it stage by stage and returns full-size depth. The numbers
and switches of the path are in lipjax.defaults. Names of every kind of completer (learned, classical, a path)
resolve in lipjax.methods.get_completer.

`Completer.__call__` takes RGB uint8 (H, W, 3) or (B, H, W, 3) and sparse depth in metres (0 = missing) of the
same size, and returns dense depth in metres. The solver is compiled once per (config, input shape): jit caches
one executable per shape, and `compiled_apply` caches the jitted function per config (the training loop's
validation uses it too, so one compilation serves both).
"""
from __future__ import annotations

import dataclasses
import functools
import math
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import jax
import numpy as np

from lipjax import crosscheck, model_io
from lipjax.defaults import (CROSS_CHECK, LARGE_FRAME_PIXELS, MAX_WORKING_PIXELS,  # noqa: F401  (read from here too)
                             FLIP_SCAN_LINES, SPREAD_RESIDUALS, TARGET_SPACING_PX)
from lipjax.inputs import InputError, check_inputs, is_lidar_pattern, quietly  # noqa: F401  (lipjax.InputError)
from lipjax.interfaces import MIXED_SCENES, LearnedModel
from lipjax.model import LIPConfig
from lipjax.resolution import (MIN_MAX_SIDE_PX, dense_from, is_capped, max_side_size, sample_spacing_px,
                               working_size)
from lipjax.shipped import DEFAULT_MODEL
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
        """An untrained model (its network prox is the identity, so it returns the initial estimate)."""
        config = config or LIPConfig()
        return cls(config, config.init(jax.random.key(seed)), name="random")

    def with_iterations(self, num_iterations: int) -> "Completer":
        """The same model run for fewer iterations (uses the first K of its per-iteration operators)."""
        config, params = self.config.with_iterations(self.params, num_iterations)
        return self if config is self.config else Completer(config, params, self.name, self.metadata)

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray, *, scan_lines: bool | None = None) -> np.ndarray:
        """Dense depth in metres, (H, W) or (B, H, W) like the input: the model itself, at the input's size.

        `scan_lines`: whether the samples lie in LiDAR scan lines, where the caller knows it (the default path's
        `FramePlan`, asked of the full-size frame); the input checks and an "auto" initial estimate take it instead of
        asking lipjax.inputs.is_lidar_pattern of the map given here.
        `lipjax.complete(rgb, sparse, model=completer)` is the default path instead (`complete_frame`): the model at
        the working size of the samples (lipjax.resolution), every measured pixel set back. On 200 points on 480x640
        synthetic rooms the two differ a lot: lip-any is 0.95x a linear fill at full size and 0.82x at the working size
        (`python -m benchmarks.working_resolution`; docs/decisions/0001-working-resolution.md)."""
        rgb, sparse, batched = check_inputs(rgb, sparse, self.config.max_depth_m, self.name, self.scan_lines_trained,
                                             self.both_scenes, scan_lines=scan_lines)
        extra = self.config.host_inputs(sparse, scan_lines)
        depth, _ = compiled_apply(self.config, False)(self.params, rgb, sparse, extra)
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


@functools.lru_cache(maxsize=1)
def default_model() -> Completer:
    """The shipped default model, one for every input (lipjax.defaults.DEFAULT_MODEL; loaded once), or, while no
    weights are shipped, an untrained model (warns)."""
    name = DEFAULT_MODEL
    if name in model_io.available():
        return load_model(name)
    warn_user(f"no trained weights shipped ({name!r} is not in `lipjax models`): using an UNTRAINED model, whose "
              "output is only a smooth fill of the samples; pass a model name or path")
    return Completer.random()


# Threads that run the flipped frame's estimate beside the frame's (`flip_averaged`, on the CPU): a pool of its own,
# as a held-out fold running in lipjax.crosscheck's threads asks for one (its tasks wait on nothing, so a full pool
# only queues them); one per fold and one for the frame.
_FLIP_BESIDE = ThreadPoolExecutor(max_workers=crosscheck.FOLDS + 1, thread_name_prefix="lipjax-flip")

# The patterns of samples the default path tells apart (`sample_pattern`), each treated in its own way, and what
# each is, in words (`FramePlan.describe`).
SCAN_LINES, DENSE_MAP, FEW_POINTS, SCATTERED = "scan lines", "dense", "few points", "scattered"
PATTERN_WORDS = {SCAN_LINES: "a spinning LiDAR's", DENSE_MAP: "a depth camera's or stereo's map, with holes",
                 FEW_POINTS: f"scattered, under {crosscheck.MIN_SAMPLES}",
                 SCATTERED: f"{crosscheck.MIN_SAMPLES} or more, not in scan lines"}


def sample_pattern(sparse_m: np.ndarray, scan_lines: bool | None = None) -> str:
    """The pattern of the samples of a checked (H, W) sparse map (metres, 0 = none), as the default path treats it:

        SCAN_LINES  LiDAR scan lines (lipjax.inputs.is_lidar_pattern; `scan_lines` when the caller knows it): the
                    working size capped, flip averaging, the scan lines' spreading sigmas, no cross-check
        DENSE_MAP   over lipjax.defaults.DENSE samples per pixel (a depth camera's or stereo's, with holes): the
                    working size capped, no cross-check (docs/decisions/0016, 0017)
        FEW_POINTS  scattered, fewer than lipjax.defaults.MIN_SAMPLES: too few to hold any out, no cross-check
        SCATTERED   the other scattered samples: cross-checked against the linear fill
    """
    lines = is_lidar_pattern(sparse_m) if scan_lines is None else scan_lines
    n = int(np.count_nonzero(sparse_m > 0))
    if lines:
        return SCAN_LINES
    if n >= dense_from(sparse_m.size):
        return DENSE_MAP
    return FEW_POINTS if n < crosscheck.MIN_SAMPLES else SCATTERED


@dataclasses.dataclass(frozen=True)
class FramePlan:
    """What the default path does to one frame, decided before anything runs (`plan_frame`); `complete_frame` runs
    it, stage by stage, and `describe` says it in words (`lipjax complete --explain`).

    Attributes:
      model: the completer's name. learned: a `Completer` (runs at the working size, measured pixels set back).
      shape: the frame's (H, W). samples: how many pixels have a sample. pattern: `sample_pattern`'s answer.
      size: (h, w) the model runs at: the working size (lipjax.resolution), `max_side`'s size, or the frame's own.
      max_side: the caller's cap on the longer side, pixels (--max-side), or None.
      initial_estimate: the kind of z_0, the estimate the model starts from at that size ("nearest", "linear",
        "box_fill", "sparse"; LIPConfig.initial_estimate_for of the pattern); None for an end-to-end network or a
        hand-crafted method.
      flip: average the model's estimate with the flipped frame's (`flip_averaged`).
      spread: spread the samples' residuals over an estimate resized back to full size (lipjax.spread).
      cross_check: check the model against the linear fill on held-out samples (lipjax.crosscheck).
    """

    model: str
    learned: bool
    shape: tuple[int, int]
    samples: int
    pattern: str
    size: tuple[int, int]
    max_side: int | None
    initial_estimate: str | None
    flip: bool
    spread: bool
    cross_check: bool

    @property
    def scan_lines(self) -> bool:
        return self.pattern == SCAN_LINES

    @property
    def resized(self) -> bool:
        return self.size != self.shape

    @property
    def set_back(self) -> bool:
        """Whether every measured pixel is set back to its measured value at full size: for a learned model, and for
        any completer run below full size (a hand-crafted method at full size is returned as it returns)."""
        return self.learned or self.resized

    def describe(self) -> list[str]:
        """The plan in words, one line per decision: what `lipjax complete --explain` prints for a frame."""
        (big_h, big_w), (h, w) = self.shape, self.size
        spacing = math.sqrt(big_h * big_w / self.samples) if self.samples else math.inf
        if self.max_side is not None:
            why_size = f"--max-side {self.max_side}"
        elif not self.learned:
            why_size = "a hand-crafted method runs at full size"
        else:
            capped = {SCAN_LINES: "scan lines", DENSE_MAP: "dense maps"}.get(self.pattern)  # is_capped
            why_size = (f"the rule: samples about {TARGET_SPACING_PX:g} px apart"
                        + (f", at most {MAX_WORKING_PIXELS:,} pixels for {capped}" if capped else ""))
        scale = f"{h / big_h:.2f}x of {big_h}x{big_w}" if self.resized else "the frame's own"
        if not self.spread or self.resized:
            spreading = _on(self.spread)
        else:  # nothing to resize back, but a held-out run of the check may run smaller
            spreading = "on held-out runs resized (the frame runs at its own size)" if self.cross_check else "none"
        return [f"model: {self.model} ({'learned' if self.learned else 'hand-crafted'})",
                f"pattern: {self.pattern} ({PATTERN_WORDS[self.pattern]}): {self.samples:,} samples on "
                f"{big_h}x{big_w}, {spacing:.1f} px apart",
                f"working size: {h}x{w} ({scale}; {why_size})",
                f"initial estimate z0: {self.initial_estimate or 'none'}"
                + ("" if self.learned else " (the method is the fill)"),
                f"flip averaging: {_on(self.flip)}",
                f"residual spreading: {spreading}",
                f"cross-check against the linear fill: {_on(self.cross_check)}" + self._unchecked(),
                "measured pixels: " + ("set back to their values" if self.set_back else "as the method returns them")]

    def _unchecked(self) -> str:
        """Why a frame is not cross-checked, in a few words ("" when it is, or when it was turned off)."""
        if self.cross_check:
            return ""
        if not self.learned:
            return " (learned models only)"
        return {SCAN_LINES: " (not on scan lines)", DENSE_MAP: " (not on dense maps)",
                FEW_POINTS: f" (fewer than {crosscheck.MIN_SAMPLES} samples)"}.get(self.pattern, " (turned off)")


def _on(flag: bool) -> str:
    return "on" if flag else "off"


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


def flips(completer, scan_lines: bool, flip: bool | None) -> bool:
    """Whether the default path averages `completer`'s estimate of a frame with the flipped frame's: `flip` where
    it is given, else (None) for a learned model on LiDAR scan lines (`scan_lines`: lipjax.inputs.is_lidar_pattern
    of the frame's samples; FLIP_SCAN_LINES)."""
    if flip is not None:
        return flip
    return FLIP_SCAN_LINES and scan_lines and isinstance(completer, Completer)


def one_frame(rgb: np.ndarray, sparse_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """lipjax.inputs.check_inputs of one frame: rgb (H, W, 3) uint8 or float32 in [0, 1], sparse (H, W) float32 m;
    InputError for a batch."""
    rgb, sparse, batched = check_inputs(rgb, sparse_m)
    if batched:
        raise InputError(f"one frame at a time: rgb (H, W, 3) and sparse (H, W), got rgb {np.shape(rgb)}; loop over "
                         "a batch, or call the completer itself at one size")
    return rgb[0], sparse[0]


def plan_frame(completer, sparse_m: np.ndarray, max_side: int | None = None, *, flip: bool | None = None,
               cross_check: bool = CROSS_CHECK, spread: bool = SPREAD_RESIDUALS, size: tuple[int, int] | None = None,
               scan_lines: bool | None = None) -> FramePlan:
    """The `FramePlan` of `completer` on a frame with checked (H, W) samples `sparse_m` (metres; `one_frame`): the
    pattern asked once (`sample_pattern`; `scan_lines` when the caller knows it), and from it the working size
    (`frame_size`; `size` instead when given, `max_side` to cap it), the model's initial estimate, flip averaging
    (`flips`: `flip`, None for the default), residual spreading (`spread`) and the cross-check (`cross_check`,
    for a learned model on SCATTERED samples). InputError for `flip` with a completer that is not learned."""
    learned = isinstance(completer, Completer)
    if flip and not learned:
        raise InputError(f"flip averaging is for learned models; drop --flip (flip=True) for {completer.name}")
    pattern = sample_pattern(sparse_m, scan_lines)
    lines = pattern == SCAN_LINES
    return FramePlan(
        model=getattr(completer, "name", type(completer).__name__), learned=learned, shape=tuple(sparse_m.shape),
        samples=int(np.count_nonzero(sparse_m > 0)), pattern=pattern, max_side=max_side,
        size=tuple(size) if size is not None else frame_size(completer, sparse_m, max_side, scan_lines=lines),
        initial_estimate=completer.config.initial_estimate_for(lines) if learned else None,
        flip=flips(completer, lines, flip),
        spread=spread, cross_check=cross_check and learned and pattern == SCATTERED)


def complete_frame(completer, rgb: np.ndarray, sparse_m: np.ndarray, max_side: int | None = None, *,
                   flip: bool | None = None, cross_check: bool = CROSS_CHECK,
                   plan: FramePlan | None = None) -> np.ndarray:
    """Dense (H, W) float32 metres for one frame: the default path (`lipjax.complete`, `lipjax complete`), stage by
    stage as its plan (`plan_frame`) says. `max_side` caps the longer side (pixels) instead of the working size,
    `flip` and `cross_check` as in `plan_frame`; or `plan`, made for this frame already (`complete_at`).

    The final x-update runs at full size: with rho -> 0 at the measured pixels (m = 1), x = (m y + rho z) / (m + rho)
    sets every measured pixel back to its measured value (the model's own last x-update, with its learned rho, keeps
    them only approximately); for a learned model at any size, and for any completer run below full size. Any other
    completer at full size (the hand-crafted methods, lipjax.methods.CLASSICAL) is returned as it returns: IP-Basic,
    as published, replaces background returns seen through gaps in the foreground.
    """
    # 1. the input checks, before any resize could hide a size mismatch
    rgb, sparse_m = one_frame(rgb, sparse_m)
    # 2. the plan: the samples' pattern asked once, and every decision that follows from it
    if plan is None:
        plan = plan_frame(completer, sparse_m, max_side, flip=flip, cross_check=cross_check)
    # 3-4. the estimate, cross-checked where the plan says so (`estimate_frame`)
    dense = estimate_frame(completer, rgb, plan, sparse_m)
    # 5. the measured pixels set back: the final x-update with rho -> 0 where m = 1 (also under a sensor's parallax:
    #    docs/decisions/0029-set-back-under-parallax.md)
    if plan.set_back:
        measured = sparse_m > 0
        dense[measured] = sparse_m[measured]
    return dense  # lipjax.complete then: --fill-all, the expected error, --blank-unsupported (lipjax.methods)


def estimate_frame(completer, rgb: np.ndarray, plan: FramePlan, sparse_m: np.ndarray) -> np.ndarray:
    """The default path's (H, W) float32 metres before the measured pixels are set back (`complete_frame`)."""
    # 3. the estimate from a set of samples at a size (`estimate_at`): the RGB and the samples to the working size,
    #    the initial estimate, the network (flip-averaged), the resize back, the residuals spread
    estimate = functools.partial(estimate_at, completer, rgb, plan)
    # 4. with the cross-check: held-out folds, the model against the linear fill, blended where it is the worse
    if plan.cross_check:
        return crosscheck.cross_checked(estimate, sparse_m, plan.size, scan_lines=plan.scan_lines)[0]
    return estimate(sparse_m, plan.size)


def estimate_at(completer, rgb: np.ndarray, plan: FramePlan, sparse_m: np.ndarray,
                at: tuple[int, int]) -> np.ndarray:
    """z (H, W) float32 metres: `completer`'s estimate from the (H, W) samples `sparse_m` (the frame's, or those a
    cross-check fold keeps) run at `at` (h, w). Below full size the RGB is area-resized, the samples move onto the
    small grid (`reproject_sparse`), the model runs there (from its initial estimate of the plan's pattern, computed on
    the host; averaged with the flipped frame's estimate with plan.flip), its estimate is resized back (bilinear)
    and, with plan.spread, the samples' residuals y - z are spread over it (`lipjax.spread`; scan lines get their
    own sigmas). Measured pixels are not set back here (`complete_frame` does it, after any cross-check).
    (Carrying the prox's correction over to a full-size linear fill, F * bilinear(z / f), was tried instead of
    bilinear(z): it was worse on every synthetic setting of benchmarks/working_resolution.py, 0.83 against 0.67 x
    linear on 352x1216 streets with 64 beams.)"""
    import cv2

    run = model_run(completer, plan)
    if at == sparse_m.shape:
        return np.array(run(rgb, sparse_m), np.float32)
    small_rgb = cv2.resize(rgb, at[::-1], interpolation=cv2.INTER_AREA)
    small = np.asarray(run(small_rgb, reproject_sparse(sparse_m, at)), np.float32)
    z = cv2.resize(small, sparse_m.shape[::-1], interpolation=cv2.INTER_LINEAR)
    return spread_on_host(z, sparse_m, at, plan.scan_lines) if plan.spread else z


def model_run(completer, plan: FramePlan) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """(rgb, sparse) -> depth at their size, as the plan runs `completer`: a learned model told the frame's pattern
    (its input checks and its initial estimate then take it rather than asking lipjax.inputs.is_lidar_pattern of the
    resized map), `flip_averaged` with plan.flip; any other completer as it is."""
    if not plan.learned:
        return completer
    if plan.flip:
        return functools.partial(flip_averaged, completer, scan_lines=plan.scan_lines)
    return functools.partial(completer, scan_lines=plan.scan_lines)


def complete_at(completer, rgb: np.ndarray, sparse_m: np.ndarray, size: tuple[int, int], *,
                flip: bool | None = None, cross_check: bool = CROSS_CHECK,
                spread: bool = SPREAD_RESIDUALS, scan_lines: bool | None = None) -> np.ndarray:
    """Dense (H, W) float32 metres for one frame, `completer` run at `size` (h, w) rather than at its working size:
    `complete_frame` with the plan of `plan_frame(..., size=size)` (`flip`, `cross_check`, `spread` and
    `scan_lines` as there), for benchmarks that sweep the size or turn a stage off."""
    rgb, sparse_m = one_frame(rgb, sparse_m)  # before any resize could hide a size mismatch
    plan = plan_frame(completer, sparse_m, flip=flip, cross_check=cross_check, spread=spread, size=size,
                      scan_lines=scan_lines)
    return complete_frame(completer, rgb, sparse_m, plan=plan)


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


def flip_averaged(completer: Completer, rgb: np.ndarray, sparse_m: np.ndarray,
                    scan_lines: bool | None = None) -> np.ndarray:
    """(z(I, y) + flip(z(flip(I), flip(y)))) / 2 for one frame, rgb (h, w, 3) and sparse (h, w) metres: the model's
    estimate averaged with its estimate of the flipped frame, flipped back (`scan_lines`: the frame's pattern,
    as `Completer.__call__` takes it). On the CPU the two run side by side in two threads, as XLA runs a model on
    about one core (lip-any on the 352x1216 street at 132x455, training paused: 32 ms in two threads, 52 ms as one
    batch of two, 26 ms for one frame); elsewhere as one batch of two."""
    run = completer if scan_lines is None else functools.partial(completer, scan_lines=scan_lines)
    if jax.default_backend() != "cpu":
        both = run(np.stack([rgb, rgb[:, ::-1]]), np.stack([sparse_m, sparse_m[:, ::-1]]))
        return 0.5 * (both[0] + both[1][:, ::-1])
    flipped = _FLIP_BESIDE.submit(quietly, run, rgb[:, ::-1], sparse_m[:, ::-1])  # checked as the frame is
    z = run(rgb, sparse_m)
    return 0.5 * (z + flipped.result()[:, ::-1])
