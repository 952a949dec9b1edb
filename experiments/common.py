"""Shared plumbing of the experiment entry points: evaluate methods, write results.json / table.md / figures.

Experiments stay thin: they build a config, pick a data set, a protocol and a sampler, and call these.
"""
from __future__ import annotations

import json
import pathlib
import platform
import time
from typing import Any, Sequence

import numpy as np

from lipjax.data.frame import Frame
from lipjax.evaluate import EvalResult, evaluate, markdown_table
from lipjax.inference import Completer
from lipjax.methods import get_completer


def load_methods(methods: Sequence[str]) -> dict[str, Any]:
    """Completers by name (lipjax.methods), loaded once and shared by the tables and figures of an experiment."""
    return {name: get_completer(name) for name in methods}


def evaluate_methods(
    methods: Sequence[str] | dict[str, Any], dataset, sampler, *, min_depth_m: float, max_depth_m: float,
    limit: int | None, seed: int = 0,
) -> dict[str, EvalResult]:
    """Runs every method (names, or completers by name from load_methods) on the same frames and sparse inputs."""
    completers = methods if isinstance(methods, dict) else load_methods(methods)
    results = {}
    for name, completer in completers.items():
        t0 = time.perf_counter()
        results[name] = evaluate(completer, dataset, sampler, min_depth_m=min_depth_m, max_depth_m=max_depth_m,
                                 limit=limit, seed=seed)
        print(f"[lipjax] {name}: rmse_m={results[name].metrics['rmse_m']:.4f} ({time.perf_counter() - t0:.0f} s)",
              flush=True)
    return results


def model_columns(completers: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """The columns the tables add to the metrics: a learned method's parameters (millions) and the training images
    its model file records (images_seen), so that rows of unequal budgets show theirs; None for methods without
    learned parameters."""
    return {name: {"params_M": c.parameter_count() / 1e6, "train_images": c.metadata.get("images_seen")}
            if isinstance(c, Completer) else {"params_M": None, "train_images": None}
            for name, c in completers.items()}


def write_results(out: pathlib.Path, results: dict[str, EvalResult], meta: dict[str, Any],
                  columns: Sequence[str], extra_columns: dict[str, dict[str, Any]] | None = None) -> str:
    """Writes out/results.json (aggregated metrics with units in the keys + meta) and out/table.md; returns the
    table."""
    out.mkdir(parents=True, exist_ok=True)
    doc = {
        "meta": {**meta, "hardware": f"{platform.machine()} {platform.processor() or ''}".strip(),
                 "python": platform.python_version()},
        "methods": {name: {**r.metrics, "ms_per_frame": r.ms_per_frame, "num_images": r.num_images,
                           **(extra_columns or {}).get(name, {})} for name, r in results.items()},
    }
    (out / "results.json").write_text(json.dumps(_finite(doc), indent=1))
    table = markdown_table(results, columns)
    if extra_columns:
        table = _append_columns(table, results, extra_columns)
    header = f"{meta.get('title', '')}\n\n{meta.get('description', '')}\n\n"
    (out / "table.md").write_text(header + table + "\n")
    return table


def _append_columns(table: str, results, extra: dict[str, dict[str, Any]]) -> str:
    keys = sorted({k for v in extra.values() for k in v})
    lines = table.splitlines()
    lines[0] += "".join(f" {k} |" for k in keys)
    lines[1] += "---:|" * len(keys)
    for i, name in enumerate(results, start=2):
        lines[i] += "".join(f" {_fmt(extra.get(name, {}).get(k))} |" for k in keys)
    return "\n".join(lines)


def _fmt(v) -> str:
    if v is None:
        return "n/a"
    return f"{v:.3g}" if isinstance(v, float) else f"{v:,}" if isinstance(v, int) else str(v)


def _finite(x):
    if isinstance(x, float) and not np.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    return x


KEY_METHODS = 4  # methods in a figure: it must read at 100 % on a laptop screen


def key_methods(results: dict[str, EvalResult], completers: dict[str, Any], count: int = KEY_METHODS) -> list[str]:
    """The methods a figure shows, in table order: the `count` - 1 lowest-RMSE ones, and the best method without
    learned weights (the reference a learned model has to beat); `count` by RMSE when that one is among them."""
    ranked = sorted(results, key=lambda m: results[m].metrics.get("rmse_m", float("inf")))
    classical = [m for m in ranked if not isinstance(completers[m], Completer)]
    chosen = ranked[:count - 1] + [m for m in classical[:1] if m not in ranked[:count - 1]]
    chosen += [m for m in ranked if m not in chosen][:count - len(chosen)]
    return [m for m in results if m in chosen]


def qualitative_figure(path: pathlib.Path, frames: Sequence[Frame], sparse_inputs: Sequence[np.ndarray],
                       completers: dict[str, Any], results: dict[str, EvalResult], max_depth_m: float,
                       max_error_m: float, sparse_title: str = "sparse input") -> None:
    """The paper's Fig. 3 as a grid: per frame, RGB | sparse input | ground truth | the key methods' predictions
    (`key_methods`), each with its error map below (lipjax.viz.save_comparison_grid)."""
    from lipjax import viz

    shown = key_methods(results, completers)
    comparisons = [viz.Comparison(frame.id, frame.rgb, sparse, frame.depth,
                                  {name: np.asarray(completers[name](frame.rgb, sparse)) for name in shown},
                                  frame.valid)
                   for frame, sparse in zip(frames, sparse_inputs)]
    viz.save_comparison_grid(path, comparisons, max_depth_m, max_error_m, sparse_title=sparse_title)


def line_plot(path: pathlib.Path, xs: Sequence[float], series: dict[str, Sequence[float]], *, xlabel: str,
              ylabel: str, title: str = "", logx: bool = False, logy: bool = False) -> None:
    """One line per method (the paper's Fig. 4 style), written as PNG. logy: for errors that span orders of
    magnitude across methods (e.g. a KITTI-tuned fill failing on scattered points next to the LIP models)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5.5, 3.8), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    if len(series) > 10:  # the default cycle has 10 colours: no two methods may share one
        from matplotlib import colormaps

        ax.set_prop_cycle(color=colormaps["tab20"].colors)
    for name, ys in series.items():
        ax.plot(xs, ys, marker="o", label=name, linestyle="--" if "wavelet" in name else "-")
    if logx:
        ax.set_xscale("log")
    if logy:
        ax.set_yscale("log")
    ax.set_xticks(list(xs), [f"{x:g}" for x in xs])  # the measured points only (no 1.5 iterations, no 10^3 ticks)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)


def synthetic_outdoor_test():
    """The outdoor synthetic test split at the KITTI-like evaluation size (OUTDOOR_EVAL_SIZE)."""
    from experiments.configs import OUTDOOR_DATA
    from lipjax.data.synthetic import SyntheticDataset

    return SyntheticDataset("outdoor", "test", height=OUTDOOR_DATA.height, width=OUTDOOR_DATA.width)
