"""The ONNX export against `lipjax.complete` on real-size frames: |depth difference| per frame, in millimetres.

Run by hand (never a test; needs onnxruntime):

    python -m benchmarks.onnx_check [--model NAME] [--realdata ../shared/realdata] [--out DIR]
    python -m benchmarks.onnx_check --scattered [--model NAME] [--frames 5]

Default: the KITTI frames under --realdata (read here, never copied into the repository), cropped to 352x1216 as
the depth-completion selection (protocol kitti_selection), the HDL-64 pattern drawn on their ground truth as
benchmarks/baselines.py does (LidarSampler.hdl64(), seed 0); the model (default: the default outdoor one, lip-any)
exported at 352x1216 (`lipjax export`'s default --samples), run under onnxruntime (CPU) and compared with
`lipjax.complete(rgb, sparse, model)`.
Printed per frame: samples, median, 99th percentile and max |ONNX - complete| over all pixels, in mm.

--scattered: synthetic rooms (lipjax.data renders, test split) at 480x640 with 200 uniform points, where a model
whose initial estimate is "linear" or "auto" runs from the Delaunay fill under lipjax.complete but from the nearest
fill in the graph (default model: the default indoor one; lip-any, "auto"). Printed per room: the RMSE against the
rendered depth (metres) of the ONNX graph, of lipjax.complete with the model as shipped and with its nearest twin
(lipjax.onnx_export.nearest_twin) without the check against the linear fill (cross_check=False, which the graph
does not hold), and |ONNX - each|; then the mean RMSEs.
"""
from __future__ import annotations

import argparse
import os
import tempfile

import numpy as np

from benchmarks.common import REALDATA, load_kitti
from lipjax.data.protocols import KITTI_SELECTION
from lipjax.data.sampling import LidarSampler, UniformSampler
from lipjax.methods import complete, get_completer
from lipjax.onnx_export import export_onnx, nearest_twin
from lipjax.shipped import DEFAULT_MODELS


def _session(path: str):
    import onnxruntime as ort

    return ort.InferenceSession(path, providers=["CPUExecutionProvider"])


def _stats_mm(a: np.ndarray, b: np.ndarray) -> str:
    d = np.abs(a.astype(np.float64) - b) * 1e3
    return f"median {np.median(d):.3f} mm, p99 {np.percentile(d, 99):.2f} mm, max {d.max():.1f} mm"


def kitti(model: str, root: str, out: str) -> None:
    frames = [KITTI_SELECTION(s) for s in load_kitti(os.path.join(root, "kitti"))]
    h, w = frames[0].shape
    completer = get_completer(model)
    written = export_onnx(completer, os.path.join(out, "kitti.onnx"), height=h, width=w)
    print(written.summary())
    session = _session(os.fspath(written.path))
    for frame in frames:
        sparse = LidarSampler.hdl64()(frame, 0)
        got, = session.run(None, {"rgb": frame.rgb[None], "sparse": sparse[None]})
        expected = complete(frame.rgb, sparse, model=completer)
        print(f"{frame.id}: {int((sparse > 0).sum())} samples; |ONNX - lipjax.complete|: "
              f"{_stats_mm(got[0], expected)}")


def scattered(model: str, frames: int, out: str) -> None:
    from lipjax.data.synthetic import render

    completer = get_completer(model)
    written = export_onnx(completer, os.path.join(out, "room.onnx"), height=480, width=640, samples=200,
                          scan_lines=False)
    print(written.summary())
    session = _session(os.fspath(written.path))
    methods = (("ONNX", None), ("lipjax.complete as shipped", completer),
               ("lipjax.complete, nearest twin", nearest_twin(completer)))
    errors = {label: [] for label, _ in methods}
    for i in range(frames):
        frame = render("indoor", "test", i, 480, 640)
        sparse = UniformSampler(200)(frame, 0)
        got, = session.run(None, {"rgb": frame.rgb[None], "sparse": sparse[None]})
        valid = frame.valid & (frame.depth > 0)
        line = []
        for label, c in methods:
            depth = got[0] if c is None else complete(frame.rgb, sparse, model=c, cross_check=c is completer)
            errors[label].append(float(np.sqrt(np.mean((depth[valid] - frame.depth[valid]) ** 2))))
            line.append(f"{label} RMSE {errors[label][-1]:.4f} m" + ("" if c is None else
                                                                    f", |ONNX - it| {_stats_mm(got[0], depth)}"))
        print(f"room {i}: " + "; ".join(line))
    print("mean RMSE over the rooms: " + ", ".join(f"{k} {np.mean(v):.4f} m" for k, v in errors.items()))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", help="default: the default outdoor model (KITTI), indoor (--scattered)")
    ap.add_argument("--realdata", default=REALDATA)
    ap.add_argument("--scattered", action="store_true")
    ap.add_argument("--frames", type=int, default=5, help="--scattered: rooms of the test split")
    ap.add_argument("--out", help="folder for the .onnx files (default: a temporary one)")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        out = args.out or tmp
        if args.scattered:
            scattered(args.model or DEFAULT_MODELS["indoor"], args.frames, out)
        else:
            kitti(args.model or DEFAULT_MODELS["outdoor"], os.path.abspath(args.realdata), out)


if __name__ == "__main__":
    main()
