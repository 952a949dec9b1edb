"""Exports a learned model as ONE self-contained ONNX graph: frame in, dense depth out, everything in between inside.

    written = export_onnx(lipjax.load_model("lip-ad-fast-outdoor"), "kitti.onnx", height=352, width=1216)
    # or: lipjax export --model lip-ad-fast-outdoor --height 352 --width 1216 --out kitti.onnx

    import onnxruntime as ort
    depth, = ort.InferenceSession("kitti.onnx").run(None, {"rgb": rgb_u8_bhw3, "sparse": sparse_m_bhw})

Signature: inputs `rgb` uint8 (B, H, W, 3) and `sparse` float32 (B, H, W) metres, 0 = no sample; output `depth`
float32 (B, H, W) metres. B, H and W are fixed at export (`--batch`, `--height`, `--width`); another size needs
another export (the resize tables below are constants of the graph).

The graph is `inference_graph`, the default path of `lipjax.complete` (lipjax.inference.complete_at) written in
jax.numpy, converted by lipjax.jaxpr_to_onnx (a translator of our own: jax2onnx pins an orbax-checkpoint older
than the one lipjax trains with, see that module):

  1. the working size (h, w) is fixed at export: lipjax.resolution.working_size of (H, W) for `samples` samples
     per frame in LiDAR scan lines (default) or scattered (`scan_lines=False`, --scattered), `export_working_size`.
     `lipjax.complete` picks it per frame from the frame's own sample count n and pattern; it is the same (h, w)
     for every n in an interval (`samples_interval`), printed and stored in the metadata. For scan lines at
     352x1216 and 480x640 that interval is every n from 234 up: the pixel cap MAX_WORKING_PIXELS decides; for
     scattered samples it ends at DENSE samples a pixel, beyond which a dense map is capped as scan lines are.
  2. rgb -> (h, w) as cv2.resize(INTER_AREA) and its uint8 rounding; sparse -> (h, w) by reprojection, the
     nearest depth winning (lipjax.resample: gathers with constant tables, mins and sums).
  3. z0, the initial estimate, in the graph: the nearest-sample fill by jump flooding (lipjax.fill.jump_flood_nearest),
     which equals the host fill `host_initial_estimate("nearest", ...)` (ties broken as scipy breaks them)
     except at a few pixels in a million (tests/test_fill.py). The host's "linear" (Delaunay) fill has no
     fixed-size program, so a model whose initial_estimate is "linear" or "auto" runs from the nearest fill in
     the graph: the same as its JAX result with the nearest fill, get that with
     `lipjax.complete(rgb, sparse, model=nearest_twin(model), cross_check=False)`. "auto" picks nearest for LiDAR
     scan lines, so for scan lines such a model's export equals lipjax.complete; for scattered points it differs
     from its linear default: on 5 synthetic rooms (480x640, 200 points) the lip-fast-indoor shipped until
     2026-12-06 had mean RMSE 0.261 m in the graph against 0.229 m through lipjax.complete, median |difference|
     11-67 mm per room (`python -m benchmarks.onnx_check --scattered`). The shipped outdoor models use "nearest":
     their export equals lipjax.complete on scan lines and, with cross_check=False, on any input (KITTI, 352x1216,
     HDL-64: median |difference| 0.002 mm, 99th percentile at most 0.71 mm; benchmarks/onnx_check.py).
  4. the model (its parameters are constants of the graph), max(depth, 0), the bilinear resize back to (H, W)
     (cv2's INTER_LINEAR), the samples' residuals spread over it where the default path spreads them
     (lipjax.spread; with the sigmas of scan lines, or of scattered samples with --scattered), and the measured
     pixels set back to their measured values. For LiDAR scan lines (and with `flip=True`, `lipjax export
     --flip`, for scattered samples) the frames and their flipped frames run as one batch of 2B, and each frame's
     two estimates are averaged after flipping the second back, as `lipjax.complete` does on scan lines (flip
     averaging, docs/decisions/0020-flip-averaging-on-scan-lines.md; `--no-flip` leaves it out, at half the model's
     work).
At h, w = H, W the resizes drop out, as in complete_at; the measured pixels are set back at any size. The check
of the model against the linear fill on held-out samples (lipjax.crosscheck; scattered samples only) is not in the
graph (it needs the Delaunay fill): the graph is `lipjax.complete(..., cross_check=False)`. No input
checks run inside the graph (check with `lipjax.inputs.check_inputs` where lipjax is installed); a frame without
samples gives zeros.
Speed (benchmarks/speed.py, 2-core machine): a KITTI frame with its flipped frame took 104 ms under onnxruntime
against 42 ms for the same computation through lipjax.complete (83 against 37 ms without the flipped frame, in an
earlier run); XLA fuses the element-wise operations that onnxruntime runs one pass each.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import os
import pathlib

import jax
import jax.numpy as jnp

from lipjax import jaxpr_to_onnx
from lipjax.defaults import SPREAD_RESIDUALS
from lipjax.fill import jump_flood_nearest
from lipjax.inference import Completer, flips
from lipjax.model import LIPConfig
from lipjax.resample import reproject_nearest, resize_area_uint8, resize_bilinear
from lipjax.resolution import dense_from, is_capped, working_size
from lipjax.spread import spread_residuals, spread_sigmas_px

INPUT_NAMES, OUTPUT_NAMES = ("rgb", "sparse"), ("depth",)
DEFAULT_SPACING_PX = 4.6  # a 64-beam scan on a KITTI frame (~20,000 samples on 352x1216): the robot / car case


def default_samples(height: int, width: int) -> int:
    """The sample count `export_onnx` plans for unless told: a 64-beam LiDAR's density, DEFAULT_SPACING_PX apart."""
    return max(1, round(height * width / DEFAULT_SPACING_PX**2))


def export_working_size(height: int, width: int, samples: int, scan_lines: bool = True) -> tuple[int, int]:
    """(h, w) at which lipjax.complete runs a learned model on an (height, width) frame of `samples` samples, in
    LiDAR scan lines or scattered."""
    if not 1 <= samples <= height * width:
        raise ValueError(f"--samples {samples}: give the number of depth samples per frame, 1 to {height * width}")
    return working_size((height, width), math.sqrt(height * width / samples),
                        capped=is_capped(samples, (height, width), scan_lines))


def samples_interval(height: int, width: int, samples: int, scan_lines: bool = True) -> tuple[int, int]:
    """(lo, hi): the sample counts n for which lipjax.complete picks the same working size as for `samples` (of
    the same pattern). Scan lines: the size never shrinks as n grows, so they are an interval, found by bisection.
    Scattered samples: the same within each of two ranges, up to DENSE samples a pixel and beyond (dense maps, capped
    at MAX_WORKING_PIXELS, lipjax.resolution.is_capped); the interval stays inside the range of `samples`."""
    size, n_max = export_working_size(height, width, samples, scan_lines), height * width
    lo_n, hi_n = 1, n_max
    if not scan_lines:
        first_dense = dense_from(n_max)  # the fewest samples of a dense map
        lo_n, hi_n = (first_dense, n_max) if samples >= first_dense else (1, min(n_max, first_dense - 1))

    def first(lo: int, hi: int, is_past) -> int:  # the smallest n in [lo, hi] with is_past(n); is_past(hi) holds
        while lo < hi:
            mid = (lo + hi) // 2
            lo, hi = (lo, mid) if is_past(mid) else (mid + 1, hi)
        return lo

    def same(n: int) -> bool:
        return export_working_size(height, width, n, scan_lines) == size

    low = first(lo_n, samples, same)
    high = first(samples, hi_n + 1, lambda n: n > hi_n or not same(n)) - 1
    return low, high


def inference_graph(completer: Completer, frame: tuple[int, int], working: tuple[int, int], *,
                    flip: bool | None = None, spread: bool = SPREAD_RESIDUALS, scan_lines: bool = True):
    """The jax function (rgb uint8 (B, H, W, 3), sparse float32 (B, H, W) m) -> depth (B, H, W) m that the ONNX
    graph is made of (the module docstring's steps 1-4); jit it to run the same computation in JAX. `flip`:
    average with the flipped frame as lipjax.complete does (None: on scan lines, lipjax.inference.flips);
    `spread`: spread the samples' residuals after the resize back, as it does (lipjax.defaults.SPREAD_RESIDUALS),
    with the sigmas of LiDAR scan lines or (`scan_lines=False`) of scattered samples
    (lipjax.spread.spread_sigmas_px)."""
    config = completer.config
    params = jax.tree_util.tree_map(jnp.asarray, completer.params)
    unknown = set(config.host_input_names) - {"z0"}
    if unknown:
        raise ValueError(f"{completer.name} needs host inputs {sorted(unknown)} that have no in-graph version")
    resized, flip = tuple(working) != tuple(frame), flips(completer, scan_lines, flip)

    def model(rgb, sparse):
        extra = {name: jump_flood_nearest(sparse) for name in config.host_input_names}
        return jnp.maximum(config.apply(params, rgb, sparse, **extra)[0], 0.0)

    def run(rgb, sparse):
        small_rgb, small = (resize_area_uint8(rgb, working) / 255.0, reproject_nearest(sparse, working)) if resized \
            else (rgb, sparse)
        if flip:  # lipjax.inference.flip_averaged, the batch and its flipped frames in one call
            turn = functools.partial(jnp.flip, axis=2)
            both = model(jnp.concatenate([small_rgb, turn(small_rgb)]), jnp.concatenate([small, turn(small)]))
            depth = 0.5 * (both[:len(small)] + turn(both[len(small):]))
        else:
            depth = model(small_rgb, small)
        if resized:
            depth = resize_bilinear(depth, frame)
            if spread:
                depth = spread_residuals(depth, sparse, spread_sigmas_px(frame, working, scan_lines))
        return jnp.where(sparse > 0, sparse, depth)

    return run


def _z0_kind(config) -> str | None:
    """The model's initial estimate when it has no in-graph form ("linear" or "auto"), else None."""
    fill = config.initial_estimate if isinstance(config, LIPConfig) else None
    return fill if fill in ("linear", "auto") else None


def nearest_twin(completer: Completer) -> Completer:
    """The model with the initial estimate its ONNX export computes: "nearest" where it is computed on the host."""
    config = completer.config
    if _z0_kind(config) is None:
        return completer
    return Completer(dataclasses.replace(config, initial_estimate="nearest"), completer.params, completer.name,
                     completer.metadata)


@dataclasses.dataclass(frozen=True)
class OnnxFile:
    """What `export_onnx` wrote: the file, the input shape (B, H, W), the working size, the sample counts for which
    that is lipjax.complete's working size, and the model's own initial estimate when the graph's nearest fill replaced
    it (else None); whether the graph averages with the flipped frame."""

    path: pathlib.Path
    shape: tuple[int, int, int]
    working: tuple[int, int]
    samples: tuple[int, int]
    replaced_z0: str | None
    flip: bool = False

    def summary(self) -> str:
        """The lines the export command prints: file and signature, the working size, the fill."""
        b, h, w = self.shape
        lines = [f"wrote {self.path} ({self.path.stat().st_size} bytes): rgb uint8 {(b, h, w, 3)}, sparse float32 "
                 f"{(b, h, w)} m -> depth float32 {(b, h, w)} m (ONNX opset {jaxpr_to_onnx.OPSET}, fixed shape)",
                 f"working size {self.working[0]}x{self.working[1]}: lipjax.complete's for {self.samples[0]} to "
                 f"{self.samples[1]} samples per frame (--samples and --scattered set it)"]
        if self.replaced_z0:
            lines.append(f"initial estimate z0: nearest, in the graph, instead of the model's {self.replaced_z0!r} "
                         "(no ONNX form): equal to lipjax.complete on LiDAR scan lines only when that is 'auto'")
        if self.flip:
            lines.append("flip averaging in the graph (--no-flip: without, at half the work): equal to "
                         "lipjax.complete(..., flip=True, cross_check=False)")
        return "\n".join(lines)


def need_onnx() -> None:
    """ImportError naming the install when the onnx package is missing (the export writes with it)."""
    try:
        import onnx  # noqa: F401
    except ImportError:
        raise ImportError("an ONNX export needs the 'onnx' package: pip install onnx onnxruntime") from None


def export_onnx(completer: Completer, out: str | os.PathLike, *, height: int, width: int, batch: int = 1,
                samples: int | None = None, scan_lines: bool = True, flip: bool | None = None) -> OnnxFile:
    """Writes the ONNX graph of `completer` for (batch, height, width) frames of `samples` samples each (default
    `default_samples`), in LiDAR scan lines or (`scan_lines=False`) scattered, to `out`; `flip` as
    lipjax.complete's (None: on scan lines, lipjax.inference.flips). ImportError without the onnx package."""
    need_onnx()
    import onnx

    for name, value in (("batch", batch), ("height", height), ("width", width)):
        if int(value) < 1:
            raise ValueError(f"{name} must be >= 1, got {value}")
    samples = default_samples(height, width) if samples is None else samples
    flip = flips(completer, scan_lines, flip)
    working = export_working_size(height, width, samples, scan_lines)
    interval = samples_interval(height, width, samples, scan_lines)
    replaced = _z0_kind(completer.config)
    metadata = {"lipjax_model": completer.name, "units": "metres; sparse 0 = no sample",
                "frame_size": f"{height}x{width}", "working_size": f"{working[0]}x{working[1]}",
                "working_size_samples": f"{interval[0]}-{interval[1]}" + ("" if scan_lines else " scattered"),
                "initial_estimate": "nearest (jump flooding, in the graph)"
                                    + (f", not {replaced}" if replaced else ""),
                "flip_averaged": str(bool(flip)).lower()}
    specs = [jax.ShapeDtypeStruct((batch, height, width, 3), jnp.uint8),
             jax.ShapeDtypeStruct((batch, height, width), jnp.float32)]
    graph = inference_graph(completer, (height, width), working, flip=flip, scan_lines=scan_lines)
    model = jaxpr_to_onnx.convert(graph, specs, INPUT_NAMES, OUTPUT_NAMES, metadata, doc=__doc__.split("\n")[0])
    path = pathlib.Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    onnx.save(model, os.fspath(path))
    return OnnxFile(path, (batch, height, width), working, interval, replaced, flip)
