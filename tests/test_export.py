"""The exported StableHLO model computes what the Python model computes, and runs with jax alone."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import lipjax
from lipjax.export import export_completer, load_exported, save_exported
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset

from helpers import perturbed

B, H, W = 2, 24, 32


@pytest.fixture(scope="module")
def completer():
    # A non-zero head, so the network really changes the depth and the comparison is not trivial.
    return perturbed(lipjax.Completer.random(LIPConfig(prior=network_preset("tiny"), num_iterations=1), seed=3))


@pytest.fixture(scope="module")
def exported_file(completer, tmp_path_factory):
    return save_exported(export_completer(completer, B, H, W), tmp_path_factory.mktemp("export") / "m.stablehlo")


def _inputs(seed=0):
    rng = np.random.default_rng(seed)
    rgb = rng.integers(0, 256, (B, H, W, 3), dtype=np.uint8)
    sparse = np.where(rng.random((B, H, W)) < 0.1, rng.uniform(0.5, 8, (B, H, W)), 0).astype(np.float32)
    sparse[:, 0, 0] = 1.0
    return rgb, sparse


def test_exported_output_equals_python_model(completer, exported_file):
    run = load_exported(exported_file)
    assert run.input_shape == (B, H, W)
    rgb, sparse = _inputs()
    expected = completer(rgb, sparse)
    got = run(rgb, sparse)
    assert got.shape == (B, H, W) and got.dtype == np.float32
    assert not np.allclose(expected, lipjax.Completer.random(completer.config)(rgb, sparse), atol=1e-3)
    np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-5)


def test_exported_file_runs_with_jax_only(exported_file, tmp_path):
    rgb, sparse = _inputs(seed=1)
    np.savez(tmp_path / "in.npz", rgb=rgb, sparse=sparse)
    script = textwrap.dedent(f"""
        import sys
        class _NoLipjax:  # any import of lipjax fails: the file must be self-contained
            def find_spec(self, name, path=None, target=None):
                if name == "lipjax" or name.startswith("lipjax."):
                    raise ImportError("lipjax is blocked in this test")
        sys.meta_path.insert(0, _NoLipjax())
        import jax, numpy as np
        exported = jax.export.deserialize(bytearray(open({str(exported_file)!r}, "rb").read()))
        inputs = np.load({str(tmp_path / "in.npz")!r})
        np.save({str(tmp_path / "out.npy")!r}, np.asarray(exported.call(inputs["rgb"], inputs["sparse"])))
        assert "lipjax" not in sys.modules
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    np.testing.assert_allclose(np.load(tmp_path / "out.npy"), load_exported(exported_file)(rgb, sparse),
                               rtol=1e-6, atol=1e-6)


def test_wrong_input_shape_or_file_is_a_clear_error(exported_file, tmp_path):
    run = load_exported(exported_file)
    rgb, sparse = _inputs()
    with pytest.raises(ValueError, match=r"\(2, 24, 32, 3\)"):
        run(rgb[:, :-1], sparse[:, :-1])
    with pytest.raises(ValueError, match="uint8"):
        run(rgb.astype(np.float32) / 255, sparse)
    (tmp_path / "junk.stablehlo").write_bytes(b"not an export")
    with pytest.raises(ValueError, match="not a jax.export file"):
        load_exported(tmp_path / "junk.stablehlo")


def test_host_initial_estimate_model_exports_with_a_z0_input(tmp_path):
    """A model with a host-computed z_0 (Delaunay fill) exports with z0 as a third input, and needs it."""
    import dataclasses

    from lipjax.model import host_initial_estimate

    c = lipjax.Completer.random(LIPConfig(prior=network_preset("tiny"), num_iterations=1, initial_estimate="linear"))
    run = load_exported(save_exported(export_completer(c, B, H, W), tmp_path / "lin.stablehlo"))
    rgb, sparse = _inputs(1)
    assert run.needs_z0
    np.testing.assert_allclose(run(rgb, sparse, host_initial_estimate("linear", sparse)), c(rgb, sparse), atol=1e-5)
    with pytest.raises(ValueError, match="z0"):
        run(rgb, sparse)
    assert not dataclasses.replace(c.config, initial_estimate="box_fill").needs_host_initial_estimate


@pytest.mark.parametrize("name", ["m.onx", "m", "m.stablehlo.txt"])
def test_export_command_takes_its_format_from_the_extension_and_refuses_others(name, tmp_path, capsys):
    """An unknown extension is one line naming the supported formats, before the model is looked up (the model
    named here does not exist) and without writing anything."""
    from lipjax import cli

    rc = cli.main(["export", "--model", "no-such-model", "--height", "8", "--width", "8", "--out",
                   str(tmp_path / name)])
    lines = capsys.readouterr().err.strip().splitlines()
    assert rc == 1 and len(lines) == 1 and lines[0].startswith(f"lipjax: error: --out {tmp_path / name}: unknown "
                                                               "export format"), lines
    assert ".stablehlo (serialised StableHLO" in lines[0] and ".onnx (one ONNX graph" in lines[0]
    assert list(tmp_path.iterdir()) == []


def test_export_writes_the_model_and_a_summary_and_refuses_a_hand_crafted_fill(completer, tmp_path):
    from lipjax.export import export

    done = export(completer, tmp_path / "x" / "m.StableHLO", height=H, width=W)
    assert done.path == tmp_path / "x" / "m.StableHLO" and done.z0_kind is None
    rgb, sparse = _inputs()
    np.testing.assert_allclose(load_exported(done.path)(rgb[:1], sparse[:1]), completer(rgb[:1], sparse[:1]),
                               rtol=1e-5, atol=1e-5)
    assert done.summary() == (f"wrote {done.path} ({done.path.stat().st_size} bytes): rgb uint8 (1, {H}, {W}, 3), "
                              f"sparse float32 (1, {H}, {W}) m -> depth m; platforms {list(done.exported.platforms)}")
    with pytest.raises(ValueError, match="--model linear: a hand-crafted fill has no learned model to export"):
        export("linear", tmp_path / "l.stablehlo", height=H, width=W)
