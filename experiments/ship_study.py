"""Ships the equal-budget study's seed-0 models (experiments/equal_budget.py) as the paper's learned methods
(lipjax/weights/<method>-<scene>), so that the main job's tables compare equal training budgets (issue 52).

    python -m experiments.ship_study --images 30000 --dry-run     # what it would write, and from which runs
    python -m experiments.ship_study --images 30000               # every method of every scene that reached it

A method is shipped from its seed-0 score at the budget (experiments/study_scores/<scene>/<method>-seed0-<N>.json,
which names the model it scored). Its weights and training record are kept; its metadata gains train_config
<method>-<scene> (the name experiments/configs gives its config), seed, the validation metrics of that config's
validation frames (measured here) and "study": the budget, the learning rate and the test RMSE of the study's
score. A scene ships all of its methods or none: a table of equal budgets or nothing. Printed at the end: the
experiments/configs EXPECTED lines the shipped files now state (calls to configs.study.shipped_expected).
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys

from experiments.configs.study import BASES, BRANCHES, METHODS, SCENES, SHIPPED_SEED, shipped_config
from experiments.equal_budget import SCORES, score_path
from lipjax.console import ArgumentParser, positive_int, run_main
from lipjax.shipped import WEIGHTS_DIR

PROG = f"python -m {__spec__.name}"


def shipped_name(method: str, scene: str) -> str:
    """The shipped model (and config) name of study method `method` on `scene`, e.g. ma2018-indoor."""
    return f"{method}-{scene}"


def scores_of(scores: pathlib.Path, scene: str, images: int) -> dict[str, dict]:
    """method -> its seed-0 score at `images` on `scene`; a one-line ValueError names what is missing."""
    paths = {m: score_path(scores, scene, m, SHIPPED_SEED, images) for m in METHODS}
    missing = [m for m, p in paths.items() if not p.exists()]
    if missing:
        raise ValueError(f"{scene}: no seed-{SHIPPED_SEED} score at {images:,} images for {', '.join(missing)}; "
                         "run `python -m experiments.equal_budget` on to that budget first (--plan: what is left)")
    return {m: json.loads(p.read_text()) for m, p in paths.items()}


def ship(method: str, scene: str, score: dict, out: pathlib.Path, tiny: bool = False) -> dict:
    """Writes out/<method>-<scene>.{json,msgpack} from the model of `score`; returns its metadata."""
    from lipjax import model_io
    from lipjax.train.loop import evaluate_params, validation_batches

    model_config, params, meta = model_io.load(score["model"])
    if meta.get("images_seen") != score["images"]:
        raise ValueError(f"{score['model']} has read {meta.get('images_seen')} images, its score says "
                         f"{score['images']}")
    config = shipped_config(method, scene, learning_rate=score["learning_rate"], budget=score["images"],
                            cooldown_fraction=score["cooldown"], tiny=tiny)
    run = meta["data_streams"][-1 if method in BRANCHES else 0]  # the run that config is: the cool-down, the trunk
    if model_config != config.model or run["steps"] != config.total_steps:
        raise ValueError(f"{score['model']} is not a run of {config.name}'s config (its model, "
                         f"{config.total_steps} steps): was the study's code changed since?")
    val = evaluate_params(model_config, params, validation_batches(config), model_config.max_depth_m)
    meta = {**meta, "train_config": shipped_name(method, scene), "seed": SHIPPED_SEED, "val_metrics": val,
            "val_sampler": config.data.val_sampler, "val_images": config.data.val_images,
            "study": {"budget_images": score["images"], "learning_rate": score["learning_rate"],
                      "test_rmse_m": score["rmse_m"], "test_mae_m": score["mae_m"]}}
    model_io.save(out / shipped_name(method, scene), model_config, params, meta)
    return meta


def expected_line(method: str, scene: str, meta: dict) -> str:
    """The experiments/configs EXPECTED entry of a shipped model's metadata (configs.study.shipped_expected)."""
    key, trunk = shipped_name(method, scene).replace("-", "_"), BRANCHES.get(method, (None,))[0]
    cooldown, branch = meta["steps"] * BASES[scene].batch_size, f', trunk="{trunk}"' if trunk else ""
    return (f'    "{key}": shipped_expected(val_rmse_m={meta["val_metrics"]["rmse_m"]:.7g}, '
            f'images={meta["images_seen"]:_}, cooldown={cooldown:_}{branch}),')


def main(argv=None) -> list[str]:
    p = ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--images", type=positive_int, required=True, help="the budget to ship (training images)")
    p.add_argument("--scene", choices=SCENES, action="append", help="a scene to ship (default: both)")
    p.add_argument("--scores", default=SCORES, help="the study's scores (default: %(default)s)")
    p.add_argument("--out", default=str(WEIGHTS_DIR), help="where the models go (default: the shipped models)")
    p.add_argument("--tiny", action="store_true", help="a tiny study's models (checks, not results)")
    p.add_argument("--dry-run", action="store_true", help="say what would be shipped; write nothing")
    args = p.parse_args(argv)
    scores, out = pathlib.Path(args.scores), pathlib.Path(args.out)
    found = {scene: scores_of(scores, scene, args.images) for scene in args.scene or SCENES}
    lines = []
    for scene, by_method in found.items():
        for method, score in by_method.items():
            print(f"[ship] {shipped_name(method, scene)} <- {score['model']} (test rmse_m={score['rmse_m']:.4f})",
                  flush=True)
            if not args.dry_run:
                lines.append(expected_line(method, scene, ship(method, scene, score, out, args.tiny)))
    if lines:
        print("EXPECTED entries (experiments/configs):\n" + "\n".join(lines))
    return lines


if __name__ == "__main__":
    sys.exit(run_main(PROG, main))
