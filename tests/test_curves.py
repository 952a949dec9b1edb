"""Training curves: the loss axis is logarithmic only where every loss is positive."""
import json
import warnings

from lipjax.train.curves import loss_axis_scale, plot_curves


def test_a_log_rmse_run_plots_its_negative_losses_on_a_linear_axis(tmp_path):
    assert loss_axis_scale([0.5, 0.02]) == "log"
    assert loss_axis_scale([-1.8, 0.3]) == "linear"
    metrics = tmp_path / "metrics.jsonl"
    rows = [{"step": 10 * i, "phase": "supervised", "loss": -1.0 - 0.1 * i} for i in range(5)]
    rows.append({"step": 40, "split": "val", "rmse_m": 2.3, "mae_m": 0.9})
    metrics.write_text("\n".join(json.dumps(r) for r in rows))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # matplotlib warns when asked to log-scale data with no positive values
        plot_curves(metrics, tmp_path / "curves.png", title="log_rmse")
    assert (tmp_path / "curves.png").stat().st_size > 0
