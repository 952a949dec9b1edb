"""Validation of a completer's inputs, shared by every method (learned, classical, exported): one set of rules
and one set of messages, each naming the problem.

    rgb, sparse, batched = check_inputs(rgb, sparse)    # (H, W, 3) or (B, H, W, 3); uint8 or float in [0, 1]
    rgb, sparse = check_frame(rgb, sparse)              # exactly one (H, W, 3) uint8 frame (classical methods)
    check_for_model(sparse, max_depth_m=10.0, name="lip-ad-indoor")   # units, range and pattern vs the model
    scene = suggest_scene(sparse)                       # "indoor" | "outdoor": which default model fits the input
    scene, why = scene_reason(sparse)                   # and the evidence, in words

Sparse depth is float metres with 0 = no sample. A unit mistake that is near certain raises InputError; one that is
only probable, or data unlike what the model was trained on, gives a one-line `warnings.warn` naming the likely
cause (the same text for every frame, so a folder of frames warns once):

    median sample depth > 1000 m                          error: not metres (the likely unit: `unit_hint`)
    median > 10x the model's range (10 m / 85 m)          error: not metres (the likely unit) for this model
    indoor model, a quarter of the samples beyond 10 m    warning: outdoor data (scan lines, or samples beyond
                                                          39 m): use the outdoor model; else a millimetre (Kinect)
                                                          PNG read with --depth-scale 256, or outdoor data
    indoor model, samples in LiDAR scan lines             warning: trained on scattered points, not scan lines
                                                          (none for a model whose training included scan lines)
    outdoor model, median beyond 85 m or max beyond 340 m warning: centimetres given as metres?
    outdoor model, all within 10 m, no scan lines         warning: looks like indoor data
    outdoor model, a dense map within 39 m                warning: a millimetre PNG read with --depth-scale 256?
    samples 4x sparser than the sparsest training input   warning: expect larger errors
    a depth PNG's scale puts over 5 % beyond 85 m         warning: the known scale that fits (`check_depth_scale`,
                                                          called by the file readers, which know the scale)
"""
from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Callable, Iterator

import numpy as np

from lipjax.data.folder import KNOWN_DEPTH_SCALES
from lipjax.defaults import SCAN_LINE_COLUMN_RATIO, SCAN_LINE_ROW_GAP_PX, SCAN_LINE_ROW_SHARE
from lipjax.interfaces import SCENE_MAX_DEPTH_M
from lipjax.resolution import dense_from
from lipjax.shipped import DEFAULT_MODELS, available
from lipjax.utils import T, warn_user

# A sparse map whose median reaches this is not in metres (no depth sensor here measures a kilometre).
MAX_PLAUSIBLE_DEPTH_M = 1000.0
# The deepest indoor samples (Kinect, NYU v2): the range of the indoor models (lipjax.interfaces).
INDOOR_DEPTH_M = SCENE_MAX_DEPTH_M["indoor"]
# Input whose median sample depth exceeds this is outdoor data (no room is that deep).
OUTDOOR_MEDIAN_M = 12.0
# Sparsest training input of the shipped models, samples per pixel (indoor uniform:100 on 256x320, outdoor uniform:200
# on 128x416; tests/test_configs.py checks it against their configs); a warning below a quarter of it.
TRAINED_MIN_DENSITY = {"indoor": 100 / (256 * 320), "outdoor": 200 / (128 * 416)}
# Indoor depth (<= 10 m) stored in millimetres but read with --depth-scale 256 reaches at most this.
KINECT_AT_256_M = INDOOR_DEPTH_M * KNOWN_DEPTH_SCALES["nyu"] / KNOWN_DEPTH_SCALES["kitti"]
# Median sample depth of real scenes with a margin, metres: rooms (Kinect, NYU: 1-5 m) and streets (a car's LiDAR:
# about 10-20 m). A unit that puts a median in its scene's range is a likely unit; `unit_hint` names it.
SCENE_MEDIAN_M = {"indoor": (0.5, 8.0), "outdoor": (3.0, 60.0)}
TYPICAL_MEDIAN_M = {"indoor": 2.5, "outdoor": 15.0}  # the unit nearest to it (in ratio) is named first
UNITS_PER_METRE = {"millimetres": 1000, "centimetres": 100}
# The deepest depth any model here completes (the outdoor models' range): nearly all of a street's samples lie within.
PNG_DEPTH_LIMIT_M = max(SCENE_MAX_DEPTH_M.values())
# A PNG scale that puts more than this share of the samples beyond PNG_DEPTH_LIMIT_M is wrong (`check_depth_scale`).
BEYOND_LIMIT_SHARE = 0.05
# What a PNG at each known scale holds, for the warning that names the scale that fits.
SCALE_UNITS = {KNOWN_DEPTH_SCALES["kitti"]: "KITTI's 256 per metre", KNOWN_DEPTH_SCALES["nyu"]: "millimetres",
               KNOWN_DEPTH_SCALES["tum"]: "TUM's 5000 per metre"}


class InputError(ValueError):
    """Bad input to a completer: the message names the problem."""


def check_inputs(rgb, sparse, max_depth_m: float | None = None, name: str = "this model",
                 scan_lines_trained: bool = False, both_scenes: bool = False, *,
                 scan_lines: bool | None = None) -> tuple[np.ndarray, np.ndarray, bool]:
    """Validates and batches inputs. Returns (rgb (B,H,W,3) uint8|float32, sparse (B,H,W) float32, was_batched).

    Raises InputError for: a wrong rank or channel count, an rgb dtype other than uint8 / float in [0, 1],
    mismatching sizes, non-float sparse depth (a raw PNG), NaN / inf or negative depth, an image without any
    sample, and depth that is clearly not metres. With `max_depth_m`, the range (metres) of the model `name`,
    also `check_for_model` (scan_lines_trained: the model's training input included LiDAR scan lines;
    both_scenes: it was trained on rooms and streets; scan_lines: the samples' pattern, where the caller knows it).
    """
    rgb = np.asarray(rgb)
    sparse = np.asarray(sparse)
    batched = rgb.ndim == 4
    if rgb.ndim not in (3, 4) or rgb.shape[-1] != 3:
        raise InputError(f"rgb must be (H, W, 3) or (B, H, W, 3), got shape {rgb.shape}")
    if rgb.dtype != np.uint8 and not np.issubdtype(rgb.dtype, np.floating):
        raise InputError(f"rgb must be uint8 (0-255) or float in [0, 1], got dtype {rgb.dtype}")
    if np.issubdtype(rgb.dtype, np.floating) and (not np.isfinite(rgb).all() or rgb.min() < 0 or rgb.max() > 1):
        raise InputError("float rgb must be finite and in [0, 1]; pass uint8 for 0-255 images")
    if sparse.ndim != rgb.ndim - 1:
        raise InputError(f"sparse depth must be (H, W) or (B, H, W) to match rgb {rgb.shape}, got {sparse.shape}")
    if sparse.shape != rgb.shape[:-1]:
        raise InputError(f"shape mismatch: sparse depth {sparse.shape} and rgb {rgb.shape[:-1]} differ in size; "
                         "align them first")
    if not np.issubdtype(sparse.dtype, np.floating):
        raise InputError(f"sparse depth must be float metres, got dtype {sparse.dtype} (raw PNG? divide by its scale)")
    if not np.isfinite(sparse).all():
        raise InputError("sparse depth contains NaN or inf; use 0 for missing samples")
    if (sparse < 0).any():
        raise InputError("sparse depth contains negative values; depth is in metres with 0 = missing")
    if not batched:
        rgb, sparse = rgb[None], sparse[None]
    empty = [i for i in range(sparse.shape[0]) if not (sparse[i] > 0).any()]
    if empty:
        raise InputError(f"sparse depth is empty: no samples (all zeros) in image(s) {empty}; nothing to complete")
    median = float(np.median(sparse[sparse > 0]))
    if median > MAX_PLAUSIBLE_DEPTH_M:
        raise InputError(f"sparse depth has a median of {median:.0f}: not metres ({unit_hint_of(sparse)})")
    if max_depth_m is not None:
        check_for_model(sparse, max_depth_m, name, scan_lines_trained, both_scenes, scan_lines)
    if np.issubdtype(rgb.dtype, np.floating):
        rgb = rgb.astype(np.float32)
    return rgb, sparse.astype(np.float32), batched


def check_frame(rgb, sparse) -> tuple[np.ndarray, np.ndarray]:
    """Validates one frame (check_inputs' rules, plus: unbatched, rgb uint8). Returns (rgb (H,W,3), sparse (H,W))."""
    rgb = np.asarray(rgb)
    if rgb.ndim != 3:
        raise InputError(f"rgb must be one (H, W, 3) frame, got shape {rgb.shape}")
    if rgb.dtype != np.uint8:
        raise InputError(f"rgb must be uint8 (0-255), got {rgb.dtype}")
    rgb, sparse, _ = check_inputs(rgb, sparse)
    return rgb[0], sparse[0]


def is_lidar_pattern(sparse: np.ndarray) -> bool:
    """Whether the samples of a (H, W) map lie in LiDAR scan lines: most samples have a neighbour in their row
    (SCAN_LINE_ROW_SHARE) at most 4 px away (SCAN_LINE_ROW_GAP_PX, the median), and samples in a column are at least
    twice as far apart as in a row (SCAN_LINE_COLUMN_RATIO; lipjax.defaults). The default path asks it once per frame
    (lipjax.inference.plan_frame); flatnonzero and the early returns keep it ~1 ms on a KITTI scan and ~0.1 ms on 200
    points."""
    sparse = np.asarray(sparse)
    rows, cols = np.divmod(np.flatnonzero(sparse > 0), sparse.shape[-1])  # row-major, as np.nonzero
    in_row = (cols[1:] - cols[:-1])[rows[1:] == rows[:-1]]  # consecutive samples of one row
    if rows.size == 0 or in_row.size < rows.size * SCAN_LINE_ROW_SHARE:
        return False
    row_gap = float(np.median(in_row))
    if row_gap > SCAN_LINE_ROW_GAP_PX:
        return False
    order = np.lexsort((rows, cols))
    rows, cols = rows[order], cols[order]
    in_col = (rows[1:] - rows[:-1])[cols[1:] == cols[:-1]]
    return in_col.size == 0 or float(np.median(in_col)) >= SCAN_LINE_COLUMN_RATIO * row_gap


def suggest_scene(sparse: np.ndarray) -> str:
    """"outdoor" when the (H, W) or (B, H, W) samples (metres) look outdoor (median over OUTDOOR_MEDIAN_M, or
    LiDAR scan lines), else "indoor": which default model to use."""
    return scene_reason(sparse)[0]


def scene_reason(sparse: np.ndarray) -> tuple[str, str]:
    """(suggest_scene's answer, why, a few words naming the evidence: "median sample depth 23.1 m", ...)."""
    sparse = np.asarray(sparse, np.float32)
    samples = sparse[sparse > 0]
    if sparse.ndim not in (2, 3) or samples.size == 0:
        return "indoor", "no samples to judge"  # the input checks will name the problem
    median = float(np.median(samples))
    if median > OUTDOOR_MEDIAN_M:
        return "outdoor", f"median sample depth {median:.1f} m, over {OUTDOOR_MEDIAN_M:g} m"
    if any(is_lidar_pattern(s) for s in sparse.reshape((-1,) + sparse.shape[-2:])):
        return "outdoor", f"samples in LiDAR scan lines, median depth {median:.1f} m"
    return "indoor", f"scattered samples, median depth {median:.1f} m"


def likely_units(samples: np.ndarray, lidar: bool) -> list[tuple[str, int]]:
    """The units ("millimetres", 1000) or ("centimetres", 100) that depth samples (> 0) given as metres but far too
    large are likely in, the likelier first; none when neither fits.

    A unit fits when it puts the samples' median in the range of median depths of real scenes (SCENE_MEDIAN_M):
    streets for samples in LiDAR scan lines (`lidar`); else rooms, then streets (scattered samples are mostly a
    depth camera's, in millimetres). Of two that fit, the one nearer (in ratio) the scene's TYPICAL_MEDIAN_M comes
    first: a median of 3000 in scan lines is 30 m in centimetres (a street) before 3 m in millimetres; scattered,
    it is 3 m in millimetres (a room), and 30 m fits no room. (Raw KITTI PNG values, 256 per metre, are not
    inferred: they read as centimetres.)"""
    median = float(np.median(samples))
    for scene in ("outdoor",) if lidar else ("indoor", "outdoor"):
        low, high = SCENE_MEDIAN_M[scene]
        fits = sorted((abs(np.log(median / per_metre / TYPICAL_MEDIAN_M[scene])), unit, per_metre)
                      for unit, per_metre in UNITS_PER_METRE.items() if low <= median / per_metre <= high)
        if fits:
            return [(unit, per_metre) for _, unit, per_metre in fits]
    return []


def unit_hint(samples: np.ndarray, lidar: bool) -> str:
    """`likely_units` as a hint: "centimetres? divide by 100", "millimetres? divide by 1000", both ("millimetres?
    divide by 1000; centimetres? by 100"), or, when neither fits, the rule."""
    units = likely_units(samples, lidar)
    if not units:
        return "divide by its units per metre: 100 for centimetres, 1000 for millimetres"
    return "; ".join(f"{unit}? {'divide by' if i == 0 else 'by'} {per_metre}"
                     for i, (unit, per_metre) in enumerate(units))


def unit_hint_of(sparse: np.ndarray) -> str:
    """`unit_hint` of a (H, W) or (B, H, W) sparse map, scan lines or not judged from its frames."""
    sparse = np.asarray(sparse)
    lidar = any(is_lidar_pattern(s) for s in sparse.reshape((-1,) + sparse.shape[-2:]))
    return unit_hint(sparse[sparse > 0], lidar)


def check_depth_scale(depth_m: np.ndarray, scale: float) -> None:
    """Warns (one line, the same for every frame) when a PNG depth map read at `scale` (value per metre, the
    --depth-scale) puts more than BEYOND_LIMIT_SHARE of its samples beyond PNG_DEPTH_LIMIT_M, naming the known
    scale (KNOWN_DEPTH_SCALES) that would put them within it: e.g. a millimetre PNG read at 256 (KITTI's) reaches
    3.9x its depth, 300 m for a street. A scale too large (depth too near) is not judged: no depth is too near."""
    samples = np.asarray(depth_m)[np.asarray(depth_m) > 0]
    if samples.size == 0 or np.mean(samples > PNG_DEPTH_LIMIT_M) <= BEYOND_LIMIT_SHARE:
        return
    raw = samples.astype(np.float64) * scale
    fitting = [s for s in sorted(SCALE_UNITS)
               if s > scale and np.mean(raw / s > PNG_DEPTH_LIMIT_M) <= BEYOND_LIMIT_SHARE]
    fix = (f"{SCALE_UNITS[fitting[0]]}? --depth-scale {fitting[0]:g} fits it" if fitting
           else "give the PNG's value per metre as --depth-scale")
    _warn(f"depth PNG read with --depth-scale {scale:g} puts over {100 * BEYOND_LIMIT_SHARE:g} % of its samples "
          f"beyond {PNG_DEPTH_LIMIT_M:g} m, the deepest range of any model: {fix}")


def _other_model(name: str, scene: str) -> str:
    """The shipped model of `scene` named like `name` (lip-cnn-indoor -> lip-cnn-outdoor), else the default."""
    other = {"indoor": "outdoor", "outdoor": "indoor"}[scene]
    shipped_like = name.endswith(f"-{other}") and "/" not in name and "\\" not in name
    twin = name[: -len(other)] + scene
    return twin if shipped_like and twin in available() else DEFAULT_MODELS[scene]


def check_for_model(sparse: np.ndarray, max_depth_m: float, name: str = "this model",
                    scan_lines_trained: bool = False, both_scenes: bool = False,
                    scan_lines: bool | None = None) -> None:
    """Compares checked (B, H, W) or (H, W) sparse depth (metres) with what a model of range `max_depth_m` was
    trained on: raises InputError where a unit mistake is near certain, warns (one line) where it is probable or
    the input is unlike the training data. See the module docstring for the rules. scan_lines_trained: the
    model's training input included LiDAR scan lines (lipjax.inference.Completer.scan_lines_trained), so scan
    lines are no warning for it. both_scenes: the model was trained on rooms and streets (with scan lines), so only
    the unit checks and the density warning apply. scan_lines: whether the samples lie in LiDAR scan lines, where
    the caller knows it (the default path's plan of the full-size frame); None: `is_lidar_pattern` is asked."""
    sparse = np.asarray(sparse)
    samples = sparse[sparse > 0]
    median = float(np.median(samples))
    if median > 10 * max_depth_m:
        raise InputError(f"sparse depth has a median of {median:.0f} m, over 10x the {max_depth_m:g} m range of "
                         f"{name}: not metres ({unit_hint_of(sparse)})")
    indoor = max_depth_m <= INDOOR_DEPTH_M
    if scan_lines is None:
        scan_lines = any(is_lidar_pattern(s) for s in sparse.reshape((-1,) + sparse.shape[-2:]))
    lidar, density = scan_lines, samples.size / sparse.size
    if both_scenes:
        if median > max_depth_m or samples.max() > 4 * max_depth_m:
            _warn(f"sparse depth far beyond the {max_depth_m:g} m range of {name}: centimetres given as metres? "
                  "divide by 100")
    elif indoor:
        outdoor_model = _other_model(name, "outdoor")
        if np.quantile(samples, 0.75) > max_depth_m and (lidar or samples.max() > KINECT_AT_256_M):
            _warn(f"sparse depth beyond the {max_depth_m:g} m range of the indoor model {name}: looks like outdoor "
                  f"data, use {outdoor_model}")
        elif np.quantile(samples, 0.75) > max_depth_m:
            _warn(f"sparse depth beyond the {max_depth_m:g} m range of the indoor model {name}: a millimetre PNG "
                  f"(Kinect, NYU) read with --depth-scale 256 (use 1000), or outdoor data (use {outdoor_model})?")
        elif lidar and not scan_lines_trained:
            _warn(f"samples in LiDAR scan lines, but the indoor model {name} was trained on scattered points: "
                  f"{outdoor_model} was trained on scan lines")
    elif median > max_depth_m or samples.max() > 4 * max_depth_m:
        _warn(f"sparse depth far beyond the {max_depth_m:g} m range of {name}: centimetres given as metres? "
              "divide by 100")
    elif not lidar and samples.max() <= INDOOR_DEPTH_M:
        _warn(f"every sample within {INDOOR_DEPTH_M:g} m and no LiDAR scan lines: looks like indoor data, use "
              f"{_other_model(name, 'indoor')}")
    elif not lidar and samples.size >= dense_from(sparse.size) and samples.max() <= KINECT_AT_256_M:
        _warn(f"a dense depth map within {KINECT_AT_256_M:.0f} m: a millimetre PNG (Kinect, NYU) read with "
              f"--depth-scale 256 (use 1000), or indoor data (use {_other_model(name, 'indoor')})?")
    if both_scenes:  # the sparser of the two scenes' inputs
        trained = min(TRAINED_MIN_DENSITY.values())
    else:
        trained = TRAINED_MIN_DENSITY["indoor" if indoor else "outdoor"]
    if density < trained / 4:
        _warn(f"samples on under a quarter as many pixels as in the sparsest input {name} was trained on "
              f"({100 * trained:.2g} % of the pixels): expect larger errors")


_QUIET = contextvars.ContextVar("lipjax_quiet_input_checks", default=False)


@contextlib.contextmanager
def quiet_checks() -> Iterator[None]:
    """Within: the input checks raise as ever but do not warn (a second look at a frame whose checks already spoke,
    lipjax.crosscheck's held-out runs). Unlike warnings.catch_warnings it leaves the filters alone, whose every
    change makes Python forget which warnings it has shown (a folder of frames would warn on every frame)."""
    token = _QUIET.set(True)
    try:
        yield
    finally:
        _QUIET.reset(token)


def quietly(fn: Callable[..., T], *args) -> T:
    """fn(*args) within `quiet_checks`: a second look at a frame, run in a thread of its own (a new thread does not
    inherit the caller's context, so it must say itself that its checks are quiet)."""
    with quiet_checks():
        return fn(*args)


def _warn(message: str) -> None:
    if not _QUIET.get():
        warn_user(message)  # at the user's line, past check_for_model, check_inputs, the completer, complete_at
