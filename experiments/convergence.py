"""The paper's Fig. 4a: MAE against the number of ADMM iterations, for LIP+CNN and LIP+AD. Two ways:

  1. a trained K-iteration model evaluated after each of its iterations (its x-iterates: 0 prox steps = the
     data-consistent initial estimate, then one point per learned prox, the last being the model's output);
  2. (--train-k 1,2,3,5) models trained from scratch with K = 1, 2, 3, 5 iterations for --train-steps steps each
     (a smaller budget than the shipped models; say so when reporting). A finished K-model already exported to
     --out/models (same config and budget) is reused, and a killed run resumes from its checkpoints in --out/runs,
     so the models can also be trained elsewhere (e.g. on a GPU with experiments.train) and evaluated here.

    python -m experiments.convergence [--scene indoor] [--train-k 1,2,3,5 --train-steps 300] [--variant smoke]

Writes results.json, table.md, convergence.png (and trained_k.png) into --out (default out/convergence).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import pathlib
import sys

import numpy as np

from experiments.common import line_plot, synthetic_outdoor_test
from lipjax.console import ArgumentParser, positive_int, positive_int_list, run_main
from lipjax.data.protocols import get_protocol
from lipjax.data.sampling import sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.inference import load_model
from lipjax.metrics import MetricAggregator, compute_metrics
from lipjax.model_io import available, load
from lipjax.utils import enable_compilation_cache

PROG = f"python -m {__spec__.name}"  # as run: the same when imported


@dataclasses.dataclass(frozen=True)
class Config:
    limit: int = 20
    num_points: int = 200
    seed: int = 0


VARIANTS = {"default": Config(), "smoke": Config(limit=1)}


def mae_per_iteration(model, dataset, sampler, limit: int, seed: int, max_depth_m: float) -> list[float]:
    """Mean over images of MAE (m) of x_1 .. x_K (before each prox) and of the final output: K + 1 values."""
    per_k: list[MetricAggregator] = []
    for i in range(min(limit, len(dataset))):
        frame = dataset[i]
        sparse = sampler(frame, seed)
        final, trajectory = model.trajectory(frame.rgb, sparse)
        iterates = [np.asarray(x[0]) for x in trajectory.x] + [np.asarray(final[0])]
        if not per_k:
            per_k = [MetricAggregator() for _ in iterates]
        for agg, pred in zip(per_k, iterates):
            agg.add(compute_metrics(pred, frame.depth, frame.valid, min_depth_m=0.0, max_depth_m=max_depth_m))
    return [agg.means()["mae_m"] for agg in per_k]


def train_k_models(scene: str, ks: list[int], steps: int, out: pathlib.Path) -> dict[int, str]:
    """Trains LIP+CNN with each K for `steps` steps (the shipped config otherwise); returns model paths."""
    from experiments.configs import CONFIGS
    from lipjax.train.loop import export, train

    base = CONFIGS[f"lip_cnn_{scene}"]
    paths = {}
    for k in ks:
        # The shipped warm-up (100 steps) would take a whole short run: keep it to a tenth of the budget.
        config = dataclasses.replace(base, name=f"lip-cnn-{scene}-k{k}", g_steps=steps, eval_every=0,
                                     warmup_steps=min(base.warmup_steps, max(1, steps // 10)),
                                     model=dataclasses.replace(base.model, num_iterations=k))
        paths[k] = str(out / f"models/lip-cnn-{scene}-k{k}")
        if _finished(paths[k], config):
            print(f"[lipjax] K = {k}: reusing {paths[k]} (trained {steps} steps with this config)")
            continue
        # train() resumes from the run's checkpoints, so a killed sweep picks up where it stopped
        state = train(config, out / f"runs/k{k}", progress=False)
        export(config, state, paths[k])
    return paths


def _finished(path: str, config) -> bool:
    """Whether `path` holds a model exported by a finished run of `config` (same model, same step budget)."""
    if not (pathlib.Path(path + ".json").exists() and pathlib.Path(path + ".msgpack").exists()):
        return False
    model_config, _, metadata = load(path)
    return (model_config == config.model and metadata.get("train_config") == config.name
            and metadata.get("steps") == config.total_steps)


def main(argv=None) -> dict:
    p = ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", choices=("indoor", "outdoor"), default="indoor")
    p.add_argument("--variant", choices=sorted(VARIANTS), default="default")
    p.add_argument("--models", help="comma-separated models (default: every shipped LIP model of the scene)")
    p.add_argument("--train-k", type=positive_int_list,
                   help="also train models with these iteration counts, e.g. 1,2,3,5")
    p.add_argument("--train-steps", type=positive_int, default=300)
    p.add_argument("--out", default="out/convergence")
    args = p.parse_args(argv)
    enable_compilation_cache()
    config = VARIANTS[args.variant]
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    dataset = SyntheticDataset("indoor", "test") if args.scene == "indoor" else synthetic_outdoor_test()
    protocol = get_protocol(f"synthetic_{args.scene}")
    sampler = sampler_from_spec(f"uniform:{config.num_points}")
    models = args.models.split(",") if args.models else [
        m for m in available() if m.startswith("lip-") and m.endswith(f"-{args.scene}")]
    if not models:
        raise SystemExit("no trained LIP model for this scene: train one (python -m experiments.train) "
                         "or pass --models")
    curves = {m: mae_per_iteration(load_model(m), dataset, sampler, config.limit, config.seed, protocol.max_depth_m)
              for m in models}
    doc = {"meta": {**dataclasses.asdict(config), "scene": args.scene,
                    "x": "prox steps applied (0 = data-consistent initial estimate)"}, "per_iteration_mae_m": curves}
    lines = ["| model | " + " | ".join(f"{k} prox" for k in range(max(len(c) for c in curves.values()))) + " |"]
    lines.append("|---|" + "---:|" * (len(lines[0].split("|")) - 3))
    lines += [f"| {m} | " + " | ".join(f"{v:.4f}" for v in c) + " |" for m, c in curves.items()]
    if args.train_k:
        ks = args.train_k
        paths = train_k_models(args.scene, ks, args.train_steps, out)
        trained = {k: mae_per_iteration(load_model(paths[k]), dataset, sampler, config.limit, config.seed,
                                        protocol.max_depth_m)[-1] for k in ks}
        doc["trained_k"] = {"train_steps": args.train_steps, "final_mae_m": trained}
        lines += ["", f"Trained from scratch, {args.train_steps} steps each:", "",
                  "| K | MAE (m) |", "|---:|---:|"] + [f"| {k} | {v:.4f} |" for k, v in trained.items()]
        line_plot(out / "trained_k.png", ks, {"LIP+CNN trained with K iterations": list(trained.values())},
                  xlabel="ADMM iterations K", ylabel="MAE (m)",
                  title=f"synthetic {args.scene} test, {config.num_points} points, {args.train_steps} steps each")
    longest = max(len(c) for c in curves.values())
    line_plot(out / "convergence.png", list(range(longest)),
              {m: c + [np.nan] * (longest - len(c)) for m, c in curves.items()},
              xlabel="prox steps applied", ylabel="MAE (m)",
              title=f"synthetic {args.scene} test, {config.num_points} points")
    (out / "results.json").write_text(json.dumps(doc, indent=1))
    (out / "table.md").write_text("MAE (m) after each iteration\n\n" + "\n".join(lines) + "\n")
    print("\n".join(lines))
    return doc


if __name__ == "__main__":
    sys.exit(run_main(PROG, main))
