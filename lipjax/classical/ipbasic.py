r"""IP-Basic depth completion (Ku, Harakeh, Waslander, CRV 2018, "In Defense of Classical Image Processing: Fast
Depth Completion on the CPU"), as published in kujason/ip_basic (MIT), `fill_in_fast` and `fill_in_multiscale`,
re-implemented here from their description with the same OpenCV operations.

Both work on inverted depth d' = D_max - d (D_max = `max_depth_m`, 100 m as in the original) with 0 = empty:
morphological dilation takes the maximum, so where dilated regions meet the NEAREST surface wins and foreground
edges stay sharp. A value at or below 0.1 counts as empty, in depth and in inverted depth, as in the original.

`ip_basic` (the original `fill_in_fast`):
  1. invert the samples;
  2. dilate with the 5x5 diamond kernel;
  3. close (dilate, then erode) with a 5x5 full kernel;
  4. fill empty pixels from a 7x7 full dilation;
  5. extrapolate=True only: extend each column's topmost value up to row 0, then fill the pixels still empty
     from a 31x31 full dilation;
  6. 5x5 median blur, then a bilateral filter (d = 5 px, sigma_color 1.5 m, sigma_space 2 px) or, for
     blur_type='gaussian', a 5x5 Gaussian blur kept on non-empty pixels only;
  7. re-invert.

`ip_basic_multiscale` (the original `fill_in_multiscale`): samples are dilated per depth bin with a cross kernel
sized for the bin (3x3 beyond 30 m, 5x5 for (15, 30] m, 7x7 up to 15 m; nearer bins overwrite farther), closed
(5x5 full), median-blurred on non-empty pixels, holes below each column's topmost value filled from a 9x9 full
dilation, optionally extended to the top row, then six 5x5 full dilations into the remaining empty pixels below
the top, a median blur and a bilateral filter (sigma_color 0.5 m) or Gaussian blur, all restricted to non-empty
pixels below the top; re-inverted.

Deviations from the original, which only touch inputs it does not handle: samples farther than `max_depth_m`
are ignored (the original inverts them to negative values, lost at the first dilation or returned as negative
depth), pixels left empty are 0 = no depth (the original returns the leftover inverted value there, which is 0
unless a sample lay within 0.1 m of `max_depth_m`), blur_type 'none' names the original's "any other value"
(median blur only), and the input is not modified.

With extrapolate=False (the default) nothing is filled above the topmost sample of each column, and holes wider
than the kernels reach stay empty: the output has 0 there.

`ip_basic_adaptive` is this library's variant for inputs sparser than KITTI's LiDAR, where the original's fixed
kernels leave most pixels empty. It fills every pixel:
  - D_max = 1.1 * (largest sample) + 1 m (so no sample is lost), bilateral colour sigma 2 % of D_max;
  - elliptic diamond |dy| / r_y + |dx| / r_x <= 1 and (2 r_y + 1) x (2 r_x + 1) full kernels instead of the 5x5
    ones, with radii from the data: for every pixel in the bounding box of the samples, the vector (dy, dx) to
    its nearest sample; r_y and r_x are the 75th percentiles of |dy| and |dx|, rounded up, clipped to [1, 64]
    px ((2, 1) for a 64-beam scan at 256x320, (8, 1) for a 16-beam scan, (9, 9) for 200 uniform points);
  - the top-row extension (on by default) comes right after the closing, and the hole fill (a full kernel of
    radii ~1.5 r) repeats until no pixel is empty.
"""
from __future__ import annotations

import dataclasses

import cv2
import numpy as np
from scipy import ndimage

from lipjax.inputs import check_frame

MAX_DEPTH_M = 100.0
EMPTY_M = 0.1  # depth and inverted depth at or below this count as empty (the original's threshold)
BLUR_TYPES = ("bilateral", "gaussian", "none")
BILATERAL_SIGMA_COLOR_M = {"fast": 1.5, "multiscale": 0.5}  # range sigma of the final bilateral filter
BILATERAL_DIAMETER_PX = 5
BILATERAL_SIGMA_SPACE_PX = 2.0
MULTISCALE_BINS_M = ((30.0, np.inf, 1), (15.0, 30.0, 2), (EMPTY_M, 15.0, 3))  # (lo, hi], cross radius; far first
MULTISCALE_HOLE_PASSES = 6

MIN_RADIUS_PX = 1
MAX_RADIUS_PX = 64
RADIUS_PERCENTILE = 75.0


def diamond_kernel(ry: int, rx: int | None = None) -> np.ndarray:
    """(2 ry + 1, 2 rx + 1) uint8 kernel, 1 where |dy| / ry + |dx| / rx <= 1 (rx defaults to ry)."""
    rx = ry if rx is None else rx
    dy, dx = np.mgrid[-ry : ry + 1, -rx : rx + 1]
    return (np.abs(dy) * rx + np.abs(dx) * ry <= rx * ry).astype(np.uint8)  # integer form, no rounding


def full_kernel(ry: int, rx: int | None = None) -> np.ndarray:
    """(2 ry + 1, 2 rx + 1) uint8 kernel of ones (rx defaults to ry)."""
    rx = ry if rx is None else rx
    return np.ones((2 * ry + 1, 2 * rx + 1), np.uint8)


def cross_kernel(r: int) -> np.ndarray:
    """(2 r + 1, 2 r + 1) uint8 kernel, 1 on the centre row and the centre column."""
    k = np.zeros((2 * r + 1, 2 * r + 1), np.uint8)
    k[r, :] = k[:, r] = 1
    return k


def _check_options(max_depth_m: float, blur_type: str) -> None:
    """Raises ValueError for a max depth that leaves no range or an unknown blur type."""
    if not max_depth_m > EMPTY_M:
        raise ValueError(f"max_depth_m must be above {EMPTY_M} m, got {max_depth_m}")
    if blur_type not in BLUR_TYPES:
        raise ValueError(f"blur_type must be one of {BLUR_TYPES}, got {blur_type!r}")


def _samples_in_range(sparse: np.ndarray, max_depth_m: float) -> np.ndarray:
    """(H, W) float32 metres with the samples outside (0.1, max_depth_m] set to 0; ValueError if none is left."""
    sparse = np.asarray(sparse, np.float32)
    if sparse.ndim != 2:
        raise ValueError(f"sparse depth must be one (H, W) map in metres, got shape {sparse.shape}")
    usable = (sparse > EMPTY_M) & (sparse <= max_depth_m)
    if not usable.any():
        far = f" (farthest {sparse.max():.1f} m: raise max_depth_m)" if sparse.max() > max_depth_m else ""
        raise ValueError(f"sparse depth has no sample in ({EMPTY_M}, {max_depth_m:g}] m{far}; nothing to fill from")
    return np.where(usable, sparse, 0.0).astype(np.float32)


def _invert(depth_m: np.ndarray, max_depth_m: float) -> np.ndarray:
    """Inverted depth D_max - d on non-empty pixels, unchanged elsewhere (float32)."""
    return np.where(depth_m > EMPTY_M, max_depth_m - depth_m, depth_m).astype(np.float32)


def _reinvert(inv: np.ndarray, max_depth_m: float) -> np.ndarray:
    """Depth D_max - d' in metres on non-empty pixels, 0 (no depth) elsewhere (float32)."""
    return np.where(inv > EMPTY_M, max_depth_m - inv, 0.0).astype(np.float32)


def _replace(inv: np.ndarray, where: np.ndarray, values: np.ndarray) -> np.ndarray:
    """inv with `values` at the pixels `where` (float32)."""
    return np.where(where, values, inv).astype(np.float32)


def _top_rows(inv: np.ndarray) -> np.ndarray:
    """(W,) row of each column's topmost non-empty pixel; 0 for an empty column."""
    return np.argmax(inv > EMPTY_M, axis=0)


def _below_top(inv: np.ndarray) -> np.ndarray:
    """(H, W) bool, False above each column's topmost non-empty pixel."""
    return np.arange(inv.shape[0])[:, None] >= _top_rows(inv)[None, :]


def _extend_to_top(inv: np.ndarray) -> np.ndarray:
    """inv with each column's topmost non-empty value copied into every row above it."""
    top = _top_rows(inv)
    top_values = inv[top, np.arange(inv.shape[1])]
    return _replace(inv, ~_below_top(inv), top_values[None, :])


def _final_blur(inv: np.ndarray, blur_type: str, sigma_color_m: float, mask: np.ndarray | None) -> np.ndarray:
    """The last smoothing: bilateral (5 px, sigma_color_m, 2 px), Gaussian 5x5 on non-empty pixels, or none.

    mask: the pixels the blur may change (None: all); the Gaussian changes only the non-empty ones among them.
    """
    if blur_type == "bilateral":
        blurred = cv2.bilateralFilter(inv, BILATERAL_DIAMETER_PX, sigma_color_m, BILATERAL_SIGMA_SPACE_PX)
        return blurred if mask is None else _replace(inv, mask, blurred)
    if blur_type == "gaussian":
        non_empty = inv > EMPTY_M if mask is None else (inv > EMPTY_M) & mask
        return _replace(inv, non_empty, cv2.GaussianBlur(inv, (5, 5), 0))
    return inv


def ip_basic(
    sparse: np.ndarray, *, max_depth_m: float = MAX_DEPTH_M, extrapolate: bool = False, blur_type: str = "bilateral"
) -> np.ndarray:
    """The original IP-Basic `fill_in_fast` (see the module docstring): (H, W) metres, 0 = no sample -> (H, W)
    float32 metres, 0 where it leaves no depth.

    Args:
      max_depth_m: D_max of the inversion, metres; farther samples are ignored.
      extrapolate: extend each column's topmost value to the top row and fill large holes (31x31).
      blur_type: "bilateral" (the original's default), "gaussian" or "none" (median blur only).
    """
    _check_options(max_depth_m, blur_type)
    inv = _invert(_samples_in_range(sparse, max_depth_m), max_depth_m)
    inv = cv2.dilate(inv, diamond_kernel(2))
    inv = cv2.morphologyEx(inv, cv2.MORPH_CLOSE, full_kernel(2))
    inv = _replace(inv, inv < EMPTY_M, cv2.dilate(inv, full_kernel(3)))
    if extrapolate:
        inv = _extend_to_top(inv)
        inv = _replace(inv, inv < EMPTY_M, cv2.dilate(inv, full_kernel(15)))
    inv = cv2.medianBlur(inv, 5)
    inv = _final_blur(inv, blur_type, BILATERAL_SIGMA_COLOR_M["fast"], mask=None)
    return _reinvert(inv, max_depth_m)


def _multiscale_dilation(depth_m: np.ndarray, inv: np.ndarray) -> np.ndarray:
    """inv overwritten by the per-bin cross dilations, far bin first, so nearer bins win where they overlap."""
    out = inv
    for lo, hi, radius in MULTISCALE_BINS_M:
        in_bin = (depth_m > lo) & (depth_m <= hi)
        dilated = cv2.dilate(np.where(in_bin, inv, 0.0).astype(np.float32), cross_kernel(radius))
        out = _replace(out, dilated > EMPTY_M, dilated)
    return out


def ip_basic_multiscale(
    sparse: np.ndarray, *, max_depth_m: float = MAX_DEPTH_M, extrapolate: bool = False, blur_type: str = "bilateral"
) -> np.ndarray:
    """The original IP-Basic `fill_in_multiscale` (see the module docstring): (H, W) metres, 0 = no sample ->
    (H, W) float32 metres, 0 where it leaves no depth. Arguments as for `ip_basic`.
    """
    _check_options(max_depth_m, blur_type)
    depth = _samples_in_range(sparse, max_depth_m)
    inv = _multiscale_dilation(depth, _invert(depth, max_depth_m))
    inv = cv2.morphologyEx(inv, cv2.MORPH_CLOSE, full_kernel(2))
    inv = _replace(inv, inv > EMPTY_M, cv2.medianBlur(inv, 5))
    inv = _replace(inv, ~(inv > EMPTY_M) & _below_top(inv), cv2.dilate(inv, full_kernel(4)))
    if extrapolate:
        inv, below_top = _extend_to_top(inv), np.ones(inv.shape, bool)
    else:
        below_top = _below_top(inv)
    for _ in range(MULTISCALE_HOLE_PASSES):
        inv = _replace(inv, (inv < EMPTY_M) & below_top, cv2.dilate(inv, full_kernel(2)))
    blur_mask = (inv > EMPTY_M) & below_top
    inv = _replace(inv, blur_mask, cv2.medianBlur(inv, 5))
    sigma = BILATERAL_SIGMA_COLOR_M["multiscale"]
    inv = _final_blur(inv, blur_type, sigma, mask=blur_mask if blur_type == "bilateral" else below_top)
    return _reinvert(inv, max_depth_m)


def auto_radii_px(sparse: np.ndarray) -> tuple[int, int]:
    """(r_y, r_x) dilation radii in pixels matched to the sample density and layout (see `ip_basic_adaptive`)."""
    sampled = sparse > 0
    ys, xs = np.nonzero(sampled)
    box = sampled[ys.min() : ys.max() + 1, xs.min() : xs.max() + 1]
    _, (iy, ix) = ndimage.distance_transform_edt(~box, return_distances=True, return_indices=True)
    gy, gx = np.mgrid[0 : box.shape[0], 0 : box.shape[1]]
    return tuple(  # type: ignore[return-value]
        int(np.clip(np.ceil(np.percentile(np.abs(d), RADIUS_PERCENTILE)), MIN_RADIUS_PX, MAX_RADIUS_PX))
        for d in (iy - gy, ix - gx)
    )


def ip_basic_adaptive(
    sparse: np.ndarray,
    *,
    radius_px: int | tuple[int, int] | None = None,
    extrapolate_top: bool = True,
    blur: str = "bilateral",
    sigma_color_m: float | None = None,
) -> np.ndarray:
    """This library's density-adaptive variant (module docstring): (H, W) float32 metres, 0 = no sample -> (H, W)
    float32 dense metres. Assumes at least one sample.

    Args:
      radius_px: diamond dilation radius in pixels, r or (r_y, r_x); None chooses them from the samples.
      extrapolate_top: extend each column's topmost filled value to row 0 before the large fill.
      blur: "bilateral", "gaussian" or "none" (after the 5x5 median).
      sigma_color_m: bilateral range sigma in metres; None = 2 % of D_max.
    """
    if blur not in BLUR_TYPES:
        raise ValueError(f"blur must be one of {BLUR_TYPES}, got {blur!r}")
    if radius_px is None:
        ry, rx = auto_radii_px(sparse)
    else:
        ry, rx = (radius_px, radius_px) if np.isscalar(radius_px) else radius_px
        ry, rx = int(ry), int(rx)
    if ry < 1 or rx < 1:
        raise ValueError(f"radius_px must be >= 1, got {radius_px}")
    sampled = sparse > 0
    d_max = 1.1 * float(sparse.max()) + 1.0
    inv = np.where(sampled, d_max - sparse, 0.0).astype(np.float32)

    inv = cv2.dilate(inv, diamond_kernel(ry, rx))
    inv = cv2.morphologyEx(inv, cv2.MORPH_CLOSE, full_kernel(ry, rx))
    if extrapolate_top:
        inv = _extend_to_top(inv)  # inverted samples are >= 1 m here, so "> 0.1" means "filled"

    big = full_kernel((3 * ry + 1) // 2, (3 * rx + 1) // 2)
    for _ in range(max(inv.shape)):  # terminates long before: each pass grows filled regions by >= 1 px
        empty = inv <= 0
        if not empty.any():
            break
        inv = np.where(empty, cv2.dilate(inv, big), inv)

    inv = cv2.medianBlur(inv, 5)
    if blur == "bilateral":
        sigma = 0.02 * d_max if sigma_color_m is None else float(sigma_color_m)
        inv = cv2.bilateralFilter(inv, 5, sigma, 2.0)
    elif blur == "gaussian":
        inv = cv2.GaussianBlur(inv, (5, 5), 0)
    return (d_max - inv).astype(np.float32)


@dataclasses.dataclass(frozen=True)
class IPBasicFill:
    """DepthCompleter: the original IP-Basic `fill_in_fast` (ignores RGB); see `ip_basic`.

    The median / bilateral filters also move the sampled pixels (mae_vs_input_m > 0), and with extrapolate=False
    pixels above the topmost sample of a column, or in holes wider than the 7x7 fill, are 0 (no depth).
    """

    name: str = "ip_basic"
    max_depth_m: float = MAX_DEPTH_M
    extrapolate: bool = False
    blur_type: str = "bilateral"

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray:
        _, sparse = check_frame(rgb, sparse)
        return ip_basic(sparse, max_depth_m=self.max_depth_m, extrapolate=self.extrapolate, blur_type=self.blur_type)


@dataclasses.dataclass(frozen=True)
class IPBasicMultiscaleFill:
    """DepthCompleter: the original IP-Basic `fill_in_multiscale` (ignores RGB); see `ip_basic_multiscale`."""

    name: str = "ip_basic_multiscale"
    max_depth_m: float = MAX_DEPTH_M
    extrapolate: bool = False
    blur_type: str = "bilateral"

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray:
        _, sparse = check_frame(rgb, sparse)
        return ip_basic_multiscale(
            sparse, max_depth_m=self.max_depth_m, extrapolate=self.extrapolate, blur_type=self.blur_type
        )


@dataclasses.dataclass(frozen=True)
class IPBasicAdaptiveFill:
    """DepthCompleter: this library's density-adaptive IP-Basic variant (ignores RGB); see `ip_basic_adaptive`.

    Fills every pixel; not exact at the samples (mae_vs_input_m > 0).
    """

    name: str = "ip_basic_adaptive"
    radius_px: int | tuple[int, int] | None = None
    extrapolate_top: bool = True
    blur: str = "bilateral"
    sigma_color_m: float | None = None

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray) -> np.ndarray:
        _, sparse = check_frame(rgb, sparse)
        return ip_basic_adaptive(
            sparse,
            radius_px=self.radius_px,
            extrapolate_top=self.extrapolate_top,
            blur=self.blur,
            sigma_color_m=self.sigma_color_m,
        )
