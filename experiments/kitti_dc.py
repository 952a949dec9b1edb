"""The paper's Table II: KITTI depth completion (64-beam LiDAR), RMSE / MAE in mm, iRMSE / iMAE in 1/km, params in M.

    python -m experiments.kitti_dc                                    # KITTI if found, else the synthetic split
    python -m experiments.kitti_dc --data-dir /data/kitti_depth       # KITTI DC val_selection_cropped
    python -m experiments.kitti_dc --variant smoke --out /tmp/k

Without --data-dir, KITTI is looked for in $LIPJAX_KITTI_DIR, then data/kitti_depth, ~/data/kitti_depth and
/data/kitti_depth (lipjax.data.locate); when it is not there, the run uses the embedded synthetic outdoor test split
at 128x416 (KITTI aspect) with a simulated HDL-64E pattern (lipjax.data.sampling.LidarSampler.hdl64) and says so.
On KITTI it reads
depth_selection/val_selection_cropped (the kitti_selection source of lipjax.data.sources, as training reads data)
and uses the real velodyne_raw scans as input (protocol kitti_selection).
Writes results.json, table.md and figure.png into --out (default out/kitti_dc). About 3 minutes by default.
"""
from __future__ import annotations

import argparse
import dataclasses
import pathlib
import sys

from experiments.common import (
    evaluate_methods,
    load_methods,
    model_columns,
    qualitative_figure,
    synthetic_outdoor_test,
    write_results,
)
from lipjax.console import ArgumentParser, positive_int, run_main
from lipjax.data.locate import find_data_root, not_found_note
from lipjax.data.protocols import get_protocol
from lipjax.data.sampling import sampler_from_spec
from lipjax.evaluate import open_eval_source
from lipjax.methods import available_methods
from lipjax.utils import enable_compilation_cache

PROG = f"python -m {__spec__.name}"  # as run: the same when imported

COLUMNS = ("rmse_mm", "mae_mm", "irmse_1_per_km", "imae_1_per_km", "mae_sampled_m", "ms_per_frame")


@dataclasses.dataclass(frozen=True)
class Config:
    sampler: str = "lidar:hdl64"
    limit: int | None = 50
    methods: tuple[str, ...] | None = None
    seed: int = 0


VARIANTS = {"default": Config(), "full": Config(limit=None), "smoke": Config(limit=2, methods=("nearest", "ip_basic"))}


def main(argv=None) -> dict:
    p = ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data-dir", help="KITTI depth completion root holding depth_selection/val_selection_cropped")
    p.add_argument("--variant", choices=sorted(VARIANTS), default="default")
    p.add_argument("--methods", help="comma-separated method names (default: all available for outdoor scenes)")
    p.add_argument("--limit", type=positive_int)
    p.add_argument("--out", default="out/kitti_dc")
    args = p.parse_args(argv)
    enable_compilation_cache()
    config = VARIANTS[args.variant]
    if args.limit is not None:
        config = dataclasses.replace(config, limit=args.limit)
    methods = args.methods.split(",") if args.methods else list(config.methods or available_methods("outdoor"))
    data_dir = args.data_dir or find_data_root("kitti")
    if data_dir:
        source, protocol = open_eval_source("kitti_selection", data_dir, sampler="input")
        dataset, sampler, sampler_name = source.dataset, source.sampler, "real velodyne_raw"
        data_name = f"KITTI DC val_selection_cropped ({data_dir})"
        print(f"[lipjax] KITTI depth completion from {data_dir}", flush=True)
    else:
        protocol = get_protocol("synthetic_outdoor")
        dataset = synthetic_outdoor_test()
        sampler, sampler_name = sampler_from_spec(config.sampler), config.sampler
        data_name = "embedded synthetic outdoor test split, 128x416 (lipjax.data.synthetic)"
        print(f"[lipjax] KITTI not found ({not_found_note('kitti')}), so this runs on the embedded synthetic outdoor "
              f"test split with a simulated {config.sampler} pattern.", flush=True)
    completers = load_methods(methods)
    results = evaluate_methods(completers, dataset, sampler, min_depth_m=protocol.min_depth_m,
                               max_depth_m=protocol.max_depth_m, limit=config.limit, seed=config.seed)
    n = next(iter(results.values())).num_images
    meta = {"title": f"Table II: {data_name}", "description": f"input {sampler_name}; {n} images; GT in "
            f"[{protocol.min_depth_m}, {protocol.max_depth_m}] m; RMSE/MAE in mm, iRMSE/iMAE in 1/km, params in M; "
            "train_images: the images a learned model was trained on.",
            "dataset": data_name, "protocol": protocol.name, "sampler": sampler_name, "seed": config.seed,
            "num_images": n, "variant": args.variant}
    out = pathlib.Path(args.out)
    table = write_results(out, results, meta, COLUMNS, model_columns(completers))
    frames = [dataset[i] for i in range(2 if args.variant != "smoke" else 1)]
    qualitative_figure(out / "figure.png", frames, [sampler(s, config.seed) for s in frames], completers, results,
                       max_depth_m=protocol.max_depth_m, max_error_m=5.0, sparse_title=f"input ({sampler_name})")
    print(table)
    return {name: r.metrics for name, r in results.items()}


if __name__ == "__main__":
    sys.exit(run_main(PROG, main))
