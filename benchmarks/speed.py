"""ms per frame through the default path on four inputs at three frame sizes, with the matmul rate of the same run.

Run by hand (never a test):

    python -m benchmarks.speed [--models default,unchecked:default,onnx:default,lip-fast-indoor]
                               [--classical linear,nearest,ip_basic,colorization] [--repeats 5]

Frames: synthetic test renders (the test split, never trained on) at 256x320 and 480x640 with 200 uniform points
(a room), at 480x640 as a depth camera sees it (dense depth with holes, `holes:0.2`: ~240,000 samples), and at
352x1216 with the HDL-64 pattern (a KITTI-size street, ~19,000 samples). Each learned model runs
through `lipjax.inference.complete_frame`, as `lipjax complete` does: at its working size (lipjax.resolution),
host fill, solver and resizes included, on scattered samples the check against the linear fill
(lipjax.crosscheck) and on scan lines the flipped frame (lipjax.inference.flips); "unchecked:NAME" is the same
without the check (`--no-cross-check`; the flipped frame on scan lines stays). "default" is the model
`lipjax complete` picks for the frame.
"onnx:NAME" (NAME a model or "default") is that model exported for the frame's size and sample count
(lipjax.onnx_export: one graph, fill and resizes inside) and run under onnxruntime on the CPU with its default
threads, spin-waiting off (on the 2-core machine shared with a training run, the spinning threads doubled its
time: 160 against 80 ms on the street); the export and the session's start are not timed.

Columns per size: ms per frame (median of --repeats calls after a warm-up) and frames/s normalised to a 195 GFLOP/s
machine: fps * 195 / (this run's 2048^3 float32 matmul rate). The rate and the 1-minute load average are printed
first: with other processes on the cores, both the rate and the times drop.
"""
from __future__ import annotations

import argparse
import os
import tempfile

import numpy as np

from benchmarks.common import matmul_rate, median_ms
from lipjax.data.sampling import HolesSampler, LidarSampler, UniformSampler
from lipjax.data.synthetic import render
from lipjax.inference import complete_frame, frame_size
from lipjax.inputs import is_lidar_pattern
from lipjax.methods import get_completer
from lipjax.onnx_export import export_onnx

REFERENCE_GFLOPS = 195.0  # the rate the issues normalise frames/s to
SIZES = (("room 256x320, 200 pts", "indoor", 256, 320, UniformSampler(200)),
         ("room 480x640, 200 pts", "indoor", 480, 640, UniformSampler(200)),
         ("room 480x640, depth with holes", "indoor", 480, 640, HolesSampler(0.2)),
         ("street 352x1216, HDL-64", "outdoor", 352, 1216, LidarSampler.hdl64()))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--models", default="default,unchecked:default,onnx:default,lip-fast-indoor")
    ap.add_argument("--classical", default="linear,nearest,ip_basic,colorization")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)

    _, rate = matmul_rate(10)
    print(f"2048^3 float32 matmul: {rate:.0f} GFLOP/s; load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} "
          "cores\n")
    frames = []
    for title, kind, h, w, sampler in SIZES:
        frame = render(kind, "test", 0, h, w)
        frames.append((title, frame.rgb, sampler(frame, 0)))
    names = [m for m in args.models.split(",") if m] + [m for m in args.classical.split(",") if m]
    print("| method | " + " | ".join(f"{t}: ms (fps @195)" for t, _, _ in frames) + " |")
    print("|---|" + "---|" * len(frames))
    for name in names:
        cells = []
        for _, rgb, sparse in frames:
            run, label = _runner(name, rgb, sparse)
            ms = median_ms(run, args.repeats)
            cells.append(f"{ms:.0f} ({1e3 / ms * REFERENCE_GFLOPS / rate:.1f}){label}")
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


def _runner(name: str, rgb: np.ndarray, sparse: np.ndarray):
    """(a call that completes the frame, the cell's label) for a method name of --models / --classical."""
    onnx, unchecked = name.startswith("onnx:"), name.startswith("unchecked:")
    model = name.removeprefix("onnx:").removeprefix("unchecked:")
    if ":" in model:
        raise SystemExit(f"{name}: one prefix at most (onnx: or unchecked:; the ONNX graph holds no check)")
    completer = get_completer(None if model == "default" else model, sparse=sparse)
    h, w = frame_size(completer, sparse)
    label = f" [{completer.name} at {h}x{w}]" if model == "default" else ""
    if not onnx:
        return (lambda: complete_frame(completer, rgb, sparse, cross_check=not unchecked)), label
    import onnxruntime as ort

    path = os.path.join(tempfile.mkdtemp(prefix="lipjax-speed-"), "model.onnx")
    written = export_onnx(completer, path, height=sparse.shape[0], width=sparse.shape[1],
                          samples=int((sparse > 0).sum()), scan_lines=is_lidar_pattern(sparse))
    assert written.working == (h, w), (written.working, (h, w))
    options = ort.SessionOptions()
    options.add_session_config_entry("session.intra_op.allow_spinning", "0")
    session = ort.InferenceSession(path, options, providers=["CPUExecutionProvider"])
    feeds = {"rgb": rgb[None], "sparse": sparse[None].astype(np.float32)}
    return (lambda: session.run(None, feeds)), label


if __name__ == "__main__":
    main()
