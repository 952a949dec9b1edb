"""Training curves from a run's metrics.jsonl, as a PNG (matplotlib, Agg backend)."""
from __future__ import annotations

import json
import os
import pathlib


def plot_curves(metrics_path: str | os.PathLike, out_path: str | os.PathLike, title: str = "") -> None:
    """Plots the training loss per phase and the validation RMSE / MAE (metres) against the step."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [json.loads(line) for line in pathlib.Path(metrics_path).read_text().splitlines() if line.strip()]
    train_rows = [r for r in rows if "phase" in r]
    val_rows = [r for r in rows if r.get("split") == "val"]
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(10, 3.5))
    for phase in ("supervised", "discriminator", "adversarial"):
        pts = [(r["step"], r["loss"]) for r in train_rows if r["phase"] == phase]
        if pts:
            ax0.plot(*zip(*pts), label=phase)
    ax0.set_yscale(loss_axis_scale([r["loss"] for r in train_rows]))
    ax0.set_xlabel("step")
    ax0.set_ylabel("training loss")
    ax0.legend()
    if val_rows:
        ax1.plot([r["step"] for r in val_rows], [r["rmse_m"] for r in val_rows], "o-", label="val RMSE (m)")
        ax1.plot([r["step"] for r in val_rows], [r["mae_m"] for r in val_rows], "s-", label="val MAE (m)")
        ax1.legend()
    ax1.set_xlabel("step")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out_path, dpi=100)
    plt.close(fig)


def loss_axis_scale(losses) -> str:
    """"log" when every loss is positive (L1, L2), else "linear" (the log_rmse loss is a log, often below 0)."""
    return "log" if all(v > 0 for v in losses) else "linear"
