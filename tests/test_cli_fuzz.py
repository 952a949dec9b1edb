"""Fuzzing `lipjax complete` (in-process, `lipjax.cli.main`) with generated bad inputs: image and depth shapes, dtypes
and file kinds, depth units, NaN / inf, empty maps, huge values, bad output names and flags. Every case ends in a
documented output (exit 0: the file --out names, in its format, and only "lipjax: warning:" / "wrote" lines on
stderr) or a one-line error (exit 1 "lipjax: error: ...", exit 2 for a usage error), never a traceback. The fill is
`linear` or `nearest`, so no case waits for a compilation."""
import contextlib
import io
import pathlib
import tempfile

import cv2
import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lipjax import cli

RGB_KINDS = ("rgb8", "grey8", "rgba8", "rgb16", "grey16", "garbage", "empty", "missing")
DEPTH_KINDS = ("npy", "png16", "png8", "garbage", "empty", "missing")
DEPTH_SHAPES = ("same", "taller", "transposed", "channels", "flat", "scalar", "zero-size")
DTYPES = ("float32", "float64", "float16", "int32", "uint16", "bool", "complex64")
VALUES = ("metres", "millimetres", "nan", "inf", "negative", "huge", "zeros", "tiny", "outdoor")
OUTPUTS = ("out.npy", "out.png", "out.color.png", "out.txt", "out", "missing-folder/out.npy")
FLAGS = (
    ("--fill-all",), ("--max-side", "4"), ("--max-side", "1"), ("--color-range", "5", "1"),
    ("--color-range", "0", "10"), ("--max-uncertainty", "0.5"), ("--max-uncertainty", "-1"),
    ("--max-uncertainty", "nan"), ("--uncertainty", "u.npy"), ("--uncertainty", "u.png"),
    ("--uncertainty", "u.txt"), ("--iterations", "2"), ("--ply", "c.ply", "--intrinsics", "10", "10", "5", "5"),
    ("--ply", "c.ply"), ("--ply", "c.ply", "--intrinsics", "0", "0", "0", "0"),
    ("--ply", "c.ply", "--intrinsics", "nan", "10", "5", "5"), ("--out-format", "npy"), ("--lidar", "x.bin"),
)
SCALES = (None, None, "256", "1000", "kitti", "0", "-5", "abc", "nan", "inf", "1e-30")


def _depth_values(kind, shape, rng):
    base = {"metres": rng.uniform(0.5, 9, shape), "millimetres": rng.uniform(500, 9000, shape),
            "nan": np.full(shape, np.nan), "inf": np.full(shape, np.inf), "negative": -rng.uniform(0.5, 9, shape),
            "huge": np.full(shape, 1e30), "zeros": np.zeros(shape), "tiny": np.full(shape, 1e-30),
            "outdoor": rng.uniform(5, 80, shape)}[kind]
    if kind in ("nan", "inf", "negative", "huge") and base.size:  # one bad value among good ones
        good = rng.uniform(0.5, 9, shape)
        good.flat[rng.integers(base.size)] = base.flat[0]
        base = good
    return base


def _write_rgb(path, kind, h, w, rng):
    if kind == "missing":
        return
    if kind in ("garbage", "empty"):
        path.write_bytes(b"" if kind == "empty" else rng.bytes(64))
        return
    channels = {"rgb8": 3, "grey8": 1, "rgba8": 4, "rgb16": 3, "grey16": 1}[kind]
    dtype = np.uint16 if kind.endswith("16") else np.uint8
    image = rng.integers(0, np.iinfo(dtype).max, (h, w, channels), dtype=dtype)
    assert cv2.imwrite(str(path), image[..., 0] if channels == 1 else image)


def _write_depth(folder, kind, shape_kind, dtype, values, density, h, w, rng):
    """Writes the sparse depth file; returns its path."""
    if kind in ("garbage", "empty", "missing"):
        path = folder / "d.npy"
        if kind != "missing":
            path.write_bytes(b"" if kind == "empty" else rng.bytes(80))
        return path
    shape = {"same": (h, w), "taller": (h + 1, w), "transposed": (w, h), "channels": (h, w, 3), "flat": (h * w,),
             "scalar": (), "zero-size": (0, w)}[shape_kind]
    depth = _depth_values(values, shape, rng)
    keep = rng.random(shape) < density
    if density > 0 and keep.size:
        keep.flat[rng.integers(keep.size)] = True  # at least one sample
    depth = np.where(keep, depth, 0)
    if kind == "npy":
        path = folder / "d.npy"
        with np.errstate(invalid="ignore", over="ignore"):
            np.save(path, depth.astype(dtype))
        return path
    path = folder / "d.png"
    bits = np.uint16 if kind == "png16" else np.uint8
    with np.errstate(invalid="ignore", over="ignore"):
        raw = np.nan_to_num(depth * 256, posinf=0, neginf=0).clip(0, np.iinfo(bits).max).astype(bits)
    if raw.ndim not in (2, 3) or raw.size == 0 or not cv2.imwrite(str(path), raw):
        path.write_bytes(b"")  # no PNG holds this shape: an empty file instead
    return path


VALID = {"rgb": "rgb8", "depth": "npy", "shape": "same", "dtype": "float32", "values": "metres", "scale": None}
FAULTS = ([("rgb", k) for k in RGB_KINDS[1:]] + [("depth", k) for k in DEPTH_KINDS[1:]]
          + [("shape", k) for k in DEPTH_SHAPES[1:]] + [("dtype", k) for k in DTYPES[1:]]
          + [("values", k) for k in VALUES[1:]] + [("scale", k) for k in SCALES[2:]])


@st.composite
def complete_cases(draw):
    """A valid frame with up to two faults (file kind, shape, dtype, unit, NaN / inf / huge values, scale), a
    sample density, an output name and up to three flags, each of which may be a fault too."""
    case = dict(VALID)
    case.update(draw(st.lists(st.sampled_from(FAULTS), max_size=2, unique_by=lambda f: f[0])))
    return {**case, "h": draw(st.integers(1, 10)), "w": draw(st.integers(1, 10)),
            "density": draw(st.sampled_from((0.05, 0.3, 1.0, 0.0))), "seed": draw(st.integers(0, 2 ** 16)),
            "out": draw(st.sampled_from(OUTPUTS)), "flags": draw(st.lists(st.sampled_from(FLAGS), max_size=3,
                                                                           unique=True)),
            "model": draw(st.sampled_from(("linear", "nearest")))}


def _check_output(path: pathlib.Path, h: int, w: int) -> None:
    """The documented --out formats: .npy float32 metres (finite, >= 0), .png 16-bit, .color.png 8-bit RGB."""
    assert path.is_file(), path
    if path.name.endswith(".color.png"):
        picture = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        assert picture.dtype == np.uint8 and picture.shape == (h, w, 3)
    elif path.suffix == ".png":
        raw = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        assert raw.dtype == np.uint16 and raw.shape == (h, w)
    else:
        depth = np.load(path)
        assert depth.dtype == np.float32 and depth.shape == (h, w) and np.isfinite(depth).all() and (depth >= 0).all()


@settings(max_examples=150, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(case=complete_cases())
def test_complete_ends_in_a_documented_output_or_a_one_line_error(case):
    rng = np.random.default_rng(case["seed"])
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        _write_rgb(folder / "rgb.png", case["rgb"], case["h"], case["w"], rng)
        depth = _write_depth(folder, case["depth"], case["shape"], case["dtype"], case["values"], case["density"],
                             case["h"], case["w"], rng)
        out = folder / case["out"]
        argv = ["complete", "--rgb", str(folder / "rgb.png"), "--depth", str(depth), "--model", case["model"],
                "--out", str(out)]
        argv += ["--depth-scale", case["scale"]] if case["scale"] else []
        for flag in case["flags"]:
            argv += [str(folder / a) if a.endswith((".npy", ".png", ".txt", ".ply", ".bin")) else a for a in flag]
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            rc = cli.main(argv)
        lines = [line for line in err.getvalue().splitlines() if line.strip()]
        assert "Traceback" not in err.getvalue(), (case, err.getvalue())
        if rc == 0:
            assert all(line.startswith(("lipjax: warning: ", "wrote ")) for line in lines), (case, lines)
            _check_output(out, case["h"], case["w"])
        elif rc == 1:
            errors = [line for line in lines if not line.startswith("lipjax: warning: ")]
            assert len(errors) == 1 and errors[0].startswith("lipjax: error: "), (case, lines)
        else:
            assert rc == 2 and len(lines) == 1 and lines[0].startswith("lipjax complete: error: "), (case, rc, lines)
        if rc != 0:  # a refused frame leaves nothing behind: no output, not even a partial one
            # (lipjax.utils.written_whole writes to ".partial-<pid>-<name>" and renames it into place)
            assert not out.exists() and not list(folder.rglob(".partial-*")), (case, sorted(folder.rglob("*")))


