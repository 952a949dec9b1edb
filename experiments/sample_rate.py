"""The paper's Fig. 4b / 4c: MAE over all pixels and MAE on the sampled pixels against the number of samples.

    python -m experiments.sample_rate [--scene indoor|outdoor] [--variant smoke] [--out out/sample_rate]

Fig. 4c is the data-consistency claim: LIP's x-update keeps the measured depths, while end-to-end networks blur
them. Writes results.json, table.md, mae_all.png and mae_sampled.png. About 8 minutes by default (indoor).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import pathlib
import sys

from experiments.common import evaluate_methods, line_plot, synthetic_outdoor_test
from lipjax.console import ArgumentParser, run_main
from lipjax.data.protocols import get_protocol
from lipjax.data.sampling import sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.methods import available_methods
from lipjax.utils import enable_compilation_cache

PROG = f"python -m {__spec__.name}"  # as run: the same when imported


@dataclasses.dataclass(frozen=True)
class Config:
    point_counts: tuple[int, ...] = (50, 100, 200, 500, 1000, 2000)
    limit: int | None = 20
    methods: tuple[str, ...] | None = None
    seed: int = 0


VARIANTS = {"default": Config(), "smoke": Config(point_counts=(50, 200), limit=1, methods=("nearest", "linear"))}


def plot_curves(table: dict[str, dict[int, dict[str, float]]], xs: list[int], out: pathlib.Path, title: str) -> None:
    """mae_all.png (log scale: the methods' errors span orders of magnitude) and mae_sampled.png (linear: it
    holds zeros) from the table of main (method -> N -> metric)."""
    for key, fname, label, logy in (("mae_all_m", "mae_all.png", "MAE over all pixels (m)", True),
                                    ("mae_sampled_m", "mae_sampled.png", "MAE on sampled pixels (m)", False)):
        line_plot(out / fname, xs, {m: [table[m][n][key] for n in xs] for m in table}, xlabel="number of samples",
                  ylabel=label, title=title, logx=True, logy=logy)


def main(argv=None) -> dict:
    p = ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", choices=("indoor", "outdoor"), default="indoor")
    p.add_argument("--variant", choices=sorted(VARIANTS), default="default")
    p.add_argument("--out", default="out/sample_rate")
    args = p.parse_args(argv)
    enable_compilation_cache()
    config = VARIANTS[args.variant]
    dataset = SyntheticDataset("indoor", "test") if args.scene == "indoor" else synthetic_outdoor_test()
    protocol = get_protocol(f"synthetic_{args.scene}")
    methods = list(config.methods or available_methods(args.scene))
    table: dict[str, dict[int, dict[str, float]]] = {m: {} for m in methods}
    for n in config.point_counts:
        results = evaluate_methods(methods, dataset, sampler_from_spec(f"uniform:{n}"),
                                   min_depth_m=protocol.min_depth_m, max_depth_m=protocol.max_depth_m,
                                   limit=config.limit, seed=config.seed)
        for m, r in results.items():
            table[m][n] = {"mae_all_m": r.metrics["mae_all_m"], "mae_sampled_m": r.metrics["mae_sampled_m"]}
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    xs = list(config.point_counts)
    plot_curves(table, xs, out, title=f"synthetic {args.scene} test, {config.limit} images")
    (out / "results.json").write_text(json.dumps({"meta": dataclasses.asdict(config) | {"scene": args.scene},
                                                  "methods": table}, indent=1))
    lines = ["| method | " + " | ".join(f"N={n} all / sampled" for n in xs) + " |", "|---|" + "---:|" * len(xs)]
    for m in methods:
        lines.append(f"| {m} | " + " | ".join(f"{table[m][n]['mae_all_m']:.3f} / {table[m][n]['mae_sampled_m']:.4f}"
                                             for n in xs) + " |")
    (out / "table.md").write_text("MAE (m) over all pixels / on the sampled pixels\n\n" + "\n".join(lines) + "\n")
    print("\n".join(lines))
    return table


if __name__ == "__main__":
    sys.exit(run_main(PROG, main))
