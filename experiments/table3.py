"""The paper's Table III: 200 and 500 points on KITTI odometry (or the outdoor split) and on TartanAir (or the
synthetic indoor split); RMSE (m), REL, delta1 (%).

    python -m experiments.table3 [--variant smoke] [--out out/table3]

Without data both blocks run on the embedded synthetic data: the outdoor split at 128x416 with exactly N points
drawn among valid pixels, and the indoor split at 256x320 for the TartanAir block. --kitti-odometry-dir uses the
real scans (lipjax.data.kitti_odometry: the projected scan is the ground truth and N of its points the input, as
in Ma et al.), --tartanair-dir a TartanAir root (test split by trajectory).
About 6 minutes by default.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import pathlib
import sys

from experiments.common import evaluate_methods, line_plot, synthetic_outdoor_test
from lipjax.console import ArgumentParser, run_main
from lipjax.data.protocols import ProtocolView, get_protocol
from lipjax.data.sampling import sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.evaluate import markdown_table
from lipjax.methods import available_methods
from lipjax.utils import enable_compilation_cache

PROG = f"python -m {__spec__.name}"  # as run: the same when imported

COLUMNS = ("rmse_m", "rel", "delta1_pct", "mae_m", "ms_per_frame")


@dataclasses.dataclass(frozen=True)
class Config:
    point_counts: tuple[int, ...] = (200, 500)
    limit: int | None = 30
    methods: tuple[str, ...] | None = None
    seed: int = 0


VARIANTS = {"default": Config(), "smoke": Config(point_counts=(200,), limit=1, methods=("nearest",))}


def plot_blocks(doc: dict, point_counts, out: pathlib.Path) -> list[pathlib.Path]:
    """One PNG per data block of results.json: every method's RMSE (m) against the number of samples."""
    paths = []
    blocks = sorted({key.rsplit(", ", 1)[0] for key in doc["blocks"]})
    for i, block in enumerate(blocks):
        per_n = [doc["blocks"][f"{block}, {n} points"] for n in point_counts]
        series = {m: [rows[m]["rmse_m"] for rows in per_n] for m in per_n[0]}
        paths.append(out / f"table3_block{i}.png")
        line_plot(paths[-1], list(point_counts), series, xlabel="number of samples", ylabel="RMSE (m)", title=block,
                  logy=True)
    return paths


def main(argv=None) -> dict:
    p = ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--variant", choices=sorted(VARIANTS), default="default")
    p.add_argument("--kitti-odometry-dir", help="KITTI odometry root (sequences/<SS>/{image_2,velodyne,calib.txt})")
    p.add_argument("--sequences", default="08", help="odometry sequences to evaluate, comma-separated")
    p.add_argument("--tartanair-dir", help="TartanAir root (<env>/<Easy|Hard>/<Pxxx>/...); test split by trajectory")
    p.add_argument("--out", default="out/table3")
    args = p.parse_args(argv)
    enable_compilation_cache()
    config = VARIANTS[args.variant]
    if args.kitti_odometry_dir:
        from lipjax.data.kitti_odometry import KittiOdometry

        protocol = get_protocol("kitti_paper")
        odometry = ProtocolView(KittiOdometry(args.kitti_odometry_dir, tuple(args.sequences.split(","))), protocol)
        blocks = {"KITTI odometry": ("outdoor", odometry, protocol)}
    else:
        blocks = {"outdoor (KITTI odometry stand-in)": ("outdoor", synthetic_outdoor_test(),
                                                        get_protocol("synthetic_outdoor"))}
    if args.tartanair_dir:
        from lipjax.data.tartanair import TartanAirDataset

        protocol = get_protocol("tartanair")
        blocks["TartanAir test"] = ("indoor", ProtocolView(TartanAirDataset(args.tartanair_dir, "test"), protocol),
                                    protocol)
    else:
        blocks["indoor (TartanAir stand-in)"] = ("indoor", SyntheticDataset("indoor", "test"),
                                                 get_protocol("synthetic_indoor"))
        print("[lipjax] no --tartanair-dir: the TartanAir block runs on the embedded synthetic indoor test split.")
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    doc, md = {"meta": {"seed": config.seed, "limit": config.limit, "variant": args.variant}, "blocks": {}}, []
    for block, (scene, dataset, protocol) in blocks.items():
        methods = list(config.methods or available_methods(scene))
        for n in config.point_counts:
            results = evaluate_methods(methods, dataset, sampler_from_spec(f"uniform:{n}"),
                                       min_depth_m=protocol.min_depth_m, max_depth_m=protocol.max_depth_m,
                                       limit=config.limit, seed=config.seed)
            key = f"{block}, {n} points"
            doc["blocks"][key] = {m: {**r.metrics, "num_images": r.num_images, "sampler": f"uniform:{n}",
                                      "protocol": protocol.name} for m, r in results.items()}
            md.append(f"### {key}\n\n{markdown_table(results, COLUMNS)}\n")
    (out / "results.json").write_text(json.dumps(doc, indent=1, default=lambda x: None))
    (out / "table.md").write_text("# Table III (embedded data)\n\n" + "\n".join(md))
    plot_blocks(doc, config.point_counts, out)
    print("\n".join(md))
    return doc


if __name__ == "__main__":
    sys.exit(run_main(PROG, main))
