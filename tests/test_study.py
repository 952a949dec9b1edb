"""The equal-budget study (experiments/equal_budget.py): budgets and order, the constant schedule it relies on, the
end-to-end networks' depth unit, the paired tests, and one tiny study end to end (resumed, then reported)."""
import dataclasses
import json
import pathlib

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import lipjax
from scipy import stats

from experiments import equal_budget, ship_study, study_report
from experiments.configs.study import (COOLDOWN_SEED_OFFSET, cooldown_config, cooldown_images, shipped_config,
                                      trunk_config)
from lipjax import model_io
from lipjax.networks import baseline_preset
from lipjax.train.run import logged_validation
from lipjax.train.state import g_learning_rate


def study(tmp_path, **kw):
    defaults = dict(warm_starts=None, scenes=("indoor",), seeds={"indoor": (0, 1)}, images=64,
                    curve={"indoor": (32, 64, 96)}, tune_images=16, cooldown=0.5, limit=1, tiny=True)
    return equal_budget.Study(tmp_path, tmp_path / "scores", **{**defaults, **kw})


def tuned(images):
    """A trunk's tuning.json entry: 5e-4 best of TUNE_LRS, each tried after `images` images."""
    return {f"{lr:g}": {"val_rmse_m": v, "images": images} for lr, v in zip(equal_budget.TUNE_LRS, (0.6, 0.5, 0.7))}


def made(s, method, lr, **kw):
    """A score of `method` as study `s` makes it at rate `lr` (kw: made another way)."""
    return {"method": method, "scene": "indoor", "learning_rate": lr, "cooldown": s.cooldown, **kw}


def test_budgets_every_seed_at_b_seed_0_along_the_whole_curve(tmp_path):
    s = study(tmp_path)
    assert s.budgets_for("indoor", 1) == [32, 64]
    assert s.budgets_for("indoor", 0) == [32, 64, 96]
    steps = equal_budget.plan(s)
    # every seed reaches B before seed 0 goes on past it
    first_past_b = next(i for i, step in enumerate(steps) if step[3] > 64)
    assert all(step[3] == 64 for step in steps[:first_past_b])
    assert {(t, k) for _, t, k, n in steps if n == 64} == {(t, k) for t in ("ma2018", "unet", "cspn", "lip-cnn",
                                                                          "lip-fast") for k in (0, 1)}
    assert [(t, k, n) for _, t, k, n in steps[first_past_b:]] == [(t, 0, 96) for t in ("ma2018", "unet", "cspn",
                                                                                      "lip-cnn", "lip-fast")]
    assert [s.cooldown_images(b) for b in (32, 64, 96)] == [16, 32, 48]  # whole batches of 8
    assert [cooldown_images(b) for b in (10_000, 30_000, 100_000)] == [2_000, 6_000, 20_000]  # the default 0.2
    with pytest.raises(ValueError, match="multiples of the batch size"):
        study(tmp_path, images=30)
    with pytest.raises(ValueError, match="it needs 2 steps"):
        study(tmp_path, cooldown=0.2)  # 8 of the 32 images: one step
    with pytest.raises(ValueError, match="must leave some to the trunk"):
        study(tmp_path, cooldown=1.0)


def test_a_run_committed_to_go_on_from_is_copied_to_a_machine_without_it(tmp_path, capsys):
    committed = tmp_path / "warm" / "indoor" / "unet" / "lr0.00125" / "seed1"
    (committed / "checkpoints" / "500").mkdir(parents=True)
    (committed / "run.json").write_text("{}")
    s = study(tmp_path, warm_starts=tmp_path / "warm")
    assert not equal_budget.trunk_workdir(s, "indoor", "unet", 5e-4, 1).exists()  # another rate: another run
    workdir = equal_budget.trunk_workdir(s, "indoor", "unet", 1.25e-3, 1)
    assert (workdir / "checkpoints" / "500").is_dir() and (workdir / "run.json").read_text() == "{}"
    assert "continuing from" in capsys.readouterr().out
    (workdir / "run.json").write_text("moved on")  # a workdir that exists is never replaced
    assert (equal_budget.trunk_workdir(s, "indoor", "unet", 1.25e-3, 1) / "run.json").read_text() == "moved on"
    assert not equal_budget.trunk_workdir(study(tmp_path, warm_starts=None), "indoor", "unet", 1.25e-3, 2).exists()


def test_runs_in_progress_are_kept_with_their_newest_checkpoint_and_the_exports_still_needed(tmp_path):
    from lipjax.train.checkpoint import CheckpointManager

    s = study(tmp_path / "a", warm_starts=tmp_path / "warm", methods=("unet",))
    tuning = {"unet": {"0.0002": {"val_rmse_m": 0.6, "images": 16}, "0.0005": {"val_rmse_m": 0.5, "images": 16},
                       "0.00125": {"val_rmse_m": 0.7, "images": 16}}}
    (s.scores / "indoor").mkdir(parents=True)
    (s.scores / "indoor" / "tuning.json").write_text(json.dumps(tuning))
    runs = {k: equal_budget.run_dir(s.root, "indoor", "unet", 5e-4, k) for k in (0, 1)}
    for k, workdir in runs.items():
        (workdir / "models").mkdir(parents=True)
        (workdir / "run.json").write_text(json.dumps({"seed": k}))
        for step in (1, 2, 3):
            CheckpointManager(workdir / "checkpoints").save(step, {"w": np.full(2, float(step))}, {"step": step})
        for images in (16, 32, 48):  # the trunks' models at 32 - 16, 64 - 32 and 96 - 48 images (cool-down 0.5)
            for suffix in (".msgpack", ".json"):
                (workdir / "models" / f"{images}{suffix}").write_text(str(images))
    (runs[1] / "models" / "32.msgpack").unlink()  # seed 1 has not reached the start of budget 64's cool-down
    for k, budgets in ((0, (32, 64, 96)), (1, (32,))):  # seed 0 finished; seed 1 scored at 32, not at 64
        for b in budgets:
            equal_budget._write_json(equal_budget.result_path(s, "indoor", "unet", k, b), made(s, "unet", 5e-4))
    stale = equal_budget.run_dir(s.warm_starts, "indoor", "unet", 5e-4, 0)
    (stale / "checkpoints").mkdir(parents=True)  # kept by an earlier session, finished since

    kept = equal_budget.save_in_progress(s)
    assert kept == [equal_budget.run_dir(s.warm_starts, "indoor", "unet", 5e-4, 1)] and not stale.exists()
    assert sorted(str(p.relative_to(kept[0])) for p in kept[0].glob("*/*")) == ["checkpoints/3"]
    assert sorted(p.name for p in kept[0].iterdir()) == ["checkpoints", "run.json"]  # model 16: its budget is scored
    # a new machine (another --root) goes on from the copy: the newest checkpoint restores
    workdir = equal_budget.trunk_workdir(dataclasses.replace(s, root=tmp_path / "b"), "indoor", "unet", 5e-4, 1)
    state, meta = CheckpointManager(workdir / "checkpoints").restore({"w": np.zeros(2)})
    assert meta == {"step": 3} and state["w"].tolist() == [3.0, 3.0]
    # once the trunk has made its last export, that export is kept and the checkpoint is not
    (runs[1] / "models" / "32.msgpack").write_text("32")
    equal_budget.save_in_progress(s)
    assert sorted(p.name for p in kept[0].rglob("*")) == ["32.json", "32.msgpack", "models", "run.json"]


def test_cool_downs_in_progress_are_kept_with_their_newest_checkpoint_and_a_new_machine_goes_on_from_them(tmp_path):
    from lipjax.train.checkpoint import CheckpointManager

    s = study(tmp_path / "a", warm_starts=tmp_path / "warm", seeds={"indoor": (0,)}, curve={"indoor": (32, 64)},
              methods=("lip-cnn", "lip-ad"))
    (s.scores / "indoor").mkdir(parents=True)
    (s.scores / "indoor" / "tuning.json").write_text(json.dumps({"lip-cnn": tuned(16)}))
    trunk = equal_budget.run_dir(s.root, "indoor", "lip-cnn", 5e-4, 0)
    cooldowns = {m: equal_budget.run_dir(s.root, "indoor", m, 5e-4, 0) / "64" for m in ("lip-cnn", "lip-ad")}
    (trunk / "models").mkdir(parents=True)
    for suffix in (".msgpack", ".json"):  # the trunk's export at 64 - 32 images, where both cool-downs start
        (trunk / "models" / f"32{suffix}").write_text("32")
    for m, workdir in cooldowns.items():
        workdir.mkdir(parents=True)
        (workdir / "run.json").write_text(json.dumps({"method": m}))
        (workdir / "metrics.jsonl").write_text(json.dumps({"step": 2, "images_per_s": 1.0}) + "\n")
        for step in (1, 2):
            CheckpointManager(workdir / "checkpoints").save(step, {"w": np.full(2, float(step))}, {"step": step})
    (cooldowns["lip-ad"] / "model.msgpack").write_text("m")  # exported, not yet scored: its model is kept
    (cooldowns["lip-ad"] / "model.json").write_text("{}")
    for m in ("lip-cnn", "lip-ad"):  # budget 32 finished
        equal_budget._write_json(equal_budget.result_path(s, "indoor", m, 0, 32), made(s, m, 5e-4))
    done = equal_budget._committed(s, equal_budget.run_dir(s.root, "indoor", "lip-ad", 5e-4, 0) / "32")
    (done / "checkpoints").mkdir(parents=True)  # kept by an earlier session, scored since

    kept = equal_budget.save_in_progress(s)
    warm = {m: equal_budget._committed(s, w) for m, w in cooldowns.items()}
    assert kept == [equal_budget._committed(s, trunk), warm["lip-cnn"], warm["lip-ad"]] and not done.exists()
    assert sorted(p.name for p in warm["lip-cnn"].iterdir()) == ["checkpoints", "metrics.jsonl", "run.json"]
    assert [p.name for p in (warm["lip-cnn"] / "checkpoints").iterdir()] == ["2"]  # the newest only
    assert sorted(p.name for p in warm["lip-ad"].iterdir()) == ["metrics.jsonl", "model.json", "model.msgpack",
                                                                  "run.json"]
    # a new machine: the plan counts the committed cool-down's logged steps, and the run goes on from its checkpoint
    new = dataclasses.replace(s, root=tmp_path / "b")
    assert equal_budget.images_left(new, "indoor", "lip-cnn", 0, 64) == {"lip-cnn": 32 - 16, "lip-ad": 0}
    workdir = equal_budget.cooldown_workdir(new, "indoor", "lip-cnn", 5e-4, 0, 64)
    state, meta = CheckpointManager(workdir / "checkpoints").restore({"w": np.zeros(2)})
    assert meta == {"step": 2} and state["w"].tolist() == [2.0, 2.0]
    # scored on the first machine: the copies go, and the trunk's export with them
    for m in ("lip-cnn", "lip-ad"):
        equal_budget._write_json(equal_budget.result_path(s, "indoor", m, 0, 64), made(s, m, 5e-4))
    assert equal_budget.save_in_progress(s) == [] and list(s.warm_starts.iterdir()) == []


def test_plan_counts_the_images_left_and_the_hours_at_the_rates_measured(tmp_path):
    import os

    s = study(tmp_path, seeds={"indoor": (1,)}, curve={"indoor": (32, 64)}, methods=("lip-cnn", "lip-ad"))
    # untuned: three rates of 16 images, the trunk on to 64 - 32, cool-downs of 16 (budget 32) and 32 (budget 64)
    assert equal_budget.images_left(s, "indoor", "lip-cnn", 1, 64) == {"lip-cnn": 48 + 32 + 16 + 32, "lip-ad": 48}
    (s.scores / "indoor").mkdir(parents=True)
    (s.scores / "indoor" / "tuning.json").write_text(json.dumps({"lip-cnn": tuned(16)}))
    for m in ("lip-cnn", "lip-ad"):
        equal_budget._write_json(equal_budget.result_path(s, "indoor", m, 1, 32), made(s, m, 5e-4))
    trunk = equal_budget.run_dir(s.root, "indoor", "lip-cnn", 5e-4, 1)
    for workdir, step, rate in ((trunk, 2, 0.02), (trunk / "64", 1, 0.01)):
        workdir.mkdir(parents=True)
        (workdir / "metrics.jsonl").write_text(json.dumps({"step": step, "images_per_s": rate}) + "\n" +
                                               json.dumps({"step": step, "split": "val", "rmse_m": 1.0}) + "\n")
    os.utime(trunk / "metrics.jsonl", (1, 1))  # the cool-down's log is the newest: its rate counts
    # the trunk has logged 2 steps (16 images) of the 32, lip-cnn's cool-down 1 step (8) of its 32; lip-ad none
    assert equal_budget.images_left(s, "indoor", "lip-cnn", 1, 64) == {"lip-cnn": 16 + 24, "lip-ad": 32}
    assert equal_budget.measured_rate(s, "indoor", "lip-cnn") == 0.01
    assert equal_budget.measured_rate(s, "indoor", "lip-ad") is None
    text = equal_budget.plan_text(s)
    assert "indoor lip-cnn seed 1 up to 64 images (72 images to train)" in text and "2 scores left" in text
    assert text.endswith(f"{40 / 0.01 / 3600:.1f} h of training left at the rates measured in {s.root}, one run at a "
                         "time, and the runs of indoor lip-ad (no rate measured there yet)")
    # the export at 32 and lip-cnn's cool-down model made: only lip-ad's cool-down is left to train
    for path in (trunk / "models" / "32.msgpack", trunk / "64" / "model.msgpack"):
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("")
    assert equal_budget.images_left(s, "indoor", "lip-cnn", 1, 64) == {"lip-cnn": 0, "lip-ad": 32}


def test_a_score_counts_where_made_at_the_tuned_rate_after_the_studys_tuning_images_and_cool_down(tmp_path):
    s = study(tmp_path, methods=("lip-cnn", "lip-ad"))
    (s.scores / "indoor").mkdir(parents=True)
    (s.scores / "indoor" / "tuning.json").write_text(json.dumps({"lip-cnn": tuned(3000)}))
    assert equal_budget.tuned_so_far(s, "indoor", "lip-cnn") is None  # tried after 3,000 images, not the study's 16
    (s.scores / "indoor" / "tuning.json").write_text(json.dumps({"lip-cnn": tuned(16)}))
    assert equal_budget.tuned_so_far(s, "indoor", "lip-cnn") == 5e-4
    for doc, counts in ((made(s, "lip-ad", 5e-4), True), (made(s, "lip-ad", 2e-4), False),
                        (made(s, "lip-ad", 5e-4, cooldown=0.2), False)):
        equal_budget._write_json(equal_budget.result_path(s, "indoor", "lip-ad", 0, 32), doc)
        assert equal_budget.current(s, doc) is counts and equal_budget.scored(s, "indoor", "lip-ad", 0, 32) is counts
        assert ("indoor lip-ad seed 0 at 32" in equal_budget.missing(s)) is not counts
    assert not equal_budget.scored(s, "indoor", "lip-cnn", 0, 32)  # no file


def test_a_cool_down_made_another_way_is_made_again(tmp_path):
    from lipjax.train.loop import RUN_FILE, run_record

    def cooldown(start, images):
        return cooldown_config("lip-cnn", "indoor", learning_rate=5e-4, seed=0, init_from=start, images=images,
                               tiny=True)

    config, workdir = cooldown("models/24", 16), tmp_path / "32"
    assert equal_budget.stale_cooldown(config, workdir) is None  # nothing there yet
    workdir.mkdir()
    (workdir / RUN_FILE).write_text(json.dumps(run_record(cooldown("models/16", 16))))  # from another start
    assert "started another way" in equal_budget.stale_cooldown(config, workdir)
    (workdir / RUN_FILE).write_text(json.dumps(run_record(config)))
    assert equal_budget.stale_cooldown(config, workdir) is None  # the same run, part done
    model_io.save(workdir / "model", config.model, {}, {"steps": 4})  # a model of 4 steps: a cool-down of 32 images
    assert equal_budget.stale_cooldown(config, workdir) == "has 4 steps, not the 2 asked"
    assert equal_budget.stale_cooldown(cooldown("models/24", 32), workdir) is None  # the 32-image cool-down it is
    model_io.save(workdir / "model", config.model, {}, {"steps": 2})
    assert equal_budget.stale_cooldown(config, workdir) is None


def test_tiny_checks_keep_their_scores_and_runs_in_progress_in_their_root_never_in_the_committed_ones(tmp_path,
                                                                                                    monkeypatch):
    monkeypatch.chdir(tmp_path)
    for folder in (["--scores", equal_budget.SCORES], ["--warm-starts", str(equal_budget.WARM_STARTS)]):
        with pytest.raises(SystemExit):
            equal_budget.main(["--tiny", "--plan", *folder])
    seen = []
    monkeypatch.setattr(equal_budget, "plan_text", lambda s: seen.append((s.scores, s.warm_starts)) or "")
    monkeypatch.setattr(equal_budget, "save_in_progress", lambda s: seen.append((s.scores, s.warm_starts)) or [])
    equal_budget.main(["--tiny", "--plan", "--root", "check"])
    equal_budget.main(["--tiny", "--save-in-progress", "--root", "check"])
    assert seen == [(pathlib.Path("check") / "scores", pathlib.Path("check") / "warm-starts")] * 2
    equal_budget.main(["--plan"])
    assert seen[-1] == (pathlib.Path(equal_budget.SCORES), equal_budget.WARM_STARTS)


def test_a_tiny_check_reports_into_its_root_never_into_the_committed_results(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # the committed results' relative path would land here
    equal_budget.main(["--tiny", "--report", "--root", "check", "--scores", "scores", "--images", "96",
                       "--curve", "48,96", "--tune-images", "32", "--cooldown", "0.5"])
    assert (tmp_path / "check" / "report" / "equal_budget.md").exists() and not (tmp_path / "docs").exists()


def test_tuning_goes_past_the_grid_while_its_edge_is_best_and_at_most_two_steps():
    grid = dict.fromkeys(equal_budget.TUNE_LRS, 1.0)
    assert equal_budget.next_rate({}) == 2e-4 and equal_budget.next_rate({2e-4: 1.0}) == 5e-4
    assert equal_budget.next_rate({**grid, 5e-4: 0.5}) is None  # the best inside the grid: done
    assert equal_budget.next_rate({**grid, 1.25e-3: 0.5}) == 3.125e-3  # the top is best: one step up
    assert equal_budget.next_rate({**grid, 1.25e-3: 0.5, 3.125e-3: 0.4}) == 7.8125e-3
    assert equal_budget.next_rate({**grid, 1.25e-3: 0.5, 3.125e-3: 0.4, 7.8125e-3: 0.3}) is None  # two steps past
    assert equal_budget.next_rate({**grid, 1.25e-3: 0.5, 3.125e-3: 0.6}) is None  # the step up lost: 1.25e-3
    assert equal_budget.next_rate({**grid, 2e-4: 0.5}) == 8e-5  # the bottom is best: one step down
    assert equal_budget.next_rate({**grid, 1.25e-3: 0.5, 3.125e-3: float("nan")}) is None  # diverged: the worst
    assert study_report.best_rate({**grid, 1.25e-3: 0.5, 3.125e-3: float("nan")}) == 1.25e-3


def test_scores_made_at_another_rate_or_cool_down_than_the_studys_are_dropped(tmp_path, capsys):
    s = study(tmp_path)  # cool-down 0.5
    folder = s.scores_dir("indoor")
    folder.mkdir(parents=True)
    for name, lr, cooldown in (("unet-seed0-16", 1.25e-3, 0.5), ("unet-seed0-32", 3.125e-3, 0.5),
                               ("unet-seed0-48", 3.125e-3, None), ("unet-seed1-16", 1.25e-3, 0.5),
                               ("cspn-seed0-16", 1.25e-3, None)):
        (folder / f"{name}.json").write_text(json.dumps({"learning_rate": lr, "cooldown": cooldown}))
    equal_budget.drop_stale_scores(s, "indoor", ["unet"], 0, 3.125e-3)
    assert sorted(p.stem for p in folder.glob("*.json")) == ["cspn-seed0-16", "unet-seed0-32", "unet-seed1-16"]
    out = capsys.readouterr().out
    assert "made at learning rate 0.00125 and cool-down 0.5, not the tuned 0.003125 and 0.5" in out
    assert "made at learning rate 0.003125 and cool-down None" in out


def test_a_cool_down_decays_the_trunks_rate_to_zero_and_lip_ad_is_lip_cnns_made_adversarial():
    trunk = trunk_config("lip-cnn", "indoor", learning_rate=5e-4, seed=2, steps=3750)
    cnn, ad = (cooldown_config(m, "indoor", learning_rate=5e-4, seed=2, init_from="start", images=6000)
               for m in ("lip-cnn", "lip-ad"))
    assert (cnn.g_steps, cnn.d_steps, cnn.adv_steps) == (750, 0, 0) and not cnn.adversarial
    assert (ad.g_steps, ad.d_steps, ad.adv_steps) == (0, 50, 700)  # D pretrained for the paper's 50 steps
    for c in (cnn, ad):
        assert c.total_steps * c.batch_size == 6000 and c.init_from == "start"
        assert c.seed == 2 + COOLDOWN_SEED_OFFSET  # fresh frames, the same ones for both
        assert (c.model, c.data, c.learning_rate) == (trunk.model, trunk.data, trunk.learning_rate)
    lr = g_learning_rate(cnn)  # by G's updates: 750 of LIP+CNN's, 700 of LIP+AD's
    assert float(lr(20)) == pytest.approx(5e-4) and float(lr(385)) == pytest.approx(2.5e-4)
    assert float(lr(749)) == pytest.approx(5e-4 / 730, rel=1e-4) and float(lr(750)) == 0.0
    assert float(g_learning_rate(ad)(699)) == pytest.approx(5e-4 / 680, rel=1e-4)
    assert (cnn.name, ad.name) == ("study-lip-cnn-indoor", "study-lip-ad-indoor")
    fast = cooldown_config("lip-ad-fast", "indoor", learning_rate=5e-4, seed=0, init_from="start", images=2000)
    assert fast.discriminator.inputs == "log_gradients"
    assert fast.model == trunk_config("lip-fast", "indoor", learning_rate=5e-4, seed=0, steps=10).model
    with pytest.raises(ValueError, match="it needs at least 2"):
        cooldown_config("unet", "indoor", learning_rate=5e-4, seed=0, init_from="start", images=8)


def test_constant_schedule_holds_the_rate_after_warm_up_whatever_the_run_length():
    for steps in (300, 3000):
        config = dataclasses.replace(trunk_config("ma2018", "indoor", learning_rate=1e-3, seed=0, steps=steps))
        lr = g_learning_rate(config)
        assert float(lr(0)) == 0.0 and float(lr(50)) == pytest.approx(5e-4)  # linear warm-up over 100 steps
        assert [float(lr(s)) for s in (100, 299, 2999)] == pytest.approx([1e-3] * 3)
    cosine = g_learning_rate(dataclasses.replace(config, schedule="cosine"))
    assert float(cosine(2999)) == pytest.approx(0.05e-3, rel=1e-3)  # the default still decays to 5 %
    with pytest.raises(ValueError, match="schedule must be one of"):
        dataclasses.replace(config, schedule="step")


@pytest.mark.parametrize("model_type", ["unet", "cspn", "sparse_to_dense"])
def test_depth_in_units_of_the_samples_makes_a_network_scale_equivariant(model_type):
    """depth_scale "samples": f(rgb, c * s) = c * f(rgb, s) exactly (up to float rounding) for every c > 0, so no
    frame's absolute depth has to pass through the network; "max_depth" has no such property."""
    h, w = 32, 32
    rng = np.random.default_rng(0)
    rgb = jnp.asarray(rng.integers(0, 256, (1, h, w, 3)), jnp.uint8)
    sparse = np.zeros((1, h, w), np.float32)
    idx = rng.choice(h * w, 40, replace=False)
    sparse.reshape(-1)[idx] = rng.uniform(1.0, 6.0, 40)
    for scale, equivariant in (("samples", True), ("max_depth", False)):
        model = dataclasses.replace(baseline_preset(model_type, "tiny"), depth_scale=scale)
        params = model.init(jax.random.key(0))
        a = np.asarray(model.apply(params, rgb, jnp.asarray(sparse))[0])
        b = np.asarray(model.apply(params, rgb, jnp.asarray(3.0 * sparse))[0])
        assert np.allclose(b, 3.0 * a, rtol=1e-4, atol=1e-5 * np.abs(b).max()) == equivariant, scale
    with pytest.raises(ValueError, match="depth_scale must be one of"):
        dataclasses.replace(baseline_preset("unet", "tiny"), depth_scale="inches")


def test_paired_test_matches_scipy_over_frames_averaged_over_the_seeds():
    rng = np.random.default_rng(1)
    frames = 12

    def runs(method, offset):
        return [{"method": method, "images": 32, "seed": k,
                 "per_image": [{"id": f"f{i}", "rmse_m": float(v)}
                               for i, v in enumerate(rng.uniform(0.2, 0.4, frames) + offset)]}
                for k in (0, 1)]

    a, b = runs("lip-ad", 0.0), runs("unet", 0.05)
    got = study_report.paired_test(a + b, "lip-ad", "unet", 32)
    x = np.mean([[p["rmse_m"] for p in r["per_image"]] for r in a], axis=0)
    y = np.mean([[p["rmse_m"] for p in r["per_image"]] for r in b], axis=0)
    assert got["wilcoxon_p"] == pytest.approx(stats.wilcoxon(x, y).pvalue)
    assert got["ttest_p"] == pytest.approx(stats.ttest_rel(x, y).pvalue)
    assert got["a_better_frames"] == int((x < y).sum()) and got["seeds"] == [0, 1] and got["frames"] == frames
    low, high = got["diff_interval_m"]
    assert low < float(np.mean(x - y)) < high < 0 and got["a_better_seeds"] == 2  # b is 0.05 m worse throughout
    assert got["verdict"] == "lip-ad leads"
    assert study_report.paired_test(a, "lip-ad", "unet", 32) is None  # no run of b: no test
    b[1]["per_image"] = b[1]["per_image"][1:] + b[1]["per_image"][:1]  # the same frames in another order
    with pytest.raises(ValueError, match="unet seed 1 at 32 images was scored on other test frames than lip-ad"):
        study_report.paired_test(a + b, "lip-ad", "unet", 32)


def test_the_report_compares_every_method_again_at_each_larger_budget_all_of_them_reached(tmp_path):
    """Seed 0's curve goes on past the table's budget B = 64: once every method has its 128-image score the report
    holds that table and its paired tests again (the best end-to-end network chosen there); 256, which only U-Net
    has reached, waits."""
    s = study(tmp_path)
    rng = np.random.default_rng(2)
    offsets = {"lip-ad": 0.0, "lip-cnn": 0.01, "unet": 0.02, "cspn": 0.03}  # at B U-Net is the best end-to-end net
    runs = [(m, k, 64, off) for m, off in offsets.items() for k in (0, 1)]
    runs += [(m, 0, 128, off - 0.05 if m == "cspn" else off) for m, off in offsets.items()]  # CSPN best at 128
    runs += [("unet", 0, 256, 0.0)]
    folder = s.scores / "indoor"
    folder.mkdir(parents=True)
    frames = rng.uniform(0.2, 0.3, 8)  # each frame's difficulty, shared; the offsets rank the methods
    for method, seed, images, offset in runs:
        values = frames + offset + rng.normal(0.0, 0.002, 8)
        per_image = [{"id": f"f{i}", "rmse_m": float(v)} for i, v in enumerate(values)]
        rmse = float(np.mean([p["rmse_m"] for p in per_image]))
        (folder / f"{method}-seed{seed}-{images}.json").write_text(json.dumps(
            {"method": method, "seed": seed, "images": images, "rmse_m": rmse, "mae_m": rmse / 2,
             "per_image": per_image}))
    (folder / "classical.json").write_text(json.dumps({"linear": {"rmse_m": 0.3, "mae_m": 0.1},
                                                        "nearest": {"rmse_m": 0.4, "mae_m": 0.2}}))
    scores = study_report.load_scores(s.scores, "indoor")
    assert study_report.larger_budgets(scores, 64) == [128]
    assert study_report.larger_budgets(scores, 128) == []  # only U-Net at 256
    doc = study_report.write_report(s, [], lambda score: True, out=tmp_path / "report")
    assert doc["indoor"]["unet"]["seeds"] == [0, 1] and list(doc["details"]["indoor"]["larger_budgets"]) == ["128"]
    at = doc["details"]["indoor"]["larger_budgets"]["128"]
    cspn = json.loads((folder / "cspn-seed0-128.json").read_text())
    assert at["summary"]["cspn"] == {"images": 128, "seeds": [0], "rmse_m": [cspn["rmse_m"]], "mae_m": [cspn["mae_m"]]}
    assert at["summary"]["linear"] == {"rmse_m": 0.3, "mae_m": 0.1}
    assert [(t["a"], t["b"]) for t in doc["details"]["indoor"]["paired_tests"]] == [("lip-ad", "unet"),
                                                                                    ("lip-ad", "lip-cnn")]
    assert [(t["a"], t["b"]) for t in at["paired_tests"]] == [("lip-ad", "cspn"), ("lip-ad", "lip-cnn")]
    assert at["paired_tests"][0] == study_report.paired_test(scores, "lip-ad", "cspn", 128)
    md = (tmp_path / "report" / "equal_budget.md").read_text()
    section = md.split("### Every method at 128 images (seed 0; the curve's end)")[1]
    assert f"| cspn | 0 | {cspn['rmse_m']:.4f} | {cspn['mae_m']:.4f} | {cspn['rmse_m'] / 0.3:.2f}x |" in section
    assert "| linear (no training) | | 0.3000 | 0.1000 | 1.00x |" in section
    assert "| lip-ad vs cspn | 0 | 8 | " in section and "256" not in section


def test_the_curves_change_is_taken_over_the_seeds_scored_at_both_budgets():
    points = {(0, 10_000): 0.30, (0, 30_000): 0.24, (0, 100_000): 0.216, (1, 10_000): 0.20, (1, 30_000): 0.18,
              (2, 10_000): 0.50}  # seed 2 not yet at 30,000: it must not pull the 10,000 -> 30,000 step
    scores = [{"method": "unet", "seed": k, "images": n, "rmse_m": v} for (k, n), v in points.items()]
    change = study_report.curve_change(scores)["unet"]
    assert change["30000"]["from"] == 10_000 and change["30000"]["seeds"] == [0, 1]
    assert change["30000"]["change"] == pytest.approx((-0.20 - 0.10) / 2)
    assert change["100000"] == {"from": 30_000, "seeds": [0], "change": pytest.approx(-0.10)}
    assert "10000" not in change
    text = study_report._curve_text({"10000": [0.3, 0.2, 0.5], "30000": [0.24, 0.18]}, change)
    assert text == "10,000: 0.333, 30,000: 0.210 (-15%)"
    # still falling steeply: judged on each method's last step only, against the threshold fixed in advance
    flat = [{"method": "cspn", "seed": 0, "images": n, "rmse_m": v} for n, v in ((10_000, 0.30), (30_000, 0.2880))]
    changes = study_report.curve_change(scores + flat)  # cspn: -4 %, above the -5 % threshold
    assert study_report.still_falling(changes) == {"unet": {"from": 30_000, "to": 100_000, "seeds": [0],
                                                            "change": pytest.approx(-0.10)}}
    assert set(study_report.still_falling(changes, threshold=-0.03)) == {"unet", "cspn"}
    assert study_report.still_falling(changes, threshold=-0.11) == {}


def test_the_verdict_is_decision_0028s_rule_interval_excluding_zero_and_every_seed():
    def verdict(low, high, a_better, b_better=None, seeds=3):
        return study_report.verdict({"a": "lip-ad", "b": "cspn", "diff_interval_m": [low, high],
                                     "a_better_seeds": a_better, "seeds": list(range(seeds)),
                                     "b_better_seeds": seeds - a_better if b_better is None else b_better})

    assert verdict(-0.010, -0.001, 3) == "lip-ad leads"
    assert verdict(0.001, 0.010, 0) == "cspn leads"
    assert verdict(-0.010, -0.001, 2) == "not separated"  # the interval excludes 0 but one seed goes the other way
    assert verdict(0.001, 0.010, 1) == "not separated"
    assert verdict(0.001, 0.010, 0, b_better=2) == "not separated"  # a seed on which the two tie: not better there
    assert verdict(-0.013, 0.001, 3) == "not separated"  # better on every seed, but the interval holds 0
    assert verdict(0.0, 0.010, 0) == "not separated"  # 0 itself is not excluded


def test_the_best_end_to_end_network_is_ranked_over_the_seeds_they_all_have():
    summary = {"cspn": {"seeds": [0, 1], "rmse_m": [0.21, 0.21]},
               "unet": {"seeds": [0, 1, 2], "rmse_m": [0.205, 0.205, 0.30]}}  # its seed 2 not yet run by CSPN
    assert study_report.best_end_to_end(summary) == "unet"
    assert study_report.best_end_to_end({"lip-cnn": {"seeds": [0], "rmse_m": [0.1]}}) is None


def test_bootstrap_interval_spans_the_seeds_and_the_frames_it_draws_from():
    """A difference constant within each seed: every draw's mean is the mean of the seeds it drew, so the interval
    runs between the draws of the lowest and of the highest seed only; constant throughout: a point."""
    diff = np.repeat([[0.0], [1.0]], 50, axis=1)  # seed 0: a level with b; seed 1: a 1 m worse on every frame
    assert study_report.bootstrap_interval(diff) == (0.0, 1.0)  # draws {0,0}, {0,1}, {1,0}, {1,1}: 0, 0.5, 1
    assert study_report.bootstrap_interval(np.full((3, 20), -0.02)) == pytest.approx((-0.02, -0.02))
    one_seed = np.linspace(-1.0, 1.0, 101)[None]  # one seed: frames alone, evenly spread
    low, high = study_report.bootstrap_interval(one_seed)
    sem = one_seed.std() / np.sqrt(101)
    assert low == pytest.approx(-1.96 * sem, rel=0.1) and high == pytest.approx(1.96 * sem, rel=0.1)


def test_tiny_study_resumes_scores_every_budget_and_reports(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(equal_budget, "TUNE_LRS", (5e-4, 1e-3))  # two rates: a choice, in fewer compiles
    monkeypatch.setattr(equal_budget, "TUNE_EXTENSIONS", 0)  # none past them (next_rate's own test)
    args = ["--tiny", "--root", str(tmp_path / "study"), "--scores", str(tmp_path / "scores"), "--results",
            str(tmp_path / "report"), "--scene", "indoor",
            "--seeds", "0", "--images", "96", "--curve", "48,96", "--tune-images", "16", "--cooldown", "0.5",
            "--limit", "2", "--methods", "lip-cnn,lip-ad", "--no-progress"]
    equal_budget.main(args)
    results = tmp_path / "scores" / "indoor"
    names = sorted(p.name for p in results.glob("*-seed*-*.json"))
    assert names == sorted(f"{m}-seed0-{n}.json" for m in ("lip-cnn", "lip-ad") for n in (48, 96))
    for name in names:  # each score is of a model that read exactly its budget
        doc = json.loads((results / name).read_text())
        assert doc["images_seen"] == doc["images"] and len(doc["per_image"]) == 2
    lip = json.loads((results / "lip-cnn-seed0-96.json").read_text())
    k = str(lip["metrics"].get("iterations", 3))
    assert set(lip["rmse_m_by_iterations"]) == {"1", "2", "3"}  # Fig. 4a: every K of the 3-iteration solver
    assert lip["rmse_m_by_iterations"][k] == lip["rmse_m"]
    tuning = json.loads((results / "tuning.json").read_text())["lip-cnn"]
    chosen = min(tuning, key=lambda lr: tuning[lr]["val_rmse_m"])  # the trunk ran at the rate tuning chose
    start = pathlib.Path(lip["model"]).parents[1] / "models" / "48"  # the trunk's model the cool-down started from
    assert lipjax.load_model(start).metadata["learning_rate"] == lip["learning_rate"] == float(chosen)
    assert lipjax.load_model(lip["model"]).metadata["data_streams"][0]["steps"] == 6  # the trunk's 48 images
    report = json.loads((tmp_path / "report" / "equal_budget.json").read_text())
    assert report["indoor"]["lip-ad"]["images"] == 96 and report["indoor"]["lip-ad"]["seeds"] == [0]
    assert set(report["indoor"]) == {"lip-cnn", "lip-ad", "linear", "nearest"}
    assert report["details"]["indoor"]["paired_tests"][0]["b"] == "lip-cnn"  # no end-to-end network ran
    md = (tmp_path / "report" / "equal_budget.md").read_text()
    assert "| lip-cnn | " in md.split("Tuning")[1] and md.count("**") == 2  # what was tried, the chosen rate in bold
    assert (tmp_path / "report" / "equal_budget_curve_indoor.png").stat().st_size > 0
    _ships_as_the_papers_methods(tmp_path, results)
    stale = {**json.loads((results / "lip-cnn-seed0-96.json").read_text()), "method": "unet", "cooldown": None}
    (results / "unet-seed0-96.json").write_text(json.dumps(stale))  # made before the cool-down: not reported
    before = {p: p.stat().st_mtime_ns for p in results.glob("*.json")}
    capsys.readouterr()
    equal_budget.main(args)  # everything is done: nothing is trained or scored again
    assert {p: p.stat().st_mtime_ns for p in results.glob("*.json")} == before
    assert "unet" not in json.loads((tmp_path / "report" / "equal_budget.json").read_text())["indoor"]
    assert "test rmse_m" not in capsys.readouterr().out


def _ships_as_the_papers_methods(tmp_path, results):
    """experiments/ship_study.py on the tiny study: a scene ships all of its methods or none; a shipped model is the
    study's, weight for weight, named for its config, with the validation its training logged."""
    with pytest.raises(ValueError, match="no seed-0 score at 96 images for ma2018, unet, cspn, lip-fast, lip-ad-fast"):
        ship_study.main(["--images", "96", "--scores", str(tmp_path / "scores"), "--scene", "indoor",
                         "--out", str(tmp_path / "weights"), "--tiny"])
    for method in ("lip-cnn", "lip-ad"):
        score = json.loads((results / f"{method}-seed0-96.json").read_text())
        meta = ship_study.ship(method, "indoor", score, tmp_path / "weights", tiny=True)
        config, params, shipped = model_io.load(tmp_path / "weights" / f"{method}-indoor")
        study_config, study_params, _ = model_io.load(score["model"])
        assert config == study_config and jax.tree.all(jax.tree.map(np.array_equal, params, study_params))
        assert shipped == meta and (shipped["train_config"], shipped["seed"], shipped["images_seen"]) == (
            f"{method}-indoor", 0, 96)
        assert shipped["study"] == {"budget_images": 96, "learning_rate": score["learning_rate"],
                                    "test_rmse_m": score["rmse_m"], "test_mae_m": score["mae_m"]}
        # its named config (experiments/configs): the trunk's run, or LIP+AD's cool-down from the shipped trunk
        config = shipped_config(method, "indoor", learning_rate=score["learning_rate"], budget=96,
                                cooldown_fraction=0.5, tiny=True)
        run = shipped["data_streams"][0 if method == "lip-cnn" else -1]
        assert (config.name, config.total_steps, config.seed) == (f"{method}-indoor", run["steps"], run["seed"])
        assert config.init_from == (None if method == "lip-cnn" else "lip-cnn-indoor")
    # the branch validated at its last step while training: the same frames, the same model, the same RMSE
    logged = logged_validation(pathlib.Path(score["model"]).parent / "metrics.jsonl", meta["steps"])
    assert meta["val_metrics"]["rmse_m"] == pytest.approx(logged["rmse_m"], rel=1e-6)
    line = ship_study.expected_line("lip-ad", "indoor", meta)
    assert line.endswith(f'shipped_expected(val_rmse_m={meta["val_metrics"]["rmse_m"]:.7g}, images=96, cooldown=48, '
                         'trunk="lip-cnn"),')


def test_tuning_keeps_the_rates_another_study_process_wrote_meanwhile(tmp_path, monkeypatch):
    """Two study processes on disjoint --methods share a scene's tuning.json: each writes its trunk's rates into the
    file as it is then, so neither loses the other's."""
    import lipjax.train.loop as loop

    s = study(tmp_path)
    path = s.scores_dir("indoor") / "tuning.json"
    val = {2e-4: 0.5, 5e-4: 0.4, 1.25e-3: 0.6}

    def fake_train(config, workdir, progress):  # meanwhile, the other process tunes lip-cnn
        table = json.loads(path.read_text()) if path.exists() else {}
        table.setdefault("lip-cnn", {})[f"{config.learning_rate:g}"] = {"val_rmse_m": 0.3}
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(table))
        return type("State", (), {"g_params": config.learning_rate})

    monkeypatch.setattr(loop, "train", fake_train)
    monkeypatch.setattr(loop, "validation_batches", lambda config: [])
    monkeypatch.setattr(loop, "evaluate_params", lambda model, lr, batches, max_depth: {"rmse_m": val[lr],
                                                                                        "mae_m": 0.0})
    assert equal_budget.tuned_learning_rate(s, "indoor", "unet", progress=False) == 5e-4
    table = json.loads(path.read_text())
    assert {k: v["val_rmse_m"] for k, v in table["unet"].items()} == {"0.0002": 0.5, "0.0005": 0.4, "0.00125": 0.6}
    assert set(table["lip-cnn"]) == {"0.0002", "0.0005", "0.00125"}
