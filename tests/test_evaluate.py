import json
import math

import numpy as np
import pytest

from lipjax.classical import NearestFill
from lipjax.data.frame import Frame, Intrinsics
from lipjax.evaluate import EvalResult, evaluate, markdown_table, save_json
from lipjax.metrics import compute_metrics

H, W = 12, 16


def _dataset(n=3):
    yy, xx = np.mgrid[0:H, 0:W]
    out = []
    for i in range(n):
        depth = (1.0 + i + 0.1 * xx + 0.05 * yy).astype(np.float32)
        depth[0, :3] = 0  # a few invalid pixels
        rgb = np.full((H, W, 3), 40 * i, np.uint8)
        out.append(Frame.from_depth(rgb, depth, Intrinsics(10.0, 10.0, W / 2, H / 2), f"toy/{i}"))
    return out


def _sampler(frame: Frame, seed: int) -> np.ndarray:
    """Exactly 6 valid pixels, drawn from a key derived from the frame id and the seed."""
    rng = np.random.default_rng([seed, int(frame.id.split("/")[1])])
    idx = rng.choice(np.flatnonzero(frame.valid), 6, replace=False)
    sparse = np.zeros(frame.shape, np.float32)
    sparse.flat[idx] = frame.depth.flat[idx]
    return sparse


class _Counting:
    name = "counting_nearest"

    def __init__(self):
        self.calls = 0

    def __call__(self, rgb, sparse):
        self.calls += 1
        return NearestFill()(rgb, sparse)


def test_evaluate_aggregates_per_image_metrics():
    data = _dataset()
    res = evaluate(NearestFill(), data, _sampler, min_depth_m=0.0, max_depth_m=2.5, progress=False)
    assert res.name == "nearest" and res.num_images == 3 and len(res.per_image) == 3
    assert [p["id"] for p in res.per_image] == ["toy/0", "toy/1", "toy/2"]
    expected = []
    for s in data:
        sparse = _sampler(s, 0)
        expected.append(compute_metrics(NearestFill()(s.rgb, sparse), s.depth, s.valid, sparse, min_depth_m=0.0,
                                        max_depth_m=2.5))
    for k in ("mae_m", "rmse_m", "delta1_pct", "mae_unsampled_m"):
        vals = [e[k] for e in expected if not math.isnan(e[k])]
        assert res.metrics[k] == pytest.approx(np.mean(vals))
        assert res.counts[k] == len(vals)
    # depth range: image 2 starts at 3 m, above max_depth_m, so it has no evaluated pixel and is left out
    assert res.counts["mae_m"] == 2 and res.per_image[2]["n_eval_px"] == 0
    assert res.metrics["mae_vs_input_m"] == 0.0  # nearest fill is exact at the samples
    times = [p["ms"] for p in res.per_image]  # each frame's own time: the summary is their mean and median
    assert min(times) > 0 and res.ms_per_frame == pytest.approx(np.mean(times))
    assert res.ms_per_frame_median == pytest.approx(np.median(times))


def test_warmup_call_is_extra_and_limit_and_seed_are_honoured():
    c = _Counting()
    res = evaluate(c, _dataset(), _sampler, min_depth_m=0.0, max_depth_m=100.0, limit=2, progress=False)
    assert res.num_images == 2 and c.calls == 3  # one untimed warm-up + two timed
    c2 = _Counting()
    evaluate(c2, _dataset(), _sampler, min_depth_m=0.0, max_depth_m=100.0, progress=False, warmup=False)
    assert c2.calls == 3
    seeds = []
    evaluate(NearestFill(), _dataset(2), lambda s, seed: seeds.append(seed) or _sampler(s, seed), min_depth_m=0.0,
             max_depth_m=100.0, seed=7, progress=False)
    assert seeds == [7, 7]
    a = evaluate(NearestFill(), _dataset(), _sampler, min_depth_m=0.0, max_depth_m=100.0, progress=False)
    b = evaluate(NearestFill(), _dataset(), _sampler, min_depth_m=0.0, max_depth_m=100.0, progress=False)
    assert a.metrics == b.metrics  # deterministic inputs, deterministic method


def test_evaluate_rejects_wrong_shapes_and_empty_datasets():
    with pytest.raises(ValueError, match="shape"):
        evaluate(lambda rgb, s: s[:-1], _dataset(1), _sampler, min_depth_m=0.0, max_depth_m=100.0, progress=False)
    with pytest.raises(ValueError, match="empty"):
        evaluate(NearestFill(), [], _sampler, min_depth_m=0.0, max_depth_m=100.0, progress=False)


def test_markdown_table_and_json(tmp_path):
    res = evaluate(NearestFill(), _dataset(2), _sampler, min_depth_m=0.0, max_depth_m=100.0, progress=False)
    nan_res = EvalResult("x", {"rmse_m": math.nan}, {}, [], 1.25, 1.25, 0, 0.0, 1.0)
    table = markdown_table({"nearest": res, "broken": nan_res}, columns=("rmse_m", "delta1_pct", "ms_per_frame"))
    lines = table.splitlines()
    assert lines[0] == "| method | rmse_m | delta1_pct | ms_per_frame |"
    assert lines[1] == "|---|---:|---:|---:|"
    assert lines[2].startswith("| nearest | ") and f"{res.metrics['rmse_m']:.3f}" in lines[2]
    assert lines[3] == "| broken | n/a | n/a | 1.2 |"
    path = tmp_path / "r.json"
    save_json({"nearest": res, "broken": nan_res}, path)
    loaded = json.loads(path.read_text())
    assert loaded["nearest"]["metrics"]["mae_m"] == pytest.approx(res.metrics["mae_m"])
    assert loaded["broken"]["metrics"]["rmse_m"] is None
    assert len(loaded["nearest"]["per_image"]) == 2


def test_data_and_sources_open_through_one_function(tmp_path):
    """open_eval_data: `--data synthetic-*` and `--source synthetic` give the same scenes' depth range, each
    named; arguments that do not go together are one-line errors before anything is read."""
    from lipjax.evaluate import open_eval_data

    data = open_eval_data("synthetic-outdoor", size=(16, 24), sampler="uniform:20")
    assert (data.name, data.spec, data.range_from.name) == ("synthetic-outdoor", "uniform:20", "synthetic_outdoor")
    assert data.dataset[0].rgb.shape == (16, 24, 3) and (data.sampler(data.dataset[0], 0) > 0).sum() == 20
    source = open_eval_data(source="synthetic", kind="outdoor")
    assert (source.name, source.spec) == ("synthetic outdoor val", "uniform:200")
    assert source.range_from.max_depth_m == data.range_from.max_depth_m
    for kwargs, message in [({"root": tmp_path}, "--root and --raw-root go with --source NAME"),
                            ({"data": "synthetic-indoor", "source": "synthetic"}, "--data and --source name"),
                            ({"source": "nyu_h5"}, "--source nyu_h5 needs --root DIR"),
                            ({"data": str(tmp_path / "none")}, "not synthetic-indoor, synthetic-outdoor or a folder"),
                            ({"data": str(tmp_path), "split": "test"}, "--split test: a folder has train and val")]:
        with pytest.raises(ValueError, match=message):
            open_eval_data(**kwargs)


def test_evaluate_methods_scores_each_model_over_the_data_range(tmp_path):
    import cv2

    from lipjax.evaluate import evaluate_methods

    report = evaluate_methods(["nearest", "linear"], data="synthetic-indoor", size=(16, 24), sampler="uniform:30",
                              limit=2, progress=False)
    assert list(report.results) == ["nearest", "linear"] and report.max_depth_m == 10.0
    assert all(r.num_images == 2 and r.max_depth_m == 10.0 for r in report.results.values())
    assert report.header() == "data: synthetic-indoor (2 frames), sampler: uniform:30, depth range: (0, 10] m"
    from lipjax.classical import LinearFill
    from lipjax.data.sampling import sampler_from_spec
    from lipjax.data.synthetic import SyntheticDataset

    frames = SyntheticDataset("indoor", "test", height=16, width=24)  # the frames and inputs it names, scored alone
    alone = evaluate(LinearFill(), frames, sampler_from_spec("uniform:30"), min_depth_m=0.0, max_depth_m=10.0,
                     limit=2, progress=False)
    assert report.results["linear"].metrics == alone.metrics and alone.metrics["rmse_m"] > 0
    for sub in ("rgb", "depth"):  # a folder of the user's frames has no depth range of its own
        (tmp_path / sub).mkdir()
    cv2.imwrite(str(tmp_path / "rgb" / "0.png"), np.zeros((H, W, 3), np.uint8))
    np.save(tmp_path / "depth" / "0.npy", np.ones((H, W), np.float32))
    with pytest.raises(ValueError, match="give the evaluated depth range: --max-depth-m M"):
        evaluate_methods(["nearest"], data=str(tmp_path), progress=False)


def test_working_size_scores_the_default_path_not_the_model_at_the_input_size():
    """`working_size=True` scores exactly what lipjax.complete returns: the model at the samples' working size (here
    64x80 for a 160x200 frame with 20 points), upsampled, every measured pixel set back (zero error there)."""
    from lipjax.data.sampling import sampler_from_spec
    from lipjax.data.synthetic import SyntheticDataset
    from lipjax.evaluate import evaluate_methods
    from lipjax.inference import Completer, complete_frame, frame_size
    from lipjax.model import LIPConfig
    from lipjax.priors.network import network_preset

    model = Completer.random(LIPConfig(prior=network_preset("tiny"), num_iterations=1))
    kwargs = dict(data="synthetic-indoor", size=(160, 200), sampler="uniform:20", limit=2, progress=False)
    plain = evaluate_methods([model], **kwargs).results["untrained"]
    report = evaluate_methods([model], working_size=True, **kwargs)
    default = report.results["untrained"]
    assert report.header().endswith("m, models at the samples' working size (as lipjax complete)")
    assert (default.size, plain.size) == ("working", "input")
    frame = SyntheticDataset("indoor", "test", size=1, height=160, width=200)[0]
    sparse = sampler_from_spec("uniform:20")(frame, 0)
    assert frame_size(model, sparse) == (64, 80)
    expected = compute_metrics(complete_frame(model, frame.rgb, sparse), frame.depth, frame.valid, sparse,
                               max_depth_m=10.0)
    assert default.per_image[0]["rmse_m"] == pytest.approx(expected["rmse_m"], rel=1e-6)
    assert default.metrics["mae_sampled_m"] == 0.0
    assert default.metrics["rmse_m"] != pytest.approx(plain.metrics["rmse_m"], rel=1e-3)
