"""Exports a trained model for a fixed input shape: as serialised StableHLO (`jax.export`, here), or as one ONNX
graph with the initial estimate and the resizes inside (lipjax.onnx_export, for onnxruntime: the deployment format).

    completer = lipjax.load_model("lip-ad-indoor")
    exported = export_completer(completer, batch=1, height=480, width=640)
    save_exported(exported, "lip-ad-indoor_1x480x640.stablehlo")
    run = load_exported("lip-ad-indoor_1x480x640.stablehlo")
    kind = completer.config.initial_estimate                           # "linear": a fill computed on the host
    z0 = lipjax.model.host_initial_estimate(kind, sparse_f32_bhw)      # (B, H, W) float32 metres
    depth = run(rgb_uint8_bhw3, sparse_f32_bhw, z0)                    # (B, H, W) float32 metres

or from the shell: `lipjax export --model lip-ad-indoor --height 480 --width 640 --out model.stablehlo`, which runs
`export(model, out, height=..., width=...)`: the extension of `out` chooses the format (EXPORT_FORMATS: .stablehlo
or .onnx; anything else is an error before the model loads). The choices below are the StableHLO export's; the
ONNX export's are in lipjax.onnx_export.

Choices:
  - The parameters are baked into the program as constants, so the file is the whole model: nothing else to
    ship or keep in step, and the function takes only the images. Re-export after retraining. (The file size is
    about the parameter count x 4 bytes.)
  - The signature is fixed: rgb uint8 (B, H, W, 3), sparse float32 (B, H, W) in metres with 0 = no sample ->
    dense depth float32 (B, H, W) metres, clamped at 0 like `Completer.__call__`. B, H, W are those given at
    export; another size needs another export. Any H, W works (the network pads to a multiple of 8 inside).
  - Models whose initial estimate is computed on the host (`initial_estimate="linear"`, `"nearest"` or `"auto"`: a
    Delaunay triangulation is not a jit-able program) take a third input z0 float32 (B, H, W) metres, that
    fill of `sparse`: `lipjax.model.host_initial_estimate(kind, sparse)` or any equivalent implementation. Every
    shipped LIP model is one of them (`ExportedCompleter.needs_z0`); the others take `run(rgb, sparse)`.
  - No input checks run inside the exported program (a sparse map in millimetres or all zeros gives garbage,
    not an error); `load_exported`'s callable checks shapes and dtypes only. Use `lipjax.inputs.check_inputs`
    where lipjax is installed.
  - Platforms: by default the platform of the exporting machine (`jax.export.default_export_platform()`);
    pass `platforms=("cpu", "cuda")` for a file that runs on either.

Serialising needs the `flatbuffers` package (an optional dependency of jax). Running it needs only jax, not
this package (`load_exported` is a convenience around exactly this):

    import jax, numpy as np
    exported = jax.export.deserialize(open("model.stablehlo", "rb").read())
    depth = np.asarray(exported.call(rgb_uint8, sparse_f32, z0_f32))   # without z0 when len(exported.in_avals) == 2
"""
from __future__ import annotations

import dataclasses
import os
import pathlib
from collections.abc import Sequence

import jax
import jax.numpy as jnp
import numpy as np

from lipjax.inference import Completer
from lipjax.methods import get_completer
from lipjax.onnx_export import OnnxFile, export_onnx, need_onnx

EXPORT_FORMATS = {".stablehlo": "serialised StableHLO for jax.export, which JAX runs",
                  ".onnx": "one ONNX graph, initial estimate and resizes inside, which onnxruntime runs"}
"""The formats `export` writes, by the extension of its output file."""


def export_completer(completer: Completer, batch: int, height: int, width: int,
                     platforms: Sequence[str] | None = None) -> jax.export.Exported:
    """Lowers the completer's inference function for inputs (batch, height, width) with its parameters baked in."""
    for name, value in (("batch", batch), ("height", height), ("width", width)):
        if int(value) < 1:
            raise ValueError(f"{name} must be >= 1, got {value}")
    config = completer.config
    params = jax.tree_util.tree_map(jnp.asarray, completer.params)

    specs = [jax.ShapeDtypeStruct((batch, height, width, 3), jnp.uint8),
             jax.ShapeDtypeStruct((batch, height, width), jnp.float32)]
    names = config.host_input_names  # host-computed inputs (the LIP model's z0) become extra inputs
    specs += [jax.ShapeDtypeStruct((batch, height, width), jnp.float32) for _ in names]

    def infer(rgb, sparse, *extra):
        depth, _ = config.apply(params, rgb, sparse, **dict(zip(names, extra)))
        return jnp.maximum(depth, 0.0)

    return jax.export.export(jax.jit(infer), platforms=platforms)(*specs)


def _need_flatbuffers() -> None:
    try:
        import flatbuffers  # noqa: F401 - jax.export's (de)serialisation imports it lazily
    except ImportError:
        raise ImportError("saving or loading an exported model needs the 'flatbuffers' package: "
                          "pip install flatbuffers") from None


def save_exported(exported: jax.export.Exported, path: str | os.PathLike) -> pathlib.Path:
    """Writes `exported.serialize()` to `path` (parent folders created)."""
    _need_flatbuffers()
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(exported.serialize())
    return path


@dataclasses.dataclass(frozen=True)
class ExportedCompleter:
    """A deserialised exported model, a `lipjax.interfaces.DepthCompleter` of fixed shape:
    `(rgb uint8 (B,H,W,3), sparse float32 (B,H,W) metres[, z0]) -> depth (B,H,W)`."""

    exported: jax.export.Exported
    name: str = "exported"

    @property
    def input_shape(self) -> tuple[int, int, int]:
        """(B, H, W) the model was exported for."""
        return tuple(int(d) for d in self.exported.in_avals[1].shape)  # type: ignore[return-value]

    @property
    def needs_z0(self) -> bool:
        """Whether the model takes a host-computed initial estimate z0 (B, H, W) metres as a third input."""
        return len(self.exported.in_avals) == 3

    def __call__(self, rgb: np.ndarray, sparse: np.ndarray, z0: np.ndarray | None = None) -> np.ndarray:
        rgb, sparse = np.asarray(rgb), np.asarray(sparse)
        b, h, w = self.input_shape
        if rgb.shape != (b, h, w, 3) or rgb.dtype != np.uint8:
            raise ValueError(f"this exported model takes rgb uint8 {(b, h, w, 3)}, got {rgb.dtype} {rgb.shape}")
        if sparse.shape != (b, h, w) or not np.issubdtype(sparse.dtype, np.floating):
            raise ValueError(f"this exported model takes sparse float32 metres {(b, h, w)}, "
                             f"got {sparse.dtype} {sparse.shape}")
        args = [rgb, sparse.astype(np.float32)]
        if self.needs_z0:
            if z0 is None or np.shape(z0) != (b, h, w):
                raise ValueError(f"this exported model also takes z0 float32 {(b, h, w)} metres, its initial "
                                 "estimate of sparse (lipjax.model.host_initial_estimate with the model's "
                                 "initial_estimate)")
            args.append(np.asarray(z0, np.float32))
        return np.asarray(self.exported.call(*args))


def load_exported(path: str | os.PathLike) -> ExportedCompleter:
    """Deserialises a file written by `save_exported`; the callable runs with jax only (no lipjax model code)."""
    _need_flatbuffers()
    blob = pathlib.Path(path).read_bytes()
    try:
        exported = jax.export.deserialize(bytearray(blob))
    except Exception as exc:  # noqa: BLE001 - flatbuffer / version errors all mean "not a usable export file"
        raise ValueError(f"{os.fspath(path)!r} is not a jax.export file this jax can read "
                         f"({type(exc).__name__}: {exc})") from exc
    return ExportedCompleter(exported, pathlib.Path(path).stem)


def export_format(path: str | os.PathLike) -> str:
    """The extension of `path` when it names a format of EXPORT_FORMATS; ValueError naming them otherwise."""
    suffix = pathlib.Path(path).suffix.lower()
    if suffix not in EXPORT_FORMATS:
        known = ", ".join(f"{ext} ({what})" for ext, what in EXPORT_FORMATS.items())
        raise ValueError(f"--out {os.fspath(path)}: unknown export format {suffix or '(no extension)'!r}; give it "
                         f"one of these extensions: {known}")
    return suffix


@dataclasses.dataclass(frozen=True)
class ExportedFile:
    """What `export` wrote: the file, the exported program, and the model's host-side initial estimate ("linear",
    "nearest"), which the program then takes as a third input z0; None when it takes two inputs."""

    path: pathlib.Path
    exported: jax.export.Exported
    z0_kind: str | None

    def summary(self) -> str:
        """One line: the file, its size and the program's signature (shapes, dtypes, metres) and platforms."""
        shape = tuple(int(d) for d in self.exported.in_avals[1].shape)
        z0 = (f", z0 float32 {shape} m (the model's {self.z0_kind} fill of sparse, computed outside: "
              "lipjax.model.host_initial_estimate)") if self.z0_kind else ""
        return (f"wrote {self.path} ({self.path.stat().st_size} bytes): rgb uint8 {shape + (3,)}, sparse float32 "
                f"{shape} m{z0} -> depth m; platforms {list(self.exported.platforms)}")


def export(model, out: str | os.PathLike, *, height: int, width: int, batch: int = 1, iterations: int | None = None,
           platforms: Sequence[str] | None = None, samples: int | None = None, scattered: bool = False,
           flip: bool | None = None) -> ExportedFile | OnnxFile:
    """Exports a learned model (anything lipjax.methods.get_completer takes; None: the default model) for inputs
    (batch, height, width) pixels into `out`, whose extension chooses the format (`export_format`). `platforms`
    applies to .stablehlo, `samples` (per frame) and `scattered` (points, not LiDAR scan lines), which set the
    working size, and `flip` (lipjax.complete's flip averaging in the graph; None: on scan lines), to .onnx.

    Raises ValueError for an unknown extension, an option of the other format or a hand-crafted fill (nothing
    learned to export), ImportError without the flatbuffers (.stablehlo) or onnx (.onnx) package; all before the
    model loads."""
    onnx = export_format(out) == ".onnx"
    other_format, other_options = (".stablehlo", {"--platforms": platforms}) if onnx else \
        (".onnx", {"--samples": samples, "--scattered": scattered or None, "--flip": flip or None})
    for flag, value in other_options.items():
        if value is not None:
            raise ValueError(f"{flag} applies to {other_format} exports only; drop it for {os.fspath(out)}")
    need_onnx() if onnx else _need_flatbuffers()
    completer = get_completer(model, iterations)
    if not isinstance(completer, Completer):
        raise ValueError(f"--model {completer.name}: a hand-crafted fill has no learned model to export; export a "
                         "shipped model (lipjax models) or a saved model path")
    if onnx:
        return export_onnx(completer, out, height=height, width=width, batch=batch, samples=samples,
                           scan_lines=not scattered, flip=flip)
    exported = export_completer(completer, batch, height, width, platforms=platforms)
    path = save_exported(exported, out)
    return ExportedFile(path, exported, completer.config.initial_estimate if len(exported.in_avals) == 3 else None)
