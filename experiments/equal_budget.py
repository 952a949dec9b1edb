"""The paper's comparison at equal training budgets: every learned method of Table I (rooms, 200 points) and Table II
(streets, 64-beam LiDAR) trained on the same data for the same number of images, with several seeds, and scored on
the tables' synthetic test splits (issue 52).

    python -m experiments.equal_budget                 # the whole study; resumes where it stopped
    python -m experiments.equal_budget --scene indoor --seeds 0 --images 30000 --curve 10000,30000
    python -m experiments.equal_budget --plan          # what is done and left, and the hours left; runs nothing
    python -m experiments.equal_budget --report        # docs/results/equal_budget.json, tables, figures, tests
    python -m experiments.equal_budget --save-in-progress  # at a session's end, the study stopped: what to commit
    python -m experiments.equal_budget --tiny --root /tmp/study --images 96 --curve 48,96 --tune-images 32 \\
        --cooldown 0.5 --limit 2 --methods ma2018,lip-cnn,lip-ad   # a check: tiny networks on 48x64 frames,
                                                                     # its scores and report in /tmp/study

Methods (experiments/configs/study.py): Ma et al. (ma2018), U-Net, CSPN, LIP+CNN with the paper's prox (lip-cnn),
LIP with the fast prox (lip-fast), and LIP+AD of each (lip-ad, lip-ad-fast: their trunk's cool-down made
adversarial). LIP+Wavelet needs no training and is not part of the study. Every run reads the scene's training data
with the study's seed, batch 8; a trunk at a constant learning rate after 100 warm-up steps, and the model at budget
N is the trunk's at N - C cooled down over C = --cooldown x N more images (the rate decaying linearly to 0).
"images" counts G's training images (batch x steps, LIP+AD's D steps included), equal for every method.

Stages, each skipped when its output exists, so the study continues across sessions and survives any stop (every
run is a checkpointed training that resumes). The tuning and the scores are small JSON files in --scores
(experiments/study_scores, committed: a new machine goes on from them); runs, checkpoints and models stay in --root
(runs/study, not committed) except the runs in progress at a session's end: --save-in-progress copies each trunk (its
newest checkpoint and the exports still needed) and each cool-down (its newest checkpoint) to --warm-starts
(experiments/warm_starts/study/<scene>/<method>/lr<rate>/seed<k>[/<budget>]), committed once a session, and a new
machine continues from there:
  1. tuning: each trunk's learning rate, the lowest validation RMSE after --tune-images images among TUNE_LRS and,
     while the best is the grid's edge, rates beyond it (`next_rate`; seed 0, the validation split: never the test
     split); the same small budget for every trunk;
  2. per scene, per seed: each trunk on to N - C for each budget N of its curve (--curve points <= --images for
     every seed, all of --curve for seed 0), its model exported there; then at each budget the cool-down of the
     trunk and of each LIP+AD, each scored on the test split;
  3. the report (also --report): docs/results/equal_budget.json, docs/results/equal_budget.md, the data-efficiency
     curve and Fig. 4a (RMSE against the ADMM iteration count K over the seeds) as PNGs, and paired tests.
Order: the tuning and every seed at --images on rooms, then streets, then seed 0 beyond --images (the curve).
Two processes on disjoint --methods (e.g. the end-to-end networks and the LIP models) may run at once: they share
the scene's tuning.json under a lock.
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import fcntl
import functools
import json
import pathlib
import shutil
import sys


from experiments.configs.study import (COOLDOWN_FRACTION, METHODS, SCENES, STUDY_ROOT, TRUNKS, branches_of,
                                      cooldown_config, cooldown_images, run_dir, test_split, trunk_config,
                                      trunk_export, trunk_of)
from experiments.study_report import best_rate, write_report
from lipjax.train.config import TrainConfig
from lipjax.console import ArgumentParser, run_main
from lipjax.data.protocols import get_protocol
from lipjax.data.sampling import sampler_from_spec
from lipjax.utils import enable_compilation_cache, written_whole

PROG = f"python -m {__spec__.name}"

TUNE_LRS = (2e-4, 5e-4, 1.25e-3)  # x2.5 steps around the configs' 5e-4; the same three for every trunk
# Where the best of TUNE_LRS is its largest (smallest), tuning goes on one x TUNE_FACTOR step beyond it while the best
# is the edge of what was tried, at most TUNE_EXTENSIONS steps past the grid (docs/decisions/0028, amended 2026-12-06)
TUNE_FACTOR, TUNE_EXTENSIONS = 2.5, 2
TEST_INPUT = {"indoor": "uniform:200", "outdoor": "lidar:hdl64"}  # Tables I and II
TEST_LIMIT = {"indoor": 100, "outdoor": 50}  # the tables' default frame counts
DEFAULT_SEEDS = {"indoor": (0, 1, 2), "outdoor": (0,)}
DEFAULT_CURVE = {"indoor": (10_000, 30_000, 100_000), "outdoor": ()}
BATCH = 8
SCORES = "experiments/study_scores"  # the study's record: tuning and per-frame scores (JSON), kept in the repository
# A run's workdir committed to continue from (at most one a session: the run in progress when the session ended)
WARM_STARTS = pathlib.Path("experiments/warm_starts/study")


@dataclasses.dataclass(frozen=True)
class Study:
    """What to run. images: the budget B of every run of the tables; curve: the budgets scored on the way (seed 0
    goes on to the largest); cooldown: the cool-down's share of each budget; limit: test frames (None: the
    tables' own counts); tiny: tiny networks and frames (checks, not results)."""

    root: pathlib.Path
    scores: pathlib.Path = pathlib.Path(SCORES)
    scenes: tuple[str, ...] = SCENES
    seeds: dict = dataclasses.field(default_factory=lambda: dict(DEFAULT_SEEDS))
    images: int = 30_000
    curve: dict = dataclasses.field(default_factory=lambda: dict(DEFAULT_CURVE))
    tune_images: int = 3_000
    cooldown: float = COOLDOWN_FRACTION
    limit: int | None = None
    tiny: bool = False
    methods: tuple[str, ...] = METHODS
    workers: int = 1  # loader processes of every run (data.num_workers: how fast, not what it reads)
    warm_starts: pathlib.Path | None = WARM_STARTS  # workdirs to go on from, committed (None: never)

    def __post_init__(self):
        for n in (self.images, self.tune_images, *[c for cs in self.curve.values() for c in cs]):
            if n % BATCH or n <= 0:
                raise ValueError(f"image counts must be positive multiples of the batch size {BATCH}, got {n}")
        smallest = min(self.budgets_for(s, 0)[0] for s in self.scenes)
        if not 0 < self.cooldown < 1 or not 2 * BATCH <= self.cooldown_images(smallest) < smallest:
            raise ValueError(f"--cooldown {self.cooldown} leaves {self.cooldown_images(smallest)} of the smallest "
                             f"budget's {smallest} images to the cool-down; it needs 2 steps ({2 * BATCH} images) "
                             "and must leave some to the trunk")

    def budgets_for(self, scene: str, seed: int) -> list[int]:
        """The budgets a run of `seed` is scored at: the curve's up to `images`, and `images`; seed 0 all of the
        curve."""
        curve = self.curve.get(scene, ())
        return sorted({self.images, *(c for c in curve if c <= self.images or seed == 0)})

    def cooldown_images(self, budget: int) -> int:
        """The images of the cool-down that ends at `budget` (the trunk's model at budget minus them starts it)."""
        return cooldown_images(budget, self.cooldown, BATCH)

    def scene_dir(self, scene: str) -> pathlib.Path:
        """The runs, checkpoints and models of a scene (not committed)."""
        return self.root / scene

    def scores_dir(self, scene: str) -> pathlib.Path:
        """The tuning and the scores of a scene: small JSON files, committed, so that a new machine goes on."""
        return self.scores / scene


# ---- stage 1: tuning -------------------------------------------------------------------------------------------

def next_rate(rmse: dict[float, float]) -> float | None:
    """The learning rate tuning tries next, given {rate: validation RMSE} of the rates tried so far (None: done):
    TUNE_LRS in order; then, while the best (non-finite RMSE counting as the worst) is the largest rate tried, one
    TUNE_FACTOR step above it, or the smallest, one below it, at most TUNE_EXTENSIONS steps past TUNE_LRS."""
    for lr in TUNE_LRS:
        if lr not in rmse:
            return lr
    best = best_rate(rmse)
    top, bottom = TUNE_LRS[-1] * TUNE_FACTOR ** TUNE_EXTENSIONS, TUNE_LRS[0] / TUNE_FACTOR ** TUNE_EXTENSIONS
    if best == max(rmse) and best < top * (1 - 1e-9):
        return float(f"{best * TUNE_FACTOR:.6g}")
    if best == min(rmse) and best > bottom * (1 + 1e-9):
        return float(f"{best / TUNE_FACTOR:.6g}")
    return None


def tuned_learning_rate(study: Study, scene: str, trunk: str, progress: bool) -> float:
    """The trunk's learning rate: the lowest validation RMSE after tune_images images of seed 0 among the rates
    `next_rate` asks for (cached in <scores>/<scene>/tuning.json with every rate's score)."""
    from lipjax.train.loop import evaluate_params, train, validation_batches

    path = study.scores_dir(scene) / "tuning.json"
    scores = _tried(study, scene, trunk)
    while (lr := next_rate({float(k): v["val_rmse_m"] for k, v in scores.items()})) is not None:
        config = trunk_config(trunk, scene, learning_rate=lr, seed=0, steps=study.tune_images // BATCH,
                              tiny=study.tiny)
        config = with_workers(dataclasses.replace(config, eval_every=config.g_steps), study.workers)
        state = train(config, study.scene_dir(scene) / "tune" / trunk / f"lr{lr:g}", progress=progress)
        val = evaluate_params(config.model, state.g_params, validation_batches(config), config.model.max_depth_m)
        scores[f"{lr:g}"] = {"val_rmse_m": val["rmse_m"], "val_mae_m": val["mae_m"], "images": study.tune_images}
        with _locked(path):  # another study process (--methods) may be adding its trunks' rates
            table = _tuning(path)
            table[trunk] = scores
            _write_json(path, table)
        print(f"[study] {scene} {trunk} lr {lr:g}: val rmse_m={val['rmse_m']:.4f}", flush=True)
    return best_rate({float(k): v["val_rmse_m"] for k, v in scores.items()})


def tuned_so_far(study: Study, scene: str, trunk: str) -> float | None:
    """The trunk's tuned learning rate if its tuning is complete, else None (trains nothing)."""
    scores = _tried(study, scene, trunk)
    rmse = {float(k): v["val_rmse_m"] for k, v in scores.items()}
    return best_rate(rmse) if rmse and next_rate(rmse) is None else None


def _tuning(path: pathlib.Path) -> dict:
    """{trunk: {rate: {"val_rmse_m": ...}}} of a scene's tuning.json (empty before the first rate)."""
    return json.loads(path.read_text()) if path.exists() else {}


def _tried(study: Study, scene: str, trunk: str) -> dict:
    """{rate: score} of the rates tuning has tried for `trunk` after this study's --tune-images (a rate tried after
    another count is tried again)."""
    tried = _tuning(study.scores_dir(scene) / "tuning.json").get(trunk, {})
    return {rate: v for rate, v in tried.items() if v.get("images") == study.tune_images}


def with_workers(config: TrainConfig, workers: int) -> TrainConfig:
    return dataclasses.replace(config, data=dataclasses.replace(config.data, num_workers=workers))


# ---- stage 2: runs and scores ----------------------------------------------------------------------------------

def score_path(scores: pathlib.Path, scene: str, method: str, seed: int, images: int) -> pathlib.Path:
    """The score of `method`, `seed` at `images` images in the study's scores folder `scores`."""
    return scores / scene / f"{method}-seed{seed}-{images}.json"


def result_path(study: Study, scene: str, method: str, seed: int, images: int) -> pathlib.Path:
    return score_path(study.scores, scene, method, seed, images)


def scored(study: Study, scene: str, method: str, seed: int, images: int) -> bool:
    """Whether `method` of `seed` has its score at `images` made the study's way (`current`)."""
    path = result_path(study, scene, method, seed, images)
    return path.exists() and current(study, json.loads(path.read_text()))


def current(study: Study, doc: dict) -> bool:
    """Whether score `doc` was made the study's way: at its trunk's tuned learning rate (tuning complete) and with
    the study's cool-down share. The others are left out of the report and made again (`drop_stale_scores`)."""
    made = (doc.get("learning_rate"), doc.get("cooldown"))
    return made == (tuned_so_far(study, doc.get("scene"), trunk_of(doc.get("method"))), study.cooldown)


def run_trunk(study: Study, scene: str, trunk: str, seed: int, upto: int, progress: bool) -> None:
    """Trains trunk `trunk` of `seed` on to N - C for each budget N up to `upto` images, exporting its model there,
    then finishes each budget's model of the trunk and of its LIP+AD (`finish`) and scores it on the test split."""
    from lipjax.train.loop import export, train

    lr = tuned_learning_rate(study, scene, trunk, progress)
    budgets = [b for b in study.budgets_for(scene, seed) if b <= upto]
    methods = branches_of(trunk, study.methods)
    drop_stale_scores(study, scene, methods, seed, lr)
    final = max(study.budgets_for(scene, seed))  # the run's length is fixed by its seed's largest budget
    config = with_workers(trunk_config(trunk, scene, learning_rate=lr, seed=seed, steps=final // BATCH,
                                       tiny=study.tiny), study.workers)
    workdir = trunk_workdir(study, scene, trunk, lr, seed)
    for budget in budgets:
        left = [m for m in methods if not scored(study, scene, m, seed, budget)]
        if not left:
            continue
        images = budget - study.cooldown_images(budget)
        start = trunk_export(study.root, scene, trunk, lr, seed, images)
        if not start.with_suffix(".msgpack").exists():
            state = train(config, workdir, stop_at=images // BATCH, progress=progress)
            if int(state.step) != images // BATCH:
                raise ValueError(f"{workdir} is at {int(state.step) * BATCH} images, past {images}: a budget "
                                 "added after the run went by it cannot be scored; start another --root")
            export(config, state, start, {"learning_rate": lr, "schedule": config.schedule, "data": scene})
        for method in left:
            finish(study, scene, method, lr, start, seed, budget, progress)


def drop_stale_scores(study: Study, scene: str, methods: list[str], seed: int, lr: float) -> None:
    """Removes the scores of `methods` and `seed` made at a learning rate other than the trunk's tuned `lr` (tuning
    that went past its grid after they were made) or with another cool-down share than the study's (scores made
    before the cool-down was adopted have none): they are made again."""
    for method in methods:
        for path in study.scores_dir(scene).glob(f"{method}-seed{seed}-*.json"):
            doc = json.loads(path.read_text())
            made = (doc.get("learning_rate"), doc.get("cooldown"))
            if made != (lr, study.cooldown):
                path.unlink()
                print(f"[study] {path} was made at learning rate {made[0]} and cool-down {made[1]}, not the tuned "
                      f"{lr:g} and {study.cooldown:g}: made again", flush=True)


def trunk_workdir(study: Study, scene: str, trunk: str, lr: float, seed: int) -> pathlib.Path:
    """The run's workdir in --root (one per learning rate); on a machine without it, a copy of the one committed
    under study.warm_starts (the run that was in progress when a session ended), if any."""
    return _go_on_from_committed(study, run_dir(study.root, scene, trunk, lr, seed), f"{scene} {trunk} seed {seed}")


def cooldown_workdir(study: Study, scene: str, method: str, lr: float, seed: int, budget: int) -> pathlib.Path:
    """The workdir of `method`'s cool-down to `budget` in --root; on a machine without it, a copy of the one
    committed under study.warm_starts (a cool-down in progress when a session ended), if any."""
    return _go_on_from_committed(study, run_dir(study.root, scene, method, lr, seed) / str(budget),
                                 f"{scene} {method} seed {seed} at {budget} images")


def _go_on_from_committed(study: Study, workdir: pathlib.Path, name: str) -> pathlib.Path:
    """`workdir` (under --root), copied first from its committed copy (the same path under study.warm_starts) where
    --root lacks it and a copy exists."""
    if (source := _here_or_committed(study, workdir)) != workdir and source.is_dir():
        shutil.copytree(source, workdir)
        print(f"[study] {name}: continuing from {source}", flush=True)
    return workdir


def _committed(study: Study, path: pathlib.Path) -> pathlib.Path | None:
    """Where `path` (under --root) is kept under study.warm_starts; None without warm starts."""
    return None if study.warm_starts is None else study.warm_starts / path.relative_to(study.root)


def _here_or_committed(study: Study, path: pathlib.Path) -> pathlib.Path:
    """`path`, or its committed copy where --root lacks it: what a run goes on from (`_go_on_from_committed`)."""
    committed = _committed(study, path)
    return committed if not path.exists() and committed is not None and committed.exists() else path


def save_in_progress(study: Study) -> list[pathlib.Path]:
    """Copies each run in --root that the study has not finished into study.warm_starts (the same layout), for a
    session that keeps only what is committed to go on from (`trunk_workdir`, `cooldown_workdir`): a trunk's record
    and metrics, the exports that its unscored budgets start their cool-downs from, and its newest checkpoint while
    one of those exports is still ahead of it; a cool-down's record, metrics and newest checkpoint (its model instead
    once exported). Removes the copies of runs finished since. Run it with the study stopped (a checkpoint being
    written is not yet listed). Returns the runs copied."""
    from lipjax.train.checkpoint import CheckpointManager

    copied = []
    for scene, trunk, seed in dict.fromkeys((scene, trunk, seed) for scene, trunk, seed, _ in plan(study)):
        lr = tuned_so_far(study, scene, trunk)
        if lr is None or not (workdir := run_dir(study.root, scene, trunk, lr, seed)).is_dir():
            continue
        methods = branches_of(trunk, study.methods)
        unscored = {b: [m for m in methods if not scored(study, scene, m, seed, b)]
                    for b in study.budgets_for(scene, seed)}
        starts = [trunk_export(study.root, scene, trunk, lr, seed, b - study.cooldown_images(b))
                  for b, left in unscored.items() if left]
        step = CheckpointManager(workdir / "checkpoints").latest_step()
        keep = [s.with_suffix(x) for s in starts for x in (".msgpack", ".json") if s.with_suffix(".msgpack").exists()]
        if step is not None and not all(s.with_suffix(".msgpack").exists() for s in starts):
            keep.append(workdir / "checkpoints" / str(step))
        copied += _keep(study, workdir, keep)
        for budget, left in unscored.items():
            for method in methods:
                cooldown = run_dir(study.root, scene, method, lr, seed) / str(budget)
                if method not in left:
                    _drop_committed(study, cooldown)  # finished since
                if method not in left or not cooldown.is_dir():  # a copy of one not started here stays
                    continue
                model = cooldown / "model.msgpack"
                step = CheckpointManager(cooldown / "checkpoints").latest_step()
                copied += _keep(study, cooldown, [model, model.with_suffix(".json")] if model.exists()
                                else [] if step is None else [cooldown / "checkpoints" / str(step)])
    return copied


def _keep(study: Study, workdir: pathlib.Path, keep: list[pathlib.Path]) -> list[pathlib.Path]:
    """Replaces the committed copy of `workdir` by its files (not its folders) and `keep` (paths inside it); none
    where `keep` is empty. Returns [the copy] or []."""
    dest = _committed(study, workdir)
    _drop_committed(study, workdir)
    if not keep:
        return []
    tmp = dest.with_name(dest.name + ".partial")
    shutil.rmtree(tmp, ignore_errors=True)
    for path in [p for p in workdir.iterdir() if p.is_file()] + keep:
        target = tmp / path.relative_to(workdir)
        target.parent.mkdir(parents=True, exist_ok=True)
        (shutil.copytree if path.is_dir() else shutil.copy2)(path, target)
    tmp.rename(dest)
    print(f"[study] {workdir.relative_to(study.root)}: kept in {dest} (" + ", ".join(
        str(p.relative_to(workdir)) for p in keep) + ")", flush=True)
    return [dest]


def _drop_committed(study: Study, workdir: pathlib.Path) -> None:
    """Removes the committed copy of `workdir` and the folders that this leaves empty."""
    dest = _committed(study, workdir)
    if dest is None or not dest.exists():
        return
    shutil.rmtree(dest)
    for parent in dest.parents:
        if parent == study.warm_starts or any(parent.iterdir()):
            break
        parent.rmdir()


def finish(study: Study, scene: str, method: str, lr: float, start: pathlib.Path, seed: int, budget: int,
           progress: bool) -> None:
    """The model of `method` at `budget`: the cool-down (experiments/configs/study.py) of its trunk's model `start`,
    at the trunk's learning rate `lr`, in <root>/<scene>/<method>/lr<lr>/seed<seed>/<budget>; then its score."""
    from lipjax.train.run import run

    config = with_workers(cooldown_config(method, scene, learning_rate=lr, seed=seed, init_from=str(start),
                                          images=study.cooldown_images(budget), tiny=study.tiny), study.workers)
    model = cooldown_workdir(study, scene, method, lr, seed, budget) / "model"
    if (why := stale_cooldown(config, model.parent)) is not None:
        shutil.rmtree(model.parent)
        print(f"[study] {model.parent} {why}: made again", flush=True)
    if not model.with_suffix(".msgpack").exists():
        run(config, model.parent, export=model, progress=progress)
    score(study, scene, method, seed, budget, model, lr)


def stale_cooldown(config: TrainConfig, workdir: pathlib.Path) -> str | None:
    """Why the cool-down run in `workdir` is not `config`'s (another start, seed or data: its run record; or another
    length: its model's steps), e.g. after --cooldown changed; None where it is (or there is none)."""
    from lipjax import model_io
    from lipjax.train.loop import check_same_run

    try:
        check_same_run(config, workdir)
    except ValueError:
        return "was started another way (its run.json)"
    model = workdir / "model.msgpack"
    steps = model_io.metadata(model.with_suffix("")).get("steps") if model.exists() else config.total_steps
    return None if steps == config.total_steps else f"has {steps} steps, not the {config.total_steps} asked"


def score(study: Study, scene: str, method: str, seed: int, images: int, model: pathlib.Path, lr: float) -> dict:
    """Scores `model` (trained at learning rate `lr`) on the scene's test split (Table I / II input, protocol and
    frames), per frame, and for a LIP model at every iteration count K (Fig. 4a); writes
    <scores>/<scene>/<method>-seed<seed>-<images>.json."""
    from lipjax.evaluate import evaluate
    from lipjax.inference import load_model
    from lipjax.model import LIPConfig

    completer = load_model(model)
    dataset, sampler, protocol, limit = test_setup(study, scene)
    per_k = {}
    ks = range(1, completer.config.num_iterations + 1) if isinstance(completer.config, LIPConfig) else ()
    for k in ks:
        r = evaluate(completer.with_iterations(k), dataset, sampler, min_depth_m=protocol.min_depth_m,
                     max_depth_m=protocol.max_depth_m, limit=limit, progress=False)
        per_k[k] = r
    full = per_k[max(ks)] if ks else evaluate(completer, dataset, sampler, min_depth_m=protocol.min_depth_m,
                                              max_depth_m=protocol.max_depth_m, limit=limit, progress=False)
    doc = {"method": method, "scene": scene, "seed": seed, "images": images, "learning_rate": lr,
           "cooldown": study.cooldown,
           "images_seen": completer.metadata.get("images_seen"), "model": str(model),
           "rmse_m": full.metrics["rmse_m"], "mae_m": full.metrics["mae_m"], "metrics": full.metrics,
           "per_image": [{"id": p["id"], "rmse_m": p["rmse_m"], "mae_m": p["mae_m"]} for p in full.per_image],
           "rmse_m_by_iterations": {str(k): r.metrics["rmse_m"] for k, r in per_k.items()}}
    if doc["images_seen"] != images:
        raise RuntimeError(f"{model} has read {doc['images_seen']} images, the study asked {images}")
    _write_json(result_path(study, scene, method, seed, images), doc)
    print(f"[study] {scene} {method} seed {seed} at {images} images: test rmse_m={doc['rmse_m']:.4f} "
          f"mae_m={doc['mae_m']:.4f}", flush=True)
    return doc


def test_setup(study: Study, scene: str):
    """(dataset, sampler, protocol, frame limit) of the scene's table."""
    protocol = get_protocol(f"synthetic_{scene}")
    return (test_split(scene, study.tiny), sampler_from_spec(TEST_INPUT[scene]), protocol,
            study.limit or TEST_LIMIT[scene])


def score_classical(study: Study, scene: str) -> dict:
    """The linear and nearest fills on the same test frames (<scores>/<scene>/classical.json)."""
    from lipjax.evaluate import evaluate
    from lipjax.methods import get_completer

    path = study.scores_dir(scene) / "classical.json"
    if path.exists():
        return json.loads(path.read_text())
    dataset, sampler, protocol, limit = test_setup(study, scene)
    doc = {}
    for name in ("linear", "nearest"):
        r = evaluate(get_completer(name), dataset, sampler, min_depth_m=protocol.min_depth_m,
                     max_depth_m=protocol.max_depth_m, limit=limit, progress=False)
        doc[name] = {"rmse_m": r.metrics["rmse_m"], "mae_m": r.metrics["mae_m"],
                     "per_image": [{"id": p["id"], "rmse_m": p["rmse_m"], "mae_m": p["mae_m"]} for p in r.per_image]}
    _write_json(path, doc)
    return doc


# ---- the plan ----------------------------------------------------------------------------------------------------

def plan(study: Study) -> list[tuple[str, str, int, int]]:
    """(scene, trunk, seed, up to images) in the order they run: every seed at `images` on each scene in turn, then
    seed 0 on along the curve."""
    trunks = [t for t in TRUNKS if any(trunk_of(m) == t for m in study.methods)]
    steps = [(scene, t, seed, study.images) for scene in study.scenes for seed in study.seeds[scene] for t in trunks]
    steps += [(scene, t, seed, max(study.budgets_for(scene, seed))) for scene in study.scenes
              for seed in study.seeds[scene] for t in trunks if max(study.budgets_for(scene, seed)) > study.images]
    return steps


def missing(study: Study) -> list[str]:
    """The scores the study still lacks, as 'scene method seed images'."""
    left = []
    for scene in study.scenes:
        for seed in study.seeds[scene]:
            for method in study.methods:
                left += [f"{scene} {method} seed {seed} at {b}" for b in study.budgets_for(scene, seed)
                         if not scored(study, scene, method, seed, b)]
    return left


def _done(study: Study, scene: str, trunk: str, seed: int, upto: int) -> bool:
    """Whether every score of the trunk and its branches up to `upto` images exists."""
    methods = branches_of(trunk, study.methods)
    return all(scored(study, scene, m, seed, b) for m in methods
               for b in study.budgets_for(scene, seed) if b <= upto)


def images_left(study: Study, scene: str, trunk: str, seed: int, upto: int) -> dict[str, int]:
    """The training images plan step (scene, trunk, seed, upto) still needs, by method: the trunk's tuning (rates
    of TUNE_LRS not yet tried; its extensions cannot be foreseen) and its run on to the last export still needed,
    and each cool-down whose model is not exported yet; runs part done (in --root, or committed to go on from) count
    what their metrics.jsonl logged."""
    methods = branches_of(trunk, study.methods)
    left = dict.fromkeys(methods, 0)
    lr = tuned_so_far(study, scene, trunk)
    if lr is None:
        tried = _tried(study, scene, trunk)
        left[trunk] += study.tune_images * sum(f"{r:g}" not in tried for r in TUNE_LRS)
    trunk_to = 0
    for budget in [b for b in study.budgets_for(scene, seed) if b <= upto]:
        todo = [m for m in methods if not scored(study, scene, m, seed, budget)]
        start = budget - study.cooldown_images(budget)
        if todo and (lr is None or not _here_or_committed(study, trunk_export(
                study.root, scene, trunk, lr, seed, start).with_suffix(".msgpack")).exists()):
            trunk_to = start
        for method in todo:
            cooldown = None if lr is None else _here_or_committed(
                study, run_dir(study.root, scene, method, lr, seed) / str(budget))
            if cooldown is None or not (cooldown / "model.msgpack").exists():
                left[method] += max(0, study.cooldown_images(budget) - _logged_images(cooldown))
    if trunk_to:
        left[trunk] += trunk_to - min(trunk_to, _logged_images(
            None if lr is None else _here_or_committed(study, run_dir(study.root, scene, trunk, lr, seed))))
    return left


def _logged_images(workdir: pathlib.Path | None) -> int:
    """The images a run in `workdir` has trained, as its metrics.jsonl logged them (0: no run there)."""
    rows = _training_rows(workdir / "metrics.jsonl") if workdir is not None else []
    return max((r["step"] for r in rows), default=0) * BATCH


def _training_rows(path: pathlib.Path) -> list[dict]:
    """The training lines (those with images_per_s) of a metrics.jsonl, oldest first; [] where there is none."""
    if not path.is_file():
        return []
    return [r for r in map(json.loads, path.read_text().splitlines()) if "images_per_s" in r]


def measured_rate(study: Study, scene: str, method: str) -> float | None:
    """The images/s `method` trained at on `scene` in this --root: the newest rate its runs (any seed, tuning
    included) logged; None where it has not run here."""
    logs = [*(study.scene_dir(scene) / method).glob("**/metrics.jsonl"),
            *(study.scene_dir(scene) / "tune" / method).glob("**/metrics.jsonl")]
    logs.sort(key=lambda p: p.stat().st_mtime)
    rates = [rows[-1]["images_per_s"] for rows in map(_training_rows, logs) if rows]
    return rates[-1] if rates else None


def plan_text(study: Study) -> str:
    """--plan's text: each step of the plan, done or the images it still needs; the scores left; and the hours of
    training left at the rates measured in this --root, one run at a time."""
    lines, hours, unknown, rates = [], 0.0, [], {}
    for scene, trunk, seed, upto in plan(study):
        left = {m: n for m, n in images_left(study, scene, trunk, seed, upto).items() if n}
        done = _done(study, scene, trunk, seed, upto)
        lines.append(f"{scene} {trunk} seed {seed} up to {upto} images" + (
            " (done)" if done else f" ({sum(left.values()):,} images to train)" if left else " (to score)"))
        for method, n in left.items():
            if (scene, method) not in rates:  # one read of its logs for all its steps
                rates[scene, method] = measured_rate(study, scene, method)
            rate = rates[scene, method]
            hours += n / rate / 3600 if rate else 0.0
            unknown += [] if rate or f"{scene} {method}" in unknown else [f"{scene} {method}"]
    scores = missing(study)
    lines.append(f"{len(scores)} scores left" + "".join(f"\n  {line}" for line in scores))
    lines.append(f"{hours:.1f} h of training left at the rates measured in {study.root}, one run at a time" + (
        f", and the runs of {', '.join(unknown)} (no rate measured there yet)" if unknown else ""))
    return "\n".join(lines)


def run_study(study: Study, progress: bool = True) -> None:
    for scene, trunk, seed, upto in plan(study):
        score_classical(study, scene)
        run_trunk(study, scene, trunk, seed, upto, progress)
        write_report(study, missing(study), functools.partial(current, study))


@contextlib.contextmanager
def _locked(path: pathlib.Path):
    """An exclusive lock (fcntl) on <path>.lock while the block runs: two study processes on disjoint --methods
    share the scene's tuning.json."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path.with_name(path.name + ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _write_json(path: pathlib.Path, doc) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with written_whole(path) as tmp:
        tmp.write_text(json.dumps(doc, indent=1) + "\n")


def _ints(text: str) -> tuple[int, ...]:
    return tuple(int(t) for t in text.split(",") if t.strip())


def main(argv=None) -> None:
    p = ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", choices=(*SCENES, "both"), default="both")
    p.add_argument("--seeds", type=_ints, help="seeds of every chosen scene (default: indoor 0,1,2; outdoor 0)")
    p.add_argument("--images", type=int, default=30_000, help="the budget B of every run (default 30000)")
    p.add_argument("--curve", type=_ints, help="budgets scored on the way; seed 0 goes on to the largest "
                   "(default: indoor 10000,30000,100000; outdoor none)")
    p.add_argument("--tune-images", type=int, default=3_000)
    p.add_argument("--cooldown", type=float, default=COOLDOWN_FRACTION,
                   help="the share of each budget that finishes its model, its rate decaying to 0 (default "
                   "%(default)s)")
    p.add_argument("--methods", help=f"comma-separated, of {','.join(METHODS)} (default: all)")
    p.add_argument("--limit", type=int, help="test frames (default: the tables', 100 rooms and 50 streets)")
    p.add_argument("--root", default=STUDY_ROOT, help="runs, checkpoints and models (default %(default)s)")
    p.add_argument("--scores", help=f"tuning and scores, committed (default {SCORES}; with --tiny, <root>/scores: a "
                   "check never writes the committed scores)")
    p.add_argument("--results", help="where the report goes when the study ends or with --report (default "
                   "docs/results; with --tiny, <root>/report: a check never writes the committed results)")
    p.add_argument("--workers", type=int, default=1, help="loader processes per run (default 1; 14 on a 16-core "
                   "GPU host)")
    p.add_argument("--tiny", action="store_true", help="tiny networks on 48x64 frames: a check, not a result")
    p.add_argument("--plan", action="store_true", help="print what is done and what is left; run nothing")
    p.add_argument("--report", action="store_true", help="write the report from the scores so far; train nothing")
    p.add_argument("--warm-starts", help=f"runs in progress to go on from, and where --save-in-progress copies them "
                   f"(default {WARM_STARTS}, committed; with --tiny, <root>/warm-starts)")
    p.add_argument("--save-in-progress", action="store_true", help="copy the runs not finished to --warm-starts "
                   "(commit it at a session's end: a new machine goes on from there); train nothing")
    p.add_argument("--no-progress", action="store_true")
    args = p.parse_args(argv)
    scenes = SCENES if args.scene == "both" else (args.scene,)
    methods = tuple(m.strip() for m in args.methods.split(",")) if args.methods else METHODS
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        p.error(f"unknown method(s) {unknown}; choose of {','.join(METHODS)}")
    scores = pathlib.Path(args.scores or (pathlib.Path(args.root) / "scores" if args.tiny else SCORES))
    if args.tiny and scores.resolve() == pathlib.Path(SCORES).resolve():
        p.error(f"--tiny scores are checks: give --scores another folder than the study's {SCORES}")
    warm = pathlib.Path(args.warm_starts or (pathlib.Path(args.root) / "warm-starts" if args.tiny else WARM_STARTS))
    if args.tiny and warm.resolve() == WARM_STARTS.resolve():
        p.error(f"--tiny runs are checks: give --warm-starts another folder than the study's {WARM_STARTS}")
    try:
        study = Study(pathlib.Path(args.root), scores, scenes,
                      {s: args.seeds or DEFAULT_SEEDS[s] for s in scenes},
                      args.images, {s: args.curve if args.curve is not None else DEFAULT_CURVE[s] for s in scenes},
                      args.tune_images, args.cooldown, args.limit, args.tiny, methods, args.workers, warm)
    except ValueError as exc:
        p.error(str(exc))
    if args.plan:
        print(plan_text(study))
        return
    if args.save_in_progress:
        kept = save_in_progress(study)
        commit = "" if args.tiny else f": commit it (git add {warm})"
        print(f"[study] {len(kept)} run(s) in progress kept in {warm}{commit}" if kept
              else "[study] no run in progress to keep")
        return
    enable_compilation_cache()
    if not args.report:
        run_study(study, progress=not args.no_progress)
    out = args.results or (study.root / "report" if args.tiny else "docs/results")
    write_report(study, missing(study), functools.partial(current, study), pathlib.Path(out))


if __name__ == "__main__":
    sys.exit(run_main(PROG, main))
