"""Trains a LIP model on the embedded synthetic data and exports it as a loadable model.

    python -m experiments.train --config lip_cnn_indoor [--workdir runs/lip_cnn_indoor] [--set g_steps=200]
    python -m experiments.train --config lip_cnn_indoor --export-only      # export the latest checkpoint

A killed run resumes from its last checkpoint when started again with the same workdir. On completion (or with
--export-only) the model is written to lipjax/weights/<name> (or --export PATH) with its validation metrics, and
the training curves to <workdir>/curves.png.
"""
from __future__ import annotations

import argparse
import json
import pathlib

from experiments.configs import get_config
from lipjax import model_io
from lipjax.train.curves import plot_curves
from lipjax.train.loop import evaluate_params, export, train, validation_batches
from lipjax.train.state import init_state
from lipjax.checkpoint import CheckpointManager
from lipjax.utils import enable_compilation_cache


def _final_validation(metrics_path: pathlib.Path, step: int) -> dict | None:
    """The validation metrics the training loop logged at `step`, if any."""
    if not metrics_path.exists():
        return None
    rows = [json.loads(line) for line in metrics_path.read_text().splitlines() if line.strip()]
    found = [r for r in rows if r.get("split") == "val" and r["step"] == step]
    return {k: v for k, v in found[-1].items() if k not in ("split", "step")} if found else None


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--config", required=True)
    p.add_argument("--workdir", default=None, help="default: runs/<config>")
    p.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE", help="override a config field")
    p.add_argument("--export", default=None, help="model path stem to export to (default: no export)")
    p.add_argument("--export-only", action="store_true", help="export the latest checkpoint without training")
    p.add_argument("--no-progress", action="store_true")
    args = p.parse_args(argv)
    enable_compilation_cache()
    overrides = dict(s.split("=", 1) for s in args.set)
    config = get_config(args.config, overrides)
    workdir = pathlib.Path(args.workdir or f"runs/{args.config}")
    if args.export_only:
        manager = CheckpointManager(workdir / "checkpoints", keep=config.keep_checkpoints)
        state, _ = manager.restore(init_state(config, model_io.load(config.init_from)[1] if config.init_from else None))
        manager.close()
    else:
        state = train(config, workdir, progress=not args.no_progress)
    val = _final_validation(workdir / "metrics.jsonl", int(state.step))
    if val is None:  # not evaluated at this step by the loop (e.g. --export-only of an older checkpoint)
        val = evaluate_params(config.model, state.g_params, validation_batches(config), config.model.max_depth_m)
    if args.export is None:
        print(f"[lipjax] trained {config.name} to step {int(state.step)} in {workdir}: val rmse_m={val['rmse_m']:.4f} "
              "(add --export PATH to save a loadable model)")
        return
    target = args.export
    export(config, state, target, {"val_metrics": val, "val_sampler": config.data.val_sampler,
                                   "val_images": config.data.val_images, "data": config.data.kind})
    plot_curves(workdir / "metrics.jsonl", workdir / "curves.png", title=config.name)
    print(f"[lipjax] exported {config.name} (step {int(state.step)}) to {target}: val rmse_m={val['rmse_m']:.4f}")


if __name__ == "__main__":
    main()
