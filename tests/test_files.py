"""Completing folders at the model's own rate (lipjax.files.complete_files behind `lipjax complete`): the frames are
read ahead in threads and written in the background, yet the outputs are those of running the frames one by one,
in order; a failing frame stops the run with one line and nothing half-written; `--threads N` pins the process."""
import os
import pathlib
import re
import subprocess
import sys
import threading
import warnings

import cv2
import numpy as np
import pytest

import lipjax
from lipjax import cli, files, model_io
from lipjax.inference import Completer, compiled_apply
from lipjax.methods import get_completer
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset
from lipjax.utils import written_whole

from helpers import perturbed

H, W = 24, 32
SCALE = 256.0
CONFIG = LIPConfig(prior=network_preset("tiny"), num_iterations=1)
INTRINSICS = ["--intrinsics", "30", "30", "15.5", "11.5"]


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    """The path stem of a saved tiny model with perturbed weights (the network changes the depth)."""
    stem = tmp_path_factory.mktemp("model") / "tiny"
    model_io.save(stem, CONFIG, perturbed(lipjax.Completer.random(CONFIG, seed=1)).params)
    return str(stem)


def _frames(root, stems, corrupt=()):
    """rgb/<stem>.png and depth/<stem>.png (16-bit at SCALE) frames, sample (0, 0) at 1 + index metres, so a frame
    is known by its input; the RGB of the stems in `corrupt` is not a PNG."""
    for sub in ("rgb", "depth"):
        (root / sub).mkdir(parents=True)
    for i, stem in enumerate(stems):
        rng = np.random.default_rng(i)
        rgb = rng.integers(0, 256, (H, W, 3), dtype=np.uint8)
        sparse = np.where(rng.random((H, W)) < 0.1, np.round(rng.uniform(1, 5, (H, W)) * SCALE) / SCALE, 0)
        sparse[0, 0] = 1 + i
        cv2.imwrite(str(root / "depth" / f"{stem}.png"), np.round(sparse * SCALE).astype(np.uint16))
        if stem in corrupt:
            (root / "rgb" / f"{stem}.png").write_bytes(b"not a png")
        else:
            cv2.imwrite(str(root / "rgb" / f"{stem}.png"), rgb[..., ::-1])
    return root


def _complete(model, rgb, depth, out, *extra):
    return cli.main(["complete", "--rgb", str(rgb), "--depth", str(depth), "--depth-scale", "256", "--model", model,
                     "--out", str(out), *map(str, extra)])


@pytest.mark.parametrize("fmt, extra", [("png", ["--uncertainty", "U"]),
                                        ("color.png", ["--color-range", "0", "6", "--max-uncertainty", "0.5"])])
def test_a_folder_writes_what_the_frames_one_by_one_write(model, tmp_path, fmt, extra, capsys):
    """Every file of a folder run (depth, PLY, uncertainty) is byte for byte the one-frame command's, the model
    compiles once for the frames' one shape, and the summary line gives the number of frames, the time and
    frames/s."""
    stems = ["0", "1", "2", "10"]
    data = _frames(tmp_path / "in", stems)
    folder_extra = [a if a != "U" else tmp_path / "unc" for a in extra]
    assert lipjax.load_model(model).config == CONFIG  # so the model file runs the jitted function of CONFIG
    compiled = compiled_apply(CONFIG, False)._cache_size()
    assert _complete(model, data / "rgb", data / "depth", tmp_path / "out", "--out-format", fmt,
                     "--ply", tmp_path / "ply", *INTRINSICS, *folder_extra) == 0
    assert compiled_apply(CONFIG, False)._cache_size() <= compiled + 1  # four frames of one shape: one compilation
    summary = capsys.readouterr().err.strip().splitlines()[-1]
    assert re.fullmatch(rf"wrote 4 frame\(s\) to {re.escape(str(tmp_path / 'out'))} in \d+\.\d s: [\d.]+ "
                        r"frames/s(; .*)?", summary), summary
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(f"{s}.{fmt}" for s in stems)
    for stem in stems:
        one = tmp_path / "one" / stem
        one_extra = [a if a != "U" else one / "u.npy" for a in extra]
        assert _complete(model, data / "rgb" / f"{stem}.png", data / "depth" / f"{stem}.png", one / f"d.{fmt}",
                         "--ply", one / "c.ply", *INTRINSICS, *one_extra, "-q") == 0
        assert (tmp_path / "out" / f"{stem}.{fmt}").read_bytes() == (one / f"d.{fmt}").read_bytes(), stem
        assert (tmp_path / "ply" / f"{stem}.ply").read_bytes() == (one / "c.ply").read_bytes(), stem
        if "U" in extra:
            assert (tmp_path / "unc" / f"{stem}.npy").read_bytes() == (one / "u.npy").read_bytes(), stem


class _Recording:
    """A completer that notes which frame it completes (its sample at (0, 0), metres), then fills by nearest."""

    name = "recording"

    def __init__(self):
        self.fill, self.seen = get_completer("nearest"), []

    def __call__(self, rgb, sparse):
        self.seen.append(float(sparse[0, 0]))
        return self.fill(rgb, sparse)


def test_frames_run_once_each_and_are_written_in_natural_order(tmp_path):
    stems = ["a1", "a2", "a3", "a10", "a11", "a20"]
    data = _frames(tmp_path / "in", stems)
    recording = _Recording()
    done = files.complete_files(data / "rgb", data / "depth", tmp_path / "out", depth_scale=SCALE, model=recording,
                                fill_all=True, progress=False)
    assert recording.seen[0] == 1.0 and sorted(recording.seen) == [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]  # a1 a2 a3 a10 ...
    assert done.outputs == [tmp_path / "out" / f"{s}.png" for s in stems] and done.unsupported == 0
    for i, stem in enumerate(stems):
        raw = cv2.imread(str(tmp_path / "out" / f"{stem}.png"), cv2.IMREAD_UNCHANGED)
        assert raw[0, 0] == (1 + i) * SCALE


def test_reading_and_writing_overlap_the_model(tmp_path, monkeypatch):
    """The next frame is read while the model runs, and a frame is written while the model runs on the next one:
    the model waits on frame 0 until frame 1's read has begun, and frame 0's write waits until the model runs on
    frame 1. A loop that reads, completes and writes in turn would wait forever (each wait fails after 10 s)."""
    data = _frames(tmp_path / "in", ["0", "1", "2"])
    reading_1, model_on_1 = threading.Event(), threading.Event()
    real_read, real_write = files.read_frame, files.write_depth

    def read(rgb, depth, scale):
        if pathlib.Path(rgb).stem == "1":
            reading_1.set()
        return real_read(rgb, depth, scale)

    def write(path, *args):
        if pathlib.Path(path).stem == "0":
            assert model_on_1.wait(10), "frame 0 was written before the model ran on frame 1"
        real_write(path, *args)

    class Waiting(_Recording):
        def __call__(self, rgb, sparse):
            if sparse[0, 0] == 1:
                assert reading_1.wait(10), "frame 1 was not read while the model ran on frame 0"
            if sparse[0, 0] == 2:
                model_on_1.set()
            return super().__call__(rgb, sparse)

    monkeypatch.setattr(files, "read_frame", read)
    monkeypatch.setattr(files, "write_depth", write)
    model = Waiting()
    files.complete_files(data / "rgb", data / "depth", tmp_path / "out", depth_scale=SCALE, model=model,
                         progress=False)
    assert model.seen == [1.0, 2.0, 3.0] and len(list((tmp_path / "out").iterdir())) == 3


def test_after_the_first_frame_two_are_completed_at_once_and_a_failing_one_stops_the_rest(tmp_path, monkeypatch):
    """XLA runs a model on about one core, so after the first frame (alone: one compilation) a learned model
    completes MODEL_THREADS frames at once: here the second frame waits until the third has begun (one frame at a
    time, it would wait in vain). The fifth frame fails: the four before it are written, it and the sixth are not."""
    assert files.MODEL_THREADS == 2 and files.model_threads(Completer.random()) == min(2, len(os.sched_getaffinity(0)))
    assert files.model_threads(get_completer("nearest")) == 1  # fills and a user's objects: one frame at a time
    data = _frames(tmp_path / "in", ["0", "1", "2", "3", "4", "5"])
    third_begun, call = threading.Event(), Completer.__call__

    def overlapping(self, rgb, sparse, **kw):  # kw: the frame's pattern (lipjax.inference.model_run)
        if sparse[0, 0] == 2:
            assert third_begun.wait(10), "frame 1 ran alone"
        if sparse[0, 0] == 3:
            third_begun.set()
        if sparse[0, 0] == 5:
            raise RuntimeError("frame 4 fails")
        return call(self, rgb, sparse, **kw)

    monkeypatch.setattr(files, "model_threads", lambda completer: 2)  # on a 1-core machine too
    monkeypatch.setattr(Completer, "__call__", overlapping)
    with pytest.raises(RuntimeError, match="frame 4 fails"):
        files.complete_files(data / "rgb", data / "depth", tmp_path / "out", depth_scale=SCALE, cross_check=False,
                             model=Completer.random(LIPConfig(initial_estimate="nearest")), progress=False)
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["0.png", "1.png", "2.png", "3.png"]


def test_a_folder_whose_frames_all_warn_warns_once_at_the_callers_line(tmp_path, monkeypatch):
    """Frames completed in threads hold their warnings back for the calling thread, which shows them at the user's
    line: five frames beyond an untrained indoor model's 10 m range warn once, as one frame does."""
    for sub in ("rgb", "depth"):
        (tmp_path / sub).mkdir()
    for i in range(5):
        cv2.imwrite(str(tmp_path / "rgb" / f"{i}.png"), np.full((H, W, 3), 128, np.uint8))
        np.save(tmp_path / "depth" / f"{i}.npy", np.where(np.arange(H * W).reshape(H, W) % 7 == 0, 12.0, 0.0))
    monkeypatch.setattr(files, "model_threads", lambda completer: 2)
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("default")
        files.complete_files(tmp_path / "rgb", tmp_path / "depth", tmp_path / "out", fill_all=True, progress=False,
                             model=Completer.random(LIPConfig(initial_estimate="nearest")))
    ranged = [w for w in shown if "10 m range" in str(w.message)]
    assert len(ranged) == 1 and ranged[0].filename == __file__, [(str(w.message), w.filename) for w in shown]
    assert len(list((tmp_path / "out").iterdir())) == 5


def test_prefetched_keeps_the_order_and_raises_an_error_in_its_turn():
    def read(i):
        if i == 3:
            raise ValueError("frame 3 is broken")
        return i * i

    got = []
    with pytest.raises(ValueError, match="frame 3 is broken"):
        for value in files.prefetched(read, range(8), workers=3, ahead=4):
            got.append(value)
    assert got == [0, 1, 4]


def test_a_corrupt_frame_stops_the_folder_with_one_line_and_nothing_half_written(model, tmp_path, capsys):
    """The frames before the corrupt one are written whole (the one-frame command's bytes); the corrupt one and
    those after it are not written at all, and no temporary file is left."""
    stems = ["0", "1", "2", "3", "4"]
    data = _frames(tmp_path / "in", stems, corrupt={"2"})
    rc = _complete(model, data / "rgb", data / "depth", tmp_path / "out", "--ply", tmp_path / "ply", *INTRINSICS)
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip() and "frame/s" not in line and "%|" not in line]
    assert rc == 1 and lines == [f"lipjax: error: Cannot read RGB image (missing, corrupt or unsupported format): "
                                 f"{data / 'rgb' / '2.png'}"], err
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["0.png", "1.png"]
    assert sorted(p.name for p in (tmp_path / "ply").iterdir()) == ["0.ply", "1.ply"]
    for stem in ("0", "1"):
        assert _complete(model, data / "rgb" / f"{stem}.png", data / "depth" / f"{stem}.png", tmp_path / "d.png",
                         "-q") == 0
        assert (tmp_path / "out" / f"{stem}.png").read_bytes() == (tmp_path / "d.png").read_bytes()


def test_a_failing_write_stops_the_run_and_leaves_no_partial_file(tmp_path, monkeypatch):
    """A write that fails half way (a full disk) leaves neither the file nor its temporary, and the frames queued
    behind it are not written; the frames before it stay."""
    data = _frames(tmp_path / "in", ["0", "1", "2", "3"])
    real, calls = cv2.imwrite, []

    def disk_full_on_the_third(path, image, *args):
        calls.append(path)
        if len(calls) == 3:
            pathlib.Path(path).write_bytes(b"half a fi")
            raise OSError(28, "No space left on device")
        return real(path, image, *args)

    monkeypatch.setattr(cv2, "imwrite", disk_full_on_the_third)
    with pytest.raises(OSError, match="No space left"):
        files.complete_files(data / "rgb", data / "depth", tmp_path / "out", depth_scale=SCALE, model="nearest",
                             progress=False)
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["0.png", "1.png"] and len(calls) == 3


def test_written_whole_keeps_the_old_file_when_a_write_fails(tmp_path):
    target = tmp_path / "sub" / "d.npy"
    with written_whole(target) as path:
        assert path.parent == target.parent and path.name.endswith(".npy") and path != target
        np.save(path, np.ones(3, np.float32))
    with pytest.raises(RuntimeError):
        with written_whole(target) as path:
            path.write_bytes(b"garbage")
            raise RuntimeError("interrupted")
    np.testing.assert_array_equal(np.load(target), np.ones(3, np.float32))
    assert [p.name for p in target.parent.iterdir()] == ["d.npy"]


def test_threads_flag_limits_the_process_before_the_run(model, tmp_path, monkeypatch, capsys):
    """`--threads N` calls lipjax.utils.limit_cpu_threads(N) (stubbed here: pinning would pin the test session)
    and reads with at most N threads; the outputs do not change."""
    data = _frames(tmp_path / "in", ["0", "1"])
    called, workers = [], []
    monkeypatch.setattr(lipjax.utils, "limit_cpu_threads", called.append)
    real = files.prefetched
    monkeypatch.setattr(files, "prefetched", lambda read, items, n: workers.append(n) or real(read, items, n))
    assert _complete("nearest", data / "rgb", data / "depth", tmp_path / "a", "--threads", "1", "-q") == 0
    assert called == [1] and workers == [1]
    assert _complete("nearest", data / "rgb", data / "depth", tmp_path / "b", "-q") == 0
    assert called == [1] and workers == [1, files.READ_WORKERS]
    for stem in ("0", "1"):
        assert (tmp_path / "a" / f"{stem}.png").read_bytes() == (tmp_path / "b" / f"{stem}.png").read_bytes()
    assert capsys.readouterr().err == ""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="CPU affinity is Linux's")
def test_limit_cpu_threads_pins_every_thread_and_sizes_xla_and_opencv():
    """In a fresh process (pinning is for the whole process): after limit_cpu_threads(1) every thread, XLA's
    included, may run on one core only, OpenCV uses one thread and XLA's Eigen pool has at most one."""
    code = ("import os, cv2, jax.numpy as jnp; from lipjax.utils import limit_cpu_threads; "
            "cores = limit_cpu_threads(1); jnp.ones((64, 64)).sum().block_until_ready(); "
            "tasks = os.listdir('/proc/self/task'); "
            "names = [open(f'/proc/self/task/{t}/comm').read().strip() for t in tasks]; "
            "print(len(cores), cv2.getNumThreads(), sorted({len(os.sched_getaffinity(int(t))) for t in tasks}), "
            "names.count('tf_XLAEigen'))")
    env = {**os.environ, "PYTHONPATH": str(pathlib.Path(__file__).resolve().parents[1])}
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert result.returncode == 0, result.stderr
    cores, cv_threads, affinities, eigen = result.stdout.split(" ", 3)
    assert (cores, cv_threads, affinities, int(eigen) <= 1) == ("1", "1", "[1]", True), result.stdout


def test_the_summary_line_names_the_rate_the_masked_share_and_the_fitted_colours():
    two = files.Completed([pathlib.Path("o/a.png"), pathlib.Path("o/b.png")], [], pathlib.Path("o"), 0.8, 0.25,
                          (0.0, 42.0))
    assert two.summary() == ("wrote 2 frame(s) to o in 0.8 s: 2.5 frames/s; 25.0 % of the pixels without support set "
                             "to 0 (--blank-unsupported); colours 0-42 m")
    one = files.Completed([pathlib.Path("d.npy")], [pathlib.Path("c.ply")], pathlib.Path("d.npy"), 3.0, 0.0, None)
    assert one.summary() == "wrote d.npy and c.ply"
    holes = files.Completed([pathlib.Path("d.npy")], [], pathlib.Path("d.npy"), 1.0, 0.0, None, 0.357, False,
                            "ip_basic")
    assert holes.summary() == "wrote d.npy: 35.7 % of the pixels left at 0 by ip_basic (--fill-all fills them)"
    filled = files.Completed([pathlib.Path("d.npy")], [], pathlib.Path("d.npy"), 1.0, 0.0, None, 0.357, True)
    assert filled.summary() == "wrote d.npy: 35.7 % of the pixels given the nearest depth (--fill-all)"


class _Counting:
    """A completer that counts its calls (a nearest fill)."""

    name = "counting"

    def __init__(self):
        self.calls = 0

    def __call__(self, rgb, sparse):
        self.calls += 1
        return get_completer("nearest")(rgb, sparse)


@pytest.mark.parametrize("flag", ["--out", "--ply", "--uncertainty"])
def test_an_output_folder_that_cannot_be_written_fails_first_naming_it(tmp_path, monkeypatch, flag):
    """A read-only output folder (os.access says so, as on a read-only mount; root may write anywhere else) fails
    before any frame is read or completed, in one line naming the flag and the folder, for one frame and folders."""
    root = _frames(tmp_path / "in", ["a", "b"])
    locked = tmp_path / "locked"
    locked.mkdir()
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda path, mode, **kw: pathlib.Path(path) != locked and
                        real_access(path, mode, **kw))
    outputs = {"--out": tmp_path / "out", "--ply": tmp_path / "ply", "--uncertainty": tmp_path / "u"}
    outputs[flag] = locked / "sub"  # not there yet: made by the writers, so its parent decides
    completer, names = _Counting(), {"--out": "a.npy", "--ply": "a.ply", "--uncertainty": "a.npy"}
    for rgb, depth, single in ((root / "rgb", root / "depth", False), (root / "rgb/a.png", root / "depth/a.png",
                                                                      True)):
        paths = {k: v / names[k] if single else v for k, v in outputs.items()}
        with pytest.raises(ValueError) as error:
            files.complete_files(rgb, depth, paths["--out"], ply=paths["--ply"], uncertainty=paths["--uncertainty"],
                                 depth_scale=SCALE, model=completer, intrinsics=(30, 30, 15.5, 11.5), progress=False)
        message = str(error.value)
        assert message.startswith(f"{flag} {paths[flag]}: cannot write in the folder {locked} (read-only or no "
                                  f"permission); choose another {flag} or make the folder writable"), message
        assert "\n" not in message
    assert completer.calls == 0 and not (tmp_path / "out").exists()


def test_a_file_where_the_output_folder_should_be_fails_first_in_one_line(model, tmp_path, capsys):
    root = _frames(tmp_path / "in", ["a"])
    (tmp_path / "taken").write_text("a file")
    rc = _complete(model, root / "rgb" / "a.png", root / "depth" / "a.png", tmp_path / "taken" / "out.npy")
    assert rc == 1 and capsys.readouterr().err == (f"lipjax: error: --out {tmp_path / 'taken' / 'out.npy'}: "
                                                   f"{tmp_path / 'taken'} is a file, not a folder; choose another "
                                                   "--out\n")
    rc = cli.main(["project", "--rgb", str(root / "rgb" / "a.png"), "--lidar", "no-sweep.bin", "--calib", "no.txt",
                   "--out", str(tmp_path / "taken" / "sparse.npy")])  # checked before the sweep is read
    assert rc == 1 and "is a file, not a folder; choose another --out" in capsys.readouterr().err


def _scan_lines(depth_m, seed=0):
    """(H, W) samples in LiDAR scan lines (every 4th row from row 8, every 2nd column), depth_m x 0.5-2."""
    sparse = np.zeros((H, W))
    sparse[8::4, ::2] = depth_m * np.random.default_rng(seed).uniform(0.5, 2.0, sparse[8::4, ::2].shape)
    return sparse


def test_an_integer_npy_depth_is_an_error_naming_its_dtype_and_unit(tmp_path):
    """Issue 55: an int32 .npy was read as metres (depths truncated, or millimetres taken for metres) without a word.
    Depth .npy is float metres: integers are a one-line error naming the dtype, the likely unit and the fix; also
    from `complete_files`, before any model runs."""
    cv2.imwrite(str(tmp_path / "rgb.png"), np.zeros((H, W, 3), np.uint8))
    fix = "save it as float32 metres, e.g. depth.astype(np.float32) /"
    cases = {"mm.npy": (np.round(_scan_lines(15.0) * 1000).astype(np.int32),
                        "not float metres (millimetres? divide by 1000): {fix} 1000"),
             "cm.npy": (np.round(_scan_lines(15.0) * 100).astype(np.int32),
                        "not float metres (centimetres? divide by 100): {fix} 100"),
             "m.npy": (_scan_lines(15.0).astype(np.uint16), "not float metres: metres cut to whole numbers? save "
                       "the depth as float32 metres before any cast to an integer type")}
    for name, (depth, tail) in cases.items():
        tail = f"(median {np.median(depth[depth > 0]):.0f}), " + tail.format(fix=fix)
        np.save(tmp_path / name, depth)
        with pytest.raises(ValueError) as info:
            files.read_depth_frame(tmp_path / "rgb.png", tmp_path / name, None)
        assert str(info.value) == f"{tmp_path / name}: depth .npy holds {depth.dtype} (integer) values {tail}", name
    with pytest.raises(ValueError, match=r"mm\.npy: depth \.npy holds int32 \(integer\) values"):
        files.complete_files(tmp_path / "rgb.png", tmp_path / "mm.npy", tmp_path / "out.npy", model="linear",
                             progress=False)
    assert not (tmp_path / "out.npy").exists()
    np.save(tmp_path / "metres.npy", _scan_lines(15.0).astype(np.float32))  # the fix
    assert files.read_depth_frame(tmp_path / "rgb.png", tmp_path / "metres.npy", None)[1].dtype == np.float32


def test_a_millimetre_png_read_at_kittis_scale_warns_with_the_scale_that_fits(tmp_path):
    """Issue 55: a millimetre PNG of a street read with --depth-scale 256 reached 421 m, without a word."""
    cv2.imwrite(str(tmp_path / "rgb.png"), np.zeros((H, W, 3), np.uint8))
    cv2.imwrite(str(tmp_path / "mm.png"), np.round(_scan_lines(20.0) * 1000).astype(np.uint16))
    with pytest.warns(UserWarning) as caught:
        files.read_depth_frame(tmp_path / "rgb.png", tmp_path / "mm.png", 256.0)
    assert [str(w.message) for w in caught] == [
        "depth PNG read with --depth-scale 256 puts over 5 % of its samples beyond 85 m, the deepest range of any "
        "model: millimetres? --depth-scale 1000 fits it"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        files.read_depth_frame(tmp_path / "rgb.png", tmp_path / "mm.png", 1000.0)


def test_project_file_checks_the_camera_its_images_folder_names(tmp_path):
    """`lipjax project` with an image of image_3 and the default --camera 2: a one-line error naming the fix."""
    from test_calib import _street_calib, _street_sweep

    image = tmp_path / "image_3" / "000000.png"
    image.parent.mkdir()
    cv2.imwrite(str(image), np.zeros((48, 160, 3), np.uint8))
    sweep, calib = _street_sweep(tmp_path / "000000.bin"), _street_calib(tmp_path / "calib.txt")
    with pytest.raises(ValueError) as info:
        files.project_file(image, sweep, calib, tmp_path / "sparse.npy")
    assert str(info.value) == (f"{image}: its folder names KITTI camera 3 (image_3), but camera 2's projection was "
                               f"taken from {calib}: give --camera 3")
    assert files.project_file(image, sweep, calib, tmp_path / "sparse.npy", camera=3).counts.kept > 0
