"""Smoke tests of the experiment entry points: each runs its `smoke` variant end to end and writes its files."""
import json

import h5py
import jax
import numpy as np
import pytest

from experiments import convergence, kitti_dc, nyu_200pts, sample_rate, table3
from lipjax import model_io
from lipjax.console import run_main
from lipjax.data import locate
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset


@pytest.fixture
def no_real_data(monkeypatch):
    """Neither NYU nor KITTI on this machine, whatever /data or ~/data hold: the experiments use the synthetic data."""
    for env in locate.ROOT_ENV.values():
        monkeypatch.delenv(env, raising=False)
    monkeypatch.setattr(locate, "USUAL_PLACES", {name: () for name in locate.USUAL_PLACES})


def test_nyu_200pts_smoke_writes_results_table_and_figure(tmp_path, capsys, no_real_data):
    metrics = nyu_200pts.main(["--variant", "smoke", "--out", str(tmp_path)])
    assert "NYU Depth v2 not found (--data-dir, $LIPJAX_NYU_DIR" in capsys.readouterr().out
    doc = json.loads((tmp_path / "results.json").read_text())
    assert doc["meta"]["sampler"] == "uniform:200" and doc["meta"]["num_images"] == 2
    assert set(doc["methods"]) == {"nearest", "linear"}
    assert doc["methods"]["nearest"]["rmse_m"] == metrics["nearest"]["rmse_m"] > 0
    # nearest-neighbour fill copies the samples: zero error on the sampled pixels
    assert doc["methods"]["nearest"]["mae_sampled_m"] == 0.0
    from lipjax.classical import NearestFill
    from lipjax.data.protocols import get_protocol
    from lipjax.data.sampling import sampler_from_spec
    from lipjax.data.synthetic import SyntheticDataset
    from lipjax.evaluate import evaluate

    protocol = get_protocol("synthetic_indoor")  # the rows are those of the frames and inputs the meta names
    alone = evaluate(NearestFill(), SyntheticDataset("indoor", "test"), sampler_from_spec("uniform:200"),
                     min_depth_m=protocol.min_depth_m, max_depth_m=protocol.max_depth_m, limit=2, progress=False)
    assert doc["methods"]["nearest"]["rmse_m"] == pytest.approx(alone.metrics["rmse_m"], rel=1e-12)
    assert "| nearest |" in (tmp_path / "table.md").read_text()
    assert (tmp_path / "figure.png").stat().st_size > 1000


def test_figures_show_the_three_best_methods_and_the_best_without_learned_weights():
    from experiments.common import key_methods
    from lipjax.evaluate import EvalResult
    from lipjax.inference import Completer

    def result(rmse):
        return EvalResult("m", {"rmse_m": rmse}, {}, [], 0.0, 0.0, 1, 0.0, 10.0)

    learned = Completer(LIPConfig(), None)
    rmse = {"a": 0.2, "b": 0.1, "linear": 0.5, "c": 0.15, "d": 0.3, "nearest": 0.6}
    completers = {m: "fill" if m in ("linear", "nearest") else learned for m in rmse}
    assert key_methods({m: result(r) for m, r in rmse.items()}, completers) == ["a", "b", "linear", "c"]
    rmse["linear"] = 0.05  # among the best three already: the fourth best joins
    assert key_methods({m: result(r) for m, r in rmse.items()}, completers) == ["a", "b", "linear", "c"]
    rmse["c"] = 0.35
    assert key_methods({m: result(r) for m, r in rmse.items()}, completers) == ["a", "b", "linear", "d"]


def test_tables_show_each_learned_models_training_images_beside_its_parameters(tmp_path):
    """Rows of unequal budgets say so: the budget column is the model file's images_seen."""
    from experiments.common import model_columns, write_results
    from lipjax.evaluate import EvalResult
    from lipjax.inference import Completer

    config = LIPConfig(prior=network_preset("tiny"), num_iterations=1)
    learned = Completer(config, config.init(jax.random.key(0)), "m", {"images_seen": 30_000})
    columns = model_columns({"m": learned, "linear": "fill"})
    assert columns == {"m": {"params_M": learned.parameter_count() / 1e6, "train_images": 30_000},
                       "linear": {"params_M": None, "train_images": None}}
    results = {m: EvalResult(m, {"rmse_m": 0.2}, {}, [], 0.0, 0.0, 1, 0.0, 10.0) for m in columns}
    table = write_results(tmp_path, results, {}, ["rmse_m"], columns)
    assert "| params_M | train_images |" in table.splitlines()[0]
    assert table.splitlines()[2].endswith(" | 30,000 |") and table.splitlines()[3].endswith("| n/a | n/a |")
    assert json.loads((tmp_path / "results.json").read_text())["methods"]["m"]["train_images"] == 30_000


def test_nyu_200pts_runs_on_nyu_when_it_is_on_disk(tmp_path, capsys, no_real_data, monkeypatch):
    """With NYU where the user keeps it ($LIPJAX_NYU_DIR here) and no flag, Table I is measured on NYU."""
    rng = np.random.default_rng(0)
    for n in (1, 2):
        path = tmp_path / "nyudepthv2" / "val" / "office_0001" / f"{n}.h5"
        path.parent.mkdir(parents=True, exist_ok=True)
        with h5py.File(path, "w") as f:  # Ma et al.'s layout at NYU's 480x640
            f["rgb"] = rng.integers(0, 256, (3, 480, 640), dtype=np.uint8)
            f["depth"] = rng.uniform(1.0, 9.0, (480, 640)).astype(np.float32)
    monkeypatch.setenv("LIPJAX_NYU_DIR", str(tmp_path / "nyudepthv2"))
    nyu_200pts.main(["--variant", "smoke", "--out", str(tmp_path / "out")])
    assert f"NYU Depth v2 from {tmp_path / 'nyudepthv2'}" in capsys.readouterr().out
    doc = json.loads((tmp_path / "out" / "results.json").read_text())
    assert doc["meta"]["dataset"].startswith("NYU Depth v2 val") and doc["meta"]["num_images"] == 2
    assert doc["meta"]["protocol"] == "nyu_paper"


def test_kitti_dc_smoke(tmp_path, capsys, no_real_data):
    kitti_dc.main(["--variant", "smoke", "--out", str(tmp_path)])
    assert "KITTI not found (--data-dir, $LIPJAX_KITTI_DIR" in capsys.readouterr().out
    doc = json.loads((tmp_path / "results.json").read_text())
    assert doc["meta"]["sampler"] == "lidar:hdl64"
    row = doc["methods"]["ip_basic"]
    assert row["rmse_mm"] > 0 and abs(row["rmse_mm"] - 1000 * row["rmse_m"]) < 1e-6 * row["rmse_mm"]


def test_table3_and_sample_rate_smoke(tmp_path):
    doc = table3.main(["--variant", "smoke", "--out", str(tmp_path / "t3")])
    assert set(doc["blocks"]) == {"outdoor (KITTI odometry stand-in), 200 points",
                                  "indoor (TartanAir stand-in), 200 points"}
    for rows in doc["blocks"].values():
        row = rows["nearest"]
        assert row["num_images"] == 1 and row["sampler"] == "uniform:200"
        assert row["rmse_m"] >= row["mae_m"] > 0 and 0 <= row["delta1_pct"] <= 100
    assert doc["blocks"]["indoor (TartanAir stand-in), 200 points"]["nearest"]["protocol"] == "synthetic_indoor"
    assert (tmp_path / "t3" / "table3_block0.png").exists() and (tmp_path / "t3" / "table3_block1.png").exists()
    table = sample_rate.main(["--variant", "smoke", "--out", str(tmp_path / "sr")])
    assert set(table["nearest"]) == {50, 200}
    # more samples, smaller error (on the same frame, same seed scheme)
    assert table["linear"][200]["mae_all_m"] < table["linear"][50]["mae_all_m"]
    assert (tmp_path / "sr" / "mae_sampled.png").exists()


def test_convergence_smoke_with_a_saved_model(tmp_path):
    config = LIPConfig(prior=network_preset("tiny"), num_iterations=2)
    model_io.save(tmp_path / "m", config, config.init(jax.random.key(0)))
    doc = convergence.main(["--variant", "smoke", "--models", str(tmp_path / "m"), "--out", str(tmp_path / "c")])
    curve = doc["per_iteration_mae_m"][str(tmp_path / "m")]
    assert len(curve) == 3 and all(np.isfinite(curve))
    # an untrained (identity) prox leaves the data-consistent initial estimate unchanged at every iteration
    np.testing.assert_allclose(curve, curve[0], rtol=1e-4)
    assert (tmp_path / "c" / "convergence.png").exists()


def test_convergence_reuses_only_a_finished_k_model_of_the_same_config(tmp_path):
    import dataclasses

    from experiments.configs import SMOKE

    params = SMOKE.model.init(jax.random.key(0))
    path = str(tmp_path / "k2")
    assert not convergence._finished(path, SMOKE)  # nothing there yet
    model_io.save(path, SMOKE.model, params, {"train_config": SMOKE.name, "steps": SMOKE.total_steps})
    assert convergence._finished(path, SMOKE)
    assert not convergence._finished(path, dataclasses.replace(SMOKE, g_steps=SMOKE.g_steps + 1))  # budget
    other_k = dataclasses.replace(SMOKE, model=dataclasses.replace(SMOKE.model, num_iterations=3))
    assert not convergence._finished(path, other_k)
    model_io.save(path, SMOKE.model, params, {"train_config": SMOKE.name, "steps": SMOKE.total_steps - 1})
    assert not convergence._finished(path, SMOKE)  # a run stopped early


@pytest.mark.parametrize("module, argv, status, message", [
    (kitti_dc, ["--variant", "smoke", "--data-dir", "{tmp}/no-kitti"], 1,
     "KITTI val_selection_cropped/image not found"),
    (kitti_dc, ["--variant", "nope"], 2, "argument --variant: invalid choice: 'nope'"),
    (convergence, ["--variant", "smoke", "--train-k", "x"], 2,
     "--train-k: expected comma-separated positive integers"),
    (nyu_200pts, ["--variant", "smoke", "--limit", "0"], 2, "--limit: expected a positive integer, got 0"),
    (nyu_200pts, ["--variant", "smoke", "--data-dir", "{tmp}/no-nyu"], 1, "NYU Depth v2 'val' split not found"),
    (table3, ["--variant", "smoke", "--kitti-odometry-dir", "{tmp}/no-odometry"], 1, "KITTI odometry root not found"),
])
def test_bad_arguments_give_one_line(module, argv, status, message, tmp_path, capsys):
    argv = [a.format(tmp=tmp_path) for a in argv] + ["--out", str(tmp_path / "out")]
    assert run_main(module.PROG, module.main, argv) == status
    lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"{module.PROG}: error: ") and message in lines[0], lines
