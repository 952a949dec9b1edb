"""The `lipjax` command line, in-process (`lipjax.cli.main`), plus one subprocess run: outputs equal the library's,
and every user error is one line "lipjax: error: ..." with exit status 1 and no traceback."""
import json
import os
import pathlib
import re
import subprocess
import sys

import cv2
import jax
import numpy as np
import pytest

import lipjax
import lipjax.defaults
import lipjax.methods
from lipjax import cli, model_io, viz
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset
from lipjax.inference import complete_frame

from helpers import perturbed

H, W = 24, 32
SCALE = 256.0
CONFIG = LIPConfig(prior=network_preset("tiny"), num_iterations=1)

@pytest.fixture(scope="module")
def model(tmp_path_factory):
    """(path stem of a saved tiny model, the same model as a Completer)."""
    stem = tmp_path_factory.mktemp("model") / "tiny"
    c = perturbed(lipjax.Completer.random(CONFIG, seed=1))
    model_io.save(stem, CONFIG, c.params)
    return str(stem), lipjax.load_model(stem)


def _frame(seed=0, h=H, w=W):
    rng = np.random.default_rng(seed)
    rgb = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    # Values on the PNG grid (k / 256) so the PNG and npy inputs hold the same metres.
    sparse = np.where(rng.random((h, w)) < 0.1, np.round(rng.uniform(1, 5, (h, w)) * SCALE) / SCALE, 0)
    sparse[0, 0] = 2.0
    return rgb, sparse.astype(np.float32)


def _write_frame(folder, rgb, sparse, rgb_name="rgb.png", depth_name="sparse.png"):
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(folder / rgb_name), rgb[..., ::-1])
    if depth_name.endswith(".png"):
        cv2.imwrite(str(folder / depth_name), np.round(sparse * SCALE).astype(np.uint16))
    else:
        np.save(folder / depth_name, sparse)
    return str(folder / rgb_name), str(folder / depth_name)


@pytest.fixture(scope="module")
def frame(tmp_path_factory):
    """Paths of one frame on disk: rgb png, 16-bit sparse png (scale 256), sparse npy (metres); and the arrays."""
    folder = tmp_path_factory.mktemp("frame")
    rgb, sparse = _frame()
    rgb_path, png = _write_frame(folder, rgb, sparse)
    _, npy = _write_frame(folder, rgb, sparse, depth_name="sparse.npy")
    return {"rgb": rgb_path, "png": png, "npy": npy, "rgb_array": rgb, "sparse_array": sparse}


def _complete(model, frame, out, *extra, depth="npy"):
    args = ["complete", "--rgb", frame["rgb"], "--depth", frame[depth], "--model", model[0], "--out", str(out),
            "--quiet"]
    if depth == "png":
        args += ["--depth-scale", "256"]
    return cli.main(args + list(extra))


def test_png_in_png_out_same_scale_equals_library(model, frame, tmp_path):
    assert _complete(model, frame, tmp_path / "out.png", depth="png") == 0
    raw = cv2.imread(str(tmp_path / "out.png"), cv2.IMREAD_UNCHANGED)
    assert raw.dtype == np.uint16 and raw.shape == (H, W)
    expected = complete_frame(model[1], frame["rgb_array"], frame["sparse_array"])
    np.testing.assert_array_equal(raw, np.round(expected * SCALE).astype(np.uint16))


def test_npy_in_npy_out_metres_equals_library(model, frame, tmp_path):
    assert _complete(model, frame, tmp_path / "out.npy") == 0
    out = np.load(tmp_path / "out.npy")
    assert out.dtype == np.float32 and out.shape == (H, W)
    np.testing.assert_allclose(out, complete_frame(model[1], frame["rgb_array"], frame["sparse_array"]), rtol=1e-6)


def test_flip_flags_equal_the_library_with_flip_on_and_off(model, frame, tmp_path):
    """--flip and --no-flip are flip=True and False (the default, None, flips scan lines only)."""
    rgb, sparse = frame["rgb_array"], frame["sparse_array"]
    assert _complete(model, frame, tmp_path / "on.npy", "--flip") == 0
    assert _complete(model, frame, tmp_path / "off.npy", "--no-flip") == 0
    on, off = np.load(tmp_path / "on.npy"), np.load(tmp_path / "off.npy")
    np.testing.assert_allclose(on, complete_frame(model[1], rgb, sparse, flip=True), rtol=1e-6)
    np.testing.assert_allclose(off, complete_frame(model[1], rgb, sparse, flip=False), rtol=1e-6)
    assert np.abs(on - off).max() > 1e-3
    no_flag = (["complete", "--rgb", "a.png", "--out", "b.npy"], ["export", "--height", "8", "--width", "8",
                                                                   "--out", "m.onnx"])
    for command in no_flag:
        assert cli.build_parser().parse_args(command).flip is None  # no flag: the library's default decides


def test_color_png_and_ply_outputs(model, frame, tmp_path):
    rc = _complete(model, frame, tmp_path / "out.color.png", "--color-range", "0", "6",
                   "--ply", str(tmp_path / "cloud.ply"), "--intrinsics", "30", "30", "15.5", "11.5")
    assert rc == 0
    picture = cv2.imread(str(tmp_path / "out.color.png"), cv2.IMREAD_UNCHANGED)
    assert picture.dtype == np.uint8 and picture.shape == (H, W, 3)
    expected = complete_frame(model[1], frame["rgb_array"], frame["sparse_array"])
    np.testing.assert_array_equal(picture[..., ::-1], viz.colorize_depth(expected, 0, 6))
    header = (tmp_path / "cloud.ply").read_bytes().split(b"end_header\n")[0].decode()
    assert f"element vertex {np.count_nonzero(expected > 0)}" in header and "binary_little_endian" in header


def test_folder_batch_pairs_frames_by_trailing_number(model, tmp_path):
    frames = {i: _frame(seed=i) for i in (2, 10)}
    (tmp_path / "rgb").mkdir(), (tmp_path / "depth").mkdir()
    for i, (rgb, sparse) in frames.items():  # BTS-style NYU names: stems differ, numbers match
        cv2.imwrite(str(tmp_path / "rgb" / f"rgb_{i:05d}.png"), rgb[..., ::-1])
        cv2.imwrite(str(tmp_path / "depth" / f"sync_depth_{i:05d}.png"), np.round(sparse * SCALE).astype(np.uint16))
    rc = cli.main(["complete", "--rgb", str(tmp_path / "rgb"), "--depth", str(tmp_path / "depth"), "--depth-scale",
                   "kitti", "--model", model[0], "--out", str(tmp_path / "out"), "--out-format", "npy"])
    assert rc == 0
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["rgb_00002.npy", "rgb_00010.npy"]
    for i, (rgb, sparse) in frames.items():
        expected = complete_frame(model[1], rgb, sparse)
        np.testing.assert_allclose(np.load(tmp_path / "out" / f"rgb_{i:05d}.npy"), expected, rtol=1e-6)


def test_max_side_runs_downsized_and_keeps_measured_pixels_exact(model, frame, tmp_path):
    assert _complete(model, frame, tmp_path / "out.npy", "--max-side", "16") == 0
    out = np.load(tmp_path / "out.npy")
    sparse = frame["sparse_array"]
    assert out.shape == (H, W)
    np.testing.assert_array_equal(out[sparse > 0], sparse[sparse > 0])
    # The library's frame path at that size, value for value.
    expected = complete_frame(model[1], frame["rgb_array"], sparse, max_side=16)
    np.testing.assert_allclose(out, expected, rtol=1e-6, atol=1e-6)
    assert not np.allclose(out, complete_frame(model[1], frame["rgb_array"], sparse), atol=1e-3)  # it did downsize


@pytest.mark.parametrize("case, message", [
    ("unreadable_image", "Cannot read RGB image"),
    ("size_mismatch", "aligned"),
    ("png_without_scale", "--depth-scale"),
    ("empty_sparse", "empty"),
    ("unknown_model", "unknown model 'no-such-model'"),
    ("too_many_iterations", "this model has 1 iterations"),
    ("ply_without_intrinsics", "intrinsics"),
    ("zero_intrinsics", "intrinsics fx=0 fy=0 cx=0 cy=0: the focal lengths fx, fy must be > 0"),
    ("model_files_mismatch", "bad.msgpack does not match bad.json (the config makes parameters ['log_rho', 'prox'], "
                             "the file holds ['encoder'])"),
    ("model_json_bad_field", "bad.json: not a valid lipjax model config (TypeError: "),
    ("model_file_truncated", "bad.msgpack: cannot read the parameters, the file is damaged or truncated"),
    ("model_files_swapped", "bad.msgpack is not the parameter file saved with bad.json (its SHA-256 is not "
                            "params_sha256)"),
    ("depth_as_rgb", "A 16-bit single-channel PNG is a depth map, not a colour image"),
    ("no_depth", "give the sparse depth as --depth SPARSE, or a LiDAR sweep as --lidar SWEEP --calib FILE"),
])
def test_user_errors_are_one_line_without_traceback(case, message, model, frame, tmp_path, capsys):
    rgb, depth, model_arg, extra = frame["rgb"], frame["npy"], model[0], []
    if case == "unreadable_image":
        rgb = tmp_path / "broken.png"
        rgb.write_bytes(b"this is not a png")
    elif case == "size_mismatch":
        depth = tmp_path / "small.npy"
        np.save(depth, frame["sparse_array"][:-4])
    elif case == "png_without_scale":
        depth = frame["png"]
    elif case == "empty_sparse":
        depth = tmp_path / "empty.npy"
        np.save(depth, np.zeros((H, W), np.float32))
    elif case == "unknown_model":
        model_arg = "no-such-model"
    elif case == "too_many_iterations":
        extra = ["--iterations", "2"]
    elif case == "ply_without_intrinsics":
        extra = ["--ply", str(tmp_path / "x.ply")]
    elif case == "zero_intrinsics":
        extra = ["--ply", str(tmp_path / "x.ply"), "--intrinsics", "0", "0", "0", "0"]
    elif case.startswith("model_"):
        model_arg = _broken_model(case, model, tmp_path / "bad")
    elif case == "depth_as_rgb":
        rgb = frame["png"]
    depth_args = [] if case == "no_depth" else ["--depth", str(depth)]
    rc = cli.main(["complete", "--rgb", str(rgb), *depth_args, "--model", model_arg,
                   "--out", str(tmp_path / "out.npy"), *extra])
    err = capsys.readouterr().err
    assert rc == 1
    assert len(err.strip().splitlines()) == 1 and err.startswith("lipjax: error: "), err
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "out.npy").exists() and not (tmp_path / "x.ply").exists()


def _broken_model(case, model, stem):
    """Writes stem.json + stem.msgpack broken as `case` says; returns the stem."""
    good = pathlib.Path(model[0])
    doc = json.loads(good.with_name("tiny.json").read_text())
    params = good.with_name("tiny.msgpack").read_bytes()
    if case == "model_files_mismatch":  # parameters of another kind of model
        model_io.save(stem, CONFIG, {"encoder": {"kernel": np.zeros((3, 3), np.float32)}})
        return str(stem)
    if case == "model_json_bad_field":
        doc["config"]["num_iterationz"] = 2
    if case == "model_file_truncated":
        params = params[: len(params) // 2]
    if case == "model_files_swapped":  # the same architecture's parameters from another save: every value moved
        model_io.save(stem.with_name("other"), CONFIG, jax.tree_util.tree_map(lambda a: a + 1, model_io.load(good)[1]))
        params = stem.with_name("other.msgpack").read_bytes()
    stem.with_name("bad.json").write_text(json.dumps(doc))
    stem.with_name("bad.msgpack").write_bytes(params)
    return str(stem)


def test_lidar_sweep_in_completes_its_projection_and_its_calibration_serves_the_ply(model, tmp_path):
    """`complete --lidar SWEEP --calib FILE`: the output is the model's completion of project_sweep's sparse map,
    and --ply needs no --intrinsics: the calibration's give the cloud that --intrinsics FX FY CX CY and
    --intrinsics-file CALIB give from the same sparse map as --depth."""
    from lipjax.data.lidar import project_sweep
    from test_calib import CX, CY, FX, FY, _cam_from_velo, write_object_calib

    rgb, _ = _frame(seed=3, h=40, w=120)
    cv2.imwrite(str(tmp_path / "image.png"), rgb[..., ::-1])
    rng = np.random.default_rng(2)
    cam2 = np.stack([rng.uniform(-0.3, 0.3, 400), rng.uniform(-0.1, 0.1, 400), rng.uniform(2, 5, 400), np.ones(400)])
    np.save(tmp_path / "sweep.npy", (np.linalg.inv(_cam_from_velo(2)) @ cam2)[:3].T)
    calib = write_object_calib(tmp_path / "calib.txt")
    rc = cli.main(["complete", "--rgb", str(tmp_path / "image.png"), "--lidar", str(tmp_path / "sweep.npy"),
                   "--calib", str(calib), "--model", model[0], "--out", str(tmp_path / "out.npy"),
                   "--ply", str(tmp_path / "a.ply"), "-q"])
    assert rc == 0
    sparse, _ = project_sweep(tmp_path / "sweep.npy", calib, (40, 120))
    expected = lipjax.complete(rgb, sparse, model=model[1])  # the default: depth everywhere, as the library's
    np.testing.assert_allclose(np.load(tmp_path / "out.npy"), expected, rtol=1e-6)
    np.save(tmp_path / "sparse.npy", sparse)
    for ply, intrinsics in (("b.ply", ["--intrinsics", str(FX), str(FY), str(CX), str(CY)]),
                            ("c.ply", ["--intrinsics-file", str(calib)])):
        assert cli.main(["complete", "--rgb", str(tmp_path / "image.png"), "--depth", str(tmp_path / "sparse.npy"),
                         "--model", model[0], "--out", str(tmp_path / "o.npy"), "--ply", str(tmp_path / ply),
                         *intrinsics, "-q"]) == 0
        assert (tmp_path / "a.ply").read_bytes() == (tmp_path / ply).read_bytes(), ply


def test_the_default_model_is_named_with_its_reason_and_depth_scale_on_npy_warns(model, frame, tmp_path, capsys,
                                                                                monkeypatch):
    """Without --model, one line names the model chosen, the one default for every input (none with -q);
    --depth-scale with .npy depth and .npy output warns that it is ignored."""
    monkeypatch.setattr(lipjax.methods, "default_model", lambda: model[1])
    args = ["complete", "--rgb", frame["rgb"], "--depth", frame["npy"], "--out", str(tmp_path / "out.npy")]
    assert cli.main(args) == 0
    assert capsys.readouterr().err.splitlines()[0] == (
        f"model: {model[0]}, the default for every input; choose another with --model")
    assert cli.main(args + ["-q"]) == 0 and capsys.readouterr().err == ""
    assert cli.main(args + ["-q", "--depth-scale", "256"]) == 0
    assert capsys.readouterr().err == ("lipjax: warning: --depth-scale 256 is ignored: .npy depth is metres, never "
                                       "scaled (--depth-scale applies to .png depth, in and out)\n")
    assert cli.main(args[:-1] + [str(tmp_path / "out.png"), "-q", "--depth-scale", "256"]) == 0  # the PNG's scale
    assert capsys.readouterr().err == ""


def test_color_picture_range_fits_depth_beyond_the_models(model, tmp_path, capsys):
    """The tiny model's range is 10 m; samples at 20-40 m would make a solid-red picture, so the colours span
    0 .. the output's 99th percentile, and the summary line says so; --color-range still wins."""
    rgb, sparse = _frame(seed=4)
    rgb_path, npy = _write_frame(tmp_path, rgb, sparse * 8, depth_name="far.npy")
    out = tmp_path / "o.color.png"
    args = ["complete", "--rgb", rgb_path, "--depth", npy, "--model", model[0], "--out", str(out)]
    assert cli.main(args) == 0
    with pytest.warns(UserWarning, match="beyond the 10 m range"):
        dense = complete_frame(model[1], rgb, sparse * 8)
    top = np.percentile(dense[dense > 0], 99)
    assert top > model[1].config.max_depth_m == 10  # beyond the model's range: the colours fit the output
    np.testing.assert_array_equal(cv2.imread(str(out))[..., ::-1], viz.colorize_depth(dense, 0, top))
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("lipjax: warning: sparse depth beyond the 10 m range of the indoor model")
    holes = f"{100 * np.mean(dense == 0):.1f} % of the pixels left at 0 by {model[0]} (--fill-all fills them)"
    assert err[1:] == [f"wrote {out}: {holes}; colours 0-{top:.3g} m"]  # the tiny model's estimate is 0 at some
    assert cli.main(args + ["--color-range", "0", "10", "-q"]) == 0
    np.testing.assert_array_equal(cv2.imread(str(out))[..., ::-1], viz.colorize_depth(dense, 0, 10))


def test_usage_error_returns_2_with_one_line(capsys):
    assert cli.main(["complete", "--rgb", "a.png"]) == 2
    err = capsys.readouterr().err
    assert _one_error_line(err).startswith("lipjax complete: error: one of the arguments --out --explain is required")
    assert cli.main(["complete", "--depth", "a.npy", "--out", "b.npy"]) == 2
    err = capsys.readouterr().err
    assert _one_error_line(err).startswith("lipjax complete: error: the following arguments are required: --rgb")


def _one_error_line(err, prog="lipjax"):
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"{prog}") and "Traceback" not in err, err
    return lines[0]


@pytest.mark.parametrize("command", [[], ["complete"], ["project"], ["evaluate"], ["export"], ["models"], ["train"],
                                     ["data"], ["data", "render"]])
def test_help_pages_speak_to_users_not_developers(command, capsys):
    """No function or module names of the code (`_cmd_*`, build_parser, lipjax.<module>) in any --help page."""
    assert cli.main(command + ["--help"]) == 0
    page = capsys.readouterr().out
    assert page.startswith("usage: lipjax") and re.search(r"_cmd_|build_parser|lipjax\.[a-z]", page) is None, page
    if not command:  # the overview names every command and points to their pages
        assert "Run `lipjax COMMAND --help` for a command's options." in page and "--rgb     colour" not in page


def test_version(capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.build_parser().parse_args(["--version"])
    assert exit_.value.code == 0 and capsys.readouterr().out.strip() == f"lipjax {lipjax.__version__}"
    assert cli.main(["--version"]) == 0


def test_mixed_png_npy_folder_fails_before_writing_and_names_the_odd_file(model, tmp_path, capsys):
    (tmp_path / "depth").mkdir()
    for i, name in enumerate(("a.png", "b.png", "c.npy")):
        rgb, sparse = _frame(seed=i)
        _write_frame(tmp_path / "rgb", rgb, sparse, rgb_name=f"{name[0]}.png", depth_name="../depth/" + name)
    rc = cli.main(["complete", "--rgb", str(tmp_path / "rgb"), "--depth", str(tmp_path / "depth"), "--depth-scale",
                   "256", "--model", model[0], "--out", str(tmp_path / "out")])
    line = _one_error_line(capsys.readouterr().err)
    assert rc == 1 and "mixes .png and .npy" in line and "c.npy" in line and "a.png" not in line
    assert not (tmp_path / "out").exists()


def test_large_frame_prints_a_max_side_hint(model, frame, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(lipjax.defaults, "LARGE_FRAME_PIXELS", H * W - 1)
    assert _complete(model, frame, tmp_path / "out.npy") == 0
    assert "--max-side" in _one_error_line(capsys.readouterr().err, "lipjax: warning:")
    assert _complete(model, frame, tmp_path / "out.npy", "--max-side", "16") == 0
    assert capsys.readouterr().err == ""


def test_evaluate_lidar_sampler_on_a_folder_without_intrinsics_asks_for_them(tmp_path, capsys):
    rgb, sparse = _frame()
    (tmp_path / "data" / "depth").mkdir(parents=True)
    _write_frame(tmp_path / "data" / "rgb", rgb, sparse, rgb_name="0.png", depth_name="../depth/0.npy")
    rc = cli.main(["evaluate", "--method", "nearest", "--data", str(tmp_path / "data"), "--sampler", "lidar:hdl64",
                   "--max-depth-m", "10", "--quiet"])
    line = _one_error_line(capsys.readouterr().err)
    assert rc == 1 and "sampler 'lidar:hdl64' simulates a LiDAR and needs the camera intrinsics" in line
    assert "--intrinsics fx fy cx cy" in line and "intrinsics.txt" in line


def _own_data_folder(root, frames=10, names=("", "", "")):
    """rgb/ depth/ sparse/ .npy frames, no intrinsics: ground truth 2 + i / 10 m everywhere, the sparse maps hold
    it plus 1 m at 12 pixels, so a nearest fill of sparse/ is 1 m off everywhere (and 0 m off from GT samples).
    names: the stems' prefixes in rgb/, depth/, sparse/ (frames then pair by number)."""
    for sub in ("rgb", "depth", "sparse"):
        (root / sub).mkdir(parents=True)
    for i in range(frames):
        rgb, sparse = _frame(seed=i, h=12, w=16)
        depth = np.full((12, 16), 2 + i / 10, np.float32)
        cv2.imwrite(str(root / "rgb" / f"{names[0]}{i:03d}.png"), rgb[..., ::-1])
        np.save(root / "depth" / f"{names[1]}{i:03d}.npy", depth)
        np.save(root / "sparse" / f"{names[2]}{i:03d}.npy",
                np.where(np.arange(192).reshape(12, 16) % 16 == 5, depth + 1, 0))


def test_evaluate_own_folder_scores_its_sparse_maps_on_every_frame_without_intrinsics(tmp_path, capsys):
    _own_data_folder(tmp_path / "mine")
    args = ["evaluate", "--method", "nearest", "--data", str(tmp_path / "mine"), "--max-depth-m", "10", "--quiet",
            "--columns", "rmse_m", "--json", str(tmp_path / "r.json")]
    assert cli.main(args) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == (f"data: {tmp_path / 'mine'}, every frame (10 frames), sampler: input (the data's own sparse "
                      "maps), depth range: (0, 10] m")
    result = json.loads((tmp_path / "r.json").read_text())["nearest"]
    assert result["num_images"] == 10 and result["metrics"]["rmse_m"] == pytest.approx(1.0, abs=1e-5)
    assert cli.main(args + ["--split", "val"]) == 0
    assert capsys.readouterr().out.splitlines()[0] == (
        f"data: {tmp_path / 'mine'}, val split: the last 5 % of the frames, as lipjax train holds them out "
        "(1 frames), sampler: input (the data's own sparse maps), depth range: (0, 10] m")
    assert cli.main(args + ["--sampler", "uniform:20"]) == 0  # samples of the ground truth: exact
    assert json.loads((tmp_path / "r.json").read_text())["nearest"]["metrics"]["rmse_m"] == pytest.approx(0, abs=1e-6)
    capsys.readouterr()
    assert cli.main(["evaluate", "--method", "nearest", "--source", "folder", "--root", str(tmp_path / "mine"),
                     "--sampler", "input", "--max-depth-m", "10", "--quiet", "--columns", "rmse_m"]) == 0
    assert capsys.readouterr().out.splitlines()[0].startswith(f"data: folder val ({tmp_path / 'mine'}) (1 frames)")


def test_evaluate_own_folder_pairs_sparse_maps_by_number_as_it_pairs_depth(tmp_path, capsys):
    """NYU/BTS-style names (rgb_000.png, sync_depth_000.npy): the sparse maps pair with the frames by number too."""
    _own_data_folder(tmp_path / "mine", frames=3, names=("rgb_", "sync_depth_", "sync_depth_"))
    assert cli.main(["evaluate", "--method", "nearest", "--data", str(tmp_path / "mine"), "--max-depth-m", "10",
                     "--quiet", "--json", str(tmp_path / "r.json")]) == 0
    assert "every frame (3 frames), sampler: input (the data's own sparse maps)" in capsys.readouterr().out
    assert json.loads((tmp_path / "r.json").read_text())["nearest"]["metrics"]["rmse_m"] == pytest.approx(1.0)


def test_subprocess_error_has_no_traceback(tmp_path):
    (tmp_path / "broken.jpg").write_bytes(b"\xff\xd8 truncated")
    np.save(tmp_path / "s.npy", np.ones((4, 4), np.float32))
    env = dict(os.environ)  # with conftest's LIPJAX_CACHE_DIR
    env.pop("LIPJAX_DEBUG", None)
    result = subprocess.run(
        [sys.executable, "-m", "lipjax.cli", "complete", "--rgb", str(tmp_path / "broken.jpg"),
         "--depth", str(tmp_path / "s.npy"), "--out", str(tmp_path / "o.npy")],
        capture_output=True, text=True, timeout=300, env=env,
    )
    assert result.returncode == 1
    assert result.stderr.startswith("lipjax: error: ") and "Traceback" not in result.stderr, result.stderr


def test_models_command_is_a_table_in_aligned_columns_marking_every_default(capsys):
    from lipjax.shipped import DEFAULT_MODELS

    assert cli.main(["models"]) == 0
    lines = capsys.readouterr().out.splitlines()
    header, rows = lines[0], lines[1:1 + len(lipjax.available_models())]
    assert header.split() == ["MODEL", "DEFAULT", "TYPE", "ITERS", "Z0", "RANGE", "VAL", "RMSE", "VALIDATED", "ON",
                              "IMAGES", "SEEN"]
    starts = [header.index(c) for c in model_io.TABLE_COLUMNS] + [None]
    cells = [[row[a:b].strip() for a, b in zip(starts, starts[1:])] for row in rows]
    for row, cell in zip(rows, cells):  # every cell starts at its column: no text runs across a column edge
        assert all(row[a - 1] == " " for a in starts[1:-1] if a < len(row)), row
    assert [c[0] for c in cells] == lipjax.available_models() and "None" not in "".join(rows)
    defaults = {c[0]: c[1] for c in cells if c[1]}
    marks = {name: model_io.default_mark(DEFAULT_MODELS, name) for name in DEFAULT_MODELS.values()}
    assert defaults == marks  # each default marked with its scene(s), and only they
    assert model_io.default_mark({"indoor": "a", "outdoor": "a"}, "a") == "all"
    assert model_io.default_mark({"indoor": "a", "outdoor": "b"}, "b") == "outdoor"
    for c in cells:
        assert c[2].startswith("LIP, ") and c[3].isdigit() or c[3] == c[4] == "-", c
        assert c[5] in ("10 m", "85 m") and c[6].endswith(" m") and c[8].replace(",", "").isdigit(), c
    assert max(len(line) for line in lines) < 120


def test_evaluate_prints_a_markdown_table(model, tmp_path, capsys):
    rc = cli.main(["evaluate", "--model", model[0], "--method", "nearest", "--data", "synthetic-indoor",
                   "--size", str(H), str(W), "--limit", "1", "--sampler", "uniform:20", "--quiet",
                   "--columns", "rmse_m,mae_m", "--json", str(tmp_path / "r.json")])
    out = capsys.readouterr().out
    assert rc == 0
    assert "| method | rmse_m | mae_m |" in out and f"| {model[0]} |" in out and "| nearest |" in out
    assert set(json.loads((tmp_path / "r.json").read_text())) == {model[0], "nearest"}


def test_export_command_writes_a_deserializable_file(model, tmp_path):
    out = tmp_path / "m.stablehlo"
    rc = cli.main(["export", "--model", model[0], "--height", "8", "--width", "16", "--batch", "2", "--out", str(out),
                   "--quiet"])
    assert rc == 0
    exported = jax.export.deserialize(bytearray(out.read_bytes()))
    assert [a.shape for a in exported.in_avals] == [(2, 8, 16, 3), (2, 8, 16)]
    assert exported.out_avals[0].shape == (2, 8, 16)
    rgb, sparse = (np.stack(a) for a in zip(_frame(seed=5, h=8, w=16), _frame(seed=6, h=8, w=16)))
    np.testing.assert_allclose(np.asarray(exported.call(rgb, sparse)), model[1](rgb, sparse), rtol=1e-5, atol=1e-5)


def test_export_command_writes_an_onnx_graph_with_the_fill_inside(model, tmp_path, capsys):
    ort = pytest.importorskip("onnxruntime")
    out = tmp_path / "m.onnx"
    rc = cli.main(["export", "--model", model[0], "--height", str(H), "--width", str(W), "--scattered", "--out",
                   str(out)])  # _frame's samples are scattered points: no flipped frame, as lipjax.complete there
    assert rc == 0 and f"wrote {out}" in capsys.readouterr().err
    rgb, sparse = _frame()
    got, = ort.InferenceSession(str(out), providers=["CPUExecutionProvider"]).run(
        None, {"rgb": rgb[None], "sparse": sparse[None].astype(np.float32)})
    np.testing.assert_allclose(got[0], lipjax.complete(rgb, sparse, model=model[1]), rtol=1e-5, atol=1e-4)
    rc = cli.main(["export", "--height", "8", "--width", "8", "--platforms", "cpu", "--out", str(out)])
    assert rc == 1 and "--platforms applies to .stablehlo exports only" in capsys.readouterr().err


def test_evaluate_working_size_scores_what_complete_returns(model, tmp_path):
    """--working-size: the model at the samples' working size (64x80 here), measured pixels set back exactly."""
    scores = {}
    for flags in ([], ["--working-size"]):
        out = tmp_path / f"{len(flags)}.json"
        assert cli.main(["evaluate", "--model", model[0], "--data", "synthetic-indoor", "--size", "160", "200",
                         "--limit", "1", "--sampler", "uniform:20", "--quiet", "--json", str(out), *flags]) == 0
        row = json.loads(out.read_text())[model[0]]
        assert row["size"] == ("working" if flags else "input")  # the JSON says which path was scored
        scores[tuple(flags)] = row["metrics"]
    assert scores[("--working-size",)]["mae_sampled_m"] == 0.0 < scores[()]["mae_sampled_m"]
    assert scores[("--working-size",)]["rmse_m"] != scores[()]["rmse_m"]


@pytest.fixture(scope="module")
def scan_frame(tmp_path_factory):
    """A synthetic street seen by a 64-beam LiDAR (scan lines, sky above the top beam) on disk: rgb png, sparse npy;
    and the arrays."""
    from lipjax.data.sampling import LidarSampler
    from lipjax.data.synthetic.dataset import render

    street = render("outdoor", "test", 0, height=128, width=416)
    sparse = LidarSampler.hdl64(azimuth_step_deg=0.5)(street)
    rgb_path, npy = _write_frame(tmp_path_factory.mktemp("scan"), street.rgb, sparse, depth_name="sparse.npy")
    return {"rgb": rgb_path, "npy": npy, "rgb_array": street.rgb, "sparse_array": sparse}


def test_explain_prints_each_frames_plan_and_writes_nothing(model, tmp_path, capsys):
    """--explain: the plan of each frame (lipjax.inference.plan_frame), one decision a line under the frame's file:
    200 points on a room are scattered and cross-checked, a street seen by a 64-beam LiDAR is scan lines and
    flip-averaged; no model runs, nothing is written, no --out taken (-q prints it all the same). The library says
    so too (files.explain_files, and complete_files without an output)."""
    from lipjax.data.sampling import LidarSampler, UniformSampler
    from lipjax.data.synthetic.dataset import render
    from lipjax import files
    from lipjax.inference import plan_frame

    room, street = render("indoor", "test", 0, height=120, width=160), render("outdoor", "test", 0, 128, 416)
    inputs = (("room", room, UniformSampler(200)), ("street", street, LidarSampler.hdl64()))
    frames = [_write_frame(tmp_path / name, f.rgb, sampler(f), depth_name="sparse.npy") for name, f, sampler in inputs]
    shown = {}
    for (rgb, npy), pattern, on, off in zip(frames, ("scattered", "scan lines"), ("cross-check", "flip averaging"),
                                            ("flip averaging", "cross-check")):
        assert cli.main(["complete", "--rgb", rgb, "--depth", npy, "--model", model[0], "--explain", "-q"]) == 0
        printed = capsys.readouterr().out.splitlines()
        assert printed[0] == f"{rgb}:" and printed[2].startswith(f"  pattern: {pattern} (")
        assert [line for line in printed if line.startswith(f"  {on}")][0].endswith(": on")
        assert ": off" in [line for line in printed if line.startswith(f"  {off}")][0]
        assert printed[1:] == [f"  {line}" for line in plan_frame(model[1], np.load(npy)).describe()]
        shown[pattern] = printed
    assert [len(list((tmp_path / name).iterdir())) for name in ("room", "street")] == [2, 2]  # rgb.png, sparse.npy
    rgb_path, npy = frames[0]
    assert cli.main(["complete", "--rgb", rgb_path, "--depth", npy, "--explain", "--out", "o.npy"]) == 2
    assert "not allowed with" in _one_error_line(capsys.readouterr().err)
    assert files.explain_files(rgb_path, npy, model=model[0]).summary().splitlines() == shown["scattered"]
    with pytest.raises(ValueError, match="--out is required"):
        files.complete_files(rgb_path, npy, None, model=model[0])


@pytest.mark.parametrize("flag, setting", [(None, {}), ("--fill-all", {"fill_all": True}),
                                           ("--blank-unsupported", {"blank_unsupported": True})])
def test_the_written_map_is_what_lipjax_complete_returns_by_default_and_with_each_flag(flag, setting, model, frame,
                                                                                       scan_frame, tmp_path):
    """One default for the command and the library (depth as the model or method returns it), and one flag or
    argument for each change: a learned model on scattered samples, IP-Basic on scan lines (which leaves 0s)."""
    for inputs, name, completer in ((frame, model[0], model[1]), (scan_frame, "ip_basic", "ip_basic")):
        assert cli.main(["complete", "--rgb", inputs["rgb"], "--depth", inputs["npy"], "--model", name, "--out",
                         str(tmp_path / "out.npy"), "-q", *([flag] if flag else [])]) == 0
        expected = lipjax.complete(inputs["rgb_array"], inputs["sparse_array"], model=completer, **setting)
        np.testing.assert_allclose(np.load(tmp_path / "out.npy"), expected, rtol=1e-6, atol=0)
    out = np.load(tmp_path / "out.npy")  # ip_basic's
    assert (out == 0).any() == (flag != "--fill-all")  # IP-Basic leaves 0s as published; --fill-all fills them
    assert (out[:20] == 0).all() == (flag != "--fill-all")  # the sky above the top beam


def test_fill_all_fills_what_the_method_leaves_with_the_nearest_depth_and_keeps_the_rest(scan_frame):
    from lipjax.classical import IPBasicFill, nearest_fill

    rgb, sparse = scan_frame["rgb_array"], scan_frame["sparse_array"]
    own = IPBasicFill()(rgb, sparse)
    filled = lipjax.complete(rgb, sparse, model="ip_basic", fill_all=True)
    assert (own == 0).mean() > 0.1 and (filled > 0).all()
    np.testing.assert_array_equal(filled[own > 0], own[own > 0])
    np.testing.assert_array_equal(filled, nearest_fill(own))


def test_fill_all_and_blank_unsupported_contradict_in_one_line(frame, capsys):
    args = ["complete", "--rgb", frame["rgb"], "--depth", frame["npy"], "--out", "o.npy", "--model", "linear"]
    assert cli.main(args + ["--fill-all", "--blank-unsupported"]) == 2
    assert "not allowed with argument --fill-all" in _one_error_line(capsys.readouterr().err)
    with pytest.raises(ValueError, match="contradict each other; pass one of them"):
        lipjax.complete(frame["rgb_array"], frame["sparse_array"], model="linear", fill_all=True,
                        blank_unsupported=True)


@pytest.mark.parametrize("command", [
    ["complete", "--rgb", "a.png", "--out", "b.npy"],
    ["project", "--rgb", "a.png", "--lidar", "s.bin", "--calib", "c.txt", "--out", "b.npy"],
    ["evaluate"],
    ["export", "--height", "8", "--width", "8", "--out", "m.onnx"],
    ["data", "render", "--kind", "indoor", "--count", "1", "--out", "d"],
    ["train", "--data", "d", "--out", "m"],
])
def test_every_command_that_prints_progress_or_status_takes_q_and_quiet(command):
    parser = cli.build_parser()
    assert parser.parse_args(command + ["-q"]).quiet and parser.parse_args(command + ["--quiet"]).quiet
    assert not parser.parse_args(command).quiet


def test_help_pages_load_no_jax():
    """`lipjax --help` and every command's page are built without importing JAX, Flax, SciPy or OpenCV (lipjax.cli
    imports the library inside the commands; the values the pages show are lipjax.cli_help's)."""
    code = ("import sys\nfrom lipjax import cli\nfor command in ([], ['complete'], ['project'], ['evaluate'], "
            "['export'], ['models'], ['train'], ['data'], ['data', 'render']):\n"
            "    assert cli.main(command + ['--help']) == 0\n"
            "heavy = sorted({m.split('.')[0] for m in sys.modules} & {'jax', 'flax', 'scipy', 'cv2', 'optax'})\n"
            "print('loaded:', heavy, file=sys.stderr)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and result.stderr.strip().splitlines()[-1] == "loaded: []", result.stderr


def test_the_help_values_are_the_librarys():
    """lipjax.cli_help copies values of the library so that the help loads no JAX: each copy equals its source."""
    from lipjax import cli_help, evaluate, methods
    from lipjax.data import folder, protocols, sources, synthetic
    from lipjax.train import adapt, folder as train_folder

    assert cli_help.OUT_FORMATS == folder.OUT_FORMATS
    assert (cli_help.SOURCES, cli_help.NO_PROTOCOL) == (sources.SOURCES, sources.NO_PROTOCOL)
    assert cli_help.PROTOCOLS == tuple(sorted(protocols.PROTOCOLS))
    assert (cli_help.SPLITS, cli_help.SYNTHETIC_KINDS) == (synthetic.SPLITS, synthetic.SYNTHETIC_KINDS)
    assert cli_help.DEFAULT_COLUMNS == evaluate.DEFAULT_COLUMNS
    assert cli_help.CLASSICAL == tuple(methods.CLASSICAL) == tuple(methods.CLASSICAL_SUMMARY)
    training = cli_help.TRAINING
    assert (training.steps, training.batch_size) == (train_folder.FOLDER_STEPS, train_folder.FOLDER_BATCH_SIZE)
    assert (training.crop, training.workers) == (train_folder.FOLDER_DATA.crop, train_folder.FOLDER_DATA.num_workers)
    assert training.adapt_steps == adapt.ADAPT_STEPS
    assert cli.build_parser().parse_args(["complete", "--rgb", "a", "--out", "b", "--depth-scale", "nyu"]
                                         ).depth_scale == folder.parse_depth_scale("nyu")


def test_models_lists_the_hand_crafted_methods_after_the_shipped(capsys):
    from lipjax.methods import CLASSICAL

    assert cli.main(["models"]) == 0
    lines = capsys.readouterr().out.splitlines()
    start = lines.index("HAND-CRAFTED (no weights, no training; --model NAME runs each as the method returns it):")
    assert [line.split()[0] for line in lines[start + 1:]] == list(CLASSICAL)
    assert start > len(lipjax.available_models()) and max(len(line) for line in lines) < 120
