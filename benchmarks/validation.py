"""Shipped models against every hand-crafted method on the synthetic validation split they were trained with.

Run by hand (not a test):

    python -m benchmarks.validation --scene indoor    # 32 val frames 256x320, uniform:200
    python -m benchmarks.validation --scene outdoor   # 32 val frames 128x416, lidar:hdl64

The frames, sizes and sampler are those of the scene's training config (experiments/configs/, `data.val_*`),
so this is the table behind "the shipped weights beat LIP+Wavelet and every classical baseline on the synthetic
validation split". Metrics per image over valid ground truth in the scene protocol's depth range (indoor
(0, 10] m, outdoor (0, 80] m), then averaged; sampler seed 0. Prints a Markdown table.
"""
from __future__ import annotations

import argparse

from experiments.common import evaluate_methods
from experiments.configs import CONFIGS
from lipjax.data.protocols import get_protocol
from lipjax.data.sampling import sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.evaluate import markdown_table
from lipjax.methods import available_methods
from lipjax.utils import enable_compilation_cache

COLUMNS = ("rmse_m", "mae_m", "rel", "delta1_pct", "irmse_1_per_km", "mae_sampled_m", "ms_per_frame")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", choices=("indoor", "outdoor"), default="indoor")
    ap.add_argument("--methods", help="comma-separated lipjax.methods names (default: all for the scene)")
    args = ap.parse_args(argv)
    enable_compilation_cache()
    data = CONFIGS[f"lip_cnn_{args.scene}"].data
    dataset = SyntheticDataset(data.kind, "val", size=data.val_images, height=data.height, width=data.width)
    protocol = get_protocol(f"synthetic_{args.scene}")
    methods = args.methods.split(",") if args.methods else available_methods(args.scene)
    print(f"[lipjax] synthetic {args.scene} val: {len(dataset)} frames {data.height}x{data.width}, "
          f"sampler {data.val_sampler}, depth ({protocol.min_depth_m}, {protocol.max_depth_m}] m")
    results = evaluate_methods(methods, dataset, sampler_from_spec(data.val_sampler), min_depth_m=protocol.min_depth_m,
                               max_depth_m=protocol.max_depth_m, limit=None)
    print(markdown_table(results, COLUMNS))


if __name__ == "__main__":
    main()
