"""Validation of a completer's inputs, shared by every method (learned, classical, exported): one set of rules
and one set of messages, each naming the problem.

    rgb, sparse, batched = check_inputs(rgb, sparse)    # (H, W, 3) or (B, H, W, 3); uint8 or float in [0, 1]
    rgb, sparse = check_frame(rgb, sparse)              # exactly one (H, W, 3) uint8 frame (classical methods)

Sparse depth is float metres with 0 = no sample.
"""
from __future__ import annotations

import numpy as np

# A sparse map reaching this is not in metres (no depth sensor here measures a kilometre); likely millimetres.
MAX_PLAUSIBLE_DEPTH_M = 1000.0


class InputError(ValueError):
    """Bad input to a completer: the message names the problem."""


def check_inputs(rgb, sparse) -> tuple[np.ndarray, np.ndarray, bool]:
    """Validates and batches inputs. Returns (rgb (B,H,W,3) uint8|float32, sparse (B,H,W) float32, was_batched).

    Raises InputError for: a wrong rank or channel count, an rgb dtype other than uint8 / float in [0, 1],
    mismatching sizes, non-float sparse depth (a raw PNG), NaN / inf or negative depth, an image without any
    sample, and depth that is clearly not metres.
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
        raise InputError(f"sparse depth is empty: no samples (all zeros) in image(s) {empty}; nothing to complete from")
    if sparse.max() > MAX_PLAUSIBLE_DEPTH_M:
        raise InputError(f"sparse depth reaches {sparse.max():.0f}: that is not metres (millimetres? divide by 1000)")
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
