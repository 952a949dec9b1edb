"""The equal-budget study's report (experiments/equal_budget.py): what its scores show so far.

Writes into the results folder (docs/results by default):
  equal_budget.json   {"indoor": {"<method>": {"images", "seeds", "rmse_m", "mae_m"}, "linear": {...},
                       "nearest": {...}}, "outdoor": {...}, "details": {tuning, curve, iterations, paired tests,
                       larger_budgets: {N: the same summary and tests at each larger budget all methods reached}}}
  equal_budget.md     per scene, mean +- standard deviation over seeds at the budget, the methods still falling
                      steeply at the end of their curve (STEEP_CHANGE), and the paired tests; then the same again
                      at each larger budget of the curve that every method has reached (seed 0 at 100,000)
  equal_budget_curve.png        test RMSE against training images (the data-efficiency curve), rooms
  equal_budget_iterations.png   test RMSE against the ADMM iteration count K of the LIP runs (Fig. 4a)

Paired tests: per test frame, a method's RMSE averaged over the seeds both methods have at the budget; the Wilcoxon
signed-rank test and the paired t-test over the frames (two-sided), for LIP+AD against the best end-to-end network
and against LIP+CNN (the paper's adversarial claim), and the fast prox's LIP+AD against the best end-to-end network.
The frame tests hold the trained models fixed; what a retraining could change is in two more figures: the seeds on
which a's mean RMSE is below b's, and a 95 % interval of mean RMSE a - b from a bootstrap that draws the seeds and
then the frames (both paired, with replacement), so that the spread between seeds widens it.
"""
from __future__ import annotations

import json
import math
import pathlib
import statistics

import numpy as np

from experiments.configs.study import END_TO_END, METHODS, SCENES
from lipjax.utils import written_whole

PAIRS = (("lip-ad", "best end-to-end"), ("lip-ad", "lip-cnn"), ("lip-ad-fast", "best end-to-end"))
BOOTSTRAP_DRAWS = 10_000
BOOTSTRAP_SEED = 0
# A method still falls steeply at the end of its curve when its RMSE fell by more than this over its last step
# (curve_change), e.g. 30,000 -> 100,000 images (decision 0028, fixed before the second 100,000-image score).
STEEP_CHANGE = -0.05


def bootstrap_interval(diff: np.ndarray, draws: int = BOOTSTRAP_DRAWS, level: float = 0.95) -> tuple[float, float]:
    """The `level` percentile interval of the mean of `diff` [seed, frame] (metres) over `draws` two-level bootstrap
    draws: per draw, len(seeds) seeds and then len(frames) frames, each with replacement, shared by a and b."""
    rng = np.random.default_rng(BOOTSTRAP_SEED)
    seeds = rng.integers(0, diff.shape[0], size=(draws, diff.shape[0]))
    frames = rng.integers(0, diff.shape[1], size=(draws, diff.shape[1]))
    means = diff[seeds[:, :, None], frames[:, None, :]].mean(axis=(1, 2))
    low, high = np.quantile(means, [(1 - level) / 2, (1 + level) / 2])
    return float(low), float(high)


def load_scores(scores: pathlib.Path, scene: str) -> list[dict]:
    folder = scores / scene
    return [json.loads(p.read_text()) for p in sorted(folder.glob("*-seed*-*.json"))] if folder.exists() else []


def at_budget(scores: list[dict], method: str, images: int) -> list[dict]:
    return sorted((s for s in scores if s["method"] == method and s["images"] == images), key=lambda s: s["seed"])


def scene_summary(scores: list[dict], classical: dict, images: int) -> dict:
    """The equal_budget.json entry of one scene."""
    out = {}
    for method in METHODS:
        runs = at_budget(scores, method, images)
        if runs:
            out[method] = {"images": images, "seeds": [r["seed"] for r in runs],
                           "rmse_m": [r["rmse_m"] for r in runs], "mae_m": [r["mae_m"] for r in runs]}
    for name in ("linear", "nearest"):
        if name in classical:
            out[name] = {"rmse_m": classical[name]["rmse_m"], "mae_m": classical[name]["mae_m"]}
    return out


def paired_test(scores: list[dict], a: str, b: str, images: int) -> dict | None:
    """Method a against b over the test frames, each frame's RMSE the mean over the seeds both have."""
    from scipy import stats

    runs_a, runs_b = at_budget(scores, a, images), at_budget(scores, b, images)
    seeds = sorted({r["seed"] for r in runs_a} & {r["seed"] for r in runs_b})
    if not seeds:
        return None

    runs = [r for r in runs_a + runs_b if r["seed"] in seeds]
    frames = [p["id"] for p in runs[0]["per_image"]]
    for r in runs:
        if [p["id"] for p in r["per_image"]] != frames:
            raise ValueError(f"{r['method']} seed {r['seed']} at {images} images was scored on other test frames than "
                             f"{runs[0]['method']} seed {runs[0]['seed']}: score both with the same --limit")
    if len(frames) < 2:
        return None

    def per_seed_frame(runs):  # [seed, frame] RMSE m
        return np.array([[p["rmse_m"] for p in r["per_image"]] for r in runs if r["seed"] in seeds])

    rmse_a, rmse_b = per_seed_frame(runs_a), per_seed_frame(runs_b)
    x, y = rmse_a.mean(axis=0), rmse_b.mean(axis=0)
    diff = x - y
    test = {"a": a, "b": b, "images": images, "seeds": seeds, "frames": int(len(x)),
            "mean_rmse_a_m": float(x.mean()), "mean_rmse_b_m": float(y.mean()),
            "a_better_frames": int((diff < 0).sum()), "b_better_frames": int((diff > 0).sum()),
            "a_better_seeds": int((rmse_a.mean(axis=1) < rmse_b.mean(axis=1)).sum()),
            "b_better_seeds": int((rmse_a.mean(axis=1) > rmse_b.mean(axis=1)).sum()),
            "diff_interval_m": list(bootstrap_interval(rmse_a - rmse_b)),
            "wilcoxon_p": float(stats.wilcoxon(x, y).pvalue) if np.any(diff) else 1.0,
            "ttest_p": float(stats.ttest_rel(x, y).pvalue) if np.any(diff) else 1.0}
    test["verdict"] = verdict(test)
    return test


def verdict(test: dict) -> str:
    """The rule fixed in decision 0028: a method leads where the 95 % interval of mean RMSE a - b excludes 0 and it
    is better (strictly) on every seed; otherwise the study does not separate the two."""
    low, high = test["diff_interval_m"]
    if high < 0 and test["a_better_seeds"] == len(test["seeds"]):
        return f"{test['a']} leads"
    if low > 0 and test["b_better_seeds"] == len(test["seeds"]):
        return f"{test['b']} leads"
    return "not separated"


def compare(scores: list[dict], classical: dict, images: int) -> tuple[dict, list[dict]]:
    """(the scene_summary at `images`, the PAIRS' paired tests there)."""
    summary = scene_summary(scores, classical, images)
    best = best_end_to_end(summary)
    tests = [paired_test(scores, a, best if b == "best end-to-end" else b, images)
             for a, b in PAIRS if (best or b != "best end-to-end")]
    return summary, [t for t in tests if t]


def larger_budgets(scores: list[dict], images: int) -> list[int]:
    """The budgets above `images` that every method scored at `images` has reached (seed 0's curve, decision 0028):
    where the study compares its methods again, at the curve's end, once all of them are there."""
    methods = {s["method"] for s in scores if s["images"] == images}
    later = {s["images"] for s in scores if s["images"] > images}
    return sorted(n for n in later if methods and methods <= {s["method"] for s in scores if s["images"] == n})


def best_end_to_end(summary: dict) -> str | None:
    """The end-to-end network of lowest mean RMSE over the seeds they all have (each one's own where they share
    none)."""
    present = [m for m in END_TO_END if m in summary]
    common = set.intersection(*(set(summary[m]["seeds"]) for m in present)) if present else set()

    def mean_rmse(m):
        return statistics.mean(r for k, r in zip(summary[m]["seeds"], summary[m]["rmse_m"])
                               if not common or k in common)
    return min(present, key=mean_rmse) if present else None


def curve(scores: list[dict]) -> dict:
    """{method: {images: [test RMSE per seed]}}."""
    out: dict = {}
    for s in scores:
        out.setdefault(s["method"], {}).setdefault(str(s["images"]), []).append(s["rmse_m"])
    return out


def curve_change(scores: list[dict]) -> dict:
    """{method: {images: {"from": the budget before, "seeds": [...], "change": relative change of RMSE}}} along the
    curve, each step over the seeds scored at both budgets (mean of each seed's RMSE_N / RMSE_before - 1): how fast
    a method still falls at the end of its curve."""
    by = {}
    for s in scores:
        by.setdefault(s["method"], {}).setdefault(s["images"], {})[s["seed"]] = s["rmse_m"]
    out: dict = {}
    for method, points in by.items():
        budgets = sorted(points)
        for before, n in zip(budgets, budgets[1:]):
            seeds = sorted(points[before].keys() & points[n].keys())
            if seeds:
                out.setdefault(method, {})[str(n)] = {"from": before, "seeds": seeds, "change": statistics.mean(
                    points[n][k] / points[before][k] - 1 for k in seeds)}
    return out


def still_falling(changes: dict, threshold: float = STEEP_CHANGE) -> dict[str, dict]:
    """{method: the last step of its curve, {"from", "to", "seeds", "change"}} (curve_change's steps) for the
    methods whose RMSE fell by more than -`threshold` over that step: those still falling steeply at the largest
    budget they have reached."""
    last = {method: max(steps, key=int) for method, steps in changes.items() if steps}
    return {method: {**changes[method][n], "to": int(n)} for method, n in last.items()
            if changes[method][n]["change"] < threshold}


def _curve_text(points: dict, changes: dict) -> str:
    """'10,000: 0.229, 30,000: 0.201 (-12%)': the mean RMSE at each budget, and its change from the budget before."""
    text = []
    for n, values in sorted(points.items(), key=lambda kv: int(kv[0])):
        change = changes.get(n)
        text.append(f"{int(n):,}: {statistics.mean(values):.3f}" + (f" ({change['change']:+.0%})" if change else ""))
    return ", ".join(text)


def iterations(scores: list[dict], images: int) -> dict:
    """{LIP method: {K: [test RMSE per seed]}} at the budget (Fig. 4a)."""
    out: dict = {}
    for s in scores:
        if s["images"] == images and s.get("rmse_m_by_iterations"):
            for k, v in s["rmse_m_by_iterations"].items():
                out.setdefault(s["method"], {}).setdefault(k, []).append(v)
    return out


def _mean_std(values: list[float], digits: int = 4) -> str:
    if len(values) == 1:
        return f"{values[0]:.{digits}f}"
    return f"{statistics.mean(values):.{digits}f} ± {statistics.stdev(values):.{digits}f}"


def markdown(doc: dict, images: int) -> str:
    left = doc["details"]["scores_left"]
    share = doc["details"]["cooldown"]
    lines = [f"# The equal-budget study ({images:,} training images per run)", "",
             f"Written by `python -m experiments.equal_budget --report`; {len(left)} score(s) of the study still to "
             "run (`python -m experiments.equal_budget --plan` lists them). A method's model at N images: its "
             f"constant-rate run to {1 - share:.0%} of N, then a cool-down over the last {share:.0%} (the rate "
             "decaying to 0; LIP+AD's adversarial), docs/decisions/0028-equal-budget-study.md.", ""]
    for scene in SCENES:
        summary = doc.get(scene)
        if not summary:
            continue
        linear = summary.get("linear", {}).get("rmse_m")
        curves, changes = doc["details"][scene]["curve_rmse_m"], doc["details"][scene]["curve_change"]
        lines += [f"## {'Table I, rooms, 200 points' if scene == 'indoor' else 'Table II, streets, 64 beams'}", "",
                  "| method | images | seeds | RMSE m | MAE m | RMSE / linear | RMSE m by training images, mean over "
                  "seeds (change from the budget before, over the seeds scored at both) |",
                  "|---|---:|---|---:|---:|---:|---|"]
        rows = {m: summary.get(m, {"curve only": True}) for m in METHODS if m in summary or m in curves}
        rows.update({m: row for m, row in summary.items() if m not in METHODS})
        for method, row in rows.items():
            if "curve only" in row:  # scored on the way, not yet at the budget
                curve_text = _curve_text(curves[method], changes.get(method, {}))
                lines.append(f"| {method} | not yet | | | | | {curve_text} |")
            else:
                name, seeds, *errors = _summary_cells(method, row, linear)
                images_text = f"{row['images']:,}" if "images" in row else ""  # a fill: no training
                curve_text = _curve_text(curves.get(method, {}), changes.get(method, {}))
                lines.append(_table_row([name, images_text, seeds, *errors, curve_text]))
        if changes:  # a curve of two budgets or more
            falling = ", ".join(f"{m} ({s['from']:,} -> {s['to']:,} images: {s['change']:+.0%})"
                                for m, s in still_falling(changes).items())
            lines += ["", f"Still falling steeply at the end of its curve (RMSE more than {-STEEP_CHANGE:.0%} below "
                      f"the budget before, decision 0028): {falling or 'none'}."]
        lines += tuning_table(doc["details"][scene]["tuning_val_rmse_m"])
        lines += _paired_table(doc["details"][scene]["paired_tests"])
        for n, at in doc["details"][scene]["larger_budgets"].items():
            lines += _larger_budget_section(int(n), at["summary"], at["paired_tests"])
        lines.append("")
    return "\n".join(lines)


def _paired_table(tests: list[dict]) -> list[str]:
    if not tests:
        return []
    return ["", "| paired test a vs b | seeds | frames | mean RMSE a / b m | a better on frames | Wilcoxon p | "
            "t-test p | a better on seeds | a - b m, 95 % over seeds and frames | verdict |",
            "|---|---|---:|---:|---:|---:|---:|---:|---|---|"] + [
        f"| {t['a']} vs {t['b']} | {','.join(map(str, t['seeds']))} | {t['frames']} | "
        f"{t['mean_rmse_a_m']:.4f} / {t['mean_rmse_b_m']:.4f} | {t['a_better_frames']} | "
        f"{t['wilcoxon_p']:.2g} | {t['ttest_p']:.2g} | {t['a_better_seeds']} of {len(t['seeds'])} | "
        f"{t['diff_interval_m'][0]:+.4f} to {t['diff_interval_m'][1]:+.4f} | {t['verdict']} |" for t in tests]


def _larger_budget_section(images: int, summary: dict, tests: list[dict]) -> list[str]:
    """Every method again at a larger budget of the curve (larger_budgets), with its paired tests."""
    linear = summary.get("linear", {}).get("rmse_m")
    seeds = sorted({k for row in summary.values() for k in row.get("seeds", ())})
    lines = ["", f"### Every method at {images:,} images (seed{'s' * (len(seeds) != 1)} "
             f"{','.join(map(str, seeds))}; the curve's end)", "",
             "| method | seeds | RMSE m | MAE m | RMSE / linear |", "|---|---|---:|---:|---:|"]
    lines += [_table_row(_summary_cells(method, row, linear)) for method, row in summary.items()]
    return lines + _paired_table(tests)


def _table_row(cells: list[str]) -> str:
    """'| a | | b |': a markdown table row, an empty cell as '| |'."""
    return "|" + "|".join(f" {c} " if c else " " for c in cells) + "|"


def _summary_cells(method: str, row: dict, linear: float | None) -> list[str]:
    """[name, seeds, RMSE m, MAE m, RMSE / linear] of a scene_summary row: a trained method's mean +- std over its
    seeds, or a fill's (no training) single figures."""
    if "seeds" not in row:
        return [f"{method} (no training)", "", f"{row['rmse_m']:.4f}", f"{row['mae_m']:.4f}",
                f"{row['rmse_m'] / linear:.2f}x"]
    ratio = f"{statistics.mean(row['rmse_m']) / linear:.2f}x" if linear else ""
    return [method, ",".join(map(str, row["seeds"])), _mean_std(row["rmse_m"]), _mean_std(row["mae_m"]), ratio]


def best_rate(rmse: dict[float, float]) -> float:
    """The learning rate of the lowest validation RMSE, a non-finite one (a diverged run) counting as the worst."""
    return min(rmse, key=lambda r: rmse[r] if math.isfinite(rmse[r]) else math.inf)


def tuning_table(tuning: dict) -> list[str]:
    """What tuning tried: each trunk's validation RMSE (m) per learning rate, the chosen one in bold."""
    if not tuning:
        return []
    rates = sorted({float(r) for scores in tuning.values() for r in scores})
    lines = ["", "Tuning (validation RMSE m after the tuning images, seed 0; the lowest chosen, in bold):", "",
             "| method | " + " | ".join(f"{r:g}" for r in rates) + " |", "|---|" + "---:|" * len(rates)]
    for method, scores in tuning.items():
        by_rate = {float(r): s["val_rmse_m"] for r, s in scores.items()}
        best = best_rate(by_rate)
        cells = [("" if r not in by_rate else f"**{by_rate[r]:.3f}**" if r == best else f"{by_rate[r]:.3f}")
                 for r in rates]
        lines.append(f"| {method} | " + " | ".join(cells) + " |")
    return lines


def method_colour(method: str) -> str:
    """A study method's colour, the same in every figure of the report."""
    return f"C{METHODS.index(method)}"


def plot_curve(path: pathlib.Path, curves: dict, classical: dict, title: str) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter, NullFormatter

    fig = Figure(figsize=(7, 4), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for method, marker in zip(METHODS, "osD^vPX"):  # a marker each: methods level at a budget stay visible
        if method not in curves:
            continue
        xs = sorted(curves[method], key=int)
        mean = [statistics.mean(curves[method][x]) for x in xs]
        line, = ax.plot([int(x) for x in xs], mean, marker=marker, fillstyle="none", label=method,
                        color=method_colour(method))
        lo = [min(curves[method][x]) for x in xs]
        hi = [max(curves[method][x]) for x in xs]
        ax.fill_between([int(x) for x in xs], lo, hi, color=line.get_color(), alpha=0.15)
    for name, style in (("linear", "--"), ("nearest", ":")):
        if name in classical:
            ax.axhline(classical[name]["rmse_m"], color="grey", linestyle=style, label=f"{name} fill")
    ax.set_xscale("log")  # budgets a factor apart; RMSE on a linear axis, whose ticks a reader can read off
    ax.set_xticks(sorted({int(x) for c in curves.values() for x in c}))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:,.0f}"))
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("training images")
    ax.set_ylabel("test RMSE (m), mean over seeds, band min-max")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))  # beside the curves, not over them
    fig.tight_layout()
    fig.savefig(path)


def plot_iterations(path: pathlib.Path, per_k: dict, title: str, linear_rmse_m: float | None = None) -> None:
    """Fig. 4a: each LIP method's test RMSE after its first K iterations (the trained K = 3 solver stopped early),
    mean and band over the seeds; the linear fill as a dashed line."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5, 3.6), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for method, by_k in sorted(per_k.items(), key=lambda item: METHODS.index(item[0])):
        ks = sorted(by_k, key=int)
        mean = np.array([statistics.mean(by_k[k]) for k in ks])
        std = np.array([statistics.stdev(by_k[k]) if len(by_k[k]) > 1 else 0.0 for k in ks])
        n = len(by_k[ks[0]])
        line, = ax.plot([int(k) for k in ks], mean, marker="o", label=f"{method} ({n} seed{'s' * (n != 1)})",
                        color=method_colour(method))
        ax.fill_between([int(k) for k in ks], mean - std, mean + std, color=line.get_color(), alpha=0.2)
    if linear_rmse_m is not None:
        ax.axhline(linear_rmse_m, color="0.4", linestyle="--", linewidth=1, label="linear fill")
    ax.set_xlabel("ADMM iterations K")
    ax.set_ylabel("test RMSE (m), mean ± std over seeds")
    ax.set_xticks(sorted({int(k) for by_k in per_k.values() for k in by_k}))
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)


def write_report(study, scores_left: list[str], keep, out: pathlib.Path | None = None) -> dict:
    """Writes the report of `study` (an experiments.equal_budget.Study, whose `scores_left` are still to run) into
    `out` (default: <root>/report), from the scores `keep(score)` admits (equal_budget.current: those made at the
    tuned rate and the study's cool-down)."""
    out = pathlib.Path(out) if out is not None else study.root / "report"
    out.mkdir(parents=True, exist_ok=True)
    doc: dict = {"details": {"scores_left": scores_left, "cooldown": study.cooldown}}
    for scene in SCENES:
        # a score made another way (another rate or cool-down; the study remakes it when it gets there) is left out
        scores = [s for s in load_scores(study.scores, scene) if keep(s)]
        classical_path = study.scores_dir(scene) / "classical.json"
        classical = json.loads(classical_path.read_text()) if classical_path.exists() else {}
        if not scores:
            continue
        doc[scene], tests = compare(scores, classical, study.images)
        tuning_path = study.scores_dir(scene) / "tuning.json"
        doc["details"][scene] = {
            "tuning_val_rmse_m": json.loads(tuning_path.read_text()) if tuning_path.exists() else {},
            "curve_rmse_m": curve(scores), "curve_change": curve_change(scores),
            "rmse_m_by_iterations": iterations(scores, study.images),
            "paired_tests": tests, "test_frames": len(scores[0]["per_image"]),
            "larger_budgets": {str(n): dict(zip(("summary", "paired_tests"), compare(scores, classical, n)))
                               for n in larger_budgets(scores, study.images)},
        }
        names = {"indoor": "rooms, 200 points (Table I)", "outdoor": "streets, 64 beams (Table II)"}
        plot_curve(out / f"equal_budget_curve_{scene}.png", doc["details"][scene]["curve_rmse_m"], classical,
                   names[scene])
        if doc["details"][scene]["rmse_m_by_iterations"]:
            plot_iterations(out / f"equal_budget_iterations_{scene}.png", doc["details"][scene][
                "rmse_m_by_iterations"], f"{names[scene]}, {study.images:,} images",
                classical.get("linear", {}).get("rmse_m"))
    for name, text in (("equal_budget.json", json.dumps(doc, indent=1) + "\n"),
                       ("equal_budget.md", markdown(doc, study.images))):
        with written_whole(out / name) as tmp:
            tmp.write_text(text)
    print(f"[study] report in {out}: equal_budget.json, equal_budget.md and figures", flush=True)
    return doc
