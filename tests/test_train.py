"""Training: a smoke run end to end, exact resume, NaN detection, and data-parallel equivalence on 4 devices."""
import dataclasses
import json
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import jax
import numpy as np
import pytest

import lipjax
from lipjax.data import pipeline
from lipjax.model import LIPConfig
from lipjax.priors.network import network_preset
from lipjax.train import loop
from lipjax.train.checkpoint import CheckpointManager
from lipjax.train.config import DataConfig, TrainConfig, data_recipe
from lipjax.train.state import init_state

from helpers import alive, children

# One tiny config shared by the tests in this file, so that the jitted steps compile once (make_steps is cached).
CONFIG = TrainConfig(
    name="test",
    model=LIPConfig(prior=network_preset("tiny"), num_iterations=1),  # K=1: tests are compile-bound
    data=DataConfig(kind="indoor", height=32, width=40, crop=(24, 32), train_sampler="uniform:40",
                    val_sampler="uniform:40", val_images=2, num_workers=0),
    batch_size=2, g_steps=4, d_steps=2, adv_steps=2, log_every=1, eval_every=8, checkpoint_every=2,
)


def _leaves_equal(a, b):
    """Same tree structure and every leaf bit-identical."""
    (xs, x_tree), (ys, y_tree) = jax.tree_util.tree_flatten(a), jax.tree_util.tree_flatten(b)
    return x_tree == y_tree and all(np.array_equal(np.asarray(x), np.asarray(y)) for x, y in zip(xs, ys, strict=True))


@pytest.fixture(scope="module")
def straight_run(tmp_path_factory):
    workdir = tmp_path_factory.mktemp("straight")
    return workdir, loop.train(CONFIG, workdir, progress=False)


def test_smoke_run_goes_through_all_phases_logs_and_exports(straight_run, tmp_path):
    workdir, state = straight_run
    assert int(state.step) == CONFIG.total_steps
    rows = [json.loads(line) for line in (workdir / "metrics.jsonl").read_text().splitlines()]
    phases = [r["phase"] for r in rows if "phase" in r]
    assert phases == ["supervised"] * 4 + ["discriminator"] * 2 + ["adversarial"] * 2
    assert all(np.isfinite(r["loss"]) for r in rows if "phase" in r)
    assert "d_accuracy" in rows[-2] and "g_adversarial_loss" in rows[-2]
    val = [r for r in rows if r.get("split") == "val"]
    assert len(val) == 1 and val[0]["rmse_m"] > 0
    loop.export(CONFIG, state, tmp_path / "model")
    model = lipjax.load_model(tmp_path / "model")
    assert model.metadata["images_seen"] == CONFIG.total_steps * CONFIG.batch_size  # the budget, recorded
    assert model.metadata["train_sampler"] == CONFIG.data.train_sampler  # and the training input
    assert model.scan_lines_trained == ("lidar:" in CONFIG.data.train_sampler)
    # a run started from that model adds its budget to the one it started with
    follow = dataclasses.replace(CONFIG, init_from=str(tmp_path / "model"))
    loop.export(follow, state, tmp_path / "model2")
    assert lipjax.load_model(tmp_path / "model2").metadata["images_seen"] == 2 * CONFIG.total_steps * CONFIG.batch_size
    assert _leaves_equal(model.params, state.g_params)  # the exported weights are the run's, bit for bit
    # the logged validation is the exported model scored alone on the config's val frames and inputs
    from lipjax.data.sampling import sampler_from_spec
    from lipjax.data.synthetic import SyntheticDataset
    from lipjax.evaluate import evaluate

    frames = SyntheticDataset("indoor", "val", height=CONFIG.data.height, width=CONFIG.data.width)
    alone = evaluate(model, frames, sampler_from_spec(CONFIG.data.val_sampler), min_depth_m=0.0,
                     max_depth_m=CONFIG.model.max_depth_m, limit=CONFIG.data.val_images, progress=False)
    assert val[0]["rmse_m"] == pytest.approx(alone.metrics["rmse_m"], rel=1e-5)


def test_export_averages_the_newest_checkpoints(straight_run, tmp_path):
    """`run(..., average=2)` exports the element-wise mean of G's parameters over the newest two checkpoints, with
    their steps and the budget of the newest; more checkpoints than kept is a one-line error."""
    from lipjax.train.run import run

    workdir, _ = straight_run
    manager = CheckpointManager(workdir / "checkpoints", keep=CONFIG.keep_checkpoints)
    newest = sorted(manager.all_steps())[-2:]
    trees = [manager.restore(init_state(CONFIG), step)[0].g_params for step in newest]
    manager.close()
    assert newest == [6, 8] and not _leaves_equal(*trees)  # two different parameter sets
    run(CONFIG, workdir, export=tmp_path / "avg", export_only=True, average=2, progress=False)
    model = lipjax.load_model(tmp_path / "avg")
    for got, a, b in zip(*(jax.tree_util.tree_leaves(t) for t in (model.params, *trees))):
        np.testing.assert_allclose(np.asarray(got), (np.asarray(a) + np.asarray(b)) / 2, rtol=1e-6, atol=1e-7)
    assert model.metadata["checkpoints"] == [6, 8] and model.metadata["images_seen"] == 8 * CONFIG.batch_size
    with pytest.raises(ValueError, match="holds 3 checkpoint"):
        run(CONFIG, workdir, export=tmp_path / "avg9", export_only=True, average=9, progress=False)


def test_an_export_from_a_workdir_needs_the_runs_own_config(straight_run, tmp_path):
    """A workdir records what its export's budget and data record come from (run.json); exporting it with another
    init_from or seed is a one-line error naming both values, not a model with a wrong images_seen."""
    from lipjax.train.run import run

    workdir, _ = straight_run
    assert json.loads((workdir / loop.RUN_FILE).read_text()) == loop.run_record(CONFIG)
    loop.export(CONFIG, init_state(CONFIG), tmp_path / "start")
    for other, named in ((dataclasses.replace(CONFIG, init_from=str(tmp_path / "start")), "init_from=None"),
                         (dataclasses.replace(CONFIG, seed=7), "seed=0")):
        with pytest.raises(ValueError, match=f"trained with {named}, this config has") as error:
            run(other, workdir, export=tmp_path / "wrong", export_only=True, progress=False)
        assert "\n" not in str(error.value)
    assert not (tmp_path / "wrong.json").exists()


def test_a_resume_needs_the_runs_own_config(straight_run, tmp_path):
    """Resuming a workdir with another seed is a one-line error before any step, and the run's record stays: its
    checkpoints read the recorded seed's data, and a model exported from it would carry a wrong data record."""
    import shutil

    workdir = tmp_path / "copy"
    shutil.copytree(straight_run[0], workdir)
    record, config_text = (workdir / loop.RUN_FILE).read_text(), (workdir / "config.txt").read_text()
    with pytest.raises(ValueError, match="trained with seed=0, this config has seed=7") as error:
        loop.train(dataclasses.replace(CONFIG, seed=7, adv_steps=CONFIG.adv_steps + 2), workdir, progress=False)
    assert "\n" not in str(error.value)
    assert (workdir / loop.RUN_FILE).read_text() == record and (workdir / "config.txt").read_text() == config_text
    manager = CheckpointManager(workdir / "checkpoints", keep=CONFIG.keep_checkpoints)
    assert manager.latest_step() == CONFIG.total_steps
    manager.close()


def test_a_soup_is_the_mean_of_models_of_one_chain_with_the_newest_models_budget(straight_run, tmp_path):
    """`soup` saves the element-wise mean of G's parameters over models of one chain of warm starts, validated on
    the config's validation set, with the newest model's budget; a model from outside the chain, or of another
    architecture, is a one-line error."""
    from lipjax.train.run import soup

    workdir, state = straight_run
    manager = CheckpointManager(workdir / "checkpoints", keep=CONFIG.keep_checkpoints)
    older = manager.restore(init_state(CONFIG), 6)[0]
    manager.close()
    loop.export(CONFIG, older, tmp_path / "first")
    newer = dataclasses.replace(CONFIG, init_from=str(tmp_path / "first"), seed=7)
    loop.export(newer, state, tmp_path / "second")
    val = soup(CONFIG, [str(tmp_path / "first"), str(tmp_path / "second")], tmp_path / "soup")
    model = lipjax.load_model(tmp_path / "soup")
    for got, a, b in zip(*(jax.tree_util.tree_leaves(t) for t in (model.params, older.g_params, state.g_params))):
        np.testing.assert_allclose(np.asarray(got), (np.asarray(a) + np.asarray(b)) / 2, rtol=1e-6, atol=1e-7)
    second = lipjax.load_model(tmp_path / "second").metadata
    assert model.metadata["images_seen"] == second["images_seen"] == (6 + 8) * CONFIG.batch_size  # step 6, then 8
    assert model.metadata["data_streams"] == second["data_streams"] and len(second["data_streams"]) == 2
    assert model.metadata["soup"] == [str(tmp_path / "first"), str(tmp_path / "second")]
    assert model.metadata["val_metrics"] == val
    alone = loop.evaluate_params(CONFIG.model, model.params, loop.validation_batches(CONFIG), CONFIG.model.max_depth_m)
    assert val["rmse_m"] == pytest.approx(alone["rmse_m"], rel=1e-6)
    loop.export(dataclasses.replace(CONFIG, seed=3), state, tmp_path / "stranger")  # its own chain
    with pytest.raises(ValueError, match="stranger is not in .*second's chain of warm starts"):
        soup(CONFIG, [str(tmp_path / "stranger"), str(tmp_path / "second")], tmp_path / "bad")
    other = dataclasses.replace(CONFIG, model=dataclasses.replace(CONFIG.model, num_iterations=2))
    lipjax.model_io.save(tmp_path / "wider", other.model, init_state(other).g_params, second)
    with pytest.raises(ValueError, match="differ in architecture"):
        soup(CONFIG, [str(tmp_path / "wider"), str(tmp_path / "second")], tmp_path / "bad")
    with pytest.raises(ValueError, match="at least two models"):
        soup(CONFIG, [str(tmp_path / "second")], tmp_path / "bad")


def test_discriminator_phase_keeps_generator_frozen(straight_run):
    workdir, _ = straight_run
    manager = CheckpointManager(workdir / "checkpoints")
    template = init_state(CONFIG)
    # steps 4 -> 6 are the D-pretraining phase; 6 -> 8 adversarial (checkpoint_every=2, keep 3)
    at = {step: manager.restore(template, step)[0] for step in (4, 6, 8)}
    assert _leaves_equal(at[4].g_params, at[6].g_params)
    assert not _leaves_equal(at[4].d_params, at[6].d_params)
    assert not _leaves_equal(at[6].g_params, at[8].g_params)


def test_interrupted_run_resumes_exactly(straight_run, tmp_path):
    _, straight = straight_run
    half = CONFIG.total_steps // 2
    loop.train(CONFIG, tmp_path, stop_at=half, progress=False)  # the "killed" run: stopped after a checkpoint
    resumed = loop.train(CONFIG, tmp_path, progress=False)
    assert int(resumed.step) == CONFIG.total_steps
    assert _leaves_equal(straight.g_params, resumed.g_params)
    assert _leaves_equal(straight.d_params, resumed.d_params)
    assert _leaves_equal(straight.g_opt_state, resumed.g_opt_state)


def test_non_finite_loss_stops_and_keeps_last_good_checkpoint(tmp_path, monkeypatch):
    real_augment = pipeline.augment_batch

    def poisoned(batch, augment, crop, seed, step, first_example=0):
        batch = real_augment(batch, augment, crop, seed, step, first_example)
        if step == 2:  # the third step sees a NaN in the ground truth
            batch = dataclasses.replace(batch, gt=np.full_like(batch.gt, np.nan))
        return batch

    monkeypatch.setattr(pipeline, "augment_batch", poisoned)  # num_workers=0: the loader runs in this process
    with pytest.raises(loop.TrainingDiverged, match="non-finite loss .* step 3.*last good checkpoint is step 2"):
        loop.train(CONFIG, tmp_path, progress=False)
    assert CheckpointManager(tmp_path / "checkpoints").latest_step() == 2


def test_host_initial_estimate_reaches_the_train_step(tmp_path, monkeypatch):
    """A model whose z_0 is computed on the host trains: the loop adds z0 to each batch after cropping."""
    from lipjax.classical.nearest import nearest_fill

    calls = []
    host_inputs = LIPConfig.host_inputs

    def recording(self, sparse):
        extra = host_inputs(self, sparse)
        calls.append((np.asarray(sparse), extra))
        return extra

    monkeypatch.setattr(LIPConfig, "host_inputs", recording)
    model = dataclasses.replace(CONFIG.model, initial_estimate="nearest")
    config = dataclasses.replace(CONFIG, name="host-init", model=model, g_steps=2, d_steps=0, adv_steps=0,
                                 eval_every=2)
    state = loop.train(config, tmp_path, progress=False)
    shapes = [sparse.shape for sparse, _ in calls]
    assert shapes.count((2, 24, 32)) >= 2 and (2, 32, 40) in shapes  # each training crop, and the full val frames
    for sparse, extra in calls:
        np.testing.assert_array_equal(extra["z0"], np.stack([nearest_fill(s) for s in sparse]))
    assert int(state.step) == 2
    rows = [json.loads(line) for line in (tmp_path / "metrics.jsonl").read_text().splitlines()]
    assert all(np.isfinite(r["loss"]) for r in rows if "phase" in r)
    assert [r for r in rows if r.get("split") == "val"][0]["mae_m"] > 0


# Multi-process: 2 processes on localhost, each with one CPU device and half of every batch, gloo collectives
# (tests/multiprocess_worker.py). They run the first MULTI_PROCESS_STEPS steps of CONFIG, compared with the
# single-process straight run's checkpoint of that step (so no extra compilation in this process).
MULTI_PROCESS_STEPS = 4


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_two_processes_match_one_process(straight_run, tmp_path):
    port = _free_port()
    worker = os.path.join(os.path.dirname(__file__), "multiprocess_worker.py")
    out = tmp_path / "params.npz"
    procs = [subprocess.Popen([sys.executable, worker, str(i), str(port), str(tmp_path / "run"), str(out)],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True) for i in range(2)]
    logs = [p.communicate(timeout=600)[0] for p in procs]
    assert all(p.returncode == 0 for p in procs), "\n".join(log[-2000:] for log in logs)
    workdir, _ = straight_run
    single, _ = CheckpointManager(workdir / "checkpoints").restore(init_state(CONFIG), MULTI_PROCESS_STEPS)
    with np.load(out) as multi:
        got = [multi[f"arr_{i}"] for i in range(len(multi.files))]
    want = [np.asarray(a) for a in jax.tree_util.tree_leaves(single.g_params)]
    assert len(got) == len(want)
    assert max(float(np.abs(b - i).max())
               for b, i in zip(want, jax.tree_util.tree_leaves(init_state(CONFIG).g_params))) > 1e-4
    for a, b in zip(got, want):
        # Different reduction orders give float-level differences, which Adam turns into update-sized ones on
        # parameters whose gradient is ~0; 1e-5 is 1 % of one step (learning rate 1e-3).
        np.testing.assert_allclose(a, b, rtol=1e-4, atol=1e-5)


def test_the_training_command_runs_as_two_processes(tmp_path):
    """`python -m experiments.train --distributed` as 2 processes on localhost is one run: its 2 steps of batch 2
    logged once, and one export, by process 0, of a model that has read 4 images (validated on its host copy of
    the parameters: eval_every=0 leaves the last validation to the export)."""
    port, workdir, model = _free_port(), tmp_path / "run", tmp_path / "model"

    def command(process_id: int) -> list[str]:
        return [sys.executable, "-m", "experiments.train", "--config", "smoke", "--distributed", "--coordinator",
                f"127.0.0.1:{port}", "--num-processes", "2", "--process-id", str(process_id), "--workdir",
                str(workdir), "--export", str(model), "--no-progress", "--set", "g_steps=2", "--set", "d_steps=0",
                "--set", "adv_steps=0", "--set", "eval_every=0", "--set", "data.num_workers=0"]

    procs = [subprocess.Popen(command(i), cwd=pathlib.Path(__file__).parents[1], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True) for i in range(2)]
    logs = [p.communicate(timeout=600)[0] for p in procs]
    assert all(p.returncode == 0 for p in procs), "\n".join(log[-2000:] for log in logs)
    assert "[lipjax] exported smoke (step 2)" in logs[0] and "exported" not in logs[1], logs
    rows = [json.loads(line) for line in (workdir / "metrics.jsonl").read_text().splitlines()]
    assert [r["step"] for r in rows if "phase" in r] == [2]
    meta = lipjax.model_io.metadata(model)
    assert (meta["steps"], meta["images_seen"]) == (2, 4) and np.isfinite(meta["val_metrics"]["rmse_m"])


def test_the_training_command_checks_its_process_flags(capsys):
    from experiments import train as train_command

    for argv, says in ((["--process-id", "1"], "need --distributed"),
                       (["--distributed", "--export-only", "--export", "m"], "run them without --distributed"),
                       (["--distributed", "--average", "2"], "run them without --distributed")):
        with pytest.raises(SystemExit) as exit_:
            train_command.main(["--config", "smoke", *argv])
        lines = capsys.readouterr().err.strip().splitlines()
        assert exit_.value.code == 2 and len(lines) == 1 and says in lines[0], lines


MULTI_DEVICE_SCRIPT = textwrap.dedent(
    """
    import dataclasses, sys, tempfile
    import jax, numpy as np
    sys.path.insert(0, {tests!r})
    from test_train import CONFIG
    from lipjax.data.pipeline import make_data_mesh
    from lipjax.train import loop
    assert len(jax.devices()) == 4, jax.devices()
    config = dataclasses.replace(CONFIG, batch_size=4, g_steps=2, d_steps=0, adv_steps=0, eval_every=0)
    one = loop.train(config, tempfile.mkdtemp(), progress=False, mesh=make_data_mesh(jax.devices()[:1]))
    four = loop.train(config, tempfile.mkdtemp(), progress=False, mesh=make_data_mesh())
    diffs = [float(np.abs(np.asarray(a) - np.asarray(b)).max()) for a, b in
             zip(jax.tree_util.tree_leaves(one.g_params), jax.tree_util.tree_leaves(four.g_params))]
    moved = [float(np.abs(np.asarray(a) - np.asarray(b)).max()) for a, b in
             zip(jax.tree_util.tree_leaves(one.g_params), jax.tree_util.tree_leaves(loop.init_state(config).g_params))]
    print("MAXDIFF", max(diffs), "MAXMOVE", max(moved))
    """
)


def test_four_devices_match_one_device():
    env = dict(os.environ)
    env["XLA_FLAGS"] = (env.get("XLA_FLAGS", "") + " --xla_force_host_platform_device_count=4").strip()
    script = MULTI_DEVICE_SCRIPT.format(tests=os.path.dirname(__file__))
    out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    line = [l for l in out.stdout.splitlines() if l.startswith("MAXDIFF")][0].split()
    max_diff, max_move = float(line[1]), float(line[3])
    assert max_move > 1e-4  # training moved the parameters ...
    assert max_diff < 1e-4 * max(1.0, max_move) + 1e-5  # ... identically up to float reduction order


def test_config_overrides_reach_nested_fields_convert_types_and_reject_unknown_names():
    from experiments.configs import CONFIGS, get_config

    config = get_config("smoke", {"g_steps": "7", "data.num_workers": "3", "model.num_iterations": "4"})
    assert (config.g_steps, config.data.num_workers, config.model.num_iterations) == (7, 3, 4)
    assert config.data.kind == CONFIGS["smoke"].data.kind  # the rest of the group is kept
    with pytest.raises(ValueError, match="data.nope"):
        get_config("smoke", {"data.nope": "1"})
    with pytest.raises(ValueError, match="is a group"):
        get_config("smoke", {"data": "1"})
    with pytest.raises(ValueError, match="has no sub-fields"):
        get_config("smoke", {"g_steps.x": "1"})
    assert get_config("smoke", {"model.learn_rho": "false"}).model.learn_rho is False
    with pytest.raises(ValueError, match="true or false"):
        get_config("smoke", {"model.learn_rho": "no"})


@pytest.mark.parametrize("args, message", [
    (["--config", "nope"], "unknown config 'nope'"),
    (["--config", "smoke", "--set", "g_step=3"], "unknown config field 'g_step'"),
    (["--config", "smoke", "--set", "g_steps"], "expected FIELD=VALUE"),
    (["--config", "smoke", "--soup", "a,b"], "--soup needs --export PATH"),
])
def test_train_command_errors_are_one_line(args, message, capsys):
    from experiments import train as train_command

    with pytest.raises(SystemExit) as exit_:
        train_command.main(args)
    err = capsys.readouterr().err.strip()
    assert exit_.value.code == 2 and message in err and len(err.splitlines()) == 1
    assert err.startswith(f"{train_command.PROG}: error: "), err


def test_train_command_without_its_data_set_is_one_line(tmp_path, capsys):
    """A missing data set, as the lipjax CLI reports one: "PROG: error: ..." on one line, exit status 1."""
    from experiments import train as train_command
    from lipjax.console import run_main

    argv = ["--config", "lip_cnn_nyu", "--set", f"data.root={tmp_path / 'no-nyu'}", "--workdir",
            str(tmp_path / "run"), "--no-progress"]
    assert run_main(train_command.PROG, train_command.main, argv) == 1
    lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"{train_command.PROG}: error: NYU Depth v2 'val' split not "
                                                   "found"), lines


def _loader_workers(pid: int) -> set[int]:
    """The grain worker processes (multiprocessing's spawned children) of process `pid`."""
    def spawned(child: int) -> bool:
        try:
            return b"spawn_main" in pathlib.Path(f"/proc/{child}/cmdline").read_bytes()
        except OSError:
            return False
    return {child for child in children(pid) if spawned(child)}


def _signal_a_smoke_run(tmp_path: pathlib.Path, signum: int, group: bool,
                        at_worker_start: bool = False) -> tuple[int, set[int], list[int], list[int], str]:
    """Starts `experiments.train --config smoke` (2 loader workers, no checkpoint due) in a process group of its
    own, as a terminal's foreground job, and sends `signum` once it has logged 2 steps (at_worker_start: as soon
    as its first loader worker process exists, which then takes seconds to import its modules): to the process, or
    to its whole group (as Ctrl-C, `timeout` and batch schedulers do). Returns (exit status, the loader worker
    pids, the logged steps, the saved checkpoint steps, its output)."""
    workdir = tmp_path / "run"
    cmd = [sys.executable, "-m", "experiments.train", "--config", "smoke", "--workdir", str(workdir), "--no-progress",
           "--set", "g_steps=100000", "--set", "data.num_workers=2", "--set", "checkpoint_every=100000",
           "--set", "log_every=1", "--set", "eval_every=0"]
    with open(tmp_path / "out.txt", "w") as out:
        proc = subprocess.Popen(cmd, cwd=pathlib.Path(__file__).parents[1], stdout=out, stderr=subprocess.STDOUT,
                                start_new_session=True)
    metrics = workdir / "metrics.jsonl"
    try:
        def ready() -> bool:
            if at_worker_start:
                return bool(_loader_workers(proc.pid))
            return metrics.exists() and metrics.read_text().count("\n") >= 2

        deadline = time.time() + 240
        while not ready() and time.time() < deadline:
            time.sleep(0.01)
        workers = children(proc.pid)
        assert workers, "the run should have a loader worker process"
        os.killpg(proc.pid, signum) if group else proc.send_signal(signum)
        status = proc.wait(timeout=60)
    finally:
        proc.kill()
    logged = [json.loads(line)["step"] for line in metrics.read_text().splitlines()]
    saved = [int(p.name) for p in (workdir / "checkpoints").glob("[0-9]*")]
    return status, workers, logged, saved, (tmp_path / "out.txt").read_text()


def _workers_end(workers: set[int]) -> bool:
    deadline = time.time() + 20
    while [w for w in workers if alive(w)] and time.time() < deadline:
        time.sleep(0.2)
    return not [w for w in workers if alive(w)]


@pytest.mark.skipif(not pathlib.Path("/proc/self/stat").exists(), reason="needs Linux /proc")
@pytest.mark.parametrize("group", [False, True], ids=["process", "group"])
def test_sigterm_saves_the_step_and_stops_the_loader_workers_with_the_run(tmp_path, group):
    """A killed run (SIGTERM to the process, or to its whole process group as `timeout` and batch schedulers send
    it, loader workers included) saves the step it was in, although no checkpoint was due, exits with 143 and
    takes its loader worker processes with it, leaving no shared memory behind; the checkpoint restores at that
    step, with its data position."""
    status, workers, logged, saved, text = _signal_a_smoke_run(tmp_path, signal.SIGTERM, group)
    assert status == 143
    assert len(logged) >= 2 and saved == [logged[-1]], (logged, saved)  # the step in progress, none before it
    assert _workers_end(workers), "loader workers outlived the run"
    assert "leaked shared_memory" not in text and "Traceback" not in text, text[-3000:]
    from experiments.configs import get_config

    manager = CheckpointManager(tmp_path / "run" / "checkpoints")
    state, meta = manager.restore(init_state(get_config("smoke")))  # what a resumed run starts from
    manager.close()
    assert int(state.step) == meta["data_position"] == saved[0]


@pytest.mark.skipif(not pathlib.Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_sigterm_while_the_loader_workers_start_stops_the_run_as_asked(tmp_path):
    """SIGTERM to the whole process group while the loader workers are still starting (before they can ignore
    it) kills them; the run, asked to stop before its first step, exits with 143 and says why, without a
    traceback, and nothing is saved (no step was trained)."""
    status, workers, logged, saved, text = _signal_a_smoke_run(tmp_path, signal.SIGTERM, group=True,
                                                               at_worker_start=True)
    assert status == 143, text[-3000:]
    assert logged == [] and saved == [], (logged, saved)
    assert "[lipjax] SIGTERM: a data loader worker ended with it before step 0; stopping" in text, text[-3000:]
    assert "Traceback" not in text and "leaked shared_memory" not in text, text[-3000:]
    assert _workers_end(workers), "loader workers outlived the run"


@pytest.mark.skipif(not pathlib.Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_sigterm_while_a_resumed_runs_loader_workers_start_stops_it_too(tmp_path):
    """The same for a resumed run, whose loader starts at its step (a grain iterator state restored into it
    waited forever for the acknowledgement of a worker that had died)."""
    status, _, logged, saved, _ = _signal_a_smoke_run(tmp_path, signal.SIGTERM, group=True)
    assert status == 143 and saved == [logged[-1]], (logged, saved)
    status, workers, _, _, text = _signal_a_smoke_run(tmp_path, signal.SIGTERM, group=True, at_worker_start=True)
    assert status == 143, text[-3000:]
    assert f"resumed smoke from step {saved[0]}" in text, text[-3000:]
    assert f"a data loader worker ended with it before step {saved[0]}; stopping" in text, text[-3000:]
    assert _workers_end(workers), "loader workers outlived the run"


@pytest.mark.skipif(not pathlib.Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_ctrl_c_saves_the_step_and_stops_the_loader_workers_with_the_run(tmp_path):
    """Ctrl-C as a terminal sends it (SIGINT to the whole process group, loader workers included) saves the step
    in progress, although no checkpoint was due, says so, exits with 130, and the workers end with the run,
    leaving no shared memory behind."""
    status, workers, logged, saved, text = _signal_a_smoke_run(tmp_path, signal.SIGINT, group=True)
    assert status == 130
    assert len(logged) >= 2 and saved == [logged[-1]], (logged, saved)  # the step in progress, none before it
    checkpoints = tmp_path / "run" / "checkpoints"
    assert f"[lipjax] SIGINT: saved step {saved[0]} in {checkpoints}; stopping (run again to resume)" in text
    assert "Traceback" not in text and "leaked shared_memory" not in text, text[-3000:]
    assert _workers_end(workers), "loader workers outlived the run"


def test_a_second_signal_exits_at_once_and_the_handlers_are_restored():
    """The first SIGINT or SIGTERM only asks the loop to save and stop; a second exits at once (KeyboardInterrupt
    for Ctrl-C, SystemExit(143) for SIGTERM); afterwards the previous handlers are back. A multi-process run
    (save_first=False) exits on the first SIGTERM and leaves SIGINT to Python."""
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    for signum, second in ((signal.SIGINT, KeyboardInterrupt), (signal.SIGTERM, SystemExit)):
        with pytest.raises(SystemExit) as ended:
            with loop._signals_as_exit(save_first=True) as stop:
                os.kill(os.getpid(), signum)
                time.sleep(0.01)  # the handler runs between bytecodes
                assert stop.is_set() and stop.signum == signum
                with pytest.raises(second) as info:
                    os.kill(os.getpid(), signum)
                    time.sleep(1)
                assert signum == signal.SIGINT or info.value.code == 143
        assert ended.value.code == 128 + signum  # a run that ended after the signal still stops the process
        assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before
    with loop._signals_as_exit(save_first=False) as stop:
        assert signal.getsignal(signal.SIGINT) == before[0]
        with pytest.raises(SystemExit):
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(1)
        assert not stop.is_set()


def test_a_signal_during_the_last_step_is_not_swallowed(tmp_path, monkeypatch, capsys):
    """SIGTERM in the run's last step: the run finishes and saves it, then the process stops (exit 143), so a caller
    that trains run after run (experiments.equal_budget under `timeout`) stops too; started again, nothing is left."""
    config = dataclasses.replace(CONFIG, g_steps=2, d_steps=0, adv_steps=0, checkpoint_every=100, eval_every=100)
    make_steps, calls = loop.make_steps, []

    def signalling_steps(c):
        steps = make_steps(c)

        def supervised(*args):
            calls.append(len(calls))
            out = steps.supervised(*args)
            if len(calls) == config.total_steps:  # the last step
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(0.01)  # the handler runs between bytecodes
            return out

        return dataclasses.replace(steps, supervised=supervised)

    monkeypatch.setattr(loop, "make_steps", signalling_steps)
    with pytest.raises(SystemExit) as ended:
        loop.train(config, tmp_path / "run", progress=False)
    assert ended.value.code == 143 and calls == [0, 1]
    assert "the run ended with its last step saved; stopping" in capsys.readouterr().err
    assert int(loop.train(config, tmp_path / "run", progress=False).step) == 2 and calls == [0, 1]  # nothing left


def test_init_from_takes_a_model_of_other_settings_but_not_other_parameters(tmp_path, capsys):
    """An indoor model fine-tuned outdoors: another depth range and initial estimate, the same parameter tree, are
    accepted (the saved parameters, unchanged); another architecture is a one-line error."""
    from lipjax import model_io

    params = CONFIG.model.init(jax.random.key(1))
    model_io.save(tmp_path / "indoor", CONFIG.model, params)
    outdoor = dataclasses.replace(CONFIG.model, initial_estimate="nearest",
                                  prior=dataclasses.replace(CONFIG.model.prior, max_depth_m=80.0))
    got = loop._initial_g_params(dataclasses.replace(CONFIG, model=outdoor, init_from=str(tmp_path / "indoor")))
    assert _leaves_equal(got, params)
    assert "['prior', 'initial_estimate']" in capsys.readouterr().out
    other = dataclasses.replace(CONFIG.model, num_iterations=2)  # one more prox: another parameter tree
    with pytest.raises(ValueError, match="do not fit"):
        loop._initial_g_params(dataclasses.replace(CONFIG, model=other, init_from=str(tmp_path / "indoor")))


def test_a_warm_start_records_its_data_and_warns_when_it_would_read_the_same_again(straight_run, tmp_path):
    """Step s of a run reads what its config, data settings and seed give step s: a model records each run of its
    chain of warm starts (--set data overrides included), and a run from it with a config and seed already in that
    chain warns (it repeats those frames)."""
    import warnings

    def first_frames(seed):
        return pipeline.BatchIterator(range(1000), 8, None, seed=seed).global_indices(0)

    assert np.array_equal(first_frames(0), first_frames(0)) and not np.array_equal(first_frames(0), first_frames(7))
    _, state = straight_run
    loop.export(CONFIG, state, tmp_path / "first")
    steps = CONFIG.total_steps
    recipe = data_recipe(CONFIG.data)
    assert recipe and "root" not in recipe and recipe == json.loads(json.dumps(recipe))  # JSON as recorded
    assert loop.data_streams(lipjax.load_model(tmp_path / "first").metadata) == [
        {"train_config": "test", "seed": 0, "steps": steps, "data": recipe}]
    again = dataclasses.replace(CONFIG, init_from=str(tmp_path / "first"))
    with pytest.warns(UserWarning, match="seed 0: this run reads the same frames.*--set seed=N"):
        loop._initial_g_params(again)
    fresh = dataclasses.replace(again, seed=7, data=dataclasses.replace(CONFIG.data, clutter_prob=0.5))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        loop._initial_g_params(fresh)  # a seed of its own: no warning
    loop.export(fresh, state, tmp_path / "second")
    assert loop.data_streams(lipjax.load_model(tmp_path / "second").metadata) == [
        {"train_config": "test", "seed": 0, "steps": steps, "data": recipe},
        {"train_config": "test", "seed": 7, "steps": steps, "data": {**recipe, "clutter_prob": 0.5}}]  # as --set
    with pytest.warns(UserWarning, match="seed 0"):  # the first run's stream is still in the chain
        loop._initial_g_params(dataclasses.replace(CONFIG, init_from=str(tmp_path / "second")))
    # a model saved before the streams were recorded read its config's with the default seed
    assert loop.data_streams({"train_config": "lip-any", "images_seen": 8}) == [
        {"train_config": "lip-any", "seed": 0, "steps": None}]


# A run long enough to be killed mid-way (the straight CONFIG ends within a second of compiling), with one loader
# worker process, checkpoints every 3 steps.
KILLED = dataclasses.replace(CONFIG, name="killed", g_steps=24, d_steps=0, adv_steps=0, checkpoint_every=3,
                             eval_every=0, data=dataclasses.replace(CONFIG.data, num_workers=1))  # one row a step


def _steps_logged(metrics: pathlib.Path) -> int:
    """The last training step in a run's metrics.jsonl (0 before the first)."""
    rows = [json.loads(line) for line in metrics.read_text().splitlines() if line.strip()] if metrics.exists() else []
    return max((row["step"] for row in rows), default=0)


@pytest.fixture(scope="module")
def killed_reference(tmp_path_factory):
    return loop.train(KILLED, tmp_path_factory.mktemp("killed-straight"), progress=False)


@pytest.mark.skipif(not pathlib.Path("/proc/self/stat").exists(), reason="needs Linux /proc")
@pytest.mark.parametrize("signum", [signal.SIGKILL, signal.SIGTERM, signal.SIGINT], ids=["kill", "term", "int"])
def test_a_run_killed_at_a_random_step_resumes_bit_identical_and_leaves_no_process(killed_reference, tmp_path,
                                                                                   signum):
    """A real training process killed once it has logged a seeded random step (the signal may land a step or two
    later) by SIGKILL to the process (nothing saved: resume from the last periodic checkpoint; its loader workers
    exit when orphaned), or SIGTERM or Ctrl-C to its whole process group (the step in progress saved) resumes to
    parameters and optimiser state bit-identical to an uninterrupted run, and none of its processes outlives it."""
    kill_after = int(np.random.default_rng(int(signum)).integers(2, KILLED.total_steps - 4))
    workdir = tmp_path / "run"
    script = ("import sys; sys.path.insert(0, 'tests'); from test_train import KILLED; from lipjax.train import loop; "
              "loop.train(KILLED, sys.argv[1], progress=False)")
    proc = subprocess.Popen([sys.executable, "-c", script, str(workdir)], cwd=pathlib.Path(__file__).parents[1],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    metrics = workdir / "metrics.jsonl"
    try:
        deadline = time.time() + 240
        while _steps_logged(metrics) < kill_after and time.time() < deadline:
            time.sleep(0.02)
        family = children(proc.pid) | {proc.pid}
        os.killpg(proc.pid, signum) if signum != signal.SIGKILL else proc.send_signal(signum)
        proc.wait(timeout=60)
    finally:
        proc.kill()
    assert _steps_logged(metrics) < KILLED.total_steps, "the run ended before the kill: nothing was tested"
    deadline = time.time() + 20
    while [p for p in family if alive(p)] and time.time() < deadline:
        time.sleep(0.2)
    assert not [p for p in family if alive(p)], "a process of the killed run outlived it"
    resumed = loop.train(KILLED, workdir, progress=False)
    assert int(resumed.step) == KILLED.total_steps
    assert _leaves_equal(killed_reference.g_params, resumed.g_params)
    assert _leaves_equal(killed_reference.g_opt_state, resumed.g_opt_state)
